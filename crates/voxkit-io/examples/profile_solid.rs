//! Times the parity solid on one mesh by phase (snapping and the closedness
//! count, the rows' crossings, the whole call), for profiling: `cargo run
//! --release -p voxkit-io --example profile_solid -- MESH RESOLUTION THREADS
//! [REPEATS]`. With `PROFILE_AUTO_ONLY=1` only the whole call is timed (for
//! `perf`), printed as `Auto … ms` like `profile_cover`.

use std::time::Instant;

use voxkit::topology::inside::{row_crossings, snap_all};
use voxkit::voxelize::solid;
use voxkit::GridSpec;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).map(String::as_str).unwrap_or("../shared/meshes/stanford-bunny.obj");
    let res: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(128);
    let threads: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1);
    let reps: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(11);
    let loaded = voxkit_io::read_mesh(std::path::Path::new(path)).expect("mesh");
    let grid = GridSpec::from_resolution(&loaded.report.bounds, res).expect("grid");
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    pool.install(|| {
        let mesh = loaded.mesh.as_ref();
        let time = |f: &mut dyn FnMut()| {
            median(
                (0..reps)
                    .map(|_| {
                        let t = Instant::now();
                        f();
                        t.elapsed().as_secs_f64() * 1e3
                    })
                    .collect(),
            )
        };
        let whole = time(&mut || {
            std::hint::black_box(solid::parity(mesh, &grid).expect("parity"));
        });
        let mut line = format!("parity threads {threads} res {res}: Auto {whole:.2} ms;");
        if std::env::var_os("PROFILE_AUTO_ONLY").is_none() {
            let snap = time(&mut || {
                std::hint::black_box(snap_all(mesh, &grid).expect("snap"));
            });
            let snapped = snap_all(mesh, &grid).expect("snap");
            let tris = snapped.crossing_triangles();
            let rows = time(&mut || {
                std::hint::black_box(row_crossings(&tris, grid.dims()));
            });
            line += &format!(" snap_all {snap:.2} ms; row_crossings {rows:.2} ms;");
        }
        println!("{line}");
    });
}
