//! `voxkit bench`: medians of repeated voxelizations, against the reference
//! path as the baseline in the same run.

use std::time::Instant;

use anyhow::{Context, Result};
use serde_json::json;
use voxkit::voxelize::{cover, Options};
use voxkit::GridSpec;

use crate::args::BenchArgs;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

fn time<T>(repeats: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::with_capacity(repeats);
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let t = Instant::now();
        let r = f();
        times.push(t.elapsed().as_secs_f64());
        last = Some(r);
    }
    (median(times), last.expect("at least one repeat"))
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let loaded = voxkit_io::read_mesh(&a.mesh)?;
    let mesh = loaded.mesh.as_ref();
    let bounds = loaded.report.bounds;
    let mut rows = Vec::new();
    if !a.json {
        crate::print_stdout(&format!(
            "mesh: {} ({} triangles), repeats: {}, machine threads: {}\n\n| method | threads | resolution | grid | voxels | voxelize median (ms) | with loading median (ms) |\n|---|---|---|---|---|---|---|",
            a.mesh.display(),
            loaded.report.triangles,
            a.repeats,
            std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
        ))?;
    }
    let mut emit = |method: &str, threads: usize, res: u64, grid: &GridSpec, voxels: u64, vox_s: f64, load_s: Option<f64>| -> Result<()> {
        let d = grid.dims();
        if a.json {
            let v = json!({"method": method, "threads": threads, "resolution": res, "dims": d, "voxels": voxels, "voxelize_median_s": vox_s, "with_loading_median_s": load_s});
            crate::print_stdout(&v.to_string())?;
        } else {
            let l = load_s.map(|s| format!("{:.1}", s * 1e3)).unwrap_or_else(|| "-".into());
            crate::print_stdout(&format!("| {method} | {threads} | {res} | {}x{}x{} | {voxels} | {:.2} | {l} |", d[0], d[1], d[2], vox_s * 1e3))?;
        }
        rows.push((method.to_string(), threads, res, vox_s));
        Ok(())
    };

    // Baseline: the reference path, serial by construction.
    let grid = GridSpec::from_resolution(&bounds, a.reference_resolution).context("invalid grid")?;
    let (ref_s, (_, rep)) = time(a.repeats.clamp(1, 3), || cover::reference::cover(mesh, &grid));
    emit("reference", 1, a.reference_resolution, &grid, rep.voxels, ref_s, None)?;

    for &threads in &a.threads {
        let pool = crate::thread_pool(Some(threads))?;
        for &res in &a.resolutions {
            let grid = GridSpec::from_resolution(&bounds, res).context("invalid grid")?;
            crate::plan::check_memory(&grid)?;
            let (vox_s, (_, rep)) = pool.install(|| time(a.repeats, || cover::cover(mesh, &grid, &Options::default())));
            let (load_s, _) = pool.install(|| {
                time(a.repeats.min(5), || -> Result<u64> {
                    let l = voxkit_io::read_mesh(&a.mesh)?;
                    let g = GridSpec::from_resolution(&l.report.bounds, res)?;
                    Ok(cover::cover(l.mesh.as_ref(), &g, &Options::default()).1.voxels)
                })
            });
            emit("fast", threads, res, &grid, rep.voxels, vox_s, Some(load_s))?;
        }
    }
    drop(emit);
    if !a.json {
        if let Some(fast) = rows.iter().find(|r| r.0 == "fast" && r.2 == a.reference_resolution && r.1 == 1) {
            crate::print_stdout(&format!("\nfast (1 thread) vs reference at {}: {:.1}x faster", a.reference_resolution, ref_s / fast.3))?;
        }
    }
    Ok(())
}
