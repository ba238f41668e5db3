//! `topovox spray`: rays from a camera into a mesh (topovox-view's
//! `spray`), each hit a point with its albedo, emission and light term,
//! written as PLY for `render --gpu --points`, `view --points` and other
//! point-cloud tools.

use std::time::Instant;

use anyhow::{bail, Context, Result};
use serde_json::json;
use topovox::glam::Vec3;
use topovox_io::spray_cloud::write_ply;
use topovox_view::spray::{SprayOptions, Tracer};
use topovox_view::Camera;

use crate::args::SprayArgs;
use crate::pictures::up_axis;
use crate::scene_input::{camera, check_cloud_path, load_scene};

/// The most rays one run casts: every hit is a 64-byte point held until
/// the PLY is written, so 2^26 rays need at most 4 GiB.
const MAX_RAYS: usize = 1 << 26;
/// The most light samples per point.
const MAX_SAMPLES: u32 = 4096;

pub fn run(a: &SprayArgs) -> Result<()> {
    check_cloud_path(&a.output)?;
    if a.rays == 0 || a.rays > MAX_RAYS {
        bail!("--rays must be 1..={MAX_RAYS}, not {}", a.rays);
    }
    if a.light_samples > MAX_SAMPLES {
        bail!("--light-samples must be 0..={MAX_SAMPLES}, not {}", a.light_samples);
    }
    let (width, height) = (a.size.width, a.size.height);
    topovox_io::atomic::refuse_overwriting_inputs(&a.output, std::slice::from_ref(&a.input))?;
    let pool = topovox_job::pool_for(a.threads, "--threads")?;
    let upi = up_axis(a.up);
    let mut up = Vec3::ZERO;
    up[upi] = 1.0;

    let t0 = Instant::now();
    let (scene, kind) = load_scene(&a.input, a.up, a.allow_external_paths, std::slice::from_ref(&a.output))?;
    let (lo, hi) = scene.bounds().with_context(|| format!("{}: nothing to spray at (no triangle with area)", a.input.display()))?;
    let camera = match &a.camera {
        Some(c) => camera(*c, up),
        None => Camera::framing(lo, hi, upi),
    };
    let load_s = t0.elapsed().as_secs_f64();
    let opts = SprayOptions { rays: a.rays, light_samples: a.light_samples, seed: a.seed, shadows: a.shadows.on() };
    let t1 = Instant::now();
    let tracer = pool.install(|| Tracer::new(&scene))?;
    let bvh_s = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let points = pool.install(|| tracer.spray_camera(&camera, width as f32 / height as f32, &opts));
    let spray_s = t2.elapsed().as_secs_f64();
    topovox_io::atomic::write_atomically(&a.output, |w| write_ply(w, &points))?;
    let c = camera;
    let summary = json!({
        "input": a.input,
        "kind": kind,
        "output": a.output,
        "triangles": scene.triangles(),
        "emissive_triangles": tracer.emissive_triangles(),
        "camera": {"eye": c.eye.to_array(), "target": c.target.to_array(), "up": c.up.to_array(), "fov_deg": c.fov_deg},
        "rays": a.rays,
        "points": points.len(),
        "misses": a.rays - points.len(),
        "light_samples": a.light_samples,
        "shadows": opts.shadows,
        "seed": a.seed,
        "load_s": load_s,
        "bvh_s": bvh_s,
        "spray_s": spray_s,
        "rays_per_s": a.rays as f64 / spray_s.max(1e-9),
    });
    if a.json {
        return crate::console::print_stdout(&summary.to_string());
    }
    crate::console::print_stdout(&format!(
        "spray: {} rays, {} points ({} missed), {} light samples each from {} emissive triangles, BVH {:.2} s, rays {:.2} s -> {}",
        a.rays,
        points.len(),
        a.rays - points.len(),
        a.light_samples,
        tracer.emissive_triangles(),
        bvh_s,
        spray_s,
        a.output.display()
    ))
}
