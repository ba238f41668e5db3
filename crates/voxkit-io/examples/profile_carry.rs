//! Times carrying attributes (dominant and blend colours) on one mesh, for
//! profiling: `cargo run --release -p voxkit-io --example profile_carry --
//! MESH RESOLUTION THREADS [REPEATS] [dominant|blend]`.

use std::time::Instant;

use voxkit::attributes::carry::{carry, CarryOptions};
use voxkit::attributes::ColourRule;
use voxkit::voxelize::{self, Mode, Options};
use voxkit::GridSpec;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).map(String::as_str).unwrap_or("../shared/meshes/spot-textured.obj");
    let res: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1024);
    let threads: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1);
    let reps: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(5);
    let rule = if args.get(5).map(String::as_str) == Some("blend") { ColourRule::Blend } else { ColourRule::Dominant };
    let loaded = voxkit_io::read_mesh(std::path::Path::new(path)).expect("mesh");
    let grid = GridSpec::from_resolution(&loaded.report.bounds, res).expect("grid");
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
    pool.install(|| {
        let mesh = loaded.mesh.as_ref();
        let bits = voxelize::fast(Mode::Cover, mesh, &grid, &Options::default()).0;
        let mut times: Vec<f64> = (0..reps)
            .map(|_| {
                let t = Instant::now();
                std::hint::black_box(carry(mesh, &loaded.appearance, &grid, &bits, &CarryOptions { rule, normals: false }));
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        times.sort_by(f64::total_cmp);
        // A checksum of every attribute, to compare implementations.
        use std::hash::{Hash, Hasher};
        let a = carry(mesh, &loaded.appearance, &grid, &bits, &CarryOptions { rule, normals: true });
        let mut h = std::hash::DefaultHasher::new();
        a.keys.hash(&mut h);
        a.colour.hash(&mut h);
        a.material.hash(&mut h);
        a.normal.iter().flatten().flatten().for_each(|x| x.to_bits().hash(&mut h));
        a.coverage.iter().flatten().for_each(|x| x.to_bits().hash(&mut h));
        println!(
            "carry {rule:?} threads {threads} res {res}: median {:.1} ms ({} voxels, checksum {:016x})",
            times[times.len() / 2],
            bits.count(),
            h.finish()
        );
    });
}
