//! The panic fence around third-party parsers: a panic in one becomes an
//! ordinary error naming the format, never a crash.

use crate::error::ErrorKind;

thread_local! {
    static FENCED: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
}

/// True while this thread runs a third-party parser inside the panic fence: a
/// panic hook can stay silent, since the panic becomes an ordinary error.
pub fn panic_is_fenced() -> bool {
    FENCED.with(|f| f.get() > 0)
}

/// Runs a third-party parser so that a panic inside it (a bug in that
/// crate, triggered by malformed input) becomes an error naming the format
/// instead of aborting the program.
pub(crate) fn fence<T>(format: &'static str, f: impl FnOnce() -> Result<T, ErrorKind>) -> Result<T, ErrorKind> {
    fenced(f).unwrap_or_else(|msg| Err(ErrorKind::malformed(format, format!("the parser crashed on it ({msg})"))))
}

/// Runs `f` (a parser outside topovox-io, such as the spray cloud's) inside
/// the panic fence: a panic becomes `Err` with its message, and the panic
/// hook stays silent ([`panic_is_fenced`]).
pub fn fenced<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    FENCED.with(|c| c.set(c.get() + 1));
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    FENCED.with(|c| c.set(c.get() - 1));
    r.map_err(|p| {
        p.downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown cause".into())
    })
}
