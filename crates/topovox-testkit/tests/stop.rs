//! A requested [`Stop`] is looked at by every long loop (issue 44, item 8:
//! Ctrl-C in Python): with the stop requested before the work starts,
//! each driver, tiled path and solid skips all of its slabs, tiles, rows
//! and layers, so its result is empty; without it, the same call sets
//! voxels. (Python requests the stop from another thread while the work
//! runs; `python/tests/test_promises.py` interrupts a real call.)

use topovox::topology::inside::snap_all;
use topovox::voxelize::{self, driver::Driver, fill, scanline, solid, tiled, winding, Mode, Options, Stop};
use topovox::{GridSpec, Mesh};
use topovox_testkit::shared_mesh;

/// `(voxels without a stop, voxels with one requested)` for each named
/// piece of work.
fn both(run: impl Fn(&Stop) -> u64) -> (u64, u64) {
    let stopped = Stop::new();
    stopped.request();
    (run(&Stop::new()), run(&stopped))
}

fn assert_stops(what: &str, run: impl Fn(&Stop) -> u64) {
    let (free, stopped) = both(run);
    assert!(free > 0, "{what}: sets no voxel even without a stop");
    assert_eq!(stopped, 0, "{what}: ran on after the stop was requested");
}

/// The first edge of each triangle, as a polyline soup.
fn edges_of(m: &Mesh) -> Mesh {
    Mesh { positions: m.positions.clone(), triangles: Vec::new(), segments: m.triangles.iter().map(|t| [t[0], t[1]]).collect() }
}

fn opts(stop: &Stop) -> Options<'_> {
    Options { stop: Some(stop), ..Options::default() }
}

#[test]
fn every_long_loop_looks_at_the_stop() {
    let cow = shared_mesh("cow.obj");
    let grid = GridSpec::from_resolution(&cow.as_ref().bounds(), 120).unwrap();
    for driver in [Driver::Slabs, Driver::Triangles] {
        for mode in [Mode::Cover, Mode::Sep26, Mode::Tunnel26, Mode::Line26] {
            let mesh = if mode == Mode::Line26 { edges_of(&cow) } else { cow.clone() };
            assert_stops(&format!("{} on the {driver:?} driver", mode.name()), |s| {
                voxelize::fast(mode, mesh.as_ref(), &grid, &Options { driver, ..opts(s) }).0.count()
            });
        }
    }
    assert_stops("scanline cover", |s| scanline::scanline(Mode::Cover, cow.as_ref(), &grid, &opts(s)).unwrap().0.count());
    assert_stops("tiled cover", |s| tiled::tiled(Mode::Cover, cow.as_ref(), &grid, 32, &opts(s)).unwrap().0.count());
    let snapped = snap_all(cow.as_ref(), &grid).unwrap();
    let dims = grid.dims();
    assert_stops("dense parity", |s| solid::parity_snapped(&snapped, dims, s).0.count());
    assert_stops("dense closed winding", |s| solid::winding_closed_snapped(&snapped, dims, s).0.count());
    assert_stops("sparse parity", |s| solid::parity_sparse(&snapped, dims, s).0.count());
    assert_stops("sparse closed winding", |s| solid::winding_closed_sparse(&snapped, dims, s).0.count());
    let shell = tiled::tiled(Mode::Cover, cow.as_ref(), &grid, 32, &Options::default()).unwrap().0;
    // The flood fill keeps the shell it was given: only the enclosed
    // voxels are work.
    assert_stops("sparse flood fill", |s| fill::flood_fill_sparse(&shell, s).1.enclosed);
    let bunny = shared_mesh("stanford-bunny.obj");
    let grid = GridSpec::from_resolution(&bunny.as_ref().bounds(), 120).unwrap();
    let open = snap_all(bunny.as_ref(), &grid).unwrap();
    assert_stops("dense generalized winding", |s| winding::winding_snapped(&open, grid.dims(), s).0.count());
    assert_stops("sparse generalized winding", |s| winding::winding_sparse(&open, grid.dims(), s).0.count());
}
