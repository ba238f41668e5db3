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

/// A command's JSON summary: the job's facts, then what the command adds
/// (its times, paths and inputs) over them.
pub fn summary_json(facts: serde_json::Value, extra: serde_json::Value) -> serde_json::Value {
    let mut j = facts;
    if let (Some(obj), serde_json::Value::Object(add)) = (j.as_object_mut(), extra) {
        obj.extend(add);
    }
    j
}
