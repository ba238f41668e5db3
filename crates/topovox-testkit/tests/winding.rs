//! The generalized-winding-number solid: equals the direct sum over all
//! triangles (up to voxels whose winding number is within 10⁻² of 1/2),
//! equals the exact winding number on watertight meshes, ignores
//! orientation flips, and gives open meshes a plausible solid.

use glam::DVec3;
use topovox::voxelize::{solid, winding};
use topovox::{GridSpec, Mesh};
use topovox_testkit::{assert_whole_voxel_shift, box_mesh, random_rotation, rng, rotated, shared_mesh, sphere};

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

/// Swapping the x and y axes of an open mesh (and of the grid) transposes
/// the solid: the exact part follows rows along x, so a ray-dependent error
/// (a streak) would show here.
#[test]
fn swapping_axes_transposes_the_solid_of_open_meshes() {
    for name in ["stanford-bunny.obj", "teapot.obj"] {
        let m = shared_mesh(name);
        let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 40).unwrap();
        let mut s = m.clone();
        s.transform(|p| DVec3::new(p.y, p.x, p.z));
        let o = grid.origin();
        let d = grid.dims();
        let sgrid = GridSpec::new(DVec3::new(o.y, o.x, o.z), grid.voxel_size().0, [d[1] as u64, d[0] as u64, d[2] as u64]).unwrap();
        let (a, _) = winding::winding(m.as_ref(), &grid).unwrap();
        let (b, _) = winding::winding(s.as_ref(), &sgrid).unwrap();
        let mut differ = 0u64;
        a.for_each_set(|i, j, k| differ += !b.get(j, i, k) as u64);
        b.for_each_set(|j, i, k| differ += !a.get(i, j, k) as u64);
        // Only voxels whose winding number is within the approximation of
        // 1/2 may differ.
        assert!(differ * 2000 <= a.count(), "{name}: {differ} of {} voxels differ", a.count());
    }
}

#[test]
fn translating_an_open_mesh_by_whole_voxels_shifts_the_solid() {
    let m = shared_mesh("teapot.obj");
    let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 30).unwrap();
    assert_whole_voxel_shift(&m, &grid, [2, -1, 3], 3, |m, g| winding::winding(m.as_ref(), g).unwrap().0);
}

/// A torus (genus 1): every method agrees with the exact reference.
#[test]
fn torus() {
    let (rr, r, n) = (6.3, 2.4, 32u32);
    let mut m = Mesh::default();
    for a in 0..n {
        for b in 0..n {
            let (u, v) = (a as f64 / n as f64 * std::f64::consts::TAU, b as f64 / n as f64 * std::f64::consts::TAU);
            m.positions.push(DVec3::new((rr + r * v.cos()) * u.cos(), (rr + r * v.cos()) * u.sin(), r * v.sin()) + DVec3::splat(10.0));
        }
    }
    let idx = |a: u32, b: u32| (a % n) * n + (b % n);
    for a in 0..n {
        for b in 0..n {
            m.triangles.push([idx(a, b), idx(a + 1, b), idx(a + 1, b + 1)]);
            m.triangles.push([idx(a, b), idx(a + 1, b + 1), idx(a, b + 1)]);
        }
    }
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [21, 21, 21]).unwrap();
    let (p, rep) = solid::parity(m.as_ref(), &grid).unwrap();
    assert!(rep.watertight());
    let (w, _) = winding::winding(m.as_ref(), &grid).unwrap();
    let (r0, _) = solid::reference::solid(m.as_ref(), &grid).unwrap();
    assert_eq!(p.first_difference(&r0), None);
    assert_eq!(w.first_difference(&r0), None);
    let v = 2.0 * std::f64::consts::PI.powi(2) * rr * r * r;
    assert!((p.count() as f64 - v).abs() < 0.1 * v, "{} voxels for volume {v}", p.count());
    // The hole stays empty.
    assert!(!p.get(10, 10, 10));
}
