//! Times the parity solid on one mesh by phase (snapping and the closedness
//! count, the rows' crossings, the whole call), for profiling: `cargo run
//! --release -p topovox-io --example profile_solid -- MESH RESOLUTION THREADS
//! [REPEATS]`. With `PROFILE_AUTO_ONLY=1` only the whole call is timed (for
//! `perf`), printed as `Auto … ms` like `profile_cover`.

mod profiling;

use topovox::topology::inside::{row_crossings, snap_all};
use topovox::voxelize::solid;

fn main() {
    let run = profiling::Profiled::from_args("../shared/meshes/stanford-bunny.obj", 128, 11);
    let (threads, res, grid) = (run.threads, run.res, &run.grid);
    run.pool.install(|| {
        let mesh = run.loaded.mesh.as_ref();
        let whole = run.median_ms(&mut || {
            std::hint::black_box(solid::parity(mesh, grid).expect("parity"));
        });
        let mut line = format!("parity threads {threads} res {res}: Auto {whole:.2} ms;");
        if std::env::var_os("PROFILE_AUTO_ONLY").is_none() {
            let snap = run.median_ms(&mut || {
                std::hint::black_box(snap_all(mesh, grid).expect("snap"));
            });
            // The triangles as the fill reads them (zero-area ones cross nothing).
            let snapped = snap_all(mesh, grid).expect("snap");
            let rows = run.median_ms(&mut || {
                std::hint::black_box(row_crossings(&snapped.triangles, grid.dims()));
            });
            line += &format!(" snap_all {snap:.2} ms; row_crossings {rows:.2} ms;");
        }
        println!("{line}");
    });
}
