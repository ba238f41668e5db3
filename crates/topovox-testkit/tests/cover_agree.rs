//! The fast `cover` path equals the reference voxel for voxel on real
//! meshes, rotated meshes, clipped grids and huge triangles.

use glam::DVec3;
use topovox::GridSpec;
use topovox_testkit::{agree, box_mesh, random_rotation, rng, rotated, shared_mesh, soup, sphere, SHARED_MESHES};

#[test]
fn every_shared_mesh_at_two_resolutions() {
    for name in SHARED_MESHES {
        let mesh = shared_mesh(name);
        for res in [40, 73] {
            let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), res).unwrap();
            let bits = agree(&mesh, &grid).unwrap_or_else(|e| panic!("{name} at {res}: {e}"));
            assert!(bits.count() > 0, "{name}: empty result");
        }
    }
}

#[test]
fn every_shared_mesh_randomly_rotated() {
    let mut r = rng(0x5eed);
    for name in SHARED_MESHES {
        let mesh = shared_mesh(name);
        for _ in 0..2 {
            let m = rotated(&mesh, random_rotation(&mut r));
            let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 57).unwrap();
            agree(&m, &grid).unwrap_or_else(|e| panic!("{name} rotated: {e}"));
        }
    }
}

#[test]
fn explicit_grids_that_clip_the_mesh() {
    let mesh = shared_mesh("cow.obj");
    let b = mesh.as_ref().bounds();
    let e = b.extent();
    // A grid covering the middle of the mesh only: triangles are clipped, never wrapped.
    let grid = GridSpec::new(b.min + e * 0.3, e.max_element() / 50.0, [20, 17, 23]).unwrap();
    let bits = agree(&mesh, &grid).unwrap();
    assert!(bits.count() > 0);
    // A grid entirely off the mesh sets nothing.
    let off = GridSpec::new(b.max + DVec3::splat(1.0), 0.1, [5, 5, 5]).unwrap();
    assert_eq!(agree(&mesh, &off).unwrap().count(), 0);
}

#[test]
fn huge_triangles_take_the_wide_arithmetic_path() {
    // Faces of a box 150 voxels wide exceed the i64 plane bound.
    let m = box_mesh(DVec3::new(0.3, 0.2, 0.1), DVec3::new(150.3, 120.7, 90.9));
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [152, 122, 92]).unwrap();
    let bits = agree(&m, &grid).unwrap();
    assert!(bits.count() > 2 * 150 * 120);
    let rot = rotated(&m, random_rotation(&mut rng(7)));
    let grid = GridSpec::from_resolution(&rot.as_ref().bounds(), 160).unwrap();
    agree(&rot, &grid).unwrap();
}

#[test]
fn triangles_far_outside_the_lattice_range_are_clipped_exactly() {
    // Vertices a million voxels away: clipped to the grid's neighbourhood.
    let t = [DVec3::new(-1e6, -1e6, 3.5), DVec3::new(1e6, -1e6, 4.25), DVec3::new(0.0, 1e6, 3.75)];
    let m = soup(&[t]);
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [8, 8, 8]).unwrap();
    let bits = agree(&m, &grid).unwrap();
    // Nearly flat: every column is hit, in layers 3 and 4 only.
    for i in 0..8 {
        for j in 0..8 {
            assert!((0..8).any(|k| bits.get(i, j, k)));
        }
    }
    assert!((0..8).all(|i| (0..8).all(|j| !bits.get(i, j, 0) && !bits.get(i, j, 7))));
}

#[test]
fn sphere_shell_is_26_separating_by_flood_fill() {
    // Independent check of the guarantee: a 6-connected flood from the grid
    // boundary through unset voxels must never reach the centre.
    let m = sphere(DVec3::ZERO, 1.0, 24);
    let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 31).unwrap();
    let bits = agree(&m, &grid).unwrap();
    let d = grid.dims();
    let idx = |i: u32, j: u32, k: u32| (i + d[0] * (j + d[1] * k)) as usize;
    let mut seen = vec![false; (d[0] * d[1] * d[2]) as usize];
    let mut stack = Vec::new();
    for i in 0..d[0] {
        for j in 0..d[1] {
            for k in 0..d[2] {
                let border = i == 0 || j == 0 || k == 0 || i == d[0] - 1 || j == d[1] - 1 || k == d[2] - 1;
                if border && !bits.get(i, j, k) {
                    seen[idx(i, j, k)] = true;
                    stack.push([i, j, k]);
                }
            }
        }
    }
    while let Some([i, j, k]) = stack.pop() {
        for (di, dj, dk) in [(1i64, 0i64, 0i64), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)] {
            let (a, b, c) = (i as i64 + di, j as i64 + dj, k as i64 + dk);
            if a < 0 || b < 0 || c < 0 || a >= d[0] as i64 || b >= d[1] as i64 || c >= d[2] as i64 {
                continue;
            }
            let (a, b, c) = (a as u32, b as u32, c as u32);
            if !bits.get(a, b, c) && !seen[idx(a, b, c)] {
                seen[idx(a, b, c)] = true;
                stack.push([a, b, c]);
            }
        }
    }
    let c = [d[0] / 2, d[1] / 2, d[2] / 2];
    assert!(!bits.get(c[0], c[1], c[2]));
    assert!(!seen[idx(c[0], c[1], c[2])], "the outside leaked into the sphere");
}
