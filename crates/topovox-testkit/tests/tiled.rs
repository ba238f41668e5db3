//! The tiled driver gives the dense fast path's voxels: every shared mesh at
//! 256–1024 with tiles of 64, every mode on rotated meshes, line modes on a
//! polyline and a mesh, and a cropped window of a large grid equals the
//! same window run alone.
//! (`agree_mode` also runs tiles of 8, 24 and 64 against every reference.)

use glam::DVec3;
use topovox::voxelize::{self, tiled::tiled, Mode, Options, Stop};
use topovox::GridSpec;
use topovox_testkit::{random_rotation, rng, rotated, shared_mesh, SHARED_MESHES};

const MODES: [Mode; 9] =
    [Mode::Cover, Mode::Sep26, Mode::Sep6, Mode::Ss6, Mode::Pos, Mode::Tunnel18, Mode::Tunnel26, Mode::Bubble { seed: 3 }, Mode::Diagonal];

fn same(mode: Mode, mesh: &topovox::Mesh, grid: &GridSpec, tile: u32, what: &str) {
    let (dense, drep) = voxelize::fast(mode, mesh.as_ref(), grid, &Options::default());
    let (sparse, trep) = tiled(mode, mesh.as_ref(), grid, tile, &Options::default()).unwrap();
    assert_eq!(trep, drep, "{what} {}: reports differ", mode.name());
    let d = dense.to_dense();
    if let Some(v) = d.first_difference(&sparse.to_dense()) {
        panic!("{what} {} tile {tile}: differs at {v:?} (dense {})", mode.name(), d.get(v[0], v[1], v[2]));
    }
}

#[test]
fn every_shared_mesh_cover_at_256_and_512_with_tiles_of_64() {
    for name in SHARED_MESHES {
        let mesh = shared_mesh(name);
        for res in [256, 512] {
            let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), res).unwrap();
            same(Mode::Cover, &mesh, &grid, 64, &format!("{name} at {res}"));
        }
    }
}

#[test]
fn bunny_at_1024_with_tiles_of_64() {
    let mesh = shared_mesh("stanford-bunny.obj");
    let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), 1024).unwrap();
    for mode in [Mode::Cover, Mode::Sep6] {
        same(mode, &mesh, &grid, 64, "bunny at 1024");
    }
}

/// The scanline kernel in tiles gives the dense fast path's voxels too.
#[test]
fn scanline_tiles_equal_dense_on_rotated_meshes() {
    use topovox::voxelize::tiled::{tiled_with, TileKernel};
    let mut r = rng(0x5ca7);
    for name in ["stanford-bunny.obj", "fandisk.obj", "cheburashka.obj"] {
        let mesh = rotated(&shared_mesh(name), random_rotation(&mut r));
        for res in [200, 512] {
            let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), res).unwrap();
            for mode in [Mode::Cover, Mode::Sep26, Mode::Sep6] {
                let (dense, drep) = voxelize::fast(mode, mesh.as_ref(), &grid, &Options::default());
                let (sparse, trep) = tiled_with(mode, TileKernel::Scanline, mesh.as_ref(), &grid, 64, &Options::default()).unwrap();
                assert_eq!(trep, drep, "{name} {} at {res}: reports differ", mode.name());
                let d = dense.to_dense();
                assert!(d.first_difference(&sparse.to_dense()).is_none(), "{name} {} at {res}: scanline tiles differ", mode.name());
            }
        }
    }
    let mesh = shared_mesh("cow.obj");
    let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), 64).unwrap();
    let e = tiled_with(Mode::Ss6, TileKernel::Scanline, mesh.as_ref(), &grid, 64, &Options::default()).unwrap_err();
    assert!(e.to_string().contains("scanline exists for cover, sep26 and sep6"), "{e}");
}

#[test]
fn every_mode_on_rotated_meshes_at_256() {
    let mut r = rng(0x711e);
    for name in ["stanford-bunny.obj", "fandisk.obj", "teapot.obj"] {
        let mesh = rotated(&shared_mesh(name), random_rotation(&mut r));
        let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), 256).unwrap();
        for mode in MODES {
            same(mode, &mesh, &grid, 64, &format!("rotated {name} at 256"));
        }
    }
}

#[test]
fn a_window_of_a_large_grid_equals_the_window_run_alone() {
    // The whole grid is 4096³ (a dense index would be 512 MiB of bricks'
    // entries; the tiled run never allocates it); the window is 200³ of it.
    let mesh = shared_mesh("cheburashka.obj");
    let big = GridSpec::from_resolution(&mesh.as_ref().bounds(), 4096).unwrap();
    let (whole, _) = tiled(Mode::Sep26, mesh.as_ref(), &big, 512, &Options::default()).unwrap();
    let s = big.voxel_size().0;
    // A window around the middle voxel of the surface, in a corner of
    // tiles (it spans 8 of them).
    let mut all = Vec::new();
    topovox::VoxelSource::for_each_set(&whole, &mut |i, j, k| all.push([i, j, k]));
    let corner = |c: u32| (c + 256) / 512 * 512;
    let off = |v: &[u32; 3]| v.iter().map(|&c| (c as i64 - corner(c) as i64).abs()).max().unwrap();
    let near = *all.iter().filter(|v| v.iter().all(|&c| corner(c) >= 100)).min_by_key(|v| off(v)).unwrap();
    assert!(off(&near) < 100, "a surface voxel within 100 of a tile corner");
    let lo = near.map(|c| corner(c) - 100);
    let window = GridSpec::new(big.origin() + DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64) * s, s, [200, 200, 200]).unwrap();
    let (part, _) = voxelize::fast(Mode::Sep26, mesh.as_ref(), &window, &Options::default());
    let part = part.to_dense();
    assert!(part.count() > 1000, "the window holds surface");
    let mut inside = 0;
    topovox::VoxelSource::for_each_set(&whole, &mut |i, j, k| {
        let (a, b, c) = (i.wrapping_sub(lo[0]), j.wrapping_sub(lo[1]), k.wrapping_sub(lo[2]));
        if a < 200 && b < 200 && c < 200 {
            inside += 1;
            assert!(part.get(a, b, c), "voxel {i} {j} {k} of the whole grid is not in the window's run");
        }
    });
    assert_eq!(inside, part.count());
}

#[test]
fn bad_tiles_are_refused() {
    let mesh = shared_mesh("suzanne.obj");
    let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), 64).unwrap();
    let e = tiled(Mode::Cover, mesh.as_ref(), &grid, 12, &Options::default()).unwrap_err();
    assert!(e.to_string().contains("multiple of 8"), "{e}");
}

/// Line modes tile too: a polyline crossing tile corners, edges and faces
/// (a helix and straight runs along the tiles' planes) and a triangle mesh
/// taken as 1D input, against the dense fast path with tiles of 8 to 64.
#[test]
fn line_modes_tiled_equal_dense() {
    let mut pts: Vec<DVec3> = (0..400)
        .map(|n| {
            let t = n as f64 * 0.05;
            DVec3::new(40.0 + 30.0 * t.cos(), 40.0 + 30.0 * t.sin(), 2.0 + 3.5 * t)
        })
        .collect();
    // Along a tile corner's lines and planes (tiles of 8 and 16 meet at 16).
    pts.extend([DVec3::new(16.0, 16.0, 1.0), DVec3::new(16.0, 16.0, 60.0), DVec3::new(70.0, 16.0, 60.0), DVec3::new(3.0, 64.0, 8.0)]);
    let polyline =
        topovox::Mesh { segments: (0..pts.len() as u32 - 1).map(|i| [i, i + 1]).collect(), positions: pts, triangles: Vec::new() };
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [80, 80, 76]).unwrap();
    let suzanne = shared_mesh("suzanne.obj");
    let sgrid = GridSpec::from_resolution(&suzanne.as_ref().bounds(), 100).unwrap();
    for mode in [Mode::Line26, Mode::Line6] {
        assert!(voxelize::fast(mode, polyline.as_ref(), &grid, &Options::default()).1.voxels > 400, "the polyline crosses the grid");
        for tile in [8, 16, 24, 64] {
            same(mode, &polyline, &grid, tile, "helix polyline");
            same(mode, &suzanne, &sgrid, tile, "suzanne as 1D input at 100");
        }
    }
}

/// The sparse solid (brick rows into sparse bricks and full runs) equals
/// the dense one voxel for voxel, parity, closed and generalized winding
/// alike: every
/// shared mesh at a size that is not a multiple of 8, rotated meshes, a
/// box whose faces pass through voxel centres and lie on brick borders,
/// and nested boxes (winding fills the doubly wrapped core, parity not).
#[test]
fn sparse_solids_equal_dense_ones() {
    use topovox::topology::inside::snap_all;
    use topovox::voxelize::solid;
    let check = |mesh: &topovox::Mesh, grid: &GridSpec, what: &str| {
        let snapped = snap_all(mesh.as_ref(), grid).unwrap();
        for winding in [false, true] {
            let ((d, dr), (s, sr)) = if winding {
                (
                    solid::winding_closed_snapped(&snapped, grid.dims(), &Stop::new()),
                    solid::winding_closed_sparse(&snapped, grid.dims(), &Stop::new()),
                )
            } else {
                (solid::parity_snapped(&snapped, grid.dims(), &Stop::new()), solid::parity_sparse(&snapped, grid.dims(), &Stop::new()))
            };
            assert_eq!(dr, sr, "{what} (winding {winding}): reports differ");
            if let Some(v) = d.first_difference(&s.to_dense()) {
                panic!("{what} (winding {winding}): differs at {v:?} (dense {})", d.get(v[0], v[1], v[2]));
            }
            assert_eq!(s.count(), d.count());
        }
    };
    for name in SHARED_MESHES {
        let mesh = shared_mesh(name);
        let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), 141).unwrap();
        check(&mesh, &grid, name);
    }
    let mut r = rng(0x5011d);
    for name in ["stanford-bunny.obj", "cow.obj", "suzanne.obj"] {
        let mesh = rotated(&shared_mesh(name), random_rotation(&mut r));
        let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), 203).unwrap();
        check(&mesh, &grid, &format!("rotated {name}"));
    }
    // Open meshes: the generalized winding number, sparse and dense alike
    // (both go through the same rows' spans), straight and rotated.
    let gwn = |mesh: &topovox::Mesh, grid: &GridSpec, what: &str| {
        let snapped = snap_all(mesh.as_ref(), grid).unwrap();
        let ((d, dr), (s, sr)) = (
            voxelize::winding::winding_snapped(&snapped, grid.dims(), &Stop::new()),
            voxelize::winding::winding_sparse(&snapped, grid.dims(), &Stop::new()),
        );
        assert_eq!(dr, sr, "{what} (generalized winding): reports differ");
        assert!(dr.cycles > 0 && dr.evaluated > 0, "{what}: no caps to test");
        if let Some(v) = d.first_difference(&s.to_dense()) {
            panic!("{what} (generalized winding): differs at {v:?} (dense {})", d.get(v[0], v[1], v[2]));
        }
    };
    for (name, res) in [("stanford-bunny.obj", 141), ("beetle.obj", 97), ("suzanne.obj", 120)] {
        let mesh = shared_mesh(name);
        gwn(&mesh, &GridSpec::from_resolution(&mesh.as_ref().bounds(), res).unwrap(), name);
        let mesh = rotated(&mesh, random_rotation(&mut r));
        gwn(&mesh, &GridSpec::from_resolution(&mesh.as_ref().bounds(), res + 20).unwrap(), &format!("rotated {name}"));
    }
    // Faces through voxel centres (x = 8.5, 40.5) and on brick borders (y = 8, 48).
    let b = topovox_testkit::box_mesh(DVec3::new(8.5, 8.0, 3.25), DVec3::new(40.5, 48.0, 61.0));
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [51, 60, 64]).unwrap();
    check(&b, &grid, "box on centres and brick borders");
    let inner = topovox_testkit::box_mesh(DVec3::new(16.0, 16.0, 16.0), DVec3::new(32.0, 40.0, 48.0));
    let mut nested = b.clone();
    let n = nested.positions.len() as u32;
    nested.positions.extend(&inner.positions);
    nested.triangles.extend(inner.triangles.iter().map(|t| t.map(|v| v + n)));
    check(&nested, &grid, "nested boxes");
}

/// A sparse solid keeps its interior as full runs: a 1000³ box holds
/// almost 10^9 voxels in a few megabytes.
#[test]
fn sparse_solid_interiors_are_full_runs() {
    use topovox::topology::inside::snap_all;
    let b = topovox_testkit::box_mesh(DVec3::splat(3.5), DVec3::splat(996.5));
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [1000, 1000, 1000]).unwrap();
    let (s, _) = topovox::voxelize::solid::parity_sparse(&snap_all(b.as_ref(), &grid).unwrap(), grid.dims(), &Stop::new());
    assert_eq!(s.count(), 993u64.pow(3));
    assert!(s.memory_bytes() < 64 << 20, "{} bytes", s.memory_bytes());
    assert!(s.full_bricks() > 100u64.pow(3));
    assert!(s.get(4, 4, 4) && s.get(996, 500, 996) && !s.get(3, 500, 500) && !s.get(500, 997, 500) && s.get(500, 500, 500));
}

/// The flood fill past memory (plane by plane over sparse bricks) gives
/// the dense flood fill's voxels and report: closed meshes' shells, the
/// open bunny's (which leaks), rotated meshes, a thin `sep6` shell, nested
/// boxes (a cavity inside a cavity) and a grid whose last brick layer is
/// partial.
#[test]
fn sparse_flood_fill_equals_dense() {
    use topovox::voxelize::fill;
    let check = |mode: Mode, mesh: &topovox::Mesh, grid: &GridSpec, what: &str| {
        let shell = voxelize::fast(mode, mesh.as_ref(), grid, &Options::default()).0;
        let (d, dr) = fill::flood_fill(&shell.to_dense());
        let (sparse, _) = tiled(mode, mesh.as_ref(), grid, 64, &Options::default()).unwrap();
        let (s, sr) = fill::flood_fill_sparse(&sparse, &Stop::new());
        assert_eq!(dr, sr, "{what}: reports differ");
        if let Some(v) = d.first_difference(&s.to_dense()) {
            panic!("{what}: differs at {v:?} (dense {})", d.get(v[0], v[1], v[2]));
        }
        dr
    };
    let mut enclosed = 0;
    let mut r = rng(0xf100d);
    for (name, res) in [("cow.obj", 101), ("stanford-bunny.obj", 90), ("cheburashka.obj", 77), ("fandisk.obj", 64)] {
        let mesh = shared_mesh(name);
        let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), res).unwrap();
        enclosed += check(Mode::Cover, &mesh, &grid, name).enclosed;
        check(Mode::Sep6, &mesh, &grid, &format!("{name} sep6"));
        let mesh = rotated(&mesh, random_rotation(&mut r));
        let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), res + 13).unwrap();
        check(Mode::Cover, &mesh, &grid, &format!("rotated {name}"));
    }
    assert!(enclosed > 0);
    let outer = topovox_testkit::box_mesh(DVec3::new(2.5, 2.5, 2.5), DVec3::new(40.5, 30.5, 50.5));
    let mid = topovox_testkit::box_mesh(DVec3::new(8.0, 8.0, 8.0), DVec3::new(30.0, 25.0, 40.0));
    let inner = topovox_testkit::box_mesh(DVec3::new(14.0, 12.0, 15.0), DVec3::new(20.0, 18.0, 30.0));
    let mut nested = outer.clone();
    for b in [&mid, &inner] {
        let n = nested.positions.len() as u32;
        nested.positions.extend(&b.positions);
        nested.triangles.extend(b.triangles.iter().map(|t| t.map(|v| v + n)));
    }
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [45, 33, 53]).unwrap();
    assert!(check(Mode::Cover, &nested, &grid, "nested boxes").enclosed > 0);
    // Shells far from the grid's faces (the fill runs on their box grown by
    // a brick), one touching a face, and one in the middle of a partial
    // last brick.
    let big = GridSpec::new(DVec3::ZERO, 1.0, [150, 141, 133]).unwrap();
    for (at, what) in [(DVec3::new(60.0, 70.0, 50.0), "in the middle"), (DVec3::new(0.2, 90.5, 100.0), "at the x = 0 face")] {
        let mut moved = nested.clone();
        moved.positions.iter_mut().for_each(|p| *p += at);
        assert!(check(Mode::Cover, &moved, &big, &format!("nested boxes {what}")).enclosed > 0);
    }
    let cow = rotated(&shared_mesh("cow.obj"), random_rotation(&mut r));
    let grid = GridSpec::from_resolution(&cow.as_ref().bounds(), 60).unwrap();
    let wide = GridSpec::new(grid.origin() - grid.voxel_size().0 * 37.0, grid.voxel_size().0, grid.dims().map(|d| d as u64 + 80)).unwrap();
    check(Mode::Cover, &cow, &wide, "rotated cow with room around it");
}

/// A small closed shell in a 65536³ grid fills in the time and memory of
/// its own box (it walked every plane of the grid before).
#[test]
fn a_sparse_flood_fill_follows_the_shell_not_the_grid() {
    use topovox::voxelize::fill;
    let b = topovox_testkit::box_mesh(DVec3::new(30000.5, 40000.5, 50000.5), DVec3::new(30040.5, 40030.5, 50020.5));
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [65536; 3]).unwrap();
    let (shell, _) = tiled(Mode::Cover, b.as_ref(), &grid, 512, &Options::default()).unwrap();
    let (s, rep) = fill::flood_fill_sparse(&shell, &Stop::new());
    // Voxel centres strictly inside the box: 40 x 30 x 20 of them, the
    // shell the ones the faces pass through.
    assert_eq!(s.count(), 41 * 31 * 21);
    assert_eq!(rep.enclosed, 39 * 29 * 19);
    assert!(s.get(30020, 40015, 50010) && !s.get(30041, 40015, 50010));
}
