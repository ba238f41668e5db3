//! `topovox sample MESH -o OUT.npz`: training samples (see `topovox_job::sample`).

use std::time::Instant;

use anyhow::Result;
use serde_json::json;

use crate::args::SampleArgs;
use crate::progress::Bar;

pub fn run(a: &SampleArgs) -> Result<()> {
    let t_total = Instant::now();
    let opts = &a.sample.options;
    topovox_job::output::check_output_path(&a.output)?;
    topovox_io::atomic::refuse_overwriting_inputs(&a.output, std::slice::from_ref(&a.mesh))?;
    let pool = topovox_job::pool_for(opts.run.threads, "--threads")?;
    let threads = pool.current_num_threads();
    let bar = Bar::new(a.quiet || a.json);
    let (loaded, load_s) = crate::console::load_mesh(&a.mesh, &opts.run.read_options(), &bar)?;
    topovox_io::atomic::refuse_overwriting_inputs(&a.output, &loaded.sources)?;
    let name = a.mesh.display().to_string();
    bar.phase("sampling");
    let s = pool.install(|| topovox_job::sample::sample(&loaded, &name, opts))?;
    bar.phase("writing");
    let t = Instant::now();
    s.write(&a.output)?;
    let write_s = t.elapsed().as_secs_f64();
    bar.finish();
    let total_s = t_total.elapsed().as_secs_f64();
    let mut warnings = loaded.warnings.clone();
    warnings.extend(s.sign_warning(&name));
    if !a.json {
        for w in &warnings[loaded.warnings.len()..] {
            crate::console::warn(w);
        }
    }
    if a.json {
        let extra = json!({
            "load_s": load_s,
            "write_s": write_s,
            "total_s": total_s,
            "threads": threads,
            "input": name,
            "output": a.output.display().to_string(),
            "format": "npz",
            "peak_memory_bytes": topovox_job::peak_memory(),
            "mesh": {"vertices": loaded.report.vertices, "triangles": loaded.report.triangles, "segments": loaded.report.segments},
            "warnings": warnings,
        });
        let j = crate::console::summary_json(s.summary(), extra);
        crate::console::print_stdout(&j.to_string())?;
    } else if !a.quiet {
        let inside = s.samples.occupancy.iter().filter(|&&o| o).count();
        crate::console::print_stdout(&format!(
            "sample: {} points ({} inside, sign by {}); total {:.2} s -> {}",
            s.samples.points.len(),
            inside,
            s.summary()["sign"].as_str().unwrap_or("?"),
            total_s,
            a.output.display()
        ))?;
    }
    Ok(())
}
