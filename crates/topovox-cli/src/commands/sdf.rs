//! `topovox sdf MESH -o OUT`: a distance field (see `topovox_job::distance`).

use std::time::Instant;

use anyhow::Result;
use serde_json::json;
use topovox_job::distance::DistanceFormat;
use topovox_job::{Choice, SdfJob};

use crate::args::SdfArgs;
use crate::progress::Bar;

pub fn run(a: &SdfArgs) -> Result<()> {
    let t_total = Instant::now();
    // Everything that does not need the mesh first.
    let opts = &a.sdf.options;
    let format = DistanceFormat::of(a.format.map(|f| f.name()), &a.output)?;
    let job = SdfJob::prepare(opts, &a.output, format, std::slice::from_ref(&a.mesh))?;
    let pool = topovox_job::pool_for(opts.run.threads, "--threads")?;
    let threads = pool.current_num_threads();

    let bar = Bar::new(a.quiet || a.json);
    let (loaded, load_s) = crate::console::load_mesh(&a.mesh, &opts.run.read_options(), &bar)?;
    let name = a.mesh.display().to_string();
    let done = pool.install(|| job.run(&a.output, &loaded, &name, Some(&bar), None))?;
    let (sdf, write_s) = (&done.sdf, done.write_s);
    for w in &sdf.warnings {
        eprintln!("topovox: warning: {w}");
    }
    bar.finish();
    let total_s = t_total.elapsed().as_secs_f64();
    let (g, dims) = (sdf.grid, sdf.grid.dims());
    let o = g.origin();
    if a.json {
        let extra = json!({
            "origin": [o.x, o.y, o.z],
            "voxel_size": topovox_io::size_json(g.voxel_size()),
            "dims": dims,
            "load_s": load_s,
            "write_s": write_s,
            "total_s": total_s,
            "threads": threads,
            "input": name,
            "output": a.output.display().to_string(),
            "format": format.name(),
            "mesh": {"vertices": loaded.report.vertices, "triangles": loaded.report.triangles, "segments": loaded.report.segments},
            "warnings": loaded.warnings,
        });
        let j = crate::console::summary_json(sdf.facts.clone(), extra);
        crate::console::print_stdout(&j.to_string())?;
    } else if !a.quiet {
        let kind = if sdf.signed {
            format!("signed distances (inside by {})", sdf.sign.as_deref().unwrap_or("?"))
        } else {
            "unsigned distances".into()
        };
        crate::console::print_stdout(&format!(
            "sdf: {} voxels stored ({}, band {}) on grid {}x{}x{} (origin {}, {}, {}; voxel size {}); distances in {:.1} ms; total {:.2} s -> {}",
            sdf.field.band.count(),
            kind,
            opts.field.band,
            dims[0],
            dims[1],
            dims[2],
            o.x,
            o.y,
            o.z,
            g.voxel_size(),
            sdf.distance_s * 1e3,
            total_s,
            a.output.display()
        ))?;
    }
    Ok(())
}
