//! What the commands print: summary lines on stdout.

use std::io::Write;

use anyhow::Result;

/// Prints a line on stdout; a closed pipe surfaces as an error that `main` ignores.
pub fn print_stdout(s: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{s}")?;
    out.flush()?;
    Ok(())
}

/// `s` as one line a terminal shows as it is: control characters
/// (a newline in a file name), and the bidirectional controls that would
/// reorder what follows them, are written as escapes (`\n`, `\u{202e}`);
/// everything else, other scripts included, is kept.
pub fn one_line(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        let bidi = matches!(c, '\u{061c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
        if c.is_control() || bidi {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// Prints a warning on stderr, in one line (see [`one_line`]).
pub fn warn(message: &str) {
    eprintln!("topovox: warning: {}", one_line(message));
}

/// A command's JSON summary: the job's facts, then what the command adds
/// (its times, paths and inputs) over them.
pub fn summary_json(facts: serde_json::Value, extra: serde_json::Value) -> serde_json::Value {
    let mut j = facts;
    if let (Some(obj), serde_json::Value::Object(add)) = (j.as_object_mut(), extra) {
        obj.extend(add);
    }
    j
}

/// Reads the mesh a command works on, the bar showing it: the mesh and
/// the seconds it took; its warnings go to stderr, naming the file.
pub fn load_mesh(
    path: &std::path::Path,
    opts: &topovox_io::ReadOptions,
    bar: &crate::progress::Bar,
) -> Result<(topovox_io::LoadedMesh, f64)> {
    bar.phase("loading mesh");
    let t = std::time::Instant::now();
    let loaded = topovox_io::read_mesh(path, opts)?;
    let load_s = t.elapsed().as_secs_f64();
    for w in &loaded.warnings {
        warn(&format!("{}: {w}", path.display()));
    }
    Ok((loaded, load_s))
}
