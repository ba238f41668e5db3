//! Times carrying attributes (dominant and blend colours) on one mesh, for
//! profiling: `cargo run --release -p topovox-io --example profile_carry --
//! MESH RESOLUTION THREADS [REPEATS] [dominant|blend]`.

mod profiling;

use topovox::attributes::carry::{carry, CarryOptions};
use topovox::attributes::ColourRule;
use topovox::voxelize::{self, Mode, Options};

fn main() {
    let run = profiling::Profiled::from_args("../shared/meshes/spot-textured.obj", 1024, 5);
    let rule = if run.args.get(5).map(String::as_str) == Some("blend") { ColourRule::Blend } else { ColourRule::Dominant };
    let (threads, res, grid, loaded) = (run.threads, run.res, &run.grid, &run.loaded);
    run.pool.install(|| {
        let mesh = loaded.mesh.as_ref();
        let bits = voxelize::fast(Mode::Cover, mesh, grid, &Options::default()).0;
        let median = run.median_ms(&mut || {
            std::hint::black_box(carry(mesh, &loaded.appearance, grid, &bits, &CarryOptions { rule, normals: false }));
        });
        // A checksum of every attribute, to compare implementations.
        use std::hash::{Hash, Hasher};
        let a = carry(mesh, &loaded.appearance, grid, &bits, &CarryOptions { rule, normals: true });
        let mut h = std::hash::DefaultHasher::new();
        a.keys.hash(&mut h);
        a.colour.hash(&mut h);
        a.material.hash(&mut h);
        a.normal.iter().flatten().flatten().for_each(|x| x.to_bits().hash(&mut h));
        a.coverage.iter().flatten().for_each(|x| x.to_bits().hash(&mut h));
        println!(
            "carry {rule:?} threads {threads} res {res}: median {:.1} ms ({} voxels, checksum {:016x})",
            median,
            bits.count(),
            h.finish()
        );
    });
}
