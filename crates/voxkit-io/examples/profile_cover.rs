//! Times one mode's fast path on one mesh, by driver (and the phases of the
//! slab driver: prepare, kernel), for profiling: `cargo run --release -p
//! voxkit-io --example profile_cover -- MESH RESOLUTION THREADS [REPEATS] [MODE]`.
//! With `PROFILE_AUTO_ONLY=1` only the default driver runs (for `perf`).

use std::time::Instant;

use voxkit::geom::lattice::prepare;
use voxkit::voxelize::driver::Driver;
use voxkit::voxelize::{self, cover, Mode, Options};
use voxkit::GridSpec;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).map(String::as_str).unwrap_or("../shared/meshes/stanford-bunny.obj");
    let res: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1024);
    let threads: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1);
    let reps: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(11);
    let mode = args.get(5).and_then(|m| Mode::ALL.into_iter().find(|x| x.name() == m)).unwrap_or(Mode::Cover);
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
        let mut line = format!("{} threads {threads} res {res}:", mode.name());
        let auto_only = std::env::var_os("PROFILE_AUTO_ONLY").is_some();
        let drivers: &[Driver] = if auto_only { &[Driver::Auto] } else { &[Driver::Auto, Driver::Slabs, Driver::Triangles] };
        for &driver in drivers {
            let opts = Options { driver, ..Options::default() };
            let t = time(&mut || {
                std::hint::black_box(voxelize::fast(mode, mesh, &grid, &opts));
            });
            line += &format!(" {driver:?} {t:.2} ms;");
        }
        if mode == Mode::Cover && !auto_only {
            let prep = time(&mut || {
                std::hint::black_box(prepare(mesh, &grid));
            });
            let (tris, _) = prepare(mesh, &grid);
            let kernel = time(&mut || {
                std::hint::black_box(cover::cover_lattice(&tris, grid.dims(), &Options::default()));
            });
            let snap = time(&mut || {
                std::hint::black_box(voxkit::geom::lattice::SnappedMesh::new(mesh, &grid));
            });
            line += &format!(" slab phases: prepare {prep:.2} ms, kernel {kernel:.2} ms; snapping vertices {snap:.2} ms;");
        }
        let bits = voxelize::fast(mode, mesh, &grid, &Options::default()).0;
        println!("{line} {} voxels in {} bricks ({:.1} MB)", bits.count(), bits.brick_count(), bits.memory_bytes() as f64 / 1e6);
    });
}
