//! `voxkit bench`: medians of repeated voxelizations, with the reference
//! path timed in the same run as the baseline.

use std::time::Instant;

use anyhow::{Context, Result};
use serde_json::json;
use voxkit::voxelize::{self, Options};
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

/// Runs `f` `repeats` times; returns the median seconds and the last result.
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

struct Row {
    mode: &'static str,
    method: &'static str,
    threads: usize,
    resolution: u64,
    dims: [u32; 3],
    voxels: u64,
    voxelize_s: f64,
    with_loading_s: Option<f64>,
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let loaded = voxkit_io::read_mesh(&a.mesh)?;
    let mesh = loaded.mesh.as_ref();
    let bounds = loaded.report.bounds;
    let mut rows = Vec::new();

    let mut ref_s = std::collections::HashMap::new();
    for &cli_mode in &a.modes {
        let (mode, _) = crate::plan::resolve_method(cli_mode, crate::args::Method::Auto)?;
        // Baseline: the reference path (serial by construction).
        let grid = GridSpec::from_resolution(&bounds, a.reference_resolution).context("invalid grid")?;
        let (s, (_, rep)) = time(a.repeats.clamp(1, 3), || voxelize::reference(mode, mesh, &grid));
        ref_s.insert(mode.name(), s);
        rows.push(Row {
            mode: mode.name(),
            method: "reference",
            threads: 1,
            resolution: a.reference_resolution,
            dims: grid.dims(),
            voxels: rep.voxels,
            voxelize_s: s,
            with_loading_s: None,
        });

        for &threads in &a.threads {
            let pool = crate::thread_pool(Some(threads))?;
            for &res in &a.resolutions {
                let grid = GridSpec::from_resolution(&bounds, res).context("invalid grid")?;
                crate::plan::check_memory(&grid)?;
                let (vox_s, (_, rep)) = pool.install(|| time(a.repeats, || voxelize::fast(mode, mesh, &grid, &Options::default())));
                let (load_s, r) = pool.install(|| {
                    time(a.repeats.min(5), || -> Result<u64> {
                        let l = voxkit_io::read_mesh(&a.mesh)?;
                        let g = GridSpec::from_resolution(&l.report.bounds, res)?;
                        Ok(voxelize::fast(mode, l.mesh.as_ref(), &g, &Options::default()).1.voxels)
                    })
                });
                r?;
                rows.push(Row {
                    mode: mode.name(),
                    method: "fast",
                    threads,
                    resolution: res,
                    dims: grid.dims(),
                    voxels: rep.voxels,
                    voxelize_s: vox_s,
                    with_loading_s: Some(load_s),
                });
            }
        }
    }

    if a.json {
        for r in &rows {
            let v = json!({"mode": r.mode, "method": r.method, "threads": r.threads, "resolution": r.resolution, "dims": r.dims, "voxels": r.voxels,
                "voxelize_median_s": r.voxelize_s, "with_loading_median_s": r.with_loading_s, "repeats": a.repeats});
            crate::print_stdout(&v.to_string())?;
        }
        return Ok(());
    }
    let mut out = format!(
        "mesh: {} ({} triangles); median of {} repeats ({} with loading); {} hardware threads\n\n",
        a.mesh.display(),
        loaded.report.triangles,
        a.repeats,
        a.repeats.min(5),
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
    );
    out += "| mode | method | threads | resolution | grid | voxels | voxelize (ms) | with loading (ms) | vs reference |\n|---|---|---|---|---|---|---|---|---|\n";
    for r in &rows {
        let d = r.dims;
        let load = r.with_loading_s.map(|s| format!("{:.1}", s * 1e3)).unwrap_or_else(|| "-".into());
        let speed = if r.resolution == a.reference_resolution { format!("{:.1}x", ref_s[r.mode] / r.voxelize_s) } else { "-".into() };
        out += &format!(
            "| {} | {} | {} | {} | {}x{}x{} | {} | {:.2} | {} | {} |\n",
            r.mode,
            r.method,
            r.threads,
            r.resolution,
            d[0],
            d[1],
            d[2],
            r.voxels,
            r.voxelize_s * 1e3,
            load,
            speed
        );
    }
    crate::print_stdout(out.trim_end())
}
