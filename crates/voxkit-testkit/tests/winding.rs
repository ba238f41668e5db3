//! The generalized-winding-number solid: equals the direct sum over all
//! triangles (up to voxels whose winding number is within 10⁻² of 1/2),
//! equals the exact winding number on watertight meshes, ignores
//! orientation flips, and gives open meshes a plausible solid.

use glam::DVec3;
use voxkit::voxelize::{solid, winding};
use voxkit::{GridSpec, Mesh};
use voxkit_testkit::{box_mesh, random_rotation, rng, rotated, shared_mesh, sphere};

/// Fast vs reference: every disagreement must be at an ambiguous voxel.
fn agree(name: &str, m: &Mesh, grid: &GridSpec) -> u64 {
    let (fast, rep) = winding::winding(m.as_ref(), grid).unwrap();
    let w = winding::reference::winding_numbers(m.as_ref(), grid).unwrap();
    let dims = grid.dims();
    let mut bad = 0;
    for (idx, w) in w.iter().enumerate() {
        let (i, j, k) = (idx % dims[0] as usize, (idx / dims[0] as usize) % dims[1] as usize, idx / (dims[0] as usize * dims[1] as usize));
        let f = fast.get(i as u32, j as u32, k as u32);
        if f != (w.abs() >= 0.5) && (w.abs() - 0.5).abs() > 1e-2 {
            bad += 1;
            eprintln!("{name}: voxel {i} {j} {k}: w = {w}, fast says {f}");
        }
    }
    assert_eq!(bad, 0, "{name}: {bad} voxels disagree ({rep:?})");
    rep.solid.voxels
}

#[test]
fn open_shared_meshes_agree_with_the_direct_sum() {
    for name in ["stanford-bunny.obj", "teapot.obj", "suzanne.obj", "beetle.obj"] {
        let m = shared_mesh(name);
        let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 12).unwrap();
        assert!(agree(name, &m, &grid) > 0, "{name}: empty");
        let r = rotated(&m, random_rotation(&mut rng(name.len() as u64 + 1)));
        let grid = GridSpec::from_resolution(&r.as_ref().bounds(), 10).unwrap();
        agree(name, &r, &grid);
    }
}

#[test]
fn watertight_meshes_give_the_exact_winding_number() {
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [11, 11, 11]).unwrap();
    for lo in [1.0, 1.5, 1.25] {
        let m = box_mesh(DVec3::splat(lo), DVec3::splat(lo + 8.0));
        let (w, rep) = winding::winding(m.as_ref(), &grid).unwrap();
        assert_eq!((w.count(), rep.cycles, rep.evaluated), (512, 0, 0));
    }
    let m = shared_mesh("cow.obj");
    let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 40).unwrap();
    let (a, _) = winding::winding(m.as_ref(), &grid).unwrap();
    let (b, _) = solid::winding_closed(m.as_ref(), &grid).unwrap();
    assert_eq!(a.first_difference(&b), None);
}

#[test]
fn flipping_every_triangle_changes_nothing() {
    let m = shared_mesh("teapot.obj");
    let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 40).unwrap();
    let mut f = m.clone();
    for t in &mut f.triangles {
        t.swap(1, 2);
    }
    let (a, _) = winding::winding(m.as_ref(), &grid).unwrap();
    let (b, _) = winding::winding(f.as_ref(), &grid).unwrap();
    assert_eq!(a.first_difference(&b), None);
}

/// A sphere with a cap cut away keeps (nearly) the closed sphere's volume,
/// with no streaks: every row's inside voxels form one run.
#[test]
fn a_sphere_with_a_hole_fills_like_the_closed_sphere() {
    let closed = sphere(DVec3::splat(12.3), 9.6, 40);
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [25, 25, 25]).unwrap();
    let (full, _) = solid::parity(closed.as_ref(), &grid).unwrap();
    let mut open = closed.clone();
    // Remove the triangles near the top: a hole about a third of the radius wide.
    let top = DVec3::new(12.3, 12.3, 12.3 + 9.6);
    open.triangles.retain(|t| t.iter().all(|&i| open.positions[i as usize].distance(top) > 4.0));
    assert!(open.triangles.len() < closed.triangles.len());
    let (w, rep) = winding::winding(open.as_ref(), &grid).unwrap();
    assert!(rep.cycles >= 1 && rep.solid.boundary_edges > 0);
    let (a, b) = (full.count() as f64, w.count() as f64);
    assert!((a - b).abs() / a < 0.02, "closed {a} vs open {b}");
    for k in 0..25 {
        for j in 0..25 {
            let row: Vec<bool> = (0..25).map(|i| w.get(i, j, k)).collect();
            let runs = row.windows(2).filter(|p| !p[0] && p[1]).count() + row[0] as usize;
            assert!(runs <= 1, "row {j} {k} has {runs} runs: a streak or a gap");
        }
    }
}
