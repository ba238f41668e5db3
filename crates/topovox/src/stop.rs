//! [`Stop`]: how a front end asks long work to end early. On the ground
//! floor, so every algorithm can look at it without reaching into another.

/// A request to stop long work early: a front end (Python on Ctrl-C)
/// requests it from another thread, and the work checks it between slabs,
/// tiles, triangle chunks and brick rows, skipping what is left. Work that
/// was stopped returns an incomplete result: whoever requested the stop
/// must discard it (`topovox-job` turns it into an `Interrupted` error).
#[derive(Debug, Default)]
pub struct Stop(std::sync::atomic::AtomicBool);

impl Stop {
    /// Not requested yet.
    pub fn new() -> Stop {
        Stop::default()
    }

    /// Asks the work to stop.
    pub fn request(&self) {
        self.0.store(true, std::sync::atomic::Ordering::Relaxed);
    }

    /// Whether a stop was requested.
    #[inline]
    pub fn requested(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
}
