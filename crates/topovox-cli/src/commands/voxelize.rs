//! `topovox voxelize MESH -o OUT`.

use std::time::Instant;

use anyhow::Result;
use serde_json::json;
use topovox_job::output::output_format;
use topovox_job::{Choice, Done, VoxelizeJob};

use crate::args::VoxelizeArgs;
use crate::progress::Bar;

pub fn run(a: &VoxelizeArgs) -> Result<()> {
    let t_total = Instant::now();
    // Everything that does not need the mesh first; nothing is read or
    // written before we know no output is an input.
    let opts = &a.job.options;
    let format = output_format(a.format, &a.output)?;
    let job = VoxelizeJob::prepare(opts, &a.output, format, std::slice::from_ref(&a.mesh), a.preview.as_deref())?;
    if !a.quiet && !a.json {
        crate::export::warn_unused(&opts.export, &a.job.given, format, &a.output, true, a.preview.is_some());
    }
    let preview = match &a.preview {
        Some(p) => {
            crate::pictures::check_png_path(p)?;
            Some((p, crate::pictures::options(&a.picture, Some(opts.export.up))?))
        }
        None => None,
    };
    let pool = topovox_job::pool_for(opts.run.threads, "--threads")?;

    let bar = Bar::new(a.quiet || a.json);
    let (loaded, load_s) = crate::console::load_mesh(&a.mesh, &opts.run.read_options(), &bar)?;
    let name = a.mesh.display().to_string();
    let done = pool.install(|| job.run(&a.output, &loaded, &name, Some(&bar), None))?;
    for w in &done.made.voxels.warnings {
        eprintln!("topovox: warning: {w}");
    }
    if let Some((path, o)) = &preview {
        bar.phase("rendering the preview");
        let (v, attrs) = (&done.made.voxels, done.made.attributes.as_ref());
        let o = &topovox::render::raycast::RenderOptions { voxel_shape: v.grid.voxel_size().0.to_array(), ..*o };
        let outline = a.picture.outline.then(|| crate::pictures::outline_triangles(loaded.mesh.as_ref(), &v.grid));
        match &v.voxels {
            topovox_job::Voxels::Sparse(sparse) => {
                pool.install(|| crate::pictures::picture_sparse(sparse, path, o, attrs, outline.as_deref()))?
            }
            voxels => pool.install(|| crate::pictures::picture(voxels, path, o, attrs, outline.as_deref()))?,
        };
    }
    bar.finish();
    let times = Times { load_s, total_s: t_total.elapsed().as_secs_f64(), threads: pool.current_num_threads() };
    print_summary(a, &job, &loaded, &done, &times)
}

/// The times and threads of a run, for its summary.
struct Times {
    load_s: f64,
    total_s: f64,
    threads: usize,
}

/// The summary line, or with `--json` the JSON object.
fn print_summary(a: &VoxelizeArgs, job: &VoxelizeJob, loaded: &topovox_io::LoadedMesh, done: &Done, t: &Times) -> Result<()> {
    let (opts, format, plan) = (&a.job.options, job.format, job.plan());
    let (v, grid, attrs) = (&done.made.voxels, done.made.voxels.grid, done.made.attributes.as_ref());
    let (load_s, total_s, threads) = (t.load_s, t.total_s, t.threads);
    let (write_s, attributes_s, export_facts) = (done.write_s, done.made.attributes_s, &done.export);
    // Said in the summary, not on stderr: a successful run is quiet there.
    let one_colour = format.has_colour() && !loaded.appearance.has_colour();
    let o = grid.origin();
    let dims = grid.dims();
    // With `-o -` the voxels are on stdout: the summary goes to stderr.
    let to_stdout = a.output.as_os_str() == "-";
    if a.json {
        let extra = json!({
            "load_s": load_s,
            "write_s": write_s,
            "attributes_s": attributes_s,
            "attributes": attrs.as_ref().map(|t| json!({
                "colour": t.colour.is_some(),
                "colour_rule": opts.export.colour_rule.name(),
                "material": t.material.is_some(),
                "normal": t.normal.is_some(),
                "coverage": t.coverage.is_some(),
            })),
            "export": export_facts,
            "preview": a.preview,
            "total_s": total_s,
            "threads": threads,
            "input": a.mesh.display().to_string(),
            "output": a.output.display().to_string(),
            "format": format.name(),
            "mesh": {
                "vertices": loaded.report.vertices,
                "triangles": loaded.report.triangles,
                "degenerate": loaded.report.degenerate,
                "segments": loaded.report.segments,
            },
            "warnings": loaded.warnings,
        });
        let j = crate::console::summary_json(v.facts(plan), extra);
        summary(to_stdout, &j.to_string())?;
    } else if !a.quiet {
        let method = match v.mesh_closed() {
            Some(true) => format!("{} (mesh closed)", v.method),
            Some(false) => format!("{} (mesh not closed)", v.method),
            None => v.method.to_string(),
        };
        summary(
            to_stdout,
            &format!(
                "{}: {} voxels set on grid {}x{}x{} (origin {}, {}, {}; voxel size {}) by {} in {:.1} ms; total {:.2} s -> {}{}",
                opts.mode.name(),
                v.report.voxels,
                dims[0],
                dims[1],
                dims[2],
                o.x,
                o.y,
                o.z,
                grid.voxel_size(),
                method,
                v.voxelize_s * 1e3,
                total_s,
                a.output.display(),
                if one_colour { " (the mesh has no colours: every voxel gets one)" } else { "" }
            ),
        )?;
    }
    Ok(())
}

/// Prints the summary on stdout, or on stderr when the voxels went to stdout.
fn summary(voxels_on_stdout: bool, line: &str) -> Result<()> {
    if voxels_on_stdout {
        eprintln!("{line}");
        Ok(())
    } else {
        crate::console::print_stdout(line)
    }
}
