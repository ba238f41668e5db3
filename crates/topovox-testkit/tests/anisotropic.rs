//! Grids of boxes (a voxel size per axis, edges up to 1:8): every path of
//! every mode equals its reference voxel for voxel on them (shared meshes,
//! randomly rotated, random soups, polylines, solids), and the metamorphic
//! law holds: sizes `s` on a mesh give the voxels of the mesh scaled by
//! `1/s` on unit cubes with the origin scaled alike. Each mode is defined in
//! index space, so nothing else may change.

use glam::DVec3;
use proptest::prelude::*;
use topovox::voxelize::{self, solid, Mode, Options};
use topovox::{DenseBits, GridSpec, Mesh};
use topovox_testkit::{
    agree_mode, box_grid, random_rotation, rng, rotated, scaled_to_unit, shared_mesh, soup, sphere, strategies, unit_grid,
};

const SURFACE: [Mode; 9] =
    [Mode::Cover, Mode::Sep26, Mode::Sep6, Mode::Ss6, Mode::Pos, Mode::Tunnel18, Mode::Tunnel26, Mode::Bubble { seed: 7 }, Mode::Diagonal];

fn fast(mode: Mode, mesh: &Mesh, grid: &GridSpec) -> DenseBits {
    voxelize::fast(mode, mesh.as_ref(), grid, &Options::default()).0.to_dense()
}

/// `run` on `mesh` and `grid` equals `run` on the mesh scaled by `1/s` on
/// unit cubes.
fn assert_metamorphic(what: &str, mesh: &Mesh, grid: &GridSpec, run: impl Fn(&Mesh, &GridSpec) -> DenseBits) {
    let a = run(mesh, grid);
    let b = run(&scaled_to_unit(mesh, grid), &unit_grid(grid));
    if let Some(v) = a.first_difference(&b) {
        panic!("{what}: sizes {} and the scaled mesh on cubes differ at {v:?} ({} vs {})", grid.voxel_size(), a.count(), b.count());
    }
}

#[test]
fn every_surface_mode_agrees_on_boxes() {
    let mut r = rng(0xb0c5);
    for name in ["suzanne.obj", "cow.obj", "teapot.obj", "fandisk.obj"] {
        let mesh = rotated(&shared_mesh(name), random_rotation(&mut r));
        let grid = box_grid(&mesh.as_ref().bounds(), 40, &mut r);
        for mode in SURFACE {
            let bits = agree_mode(mode, &mesh, &grid).unwrap_or_else(|e| panic!("{name} on {}: {e}", grid.voxel_size()));
            assert!(bits.count() > 0, "{name} {mode:?}: empty");
            assert_metamorphic(&format!("{name} {mode:?}"), &mesh, &grid, |m, g| fast(mode, m, g));
        }
    }
}

#[test]
fn solids_agree_on_boxes() {
    let mut r = rng(0x5011d);
    let meshes = [
        ("sphere", sphere(DVec3::new(0.3, -0.2, 0.1), 2.7, 24)),
        ("rotated cow", rotated(&shared_mesh("cow.obj"), random_rotation(&mut r))),
        ("rotated fandisk", rotated(&shared_mesh("fandisk.obj"), random_rotation(&mut r))),
    ];
    for (name, mesh) in &meshes {
        let grid = box_grid(&mesh.as_ref().bounds(), 24, &mut r);
        let (slow, _) = solid::reference::solid(mesh.as_ref(), &grid).unwrap();
        let (wind, _) = solid::winding_closed(mesh.as_ref(), &grid).unwrap();
        assert!(slow.count() > 0, "{name}: empty");
        if let Some(v) = slow.first_difference(&wind) {
            panic!("{name} on {}: winding differs from the reference at {v:?}", grid.voxel_size());
        }
        let (par, _) = solid::parity(mesh.as_ref(), &grid).unwrap();
        par.for_each_set(|i, j, k| assert!(wind.get(i, j, k), "{name}: parity sets {i} {j} {k} outside the winding solid"));
        assert_metamorphic(&format!("{name} winding"), mesh, &grid, |m, g| solid::winding_closed(m.as_ref(), g).unwrap().0);
        assert_metamorphic(&format!("{name} parity"), mesh, &grid, |m, g| solid::parity(m.as_ref(), g).unwrap().0);
    }
}

#[test]
fn a_box_grid_changes_what_a_voxel_is_not_the_rules() {
    // A plane z = 1.3 on sizes (0.5, 0.25, 2): in index space z = 0.65, so
    // sep6 sets exactly the layer k = 0 over the whole plane.
    let m = soup(&[
        [DVec3::new(0.0, 0.0, 1.3), DVec3::new(4.0, 0.0, 1.3), DVec3::new(4.0, 2.0, 1.3)],
        [DVec3::new(0.0, 0.0, 1.3), DVec3::new(4.0, 2.0, 1.3), DVec3::new(0.0, 2.0, 1.3)],
    ]);
    let grid = GridSpec::new(DVec3::ZERO, [0.5, 0.25, 2.0], [8, 8, 3]).unwrap();
    let bits = agree_mode(Mode::Sep6, &m, &grid).unwrap();
    assert_eq!(bits.count(), 64);
    bits.for_each_set(|_, _, k| assert_eq!(k, 0));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

    /// Random soups (edge cases of the unit lattice, taken to the box grid)
    /// on random sizes: every path of every mode, and the metamorphic law.
    #[test]
    fn random_soups_on_random_boxes(
        tris in prop::collection::vec(strategies::triangle(), 1..8),
        size in (1.0f64..8.0, 1.0f64..8.0, 1.0f64..8.0),
        origin in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
    ) {
        let s = DVec3::new(size.0, size.1, size.2) * 0.125;
        let o = DVec3::new(origin.0, origin.1, origin.2) * s;
        let world: Vec<[DVec3; 3]> = tris.iter().map(|t| t.map(|p| o + p * s)).collect();
        let mesh = soup(&world);
        let grid = GridSpec::new(o - 2.0 * s, s, [14, 14, 14]).unwrap();
        for mode in SURFACE {
            if let Err(e) = agree_mode(mode, &mesh, &grid) {
                prop_assert!(false, "{e}\nsizes {s:?}\ntriangles: {world:?}");
            }
            assert_metamorphic(&format!("{mode:?}"), &mesh, &grid, |m, g| fast(mode, m, g));
        }
    }

    /// Polylines on random sizes: `line6` and `line26` agree and scale.
    #[test]
    fn random_polylines_on_random_boxes(
        pts in prop::collection::vec(strategies::point(), 2..6),
        size in (1.0f64..8.0, 1.0f64..8.0, 1.0f64..8.0),
    ) {
        let s = DVec3::new(size.0, size.1, size.2) * 0.3;
        let positions: Vec<DVec3> = pts.iter().map(|p| *p * s).collect();
        let mesh = Mesh { positions, triangles: Vec::new(), segments: (0..pts.len() as u32 - 1).map(|i| [i, i + 1]).collect() };
        let grid = GridSpec::new(DVec3::ZERO, s, [8, 8, 8]).unwrap();
        for mode in [Mode::Line6, Mode::Line26] {
            if let Err(e) = agree_mode(mode, &mesh, &grid) {
                prop_assert!(false, "{e}\nsizes {s:?}\npoints: {pts:?}");
            }
            assert_metamorphic(&format!("{mode:?}"), &mesh, &grid, |m, g| fast(mode, m, g));
        }
    }
}
