//! `topovox remesh MESH -o OUT`: a watertight mesh (see `topovox_job::remesh`).

use std::time::Instant;

use anyhow::Result;
use serde_json::json;
use topovox_job::remesh::{format_of, RemeshJob};
use topovox_job::Choice;

use crate::args::RemeshArgs;
use crate::progress::Bar;

pub fn run(a: &RemeshArgs) -> Result<()> {
    let t_total = Instant::now();
    let opts = &a.remesh.options;
    let format = format_of(a.format.map(|f| f.name()), &a.output)?;
    let job = RemeshJob::prepare(opts, &a.output, format, std::slice::from_ref(&a.mesh))?;
    let pool = topovox_job::pool_for(opts.run.threads, "--threads")?;
    let threads = pool.current_num_threads();

    let bar = Bar::new(a.quiet || a.json);
    let (loaded, load_s) = crate::console::load_mesh(&a.mesh, &opts.run.read_options(), &bar)?;
    let name = a.mesh.display().to_string();
    let done = pool.install(|| job.run(&a.output, &loaded, &name, Some(&bar), None))?;
    let r = &done.made;
    for w in &r.warnings {
        eprintln!("topovox: warning: {w}");
    }
    bar.finish();
    let total_s = t_total.elapsed().as_secs_f64();
    let (g, dims) = (r.grid, r.grid.dims());
    let o = g.origin();
    if a.json {
        let facts = r.summary();
        let extra = json!({
            "origin": [o.x, o.y, o.z],
            "voxel_size": topovox_io::size_json(g.voxel_size()),
            "dims": dims,
            "surface": opts.shell.surface.name(),
            "vertices": r.vertices,
            "triangles": r.triangles,
            "load_s": load_s,
            "write_s": done.write_s,
            "total_s": total_s,
            "peak_memory_bytes": topovox_job::peak_memory(),
            "threads": threads,
            "input": name,
            "output": a.output.display().to_string(),
            "format": format.name(),
            "mesh": {"vertices": loaded.report.vertices, "triangles": loaded.report.triangles, "segments": loaded.report.segments},
            "warnings": loaded.warnings,
        });
        let j = crate::console::summary_json(facts, extra);
        crate::console::print_stdout(&j.to_string())?;
    } else if !a.quiet {
        let certified = match &r.certificate {
            Some(c) => format!("; certified: closed, manifold, oriented, no self-intersection, genus {}", c.genus.unwrap_or(-1)),
            None => String::new(),
        };
        crate::console::print_stdout(&format!(
            "remesh: {} triangles, {} vertices ({} surface around {} inside voxels, {}, {} parts) on grid {}x{}x{}{certified}; total {:.2} s -> {}",
            r.triangles,
            r.vertices,
            opts.shell.surface.name(),
            r.facts.inside_voxels,
            r.facts.inside,
            r.facts.parts,
            dims[0],
            dims[1],
            dims[2],
            total_s,
            a.output.display()
        ))?;
    }
    Ok(())
}
