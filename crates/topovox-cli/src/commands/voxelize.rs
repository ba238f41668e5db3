//! `topovox voxelize MESH -o OUT`.

use std::time::Instant;

use anyhow::Result;
use serde_json::json;
use topovox_job::output::{check_output_path, output_format};
use topovox_job::Choice;

use crate::args::VoxelizeArgs;
use crate::progress::Bar;

pub fn run(a: &VoxelizeArgs) -> Result<()> {
    let t_total = Instant::now();
    // Validate everything that does not need the mesh first.
    let opts = &a.job.options;
    let mut plan = opts.plan()?;
    let format = output_format(a.format, &a.output)?;
    plan.request.writer_bytes_per_brick = topovox_job::output::writer_bytes_per_brick(format);
    check_output_path(&a.output)?;
    // Nothing is read or written before we know no output is an input.
    topovox_job::output::refuse_overwriting(&a.output, format, std::slice::from_ref(&a.mesh))?;
    if let Some(p) = &a.preview {
        topovox_io::atomic::refuse_overwriting_inputs(p, std::slice::from_ref(&a.mesh))?;
    }
    let write_opts = opts.export.write_options()?;
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
    let threads = pool.current_num_threads();

    let bar = Bar::new(a.quiet || a.json);
    bar.phase("loading mesh");
    let t_load = Instant::now();
    let loaded = topovox_io::read_mesh_with(&a.mesh, &opts.run.read_options())?;
    let load_s = t_load.elapsed().as_secs_f64();
    // Nor any file the mesh led to (its .mtl, textures, buffers).
    topovox_job::output::refuse_overwriting(&a.output, format, &loaded.sources)?;
    if let Some(p) = &a.preview {
        topovox_io::atomic::refuse_overwriting_inputs(p, &loaded.sources)?;
    }
    for w in &loaded.warnings {
        eprintln!("topovox: warning: {}: {w}", a.mesh.display());
    }
    // A dense format for a grid past memory is refused before any work.
    let fitted = plan.request.grid.fit(&loaded.mesh.as_ref().bounds())?;
    topovox_job::output::check_fits(format, &fitted, plan.request.max_memory)?;
    bar.phase(if plan.surface_method == topovox_job::SurfaceMethod::Reference { "voxelizing (reference, serial)" } else { "voxelizing" });
    let name = a.mesh.display().to_string();
    let v = pool.install(|| topovox_job::voxelize(&plan, loaded.mesh.as_ref(), &name, Some(&bar), None))?;
    for w in &v.warnings {
        eprintln!("topovox: warning: {w}");
    }
    let grid = v.grid;

    // Attributes: colours for the formats that store them (and the preview),
    // every array (coverage, material, normal) for .vti, and for .vdb and
    // .zarr with --attributes; tiled grids too, while they fit in memory.
    let every = topovox_job::every_attribute(format, opts.export.attributes);
    let app = &loaded.appearance;
    let want_colour = app.has_colour() && (format.has_colour() || preview.is_some());
    let t_attr = Instant::now();
    if (want_colour || every) && !plan.is_line() {
        topovox_job::check_attributes_carried(&plan, &v)?;
    }
    let attrs = (want_colour || every).then(|| {
        bar.phase("carrying colours into voxels");
        pool.install(|| topovox_job::attributes(&plan, loaded.mesh.as_ref(), app, &v, &opts.export.carry()))
    });
    let attrs = attrs.flatten();
    let attributes_s = t_attr.elapsed().as_secs_f64();
    // Said in the summary, not on stderr: a successful run is quiet there.
    let one_colour = format.has_colour() && !app.has_colour();

    bar.phase("writing");
    let t_write = Instant::now();
    let export_facts = pool.install(|| topovox_job::output::write(&a.output, format, &v.voxels, &grid, attrs.as_ref(), &write_opts))?;
    let write_s = t_write.elapsed().as_secs_f64();
    if let Some((path, o)) = &preview {
        bar.phase("rendering the preview");
        let o = &topovox::render::raycast::RenderOptions { voxel_shape: grid.voxel_size().to_array(), ..*o };
        let outline = a.picture.outline.then(|| crate::pictures::outline_triangles(loaded.mesh.as_ref(), &grid));
        match &v.voxels {
            topovox_job::Voxels::Sparse(sparse) => {
                pool.install(|| crate::pictures::picture_sparse(sparse, path, o, attrs.as_ref(), outline.as_deref()))?
            }
            voxels => pool.install(|| crate::pictures::picture(voxels, path, o, attrs.as_ref(), outline.as_deref()))?,
        };
    }
    bar.finish();
    let total_s = t_total.elapsed().as_secs_f64();

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
        let j = crate::console::summary_json(v.facts(&plan), extra);
        summary(to_stdout, &j.to_string())?;
    } else if !a.quiet {
        let method = match v.solid.get("closed").and_then(|c| c.as_bool()) {
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
                grid.size(),
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
