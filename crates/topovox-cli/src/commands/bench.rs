//! `topovox bench`: medians of repeated voxelizations, with the reference
//! path timed in the same run as the baseline.

use std::time::Instant;

use anyhow::{Context, Result};
use serde_json::json;
use topovox::voxelize::{self, solid, winding, Options};
use topovox::{GridSpec, MeshRef};

use super::brute;
use crate::args::{Baseline, BenchArgs};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

/// Runs `f` on each of `items` once per round, `repeats` rounds, so that drifts in the
/// machine's speed hit every one alike; returns each one's median seconds
/// and last result.
fn time_alternating<E, T>(repeats: usize, items: &[E], mut f: impl FnMut(&E) -> T) -> Vec<(f64, T)> {
    let mut times = vec![Vec::with_capacity(repeats); items.len()];
    let mut last: Vec<Option<T>> = items.iter().map(|_| None).collect();
    for _ in 0..repeats.max(1) {
        for (i, item) in items.iter().enumerate() {
            let t = Instant::now();
            let r = f(item);
            times[i].push(t.elapsed().as_secs_f64());
            last[i] = Some(r);
        }
    }
    times.into_iter().zip(last).map(|(t, r)| (median(t), r.expect("at least one round"))).collect()
}

/// Runs `f` `repeats` times; returns the median seconds and the last result.
fn time<T>(repeats: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    time_alternating(repeats, &[()], |_| f()).pop().expect("one item")
}

/// What a benchmark row runs: a surface/line mode by its triangle-box fast
/// path or its scanline path, or the solid by parity or winding.
enum Engine {
    Surface(voxelize::Mode),
    Scanline(voxelize::Mode),
    SolidParity,
    SolidWinding,
}

impl Engine {
    /// Groups of engines, each timed against one reference: `solid`
    /// measures parity and the generalized winding number (two groups);
    /// modes with a scanline path measure it beside the fast path, in one
    /// group whose engines are timed in alternation.
    fn new(m: topovox_job::Mode) -> Result<Vec<Vec<Engine>>> {
        Ok(match m {
            topovox_job::Mode::Solid => vec![vec![Engine::SolidParity], vec![Engine::SolidWinding]],
            m => {
                let core = crate::plan::core_mode(m)?;
                let mut v = vec![Engine::Surface(core)];
                if voxelize::scanline::supports(core) {
                    v.push(Engine::Scanline(core));
                }
                vec![v]
            }
        })
    }

    /// Largest resolution the reference runs at (the solid references test
    /// every triangle for every voxel).
    fn reference_cap(&self) -> u64 {
        match self {
            Engine::Surface(_) | Engine::Scanline(_) => u64::MAX,
            Engine::SolidParity => 32,
            Engine::SolidWinding => 12,
        }
    }

    fn name(&self) -> &'static str {
        match self {
            Engine::Surface(m) | Engine::Scanline(m) => m.name(),
            Engine::SolidParity => "solid (parity)",
            Engine::SolidWinding => "solid (winding)",
        }
    }

    fn fast_name(&self) -> &'static str {
        match self {
            Engine::Surface(_) => "fast",
            Engine::Scanline(_) => "scanline",
            Engine::SolidParity => "parity",
            Engine::SolidWinding => "winding",
        }
    }

    fn reference(&self, mesh: MeshRef<'_>, grid: &GridSpec) -> Result<u64> {
        Ok(match self {
            Engine::Surface(m) | Engine::Scanline(m) => voxelize::reference(*m, mesh, grid).1.voxels,
            Engine::SolidParity => solid::reference::solid(mesh, grid)?.1.voxels,
            Engine::SolidWinding => winding::reference::winding(mesh, grid)?.count(),
        })
    }

    fn fast(&self, mesh: MeshRef<'_>, grid: &GridSpec) -> Result<u64> {
        Ok(match self {
            Engine::Surface(m) => voxelize::fast(*m, mesh, grid, &Options::default()).1.voxels,
            Engine::Scanline(m) => {
                voxelize::scanline::scanline(*m, mesh, grid, &Options::default()).context("mode has no scanline path")?.1.voxels
            }
            Engine::SolidParity => solid::parity(mesh, grid)?.1.voxels,
            Engine::SolidWinding => winding::winding(mesh, grid)?.1.solid.voxels,
        })
    }
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
    let loaded = topovox_io::read_mesh(&a.mesh, &topovox_io::ReadOptions::default())?;
    if a.attributes {
        return attributes(a, &loaded);
    }
    if a.gpu {
        return gpu(a, &loaded);
    }
    let mut owned = loaded.mesh.clone();
    for _ in 0..a.subdivide {
        owned = subdivide(&owned);
    }
    let mesh = owned.as_ref();
    let m = measure(a, mesh, &loaded.report.bounds)?;
    if a.json {
        return print_json(a, &m);
    }
    print_table(a, mesh, &m)
}

/// The rows of the table, with the reference's and brute force's times.
struct Measured {
    rows: Vec<Row>,
    /// Per mode: the reference's resolution and median seconds.
    ref_s: std::collections::HashMap<&'static str, (u64, f64)>,
    /// Per resolution: the brute-force loop's median seconds.
    brute_s: std::collections::HashMap<u64, f64>,
}

/// Times every engine of `a.modes` at every thread count and resolution.
fn measure(a: &BenchArgs, mesh: topovox::MeshRef<'_>, bounds: &topovox::Aabb) -> Result<Measured> {
    let mut rows = Vec::new();
    let mut ref_s = std::collections::HashMap::new();
    let mut brute_s = std::collections::HashMap::new();
    let groups: Vec<Vec<Engine>> = a.modes.iter().map(|&m| Engine::new(m)).collect::<Result<Vec<_>>>()?.into_iter().flatten().collect();
    for group in &groups {
        // Baseline: the reference path (serial by construction), capped for
        // the solids.
        let first = &group[0];
        let ref_res = a.reference_resolution.min(first.reference_cap());
        let grid = GridSpec::from_resolution(bounds, ref_res).context("invalid grid")?;
        let (s, voxels) = time(a.repeats.clamp(1, 3), || first.reference(mesh, &grid));
        let voxels = voxels?;
        ref_s.insert(first.name(), (ref_res, s));
        rows.push(Row {
            mode: first.name(),
            method: "reference",
            threads: 1,
            resolution: ref_res,
            dims: grid.dims(),
            voxels,
            voxelize_s: s,
            with_loading_s: None,
        });

        for (n_threads, &threads) in a.threads.iter().enumerate() {
            let pool = topovox_job::pool_for(Some(threads), "--threads")?;
            for &res in &a.resolutions {
                let grid = GridSpec::from_resolution(bounds, res).context("invalid grid")?;
                crate::plan::check_memory(&grid)?;
                // The brute-force baseline runs on one thread whatever the
                // pool, so it is timed (in alternation) with the first thread
                // count of each resolution only.
                let with_brute = a.baseline == Some(Baseline::Brute) && n_threads == 0 && !brute_s.contains_key(&res);
                let items: Vec<Option<&Engine>> = group.iter().map(Some).chain(with_brute.then_some(None)).collect();
                let timed = pool.install(|| {
                    time_alternating(a.repeats, &items, |e| match e {
                        Some(e) => e.fast(mesh, &grid),
                        None => Ok(brute::cover(mesh, &grid).iter().map(|w| w.count_ones() as u64).sum()),
                    })
                });
                for (item, (vox_s, voxels)) in items.iter().zip(timed) {
                    let voxels = voxels?;
                    let Some(engine) = item else {
                        brute_s.insert(res, vox_s);
                        // With its own loading: the serial v/f reader a short
                        // program would have (OBJ only), then the loop.
                        let load_s = (a.subdivide == 0 && brute::load_obj(&a.mesh).is_some()).then(|| {
                            time(a.repeats.min(5), || {
                                let m = brute::load_obj(&a.mesh).unwrap_or_default();
                                let g = GridSpec::from_resolution(&m.as_ref().bounds(), res);
                                g.map(|g| brute::cover(m.as_ref(), &g).len()).unwrap_or(0)
                            })
                            .0
                        });
                        rows.push(Row {
                            mode: "(any)",
                            method: "brute",
                            threads: 1,
                            resolution: res,
                            dims: grid.dims(),
                            voxels,
                            voxelize_s: vox_s,
                            with_loading_s: load_s,
                        });
                        continue;
                    };
                    // With loading: only for the file as it is (a subdivided
                    // mesh is built in memory).
                    let load_s = if a.subdivide == 0 {
                        let (load_s, r) = pool.install(|| {
                            time(a.repeats.min(5), || -> Result<u64> {
                                let l = topovox_io::read_mesh(&a.mesh, &topovox_io::ReadOptions::default())?;
                                let g = GridSpec::from_resolution(&l.report.bounds, res)?;
                                engine.fast(l.mesh.as_ref(), &g)
                            })
                        });
                        r?;
                        Some(load_s)
                    } else {
                        None
                    };
                    rows.push(Row {
                        mode: engine.name(),
                        method: engine.fast_name(),
                        threads,
                        resolution: res,
                        dims: grid.dims(),
                        voxels,
                        voxelize_s: vox_s,
                        with_loading_s: load_s,
                    });
                }
            }
        }
    }

    Ok(Measured { rows, ref_s, brute_s })
}

/// `--json`: one object per row.
fn print_json(a: &BenchArgs, m: &Measured) -> Result<()> {
    for r in &m.rows {
        let v = json!({"mode": r.mode, "method": r.method, "threads": r.threads, "resolution": r.resolution, "dims": r.dims, "voxels": r.voxels,
                "voxelize_median_s": r.voxelize_s, "with_loading_median_s": r.with_loading_s, "repeats": a.repeats,
                "brute_median_s": m.brute_s.get(&r.resolution)});
        crate::console::print_stdout(&v.to_string())?;
    }
    Ok(())
}

/// The Markdown table.
fn print_table(a: &BenchArgs, mesh: topovox::MeshRef<'_>, m: &Measured) -> Result<()> {
    let (rows, ref_s, brute_s) = (&m.rows, &m.ref_s, &m.brute_s);
    let mut out = format!(
        "mesh: {}{} ({} triangles); median of {} repeats ({} with loading); {} hardware threads\n\n",
        a.mesh.display(),
        if a.subdivide > 0 { format!(" subdivided {} times", a.subdivide) } else { String::new() },
        mesh.triangles.len(),
        a.repeats,
        a.repeats.min(5),
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
    );
    let brute_col = a.baseline == Some(Baseline::Brute);
    out += &format!(
        "| mode | method | threads | resolution | grid | voxels | voxelize (ms) | with loading (ms) | vs reference | vs fast |{}\n|---|---|---|---|---|---|---|---|---|---|{}\n",
        if brute_col { " vs brute |" } else { "" },
        if brute_col { "---|" } else { "" }
    );
    for r in rows {
        let vs_fast = rows
            .iter()
            .find(|f| f.method == "fast" && f.mode == r.mode && f.threads == r.threads && f.resolution == r.resolution)
            .filter(|_| r.method == "scanline")
            .map(|f| format!("{:.2}x", f.voxelize_s / r.voxelize_s))
            .unwrap_or_else(|| "-".into());
        let d = r.dims;
        let load = r.with_loading_s.map(|s| format!("{:.1}", s * 1e3)).unwrap_or_else(|| "-".into());
        let speed = match ref_s.get(r.mode) {
            Some(&(rr, rs)) if r.resolution == rr => format!("{:.1}x", rs / r.voxelize_s),
            _ => "-".into(),
        };
        let vs_brute = match brute_s.get(&r.resolution) {
            Some(b) if brute_col && r.method != "brute" && r.method != "reference" => format!(" {:.2}x |", b / r.voxelize_s),
            _ if brute_col => " - |".into(),
            _ => String::new(),
        };
        out += &format!(
            "| {} | {} | {} | {} | {}x{}x{} | {} | {:.2} | {} | {} | {} |{}\n",
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
            speed,
            vs_fast,
            vs_brute
        );
    }
    crate::console::print_stdout(out.trim_end())
}

/// `--attributes`: per thread count and resolution, the medians of
/// voxelizing (`cover`, the baseline), carrying colours (dominant, blend),
/// a coloured picture and two coloured writers, timed in alternation.
fn attributes(a: &BenchArgs, loaded: &topovox_io::LoadedMesh) -> Result<()> {
    use topovox::attributes::carry::{carry, CarryOptions};
    use topovox::attributes::ColourRule;
    if !loaded.appearance.has_colour() {
        anyhow::bail!("{}: --attributes needs a mesh with colours (materials, textures or vertex colours)", a.mesh.display());
    }
    if a.subdivide > 0 {
        anyhow::bail!("--attributes times the mesh as it is; it cannot be combined with --subdivide");
    }
    let mesh = loaded.mesh.as_ref();
    let dir = std::env::temp_dir().join(format!("topovox-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let mut out = format!(
        "mesh: {} ({} triangles); cover by the fast path; median of {} repeats\n\n| threads | resolution | voxels | voxelize (ms) | carry dominant (ms) | carry blend (ms) | render 1024x768 (ms) | write .vox (ms) | write .vti (ms) | carry dominant vs voxelize |\n|---|---|---|---|---|---|---|---|---|---|\n",
        a.mesh.display(),
        mesh.triangles.len(),
        a.repeats
    );
    let mut json_rows = Vec::new();
    for &threads in &a.threads {
        let pool = topovox_job::pool_for(Some(threads), "--threads")?;
        for &res in &a.resolutions {
            let grid = GridSpec::from_resolution(&loaded.report.bounds, res).context("invalid grid")?;
            crate::plan::check_memory(&grid)?;
            let (bits, _) = pool.install(|| voxelize::fast(voxelize::Mode::Cover, mesh, &grid, &Options::default()));
            let attrs = pool.install(|| carry(mesh, &loaded.appearance, &grid, &bits, &CarryOptions::default()));
            let render_opts = topovox::render::raycast::RenderOptions::default();
            let steps = ["voxelize", "dominant", "blend", "render", "vox", "vti"];
            let timed = pool.install(|| {
                time_alternating(a.repeats, &steps, |&step| -> Result<()> {
                    let wo = topovox_io::WriteOptions::default();
                    match step {
                        "voxelize" => drop(voxelize::fast(voxelize::Mode::Cover, mesh, &grid, &Options::default())),
                        "dominant" | "blend" => {
                            let rule = if step == "blend" { ColourRule::Blend } else { ColourRule::Dominant };
                            drop(carry(mesh, &loaded.appearance, &grid, &bits, &CarryOptions { rule, normals: false }));
                        }
                        "render" => drop(topovox::render::raycast::render_with(&bits, &render_opts, Some(&attrs), None)),
                        f => {
                            let format = topovox_io::VoxelFormat::from_name(f).context("format")?;
                            topovox_io::write_voxels_with(&dir.join(format!("b.{f}")), format, &bits, &grid, Some(&attrs), &wo)?;
                        }
                    }
                    Ok(())
                })
            });
            let mut ms = Vec::new();
            for (s, r) in timed {
                r?;
                ms.push(s * 1e3);
            }
            out += &format!(
                "| {threads} | {res} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1}x |\n",
                bits.count(),
                ms[0],
                ms[1],
                ms[2],
                ms[3],
                ms[4],
                ms[5],
                ms[1] / ms[0]
            );
            json_rows.push(json!({"threads": threads, "resolution": res, "voxels": bits.count(), "voxelize_median_ms": ms[0],
                "carry_dominant_median_ms": ms[1], "carry_blend_median_ms": ms[2], "render_median_ms": ms[3],
                "write_vox_median_ms": ms[4], "write_vti_median_ms": ms[5]}));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    if a.json {
        for r in json_rows {
            crate::console::print_stdout(&r.to_string())?;
        }
        return Ok(());
    }
    crate::console::print_stdout(out.trim_end())
}

/// `--gpu`: `cover` by the GPU compute path against the CPU fast path
/// (timed in alternation), with the GPU's upload, run and download medians.
#[cfg(feature = "gpu")]
fn gpu(a: &BenchArgs, loaded: &topovox_io::LoadedMesh) -> Result<()> {
    let g = topovox_gpu::Gpu::new()?;
    let mut owned = loaded.mesh.clone();
    for _ in 0..a.subdivide {
        owned = subdivide(&owned);
    }
    let mesh = owned.as_ref();
    let mut out = format!(
        "mesh: {}{} ({} triangles); cover; median of {} repeats; GPU: {}\n\n| resolution | voxels | CPU fast, {} threads (ms) | GPU total (ms) | upload (ms) | GPU run (ms) | GPU time, timestamps (ms) | download (ms) | CPU share (ms) | GPU vs CPU |\n|---|---|---|---|---|---|---|---|---|---|\n",
        a.mesh.display(),
        if a.subdivide > 0 { format!(" subdivided {} times", a.subdivide) } else { String::new() },
        mesh.triangles.len(),
        a.repeats,
        g.adapter(),
        rayon::current_num_threads()
    );
    let mut json_rows = Vec::new();
    for &res in &a.resolutions {
        let grid = GridSpec::from_resolution(&loaded.report.bounds, res).context("invalid grid")?;
        crate::plan::check_memory(&grid)?;
        let mut parts: Vec<topovox_gpu::Timings> = Vec::new();
        let timed = time_alternating(a.repeats, &[false, true], |&on_gpu| -> Result<u64> {
            if on_gpu {
                let (bits, r) = g.cover(mesh, &grid)?;
                parts.push(r.timings);
                Ok(bits.count())
            } else {
                Ok(voxelize::fast(voxelize::Mode::Cover, mesh, &grid, &Options::default()).0.count())
            }
        });
        let (cpu_s, cpu_n) = (timed[0].0, timed[0].1.as_ref().map_err(|e| anyhow::anyhow!("{e}"))?);
        let (gpu_s, gpu_n) = (timed[1].0, timed[1].1.as_ref().map_err(|e| anyhow::anyhow!("{e}"))?);
        anyhow::ensure!(cpu_n == gpu_n, "GPU and CPU voxel counts differ at {res}: {gpu_n} vs {cpu_n}");
        let m = |f: fn(&topovox_gpu::Timings) -> f64| median(parts.iter().map(f).collect()) * 1e3;
        let (up, run, down, cpu_share) = (m(|t| t.upload_s), m(|t| t.voxelize_s), m(|t| t.download_s), m(|t| t.cpu_s));
        let stamped = parts.iter().all(|t| t.gpu_s.is_some());
        let gpu_time = stamped.then(|| m(|t| t.gpu_s.unwrap_or(0.0)));
        let gpu_time_cell = gpu_time.map(|g| format!("{g:.3}")).unwrap_or_else(|| "-".into());
        out += &format!(
            "| {res} | {cpu_n} | {:.1} | {:.1} | {up:.1} | {run:.1} | {gpu_time_cell} | {down:.1} | {cpu_share:.1} | {:.2}x |\n",
            cpu_s * 1e3,
            gpu_s * 1e3,
            cpu_s / gpu_s
        );
        json_rows.push(json!({"resolution": res, "voxels": cpu_n, "cpu_fast_median_ms": cpu_s * 1e3, "gpu_total_median_ms": gpu_s * 1e3,
            "upload_median_ms": up, "gpu_run_median_ms": run, "gpu_timestamps_median_ms": gpu_time, "download_median_ms": down, "cpu_share_median_ms": cpu_share, "adapter": g.adapter()}));
    }
    if a.json {
        for r in json_rows {
            crate::console::print_stdout(&r.to_string())?;
        }
        return Ok(());
    }
    crate::console::print_stdout(out.trim_end())
}

#[cfg(not(feature = "gpu"))]
fn gpu(_a: &BenchArgs, _loaded: &topovox_io::LoadedMesh) -> Result<()> {
    anyhow::bail!("bench --gpu: this topovox was built without the `gpu` feature")
}

/// Splits every triangle into four at its edge midpoints (positions are
/// duplicated per triangle; the voxelizers do not need shared vertices).
fn subdivide(m: &topovox::Mesh) -> topovox::Mesh {
    let mut positions = Vec::with_capacity(m.triangles.len() * 6);
    let mut triangles = Vec::with_capacity(m.triangles.len() * 4);
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let base = positions.len() as u32;
        positions.extend([a, b, c, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5]);
        let [a, b, c, ab, bc, ca] = [0, 1, 2, 3, 4, 5].map(|i| base + i);
        triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    topovox::Mesh { positions, triangles, segments: m.segments.clone() }
}
