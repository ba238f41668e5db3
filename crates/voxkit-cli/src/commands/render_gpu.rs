//! `voxkit render --gpu`: one frame of the GPU renderer (`voxkit-view`),
//! headless, of a mesh with its materials or of a voxel file's greedy
//! quads; the picture as PNG and the frame's statistics as JSON.

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use serde_json::json;
use voxkit::glam::Vec3;
use voxkit_view::{Camera, Culling, FrameOptions, Renderer, Scene};

use crate::args::RenderArgs;
use crate::commands::render::{check_png_path, options};

/// Voxel quads' material: light grey, rough.
const VOXEL_COLOUR: [f32; 3] = [0.72, 0.72, 0.70];

/// Parses `EX,EY,EZ,TX,TY,TZ[,FOV]`.
fn parse_camera(s: &str, up: Vec3) -> Result<Camera> {
    let v: Option<Vec<f32>> = s.split(',').map(|x| x.trim().parse::<f32>().ok().filter(|v| v.is_finite())).collect();
    let Some(v) = v.filter(|v| v.len() == 6 || v.len() == 7) else {
        bail!("--camera takes EX,EY,EZ,TX,TY,TZ[,FOV]: an eye, a target and a vertical field of view in degrees, not {s:?}")
    };
    let (eye, target) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
    let fov_deg = v.get(6).copied().unwrap_or(45.0);
    if !(fov_deg > 0.5 && fov_deg < 179.0) {
        bail!("--camera: the field of view must be between 0.5 and 179 degrees, not {fov_deg}");
    }
    if (eye - target).length() <= f32::EPSILON * eye.abs().max(target.abs()).max_element().max(1.0) {
        bail!("--camera: the eye and the target must differ");
    }
    Ok(Camera { eye, target, up, fov_deg })
}

pub fn run(a: &RenderArgs) -> Result<()> {
    let g = &a.gpu;
    if a.picture.outline {
        bail!("--outline belongs to the CPU ray caster; leave out --gpu");
    }
    if a.picture.view != "iso" {
        bail!("--gpu places its camera with --camera EX,EY,EZ,TX,TY,TZ[,FOV], not --view");
    }
    let o = options(&a.picture, a.up.as_deref())?;
    check_png_path(&a.output)?;
    let mut outputs: Vec<PathBuf> = vec![a.output.clone()];
    if let Some(p) = &g.stats_json {
        voxkit_job::output::check_output_path(p)?;
        if voxkit_io::atomic::same_file(p, &a.output) {
            bail!("--stats-json {} is the picture's own path", p.display());
        }
        outputs.push(p.clone());
    }
    for out in &outputs {
        voxkit_io::atomic::refuse_overwriting_inputs(out, std::slice::from_ref(&a.input))?;
    }
    let mut up = Vec3::ZERO;
    up[o.up] = 1.0;

    let t0 = std::time::Instant::now();
    let mut scene = Scene::default();
    let kind = if voxkit_io::is_voxel_file(&a.input) {
        let upname = a.up.as_deref().and_then(voxkit_io::orient::Up::from_name).unwrap_or_default();
        let loaded = voxkit_io::read_voxels_with(&a.input, upname)?;
        let quads = voxkit::export::greedy::greedy_quads(&loaded.bits);
        let (origin, size) = loaded.placement.map(|(o, s)| (o.as_vec3(), s as f32)).unwrap_or((Vec3::ZERO, 1.0));
        let m = scene.add_material(voxkit_view::scene::ShadeMaterial::new(VOXEL_COLOUR, [0.0; 3], 0.7));
        scene.add_quads(&quads, origin, size, m);
        "voxel file"
    } else {
        let loaded = voxkit_io::read_mesh_with(&a.input, &voxkit_io::ReadOptions { allow_external_paths: a.allow_external_paths })?;
        for out in &outputs {
            voxkit_io::atomic::refuse_overwriting_inputs(out, &loaded.sources)?;
        }
        for w in &loaded.warnings {
            eprintln!("voxkit: warning: {}: {w}", a.input.display());
        }
        scene.add_mesh(loaded.mesh.as_ref(), &loaded.appearance);
        "mesh"
    };
    let load_s = t0.elapsed().as_secs_f64();
    let bounds = scene.bounds().with_context(|| format!("{}: nothing to draw (no triangle with area)", a.input.display()))?;
    let camera = match &g.camera {
        Some(s) => parse_camera(s, up)?,
        None => Camera::framing(bounds.0, bounds.1, o.up),
    };
    let renderer = Renderer::new()?;
    let t1 = std::time::Instant::now();
    let uploaded = renderer.upload(&scene)?;
    let upload_s = t1.elapsed().as_secs_f64();
    let culling = match g.culling.as_str() {
        "none" => Culling::None,
        "frustum" => Culling::Frustum,
        _ => Culling::Occlusion,
    };
    let frame = renderer.render(
        &uploaded,
        &FrameOptions {
            width: o.width,
            height: o.height,
            camera,
            culling,
            prepass: g.prepass == "on",
            gamma: g.gamma == "on",
            read_hiz: false,
        },
    )?;
    let rgb: Vec<u8> = frame.rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
    voxkit_io::write_png(&a.output, frame.width, frame.height, &rgb)?;
    let s = &frame.stats;
    let (total, mean, max) = uploaded.grid.stats();
    let stats = json!({
        "input": a.input,
        "kind": kind,
        "output": a.output,
        "adapter": renderer.adapter(),
        "width": frame.width,
        "height": frame.height,
        "camera": {"eye": camera.eye.to_array(), "target": camera.target.to_array(), "up": camera.up.to_array(), "fov_deg": camera.fov_deg},
        "culling": g.culling,
        "prepass": g.prepass == "on",
        "gamma": g.gamma == "on",
        "clusters": s.clusters,
        "clusters_after_frustum": s.clusters_after_frustum,
        "clusters_after_occlusion": s.clusters_after_occlusion,
        "triangles": s.triangles,
        "triangles_drawn": s.triangles_drawn,
        "lights": uploaded.lights.lights,
        "emissive_triangles": uploaded.lights.emissive_triangles,
        "light_grid": {"cells": uploaded.grid.ranges.len(), "total": total, "mean": mean, "max": max},
        "multi_draw": s.multi_draw,
        "frame_ms": {
            "cpu": s.cpu_ms,
            "gpu_cull": s.gpu.map(|t| t.cull_ms),
            "gpu_depth_pass": s.gpu.map(|t| t.depth_ms),
            "gpu_hiz": s.gpu.map(|t| t.hiz_ms),
            "gpu_shade": s.gpu.map(|t| t.shade_ms),
        },
        "load_s": load_s,
        "upload_s": upload_s,
    });
    if let Some(p) = &g.stats_json {
        let text = serde_json::to_string_pretty(&stats)?;
        voxkit_io::atomic::write_atomically(p, |w| w.write_all(text.as_bytes()))?;
    }
    if a.json {
        return crate::print_stdout(&stats.to_string());
    }
    crate::print_stdout(&format!(
        "render --gpu: {}x{} picture of {} triangles ({}), {} of {} clusters drawn, {} lights, {:.1} ms frame -> {}",
        frame.width,
        frame.height,
        s.triangles,
        kind,
        s.clusters_after_occlusion.unwrap_or(s.clusters_after_frustum),
        s.clusters,
        uploaded.lights.lights,
        s.cpu_ms,
        a.output.display()
    ))
}
