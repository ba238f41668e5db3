//! Solid voxelization: ray parity equals the exact winding-number reference
//! on watertight meshes, including centres exactly on faces, edges and
//! vertices; cubes fill exactly; orientation and whole-voxel translation
//! behave.

use glam::DVec3;
use topovox::voxelize::solid;
use topovox::{DenseBits, GridSpec, Mesh};
use topovox_testkit::{assert_whole_voxel_shift, box_mesh, random_rotation, rng, rotated, shared_mesh, sphere};

/// The exact winding number (signed crossings) equals the brute-force
/// reference; parity equals it too unless `overlaps` (a surface that wraps
/// some voxels twice, where parity leaves holes and must be a subset).
fn agree(m: &Mesh, grid: &GridSpec, overlaps: bool) -> DenseBits {
    let (slow, rref) = solid::reference::solid(m.as_ref(), grid).unwrap();
    let (wind, rw) = solid::winding_closed(m.as_ref(), grid).unwrap();
    let (par, rp) = solid::parity(m.as_ref(), grid).unwrap();
    assert!(rw.watertight(), "not watertight: {rw:?}");
    if let Some(v) = slow.first_difference(&wind) {
        panic!("winding differs from the reference at {v:?}: reference {}", slow.get(v[0], v[1], v[2]));
    }
    assert_eq!(rw, rref);
    assert_eq!(rp.boundary_edges, rw.boundary_edges);
    if overlaps {
        par.for_each_set(|i, j, k| assert!(wind.get(i, j, k), "parity sets {i} {j} {k} outside the winding solid"));
    } else if let Some(v) = par.first_difference(&wind) {
        panic!("parity differs from winding at {v:?}: winding {}", wind.get(v[0], v[1], v[2]));
    }
    wind
}

fn both(m: &Mesh, grid: &GridSpec) -> DenseBits {
    agree(m, grid, false)
}

#[test]
fn an_8_cube_fills_exactly_8x8x8_however_it_meets_the_grid() {
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [11, 11, 11]).unwrap();
    // Faces on grid planes; faces through voxel centres (the displacement
    // takes one layer per axis); faces in between.
    for lo in [1.0, 1.5, 1.25] {
        let m = box_mesh(DVec3::splat(lo), DVec3::splat(lo + 8.0));
        assert_eq!(both(&m, &grid).count(), 512, "cube from {lo}");
    }
}

#[test]
fn centres_on_edges_and_vertices_of_a_small_box() {
    // A 2×3×4 box with corners on voxel centres: every face, edge and
    // vertex passes through centres.
    let m = box_mesh(DVec3::new(1.5, 1.5, 1.5), DVec3::new(3.5, 4.5, 5.5));
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [6, 7, 8]).unwrap();
    assert_eq!(both(&m, &grid).count(), 2 * 3 * 4);
}

#[test]
fn spheres_and_rotated_boxes_agree_with_the_reference() {
    let s = sphere(DVec3::splat(6.2), 4.9, 20);
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [13, 13, 13]).unwrap();
    let n = both(&s, &grid).count();
    let v = 4.0 / 3.0 * std::f64::consts::PI * 4.9f64.powi(3);
    assert!((n as f64 - v).abs() < 0.1 * v, "{n} voxels for volume {v}");
    let mut r = rng(99);
    for _ in 0..4 {
        let m = rotated(&box_mesh(DVec3::splat(-3.1), DVec3::new(2.9, 3.3, 1.7)), random_rotation(&mut r));
        let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 14).unwrap();
        both(&m, &grid);
    }
}

/// The shared meshes are closed but some wrap parts of themselves twice
/// (the cow's parts interpenetrate): there parity and winding differ.
#[test]
fn watertight_shared_meshes_agree_with_the_reference() {
    for name in ["cow.obj", "fandisk.obj", "rocker-arm.obj", "spot-textured.obj"] {
        let m = shared_mesh(name);
        let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 12).unwrap();
        assert!(agree(&m, &grid, true).count() > 0, "{name}");
        let m = rotated(&m, random_rotation(&mut rng(name.len() as u64)));
        let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 11).unwrap();
        agree(&m, &grid, true);
    }
}

#[test]
fn flipping_orientation_changes_nothing_and_translation_shifts() {
    let m = shared_mesh("cow.obj");
    let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 40).unwrap();
    let (a, _) = solid::parity(m.as_ref(), &grid).unwrap();
    let mut flipped = m.clone();
    for t in &mut flipped.triangles {
        t.swap(1, 2);
    }
    let (b, _) = solid::parity(flipped.as_ref(), &grid).unwrap();
    assert_eq!(a.first_difference(&b), None);
    // Shift the mesh by whole voxels (3, −2, 1) inside a larger grid.
    assert_whole_voxel_shift(&m, &grid, [3, -2, 1], 4, |m, g| solid::parity(m.as_ref(), g).unwrap().0);
}

#[test]
fn nested_boxes_parity_makes_a_cavity_winding_fills_or_not_by_orientation() {
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [12, 12, 12]).unwrap();
    let outer = box_mesh(DVec3::splat(1.0), DVec3::splat(11.0));
    let inner = box_mesh(DVec3::splat(4.0), DVec3::splat(8.0));
    let join = |a: &Mesh, b: &Mesh, flip_b: bool| {
        let mut m = a.clone();
        let off = m.positions.len() as u32;
        m.positions.extend(&b.positions);
        m.triangles.extend(b.triangles.iter().map(|t| {
            let t = t.map(|i| i + off);
            if flip_b {
                [t[0], t[2], t[1]]
            } else {
                t
            }
        }));
        m
    };
    // Same orientation: winding 2 inside the inner box; parity hollows it.
    let same = join(&outer, &inner, false);
    let w = agree(&same, &grid, true);
    assert_eq!(w.count(), 1000);
    assert_eq!(solid::parity(same.as_ref(), &grid).unwrap().0.count(), 1000 - 64);
    // Inner box reversed: a cavity for both.
    let cavity = join(&outer, &inner, true);
    assert_eq!(agree(&cavity, &grid, false).count(), 1000 - 64);
}

#[test]
fn flood_fill_of_a_cover_shell_contains_the_parity_solid() {
    use topovox::voxelize::{self, fill, Mode, Options};
    for name in ["cow.obj", "fandisk.obj"] {
        let m = shared_mesh(name);
        let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 48).unwrap();
        let shell = voxelize::fast(Mode::Cover, m.as_ref(), &grid, &Options::default()).0.to_dense();
        let (flood, rep) = fill::flood_fill(&shell);
        assert!(rep.enclosed > 0, "{name}: shell leaks");
        let (par, _) = solid::parity(m.as_ref(), &grid).unwrap();
        par.for_each_set(|i, j, k| assert!(flood.get(i, j, k), "{name}: inside voxel {i} {j} {k} not filled"));
        // And the fill adds nothing outside the surface's reach: every
        // filled voxel is inside or on the shell.
        flood.for_each_set(|i, j, k| assert!(par.get(i, j, k) || shell.get(i, j, k), "{name}: {i} {j} {k} filled outside"));
    }
}
