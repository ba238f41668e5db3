//! `topovox view`: the interactive GPU viewer (topovox-view's window) on a
//! mesh, a voxel file, or a mesh beside its voxels.

use anyhow::{bail, Context, Result};
use serde_json::json;
use topovox::glam::Vec3;
use topovox::voxelize::{self, Options};
use topovox_view::window::{run as run_window, ViewOptions};
use topovox_view::Scene;

use crate::args::ViewArgs;
use crate::pictures::{check_png_path, up_axis};
use crate::plan;
use crate::scene_input::{add_voxel_file, add_voxels, camera, read_points};

pub fn run(a: &ViewArgs) -> Result<()> {
    let (width, height) = (a.size.width, a.size.height);
    if let Some(p) = &a.screenshot {
        check_png_path(p)?;
        topovox_io::atomic::refuse_overwriting_inputs(p, std::slice::from_ref(&a.input))?;
    }
    if let Some(p) = &a.save_points {
        crate::scene_input::check_cloud_path(p)?;
        topovox_io::atomic::refuse_overwriting_inputs(p, std::slice::from_ref(&a.input))?;
    }
    if a.frames == Some(0) {
        bail!("--frames must be at least 1");
    }
    let up_axis = up_axis(a.up);
    let mut up = Vec3::ZERO;
    up[up_axis] = 1.0;
    let mut scene = Scene::default();
    if topovox_io::is_voxel_file(&a.input) {
        if a.mode.is_some() || a.voxels.is_some() {
            bail!("--mode and --voxels draw voxels beside a mesh; {} is already a voxel file", a.input.display());
        }
        add_voxel_file(&mut scene, &a.input, a.up, Vec3::ZERO)?;
    } else {
        let loaded = topovox_io::read_mesh(
            &a.input,
            &topovox_io::ReadOptions { allow_external_paths: a.allow_external_paths, ..Default::default() },
        )?;
        if let Some(p) = &a.screenshot {
            topovox_io::atomic::refuse_overwriting_inputs(p, &loaded.sources)?;
        }
        for w in &loaded.warnings {
            eprintln!("topovox: warning: {}: {w}", a.input.display());
        }
        scene.add_mesh(loaded.mesh.as_ref(), &loaded.appearance);
        let (lo, hi) = scene.bounds().with_context(|| format!("{}: nothing to draw (no triangle with area)", a.input.display()))?;
        // Beside: shifted along the first horizontal axis by the mesh's extent and a gap.
        let mut offset = Vec3::ZERO;
        if a.layout == crate::args::Layout::Side {
            let h = (up_axis + 1) % 3;
            offset[h] = (hi[h] - lo[h]) * 1.15;
        }
        if let Some(v) = &a.voxels {
            add_voxel_file(&mut scene, v, a.up, offset)?;
        } else if let Some(mode) = a.mode {
            let (mode, _) = topovox_job::resolve_method(mode, topovox_job::Method::Fast)
                .context("view voxelizes with a surface or line mode; voxelize solids to a file and pass --voxels")?;
            let grid = plan::grid_request(&a.grid)?.fit(&loaded.report.bounds)?;
            plan::check_memory(&grid)?;
            let (bits, _) = voxelize::fast(mode, loaded.mesh.as_ref(), &grid, &Options::default());
            add_voxels(&mut scene, &bits.to_dense(), grid.origin().as_vec3() + offset, grid.voxel_size().0.as_vec3());
        }
    }
    let culling = a.culling;
    let camera = a.camera.map(|c| camera(c, up));
    if a.spray_rays == 0 || a.spray_rays > 1 << 24 {
        bail!("--spray-rays must be 1..={}, not {}", 1 << 24, a.spray_rays);
    }
    if !(a.spray_degrees > 0.0 && a.spray_degrees <= 90.0) {
        bail!("--spray-degrees must be above 0 and at most 90, not {}", a.spray_degrees);
    }
    let points = match &a.points {
        Some(p) => read_points(p)?,
        None => Vec::new(),
    };
    let opts = ViewOptions {
        width,
        height,
        camera,
        up: up_axis,
        culling,
        prepass: a.prepass.on(),
        gamma: a.gamma.on(),
        frames: a.frames,
        spray_rays: a.spray_rays,
        spray_degrees: a.spray_degrees,
    };
    let report = run_window(scene, points, opts)?;
    if let Some(p) = &a.save_points {
        topovox_io::atomic::write_atomically(p, |w| topovox_io::spray_cloud::write_ply(w, &report.points))?;
    }
    let mut shot = None;
    if let (Some(p), Some(f)) = (&a.screenshot, &report.screenshot) {
        topovox_io::write_png(p, f.width, f.height, &f.rgb())?;
        shot = Some((f.width, f.height));
    }
    let c = report.camera;
    let camera = format!("{},{},{},{},{},{},{}", c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.fov_deg);
    if a.json {
        let v = json!({"input": a.input, "frames": report.frames, "adapter": report.adapter, "camera": camera,
            "screenshot": a.screenshot, "screenshot_size": shot.map(|(w, h)| [w, h]), "points": report.points.len(), "save_points": a.save_points});
        return crate::console::print_stdout(&v.to_string());
    }
    if a.quiet {
        return Ok(());
    }
    crate::console::print_stdout(&format!("view: {} frames on {}; last camera --camera {camera}", report.frames, report.adapter))
}
