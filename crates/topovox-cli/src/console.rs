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
