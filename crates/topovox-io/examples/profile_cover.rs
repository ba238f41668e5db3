//! Times one mode's fast path on one mesh, by driver (and the phases of the
//! slab driver: prepare, kernel), for profiling: `cargo run --release -p
//! topovox-io --example profile_cover -- MESH RESOLUTION THREADS [REPEATS] [MODE]`.
//! With `PROFILE_AUTO_ONLY=1` only the default driver runs (for `perf`).

mod profiling;

use topovox::geom::lattice::prepare;
use topovox::voxelize::driver::Driver;
use topovox::voxelize::{self, cover, Mode, Options};

fn main() {
    let run = profiling::Profiled::from_args("../shared/meshes/stanford-bunny.obj", 1024, 11);
    let mode = run.args.get(5).and_then(|m| Mode::ALL.into_iter().find(|x| x.name() == m)).unwrap_or(Mode::Cover);
    let (threads, res, grid) = (run.threads, run.res, &run.grid);
    run.pool.install(|| {
        let mesh = run.loaded.mesh.as_ref();
        let time = |f: &mut dyn FnMut()| run.median_ms(f);
        let mut line = format!("{} threads {threads} res {res}:", mode.name());
        let auto_only = std::env::var_os("PROFILE_AUTO_ONLY").is_some();
        let drivers: &[Driver] = if auto_only { &[Driver::Auto] } else { &[Driver::Auto, Driver::Slabs, Driver::Triangles] };
        for &driver in drivers {
            let opts = Options { driver, ..Options::default() };
            let t = time(&mut || {
                std::hint::black_box(voxelize::fast(mode, mesh, grid, &opts));
            });
            line += &format!(" {driver:?} {t:.2} ms;");
        }
        if mode == Mode::Cover && !auto_only {
            let prep = time(&mut || {
                std::hint::black_box(prepare(mesh, grid));
            });
            let (tris, _) = prepare(mesh, grid);
            let kernel = time(&mut || {
                std::hint::black_box(cover::cover_lattice(&tris, grid.dims(), &Options::default()));
            });
            let snap = time(&mut || {
                std::hint::black_box(topovox::geom::lattice::SnappedMesh::new(mesh, grid));
            });
            line += &format!(" slab phases: prepare {prep:.2} ms, kernel {kernel:.2} ms; snapping vertices {snap:.2} ms;");
        }
        let bits = voxelize::fast(mode, mesh, grid, &Options::default()).0;
        println!("{line} {} voxels in {} bricks ({:.1} MB)", bits.count(), bits.brick_count(), bits.memory_bytes() as f64 / 1e6);
    });
}
