//! Times the phases of `cover` separately (prepare, kernel) and reports the
//! sparse storage used, on one mesh: `cargo run --release -p voxkit-io --example
//! profile_cover -- MESH RESOLUTION THREADS`.

use std::time::Instant;

use voxkit::geom::lattice::prepare;
use voxkit::voxelize::{cover, Options};
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
    let loaded = voxkit_io::read_mesh(std::path::Path::new(path)).expect("mesh");
    let grid = GridSpec::from_resolution(&loaded.report.bounds, res).expect("grid");
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    pool.install(|| {
        let mesh = loaded.mesh.as_ref();
        let reps: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(11);
        let time = |f: &mut dyn FnMut()| median((0..reps).map(|_| { let t = Instant::now(); f(); t.elapsed().as_secs_f64() * 1e3 }).collect());
        let prep = time(&mut || { std::hint::black_box(prepare(mesh, &grid)); });
        let (tris, _) = prepare(mesh, &grid);
        let kernel = time(&mut || { std::hint::black_box(cover::cover_lattice(&tris, grid.dims(), &Options::default())); });
        let bits = cover::cover_lattice(&tris, grid.dims(), &Options::default());
        let full = time(&mut || { std::hint::black_box(cover::cover(mesh, &grid, &Options::default())); });
        println!(
            "threads {threads} res {res}: prepare {prep:.2} ms, kernel {kernel:.2} ms, full {full:.2} ms; {} voxels in {} bricks ({:.1} MB)",
            bits.count(),
            bits.brick_count(),
            bits.memory_bytes() as f64 / 1e6
        );
    });
}
