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
        eprintln!("topovox: warning: {}: {w}", path.display());
    }
    Ok((loaded, load_s))
}
