//! The topological guarantees, checked by the exact certifier on closed
//! shared meshes (and random rotations), generated shapes and random input:
//! `cover` and `sep26` are 26-separating, `sep6`, `ss6`, `bubble` and
//! `diagonal` 6-separating, `tunnel18` 18-tunnel-free and `tunnel26`
//! 26-tunnel-free (and 26-separating), `sep26 ⊆ cover`, `sep6 ⊆ ss6`,
//! `sep6 ⊆ tunnel18 ⊆ tunnel26`, `diagonal ⊆ sep26`, `sep6` is thin and
//! 6-tunnel-free, and polylines give 6- / 26-connected runs.

use glam::DVec3;
use proptest::prelude::*;
use rand::Rng;
use topovox::topology::certify;
use topovox::voxelize::{self, Mode, Options};
use topovox::{DenseBits, GridSpec, Mesh};
use topovox_testkit::{box_mesh, random_rotation, rng, rotated, shared_mesh, sphere, strategies};

const CLOSED: [&str; 6] = ["cheburashka.obj", "cow.obj", "fandisk.obj", "homer.obj", "rocker-arm.obj", "spot-textured.obj"];

fn run(mode: Mode, mesh: &Mesh, grid: &GridSpec) -> DenseBits {
    voxelize::fast(mode, mesh.as_ref(), grid, &Options::default()).0.to_dense()
}

fn is_subset(a: &DenseBits, b: &DenseBits) -> bool {
    a.words().iter().zip(b.words()).all(|(x, y)| x & !y == 0)
}

const MODES: [Mode; 8] =
    [Mode::Cover, Mode::Sep26, Mode::Sep6, Mode::Ss6, Mode::Tunnel18, Mode::Tunnel26, Mode::Bubble { seed: 3 }, Mode::Diagonal];

/// Checks every guarantee of the surface modes on one closed mesh and grid.
fn surface_guarantees(name: &str, mesh: &Mesh, grid: &GridSpec) {
    let bits: Vec<(Mode, DenseBits)> = MODES.map(|m| (m, run(m, mesh, grid))).into();
    for (mode, b) in &bits {
        let r = certify(b, Some((mesh.as_ref(), grid))).unwrap();
        let f = r.mesh.unwrap();
        assert_eq!(f.boundary_edges, 0, "{name}: not closed");
        let s = f.separation.unwrap();
        assert!(s.inside_voxels > 0, "{name}: nothing inside");
        assert_eq!(s.witness_6, None, "{name} {mode:?}: not 6-separating");
        if matches!(mode, Mode::Cover | Mode::Sep26 | Mode::Tunnel26) {
            assert_eq!(s.witness_26, None, "{name} {mode:?}: not 26-separating");
        }
        if matches!(mode, Mode::Sep6 | Mode::Tunnel18 | Mode::Tunnel26) {
            assert_eq!(f.tunnels_6, 0, "{name} {mode:?}: 6-tunnels");
        }
        if matches!(mode, Mode::Tunnel18 | Mode::Tunnel26) {
            assert_eq!(f.tunnels_18, 0, "{name} {mode:?}: 18-tunnels");
        }
        if *mode == Mode::Tunnel26 {
            assert_eq!(f.tunnels_26, 0, "{name} {mode:?}: 26-tunnels");
        }
        if matches!(mode, Mode::Cover | Mode::Sep6 | Mode::Ss6 | Mode::Tunnel18 | Mode::Tunnel26) {
            // sep6 ⊆ ss6 ⊆ cover, and sep6 sets every column's crossing voxel.
            assert_eq!(f.columns.empty, 0, "{name} {mode:?}: holes in columns");
            assert!(f.columns.samples > 0);
        }
    }
    let get = |m: Mode| &bits.iter().find(|b| b.0 == m).unwrap().1;
    assert!(is_subset(get(Mode::Sep26), get(Mode::Cover)), "{name}: sep26 not within cover");
    assert!(is_subset(get(Mode::Sep6), get(Mode::Ss6)), "{name}: sep6 not within ss6");
    assert!(is_subset(get(Mode::Sep6), get(Mode::Tunnel18)), "{name}: sep6 not within tunnel18");
    assert!(is_subset(get(Mode::Tunnel18), get(Mode::Tunnel26)), "{name}: tunnel18 not within tunnel26");
    assert!(is_subset(get(Mode::Sep26), get(Mode::Tunnel26)), "{name}: sep26 not within tunnel26");
    assert!(is_subset(get(Mode::Tunnel26), get(Mode::Cover)), "{name}: tunnel26 not within cover");
    assert!(is_subset(get(Mode::Diagonal), get(Mode::Sep26)), "{name}: diagonal not within sep26");
    assert!(is_subset(get(Mode::Bubble { seed: 3 }), get(Mode::Cover)), "{name}: bubble not within cover");
    assert!(get(Mode::Sep6).count() <= get(Mode::Ss6).count());
}

#[test]
fn closed_shared_meshes_at_several_resolutions() {
    for name in CLOSED {
        let mesh = shared_mesh(name);
        for res in [37, 96] {
            let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), res).unwrap();
            surface_guarantees(name, &mesh, &grid);
        }
    }
}

/// A grid of voxel size `s` around `mesh` with two empty voxels of margin
/// on every side: no surface on the grid's faces.
fn with_margin(mesh: &Mesh, s: DVec3) -> GridSpec {
    let b = mesh.as_ref().bounds();
    let dims = (b.extent() / s).ceil().as_u64vec3() + 4;
    GridSpec::new(b.min - 2.0 * s, s, dims.to_array()).unwrap()
}

#[test]
fn closed_shared_meshes_randomly_rotated() {
    let mut r = rng(0x5e9a);
    for name in CLOSED {
        let mesh = rotated(&shared_mesh(name), random_rotation(&mut r));
        let grid = with_margin(&mesh, DVec3::splat(mesh.as_ref().bounds().extent().max_element() / 60.0));
        surface_guarantees(name, &mesh, &grid);
    }
}

/// Grids of boxes (edges up to 1:8): every guarantee holds in index space,
/// as the certifier checks it there.
#[test]
fn closed_shared_meshes_on_grids_of_boxes() {
    let mut r = rng(0xb0c5);
    for name in CLOSED {
        let mesh = rotated(&shared_mesh(name), random_rotation(&mut r));
        let base = mesh.as_ref().bounds().extent().max_element() / 40.0;
        let grid = with_margin(&mesh, DVec3::new(base * r.random_range(1.0..8.0), base * r.random_range(1.0..8.0), base));
        surface_guarantees(&format!("{name} on sizes {}", grid.voxel_size()), &mesh, &grid);
    }
}

#[test]
fn generated_shapes_with_faces_on_grid_planes_and_centres() {
    for (lo, hi) in [(1.0, 7.0), (1.5, 6.5), (1.25, 6.75)] {
        let m = box_mesh(DVec3::splat(lo), DVec3::new(hi, hi - 1.0, hi));
        let grid = GridSpec::new(DVec3::ZERO, 1.0, [9, 9, 9]).unwrap();
        surface_guarantees("box", &m, &grid);
    }
    let s = sphere(DVec3::splat(10.3), 7.7, 24);
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [21, 21, 21]).unwrap();
    surface_guarantees("sphere", &s, &grid);
}

#[test]
fn a_leaky_set_gets_an_adjacent_witness() {
    let m = box_mesh(DVec3::splat(2.0), DVec3::splat(6.0));
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [9, 9, 9]).unwrap();
    let mut b = run(Mode::Cover, &m, &grid);
    // Punch a hole through the shell's top layers.
    let mut holed = DenseBits::new(b.dims());
    b.for_each_set(|i, j, k| {
        if !(i == 4 && j == 4 && k >= 5) {
            holed.set(i, j, k);
        }
    });
    b = holed;
    let s = certify(&b, Some((m.as_ref(), &grid))).unwrap().mesh.unwrap().separation.unwrap();
    let w = s.witness_6.expect("a 6-leak");
    let d: u32 = (0..3).map(|a| w[0][a].abs_diff(w[1][a])).sum();
    assert_eq!(d, 1);
    assert!(!b.get(w[0][0], w[0][1], w[0][2]) && !b.get(w[1][0], w[1][1], w[1][2]));
}

fn soup_of(tris: &[[DVec3; 3]]) -> Mesh {
    topovox_testkit::soup(tris)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Laine's thinness: a planar triangle sets at most one `sep6` voxel per
    /// column along its normal's dominant axis.
    #[test]
    fn sep6_is_thin_for_a_planar_triangle(t in strategies::triangle()) {
        let m = soup_of(&[t]);
        let grid = GridSpec::new(DVec3::splat(-2.0), 1.0, [14, 14, 14]).unwrap();
        let bits = run(Mode::Sep6, &m, &grid);
        // The dominant axis of the snapped triangle (what the voxelizer sees).
        let snap = |p: DVec3| ((p + DVec3::splat(2.0)) * 4096.0).round();
        let (a, b, c) = (snap(t[0]), snap(t[1]), snap(t[2]));
        let n = (b - a).cross(c - a).abs();
        let w = if n.x >= n.y && n.x >= n.z { 0 } else if n.y >= n.z { 1 } else { 2 };
        let mut columns = std::collections::HashMap::new();
        bits.for_each_set(|i, j, k| {
            let mut key = [i, j, k];
            key[w] = 0;
            *columns.entry(key).or_insert(0) += 1;
        });
        prop_assert!(columns.values().all(|&c| c <= 1), "{:?}", columns);
    }

    /// Every mode's fast path equals its reference on random small soups.
    #[test]
    fn fast_equals_reference_on_random_soups(tris in prop::collection::vec(strategies::triangle(), 1..5)) {
        let m = soup_of(&tris);
        let grid = GridSpec::new(DVec3::splat(-2.0), 1.0, [14, 13, 15]).unwrap();
        for mode in Mode::ALL {
            if let Err(e) = topovox_testkit::agree_mode(mode, &m, &grid) {
                return Err(TestCaseError::fail(e));
            }
        }
    }

    /// Random polylines inside the grid: `line6` is 6-connected and `line26`
    /// 26-connected, and both agree with their references.
    #[test]
    fn polylines_are_connected(points in prop::collection::vec(strategies::point(), 2..6)) {
        let pts: Vec<DVec3> = points.iter().map(|p| p.clamp(DVec3::splat(0.0), DVec3::splat(10.0)) + DVec3::splat(1.5)).collect();
        let m = Mesh {
            positions: pts.clone(),
            triangles: Vec::new(),
            segments: (0..pts.len() as u32 - 1).map(|i| [i, i + 1]).collect(),
        };
        let grid = GridSpec::new(DVec3::ZERO, 1.0, [14, 14, 14]).unwrap();
        for (mode, six) in [(Mode::Line6, true), (Mode::Line26, false)] {
            let b = topovox_testkit::agree_mode(mode, &m, &grid).map_err(TestCaseError::fail)?;
            let r = certify(&b, None).unwrap();
            let comps = if six { r.components_6 } else { r.components_26 };
            prop_assert!(comps <= 1, "{:?}: {} components ({} voxels)", mode, comps, r.voxels);
        }
    }
}

/// `check`'s tunnel counts equal the definition, brute force: every pair of
/// adjacent unset voxels whose centre segment meets some triangle (with
/// the segment displaced), on voxels with tunnels of every kind (sep6 has
/// 18- and 26-tunnels, diagonal and bubble all three) and on a rotation.
#[test]
fn tunnel_counts_equal_brute_force() {
    use topovox::geom::fixed::ONE;
    use topovox::geom::perturb::segment_meets_triangle;
    use topovox::topology::inside::snap_all;
    let mut r = rng(41);
    let monkey = shared_mesh("suzanne.obj");
    let turned = rotated(&shared_mesh("cow.obj"), random_rotation(&mut r));
    for (mesh, n) in [(&monkey, 24), (&turned, 18)] {
        let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), n).unwrap();
        let tris = snap_all(mesh.as_ref(), &grid).unwrap().crossing_triangles();
        // (Bounding boxes only skip triangles that cannot meet a segment.)
        let boxes: Vec<_> = tris.iter().map(|t| t.bounds()).collect();
        for mode in [Mode::Sep6, Mode::Diagonal, Mode::Bubble { seed: 9 }] {
            let bits = run(mode, mesh, &grid);
            let [nx, ny, nz] = bits.dims().map(i64::from);
            let unset =
                |p: [i64; 3]| (0..3).all(|a| p[a] >= 0 && p[a] < [nx, ny, nz][a]) && !bits.get(p[0] as u32, p[1] as u32, p[2] as u32);
            let centre = |p: [i64; 3]| p.map(|x| x * ONE + ONE / 2);
            let mut counts = [0u64; 3];
            for k in 0..nz {
                for j in 0..ny {
                    for i in 0..nx {
                        for d in [
                            [1, 0, 0],
                            [0, 1, 0],
                            [0, 0, 1],
                            [1, 1, 0],
                            [1, -1, 0],
                            [1, 0, 1],
                            [1, 0, -1],
                            [0, 1, 1],
                            [0, 1, -1],
                            [1, 1, 1],
                            [1, 1, -1],
                            [1, -1, 1],
                            [1, -1, -1],
                        ] {
                            let (p, q) = ([i, j, k], [i + d[0], j + d[1], k + d[2]]);
                            if !unset(p) || !unset(q) {
                                continue;
                            }
                            let s = [centre(p), centre(q)];
                            let meets = tris.iter().zip(&boxes).any(|(t, (lo, hi))| {
                                (0..3).all(|a| s[0][a].min(s[1][a]) <= hi[a] && s[0][a].max(s[1][a]) >= lo[a])
                                    && segment_meets_triangle(s, t.v, true)
                            });
                            if meets {
                                let order = d.iter().map(|x: &i64| x.abs()).sum::<i64>() as usize;
                                counts[order - 1..].iter_mut().for_each(|c| *c += 1);
                            }
                        }
                    }
                }
            }
            let f = certify(&bits, Some((mesh.as_ref(), &grid))).unwrap().mesh.unwrap();
            assert_eq!([f.tunnels_6, f.tunnels_18, f.tunnels_26], counts, "{mode:?} at {n}");
            assert!(counts[2] > 0, "{mode:?} at {n}: no tunnels to count");
        }
    }
}
