//! `voxkit voxelize MESH -o OUT`.

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Result};
use serde_json::json;
use voxkit::attributes::carry::{carry, CarryOptions};
use voxkit::voxelize::{self, Options};
use voxkit::VoxelSource;

use crate::args::VoxelizeArgs;
use crate::plan::{self, GridRequest};
use crate::progress::Bar;

pub fn run(a: &VoxelizeArgs) -> Result<()> {
    let t_total = Instant::now();
    // Validate everything that does not need the mesh first.
    let request = GridRequest::from_args(&a.grid)?;
    let solid_plan = plan::solid_plan(a)?;
    let (mode, surface_method) = match solid_plan {
        Some(_) => (voxelize::Mode::Cover, plan::SurfaceMethod::Fast),
        None => plan::resolve_method(a.mode, a.method)?,
    };
    let format = plan::output_format(a.format.as_deref(), &a.output)?;
    check_output_dir(&a.output)?;
    let write_opts = crate::commands::export::writer_options(&a.export)?;
    let preview = match &a.preview {
        Some(p) => {
            crate::commands::render::check_png_path(p)?;
            Some((p, crate::commands::render::options(&a.picture)?))
        }
        None => None,
    };
    let pool = crate::thread_pool(a.threads)?;
    let threads = pool.current_num_threads();

    let bar = Bar::new(a.quiet || a.json);
    bar.phase("loading mesh");
    let t_load = Instant::now();
    let loaded = voxkit_io::read_mesh(&a.mesh)?;
    let load_s = t_load.elapsed().as_secs_f64();
    for w in &loaded.warnings {
        eprintln!("voxkit: warning: {}: {w}", a.mesh.display());
    }
    let is_line = solid_plan.is_none() && matches!(mode, voxelize::Mode::Line26 | voxelize::Mode::Line6);
    if !is_line && loaded.report.triangles == 0 {
        bail!("{}: has only line segments; surface modes need triangles (use --mode line26 or line6)", a.mesh.display());
    }
    if !is_line && loaded.report.segments > 0 {
        eprintln!(
            "voxkit: warning: {}: {} line segments ignored by surface mode {} (line26 and line6 voxelize them)",
            a.mesh.display(),
            loaded.report.segments,
            plan::mode_name(a.mode)
        );
    }
    let grid = request.fit(&loaded.report.bounds)?;
    plan::check_memory(&grid)?;
    let surface_method =
        if a.method == crate::args::Method::Auto { plan::auto_method(mode, loaded.mesh.as_ref(), &grid) } else { surface_method };
    let method = if solid_plan.is_some() { "solid" } else { surface_method.name() };

    bar.phase(if method == "reference" { "voxelizing (reference, serial)" } else { "voxelizing" });
    let t_vox = Instant::now();
    let mut method = method;
    let mut solid_facts = serde_json::Value::Null;
    let mut gpu_facts = serde_json::Value::Null;
    let (bits, report): (Box<dyn VoxelSource + Send>, _) = if let Some(sp) = &solid_plan {
        let name = a.mesh.display().to_string();
        let out = pool.install(|| {
            crate::commands::solid::run(sp, loaded.mesh.as_ref(), &name, &grid, &Options { progress: Some(&bar), ..Options::default() })
        })?;
        for w in &out.warnings {
            eprintln!("voxkit: warning: {w}");
        }
        method = out.method;
        solid_facts = out.facts;
        let voxels = out.bits.count();
        let report = voxelize::Report { voxels, prepare: voxkit::geom::lattice::PrepareStats::default() };
        (Box::new(out.bits) as Box<dyn VoxelSource + Send>, report)
    } else {
        let opts = Options { progress: Some(&bar), ..Options::default() };
        pool.install(|| -> Result<_> {
            Ok(match surface_method {
                plan::SurfaceMethod::Reference => {
                    let (b, r) = voxelize::reference(mode, loaded.mesh.as_ref(), &grid);
                    (Box::new(b) as Box<dyn VoxelSource + Send>, r)
                }
                plan::SurfaceMethod::Scanline => {
                    let (b, r) = voxelize::scanline::scanline(mode, loaded.mesh.as_ref(), &grid, &opts)
                        .expect("resolve_method allows scanline only for modes that have it");
                    (Box::new(b) as Box<dyn VoxelSource + Send>, r)
                }
                plan::SurfaceMethod::Fast => {
                    let (b, r) = voxelize::fast(mode, loaded.mesh.as_ref(), &grid, &opts);
                    (Box::new(b) as Box<dyn VoxelSource + Send>, r)
                }
                plan::SurfaceMethod::Gpu => {
                    let (b, r, facts) = gpu_voxelize(mode, a.gpu_path, loaded.mesh.as_ref(), &grid)?;
                    gpu_facts = facts;
                    (Box::new(b) as Box<dyn VoxelSource + Send>, r)
                }
            })
        })?
    };
    let voxelize_s = t_vox.elapsed().as_secs_f64();

    // Attributes: colours for the formats that store them (and the preview),
    // every array (coverage, material, normal) for .vti.
    let is_vti = format == plan::Output::Voxels(voxkit_io::VoxelFormat::Vti);
    let app = &loaded.appearance;
    let want_colour = app.has_colour() && (format.has_colour() || preview.is_some());
    let t_attr = Instant::now();
    let attrs = (!is_line && (want_colour || is_vti)).then(|| {
        bar.phase("carrying colours into voxels");
        let opts = CarryOptions { rule: crate::commands::export::colour_rule(a.export.colour_rule), normals: a.export.normals };
        pool.install(|| carry(loaded.mesh.as_ref(), app, &grid, bits.as_ref(), &opts))
    });
    let attributes_s = t_attr.elapsed().as_secs_f64();
    if format.has_colour() && !app.has_colour() && !a.quiet && !a.json {
        eprintln!("voxkit: note: {} has no colours (materials, textures or vertex colours); voxels get one colour", a.mesh.display());
    }

    bar.phase("writing");
    let t_write = Instant::now();
    let export_facts =
        pool.install(|| crate::commands::export::write(&a.output, format, bits.as_ref(), &grid, attrs.as_ref(), &write_opts))?;
    let write_s = t_write.elapsed().as_secs_f64();
    if let Some((path, o)) = &preview {
        bar.phase("rendering the preview");
        let outline = a.picture.outline.then(|| crate::commands::render::outline_triangles(loaded.mesh.as_ref(), &grid));
        pool.install(|| crate::commands::render::picture(bits.as_ref(), path, o, attrs.as_ref(), outline.as_deref()))?;
    }
    bar.finish();
    let total_s = t_total.elapsed().as_secs_f64();

    let p = report.prepare;
    if p.non_finite + p.invalid_index > 0 {
        eprintln!("voxkit: warning: skipped {} primitives with invalid vertices", p.non_finite + p.invalid_index);
    }
    let o = grid.origin();
    let dims = grid.dims();
    if a.json {
        let v = json!({
            "mode": plan::mode_name(a.mode),
            "method": method,
            "origin": [o.x, o.y, o.z],
            "voxel_size": grid.voxel_size(),
            "dims": dims,
            "voxels": report.voxels,
            "voxelize_s": voxelize_s,
            "load_s": load_s,
            "write_s": write_s,
            "attributes_s": attributes_s,
            "attributes": attrs.as_ref().map(|t| json!({
                "colour": t.colour.is_some(),
                "colour_rule": format!("{:?}", a.export.colour_rule).to_lowercase(),
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
            "triangles": if solid_plan.is_some() { serde_json::Value::Null } else { json!({
                "input": p.input,
                "voxelized": p.output,
                "skipped_degenerate": p.degenerate,
                "skipped_non_finite": p.non_finite,
                "skipped_invalid_index": p.invalid_index,
                "outside_grid": p.outside,
                "clipped": p.clipped,
            })},
            "warnings": loaded.warnings,
            "solid": solid_facts,
            "gpu": gpu_facts,
        });
        crate::print_stdout(&v.to_string())?;
    } else if !a.quiet {
        let method = match solid_facts.get("closed").and_then(|c| c.as_bool()) {
            Some(true) => format!("{method} (mesh closed)"),
            Some(false) => format!("{method} (mesh not closed)"),
            None => method.to_string(),
        };
        crate::print_stdout(&format!(
            "{}: {} voxels set on grid {}x{}x{} (origin {}, {}, {}; voxel size {}) by {} in {:.1} ms; total {:.2} s -> {}",
            plan::mode_name(a.mode),
            report.voxels,
            dims[0],
            dims[1],
            dims[2],
            o.x,
            o.y,
            o.z,
            grid.voxel_size(),
            method,
            voxelize_s * 1e3,
            total_s,
            a.output.display()
        ))?;
    }
    Ok(())
}

/// A surface mode on the GPU: the voxels, the report, and facts for `--json`.
#[cfg(feature = "gpu")]
fn gpu_voxelize(
    mode: voxelize::Mode,
    path: crate::args::GpuPathArg,
    mesh: voxkit::MeshRef<'_>,
    grid: &voxkit::GridSpec,
) -> Result<(voxkit::BrickBits, voxelize::Report, serde_json::Value)> {
    use crate::args::GpuPathArg;
    use voxkit_gpu::GpuPath;
    let gm = voxkit_gpu::GpuMode::of(mode).ok_or_else(|| anyhow::anyhow!("--method gpu: {} on the GPU is not built yet", mode.name()))?;
    let gpu = voxkit_gpu::Gpu::new().map_err(|e| anyhow::anyhow!("--method gpu: {e}"))?;
    let gp = match path {
        GpuPathArg::Compute => GpuPath::Compute,
        GpuPathArg::Raster => GpuPath::Raster,
        GpuPathArg::MsaaApprox => GpuPath::RasterMsaa,
    };
    let (bits, r) = gpu.voxelize_with(gm, gp, mesh, grid).map_err(|e| anyhow::anyhow!("--method gpu: {e}"))?;
    // The approximation says what it misses: the exact voxels by the compute path.
    let missed = if gp == GpuPath::RasterMsaa {
        let (exact, _) = gpu.voxelize(gm, mesh, grid).map_err(|e| anyhow::anyhow!("--method gpu: {e}"))?;
        let mut missed = 0u64;
        exact.for_each_set(|i, j, k| missed += !bits.get(i, j, k) as u64);
        eprintln!("voxkit: warning: --gpu-path msaa-approx is approximate: it missed {missed} of the mode's {} voxels", exact.count());
        Some(missed)
    } else {
        None
    };
    let t = r.timings;
    let facts = json!({
        "path": match gp { GpuPath::Compute => "compute", GpuPath::Raster => "raster", GpuPath::RasterMsaa => "msaa-approx" },
        "hardware_conservative": gpu.hardware_conservative(),
        "missed_voxels": missed,
        "adapter": gpu.adapter(),
        "software": gpu.is_software(),
        "gpu_triangles": r.gpu_triangles,
        "cpu_triangles": r.cpu_triangles,
        "upload_s": t.upload_s,
        "gpu_s": t.voxelize_s,
        "gpu_time_s": t.gpu_s,
        "download_s": t.download_s,
        "cpu_share_s": t.cpu_s,
        "slabs": t.slabs,
    });
    Ok((bits, r.report, facts))
}

#[cfg(not(feature = "gpu"))]
fn gpu_voxelize(
    _mode: voxelize::Mode,
    _path: crate::args::GpuPathArg,
    _mesh: voxkit::MeshRef<'_>,
    _grid: &voxkit::GridSpec,
) -> Result<(voxkit::BrickBits, voxelize::Report, serde_json::Value)> {
    bail!("--method gpu: this voxkit was built without the `gpu` feature")
}

pub(crate) fn check_output_dir(out: &Path) -> Result<()> {
    let dir = match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        bail!("{}: cannot write: directory {} does not exist", out.display(), dir.display());
    }
    if out.is_dir() {
        bail!("{}: cannot write: it is a directory", out.display());
    }
    Ok(())
}
