//! `topovox render --gpu`: one frame of the GPU renderer (`topovox-view`),
//! headless, of a mesh with its materials or of a voxel file's greedy
//! quads; the picture as PNG and the frame's statistics as JSON.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use serde_json::json;
use topovox::glam::Vec3;
use topovox_view::{Camera, FrameOptions, FrameStats, GpuScene, Renderer};

use crate::args::{GpuRenderArgs, RenderArgs};
use crate::pictures::{check_png_path, options};
use crate::scene_input::{camera, load_scene, read_points};

/// The flags checked and the files the run will write (the picture and
/// `--stats-json`), none of them the input.
fn checked(a: &RenderArgs) -> Result<(topovox::render::raycast::RenderOptions, Vec<PathBuf>)> {
    let g = &a.gpu;
    if a.picture.outline {
        bail!("--outline belongs to the CPU ray caster; leave out --gpu");
    }
    if a.picture.view != topovox::render::raycast::View::Iso {
        bail!("--gpu places its camera with --camera EX,EY,EZ,TX,TY,TZ[,FOV], not --view");
    }
    let o = options(&a.picture, a.up)?;
    if g.repeat == 0 || g.repeat > 1000 {
        bail!("--repeat must be 1..=1000, not {}", g.repeat);
    }
    check_png_path(&a.output)?;
    let mut outputs: Vec<PathBuf> = vec![a.output.clone()];
    if let Some(p) = &g.stats_json {
        topovox_job::output::check_output_path(p)?;
        if topovox_io::atomic::same_file(p, &a.output) {
            bail!("--stats-json {} is the picture's own path", p.display());
        }
        outputs.push(p.clone());
    }
    for out in &outputs {
        topovox_io::atomic::refuse_overwriting_inputs(out, std::slice::from_ref(&a.input))?;
    }
    Ok((o, outputs))
}

pub fn run(a: &RenderArgs) -> Result<()> {
    let g = &a.gpu;
    let (o, outputs) = checked(a)?;
    let mut up = Vec3::ZERO;
    up[o.up] = 1.0;

    let t0 = std::time::Instant::now();
    let (scene, kind) = load_scene(&a.input, a.up, a.allow_external_paths, &outputs)?;
    let load_s = t0.elapsed().as_secs_f64();
    let bounds = scene.bounds().with_context(|| format!("{}: nothing to draw (no triangle with area)", a.input.display()))?;
    let points = match &g.points {
        Some(p) => read_points(p)?,
        None => Vec::new(),
    };
    let cameras: Vec<Camera> = match (&g.camera, &g.frames) {
        (Some(c), _) => vec![camera(*c, up)],
        (None, Some(path)) => read_camera_path(path, up)?,
        (None, None) => vec![Camera::framing(bounds.0, bounds.1, o.up)],
    };
    let outputs_png: Vec<PathBuf> =
        if cameras.len() == 1 { vec![a.output.clone()] } else { (0..cameras.len()).map(|n| numbered(&a.output, n)).collect() };
    for out in &outputs_png {
        topovox_io::atomic::refuse_overwriting_inputs(out, std::slice::from_ref(&a.input))?;
    }
    let renderer = Renderer::new()?;
    let t1 = std::time::Instant::now();
    let mut uploaded = renderer.upload(&scene)?;
    renderer.add_points(&mut uploaded, &points)?;
    let upload_s = t1.elapsed().as_secs_f64();
    let mut frames: Vec<serde_json::Value> = Vec::with_capacity(cameras.len());
    for (camera, out) in cameras.iter().zip(&outputs_png) {
        frames.push(render_frame(&renderer, &uploaded, g, (o.width, o.height), camera, out)?);
    }
    let first = &frames[0];
    let (total, mean, max) = uploaded.grid.stats();
    let stats = json!({
        "input": a.input,
        "kind": kind,
        "output": a.output,
        "adapter": renderer.adapter(),
        "width": o.width,
        "height": o.height,
        "camera": first["camera"],
        "culling": g.culling.to_string(),
        "prepass": g.prepass.on(),
        "gamma": g.gamma.on(),
        "clusters": uploaded.clusters.len(),
        "clusters_after_frustum": first["clusters_after_frustum"],
        "clusters_after_occlusion": first["clusters_after_occlusion"],
        "triangles": uploaded.triangles,
        "triangles_drawn": first["triangles_drawn"],
        "points": g.points,
        "points_drawn": first["points_drawn"],
        "lights": uploaded.lights.lights,
        "emissive_triangles": uploaded.lights.emissive_triangles,
        "light_grid": {"cells": uploaded.grid.ranges.len(), "total": total, "mean": mean, "max": max, "built_on": "gpu", "build_ms": uploaded.grid_ms},
        "multi_draw": "multi_draw_indexed_indirect",
        "frame_ms": first["frame_ms"],
        "frames": frames,
        "load_s": load_s,
        "upload_s": upload_s,
    });
    if let Some(p) = &g.stats_json {
        let text = serde_json::to_string_pretty(&stats)?;
        topovox_io::atomic::write_atomically(p, |w| w.write_all(text.as_bytes()))?;
    }
    if a.json {
        return crate::console::print_stdout(&stats.to_string());
    }
    if a.quiet {
        return Ok(());
    }
    crate::console::print_stdout(&format!(
        "render --gpu: {} frame(s) {}x{} of {} triangles ({}), first: {} of {} clusters drawn, {} lights, {:.1} ms -> {}",
        stats["frames"].as_array().map_or(0, Vec::len),
        o.width,
        o.height,
        uploaded.triangles,
        kind,
        stats["clusters_after_occlusion"].as_u64().or(stats["clusters_after_frustum"].as_u64()).unwrap_or(0),
        uploaded.clusters.len(),
        uploaded.lights.lights,
        stats["frame_ms"]["cpu"].as_f64().unwrap_or(0.0),
        a.output.display()
    ))
}

/// One frame from `camera` into `out`, rendered `--repeat` times: its
/// statistics (medians of the runs), the last run's picture written.
fn render_frame(
    renderer: &Renderer,
    uploaded: &GpuScene,
    g: &GpuRenderArgs,
    size: (u32, u32),
    camera: &Camera,
    out: &Path,
) -> Result<serde_json::Value> {
    let (width, height) = size;
    let opts = FrameOptions {
        width,
        height,
        camera: *camera,
        culling: g.culling,
        prepass: g.prepass.on(),
        gamma: g.gamma.on(),
        light_grid_view: g.light_grid.on(),
        read_hiz: false,
        mesh: g.mesh.on(),
        boxes: g.boxes.on(),
    };
    // Every run's statistics, the last run's picture.
    let mut frame = renderer.render(uploaded, &opts)?;
    let mut runs = vec![frame.stats.clone()];
    for _ in 1..g.repeat {
        frame = renderer.render(uploaded, &opts)?;
        runs.push(frame.stats.clone());
    }
    let median = |f: &dyn Fn(&FrameStats) -> Option<f64>| -> Option<f64> {
        let mut v: Vec<f64> = runs.iter().filter_map(f).collect();
        v.sort_by(f64::total_cmp);
        (!v.is_empty()).then(|| v[v.len() / 2])
    };
    topovox_io::write_png(out, frame.width, frame.height, &frame.rgb())?;
    let s = &frame.stats;
    Ok(json!({
        "output": out,
        "camera": {"eye": camera.eye.to_array(), "target": camera.target.to_array(), "up": camera.up.to_array(), "fov_deg": camera.fov_deg},
        "clusters_after_frustum": s.clusters_after_frustum,
        "clusters_after_occlusion": s.clusters_after_occlusion,
        "triangles_drawn": s.triangles_drawn,
        "points_drawn": s.points_drawn,
        "frame_ms": {
            "repeats": g.repeat,
            "cpu": median(&|s| Some(s.cpu_ms)),
            "gpu_cull": median(&|s| s.gpu.map(|t| t.cull_ms)),
            "gpu_depth_pass": median(&|s| s.gpu.map(|t| t.depth_ms)),
            "gpu_hiz": median(&|s| s.gpu.map(|t| t.hiz_ms)),
            "gpu_shade": median(&|s| s.gpu.map(|t| t.shade_ms)),
        },
    }))
}

/// `out.png` → `out-0003.png` for frame 3.
fn numbered(out: &Path, n: usize) -> PathBuf {
    let stem = out.file_stem().and_then(|s| s.to_str()).unwrap_or("frame");
    let ext = out.extension().and_then(|s| s.to_str()).unwrap_or("png");
    out.with_file_name(format!("{stem}-{n:04}.{ext}"))
}

/// Reads a camera path: one `EX,EY,EZ,TX,TY,TZ[,FOV]` per line, `#` comments.
fn read_camera_path(path: &Path, up: Vec3) -> Result<Vec<Camera>> {
    let size = std::fs::metadata(path).with_context(|| format!("{}: cannot read the camera path", path.display()))?.len();
    if size > 1 << 20 {
        bail!("{}: a camera path of {size} bytes; at most 1 MiB", path.display());
    }
    let bytes = topovox_io::read_regular(path).with_context(|| format!("{}: cannot read the camera path", path.display()))?;
    let text = String::from_utf8(bytes).map_err(|_| anyhow::anyhow!("{}: the camera path is not UTF-8 text", path.display()))?;
    let mut cams = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let spec = crate::values::camera(line).map_err(|e| anyhow::anyhow!("{} line {}: {e}", path.display(), n + 1))?;
        cams.push(camera(spec, up));
        if cams.len() > 10_000 {
            bail!("{}: more than 10000 cameras", path.display());
        }
    }
    if cams.is_empty() {
        bail!("{}: no camera in the path (one EX,EY,EZ,TX,TY,TZ[,FOV] per line)", path.display());
    }
    Ok(cams)
}
