use glam::DVec3;

use super::*;
use crate::test_rng::Xorshift;

/// A unit cube at `o`, 12 triangles, counter-clockwise from outside.
fn cube(o: DVec3, first: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let p: Vec<DVec3> = (0..8).map(|c| o + DVec3::new((c & 1) as f64, (c >> 1 & 1) as f64, (c >> 2 & 1) as f64)).collect();
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let t = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).map(|t: [u32; 3]| t.map(|v| v + first)).collect();
    (p, t)
}

fn run(p: &[DVec3], t: &[[u32; 3]]) -> MeshCheck {
    check_mesh(p, t, &Stop::new()).unwrap()
}

#[test]
fn a_cube_is_watertight_with_genus_zero() {
    let (p, t) = cube(DVec3::ZERO, 0);
    let r = run(&p, &t);
    assert!(r.watertight(), "{r:?}");
    assert_eq!((r.vertices, r.edges, r.faces, r.components, r.genus), (8, 18, 12, 1, Some(0)));
    assert!((r.volume - 1.0).abs() < 1e-12);
}

#[test]
fn a_missing_face_leaves_three_boundary_edges() {
    let (p, mut t) = cube(DVec3::ZERO, 0);
    t.pop();
    let r = run(&p, &t);
    assert_eq!((r.boundary_edges, r.closed(), r.manifold(), r.genus), (3, false, true, None));
}

#[test]
fn a_flipped_face_is_inconsistent() {
    let (p, mut t) = cube(DVec3::ZERO, 0);
    t[0].swap(1, 2);
    let r = run(&p, &t);
    assert_eq!(r.inconsistent_edges, 3);
    assert!(r.closed() && !r.oriented());
}

#[test]
fn repeated_positions_are_welded() {
    let (p, t) = cube(DVec3::ZERO, 0);
    // Every triangle its own three vertices, as STL stores them.
    let soup: Vec<DVec3> = t.iter().flat_map(|f| f.map(|v| p[v as usize])).collect();
    let tris: Vec<[u32; 3]> = (0..t.len() as u32).map(|f| [3 * f, 3 * f + 1, 3 * f + 2]).collect();
    assert!(run(&soup, &tris).watertight());
}

#[test]
fn cubes_sharing_a_corner_make_a_non_manifold_vertex() {
    let (mut p, mut t) = cube(DVec3::ZERO, 0);
    let (q, u) = cube(DVec3::ONE, 8);
    p.extend(q);
    t.extend(u);
    let r = run(&p, &t);
    assert_eq!((r.non_manifold_vertices, r.self_intersections, r.components), (1, 0, 1));
    assert!(r.closed() && !r.manifold());
}

#[test]
fn overlapping_cubes_intersect_and_touching_ones_do_not() {
    let (mut p, mut t) = cube(DVec3::ZERO, 0);
    let (q, u) = cube(DVec3::splat(0.5), 8);
    p.extend(q);
    t.extend(u);
    let r = run(&p, &t);
    assert!(r.self_intersections > 0 && r.closed() && r.manifold() && !r.watertight());
    // Apart by a gap: no pair.
    let (mut p, mut t) = cube(DVec3::ZERO, 0);
    let (q, u) = cube(DVec3::new(1.0 + 1e-12, 0.0, 0.0), 8);
    p.extend(q);
    t.extend(u);
    assert_eq!(run(&p, &t).self_intersections, 0);
    // Face to face (separate vertices, same plane): they meet.
    let (mut p, mut t) = cube(DVec3::ZERO, 0);
    let (q, u) = cube(DVec3::X, 8);
    p.extend(q);
    t.extend(u);
    assert!(run(&p, &t).self_intersections > 0);
}

#[test]
fn folds_and_crossings_at_shared_vertices_count() {
    let mut p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.5, 0.25, 0.0), DVec3::new(0.2, 0.2, 1.0), DVec3::new(0.2, 0.2, -1.0)];
    p.push(DVec3::new(0.5, -0.25, 0.0));
    // Two triangles on edge 0-1, the second folded onto the first (either orientation).
    assert_eq!(run(&p, &[[0, 1, 2], [1, 0, 3]]).self_intersections, 1);
    assert_eq!(run(&p, &[[0, 1, 2], [0, 1, 3]]).self_intersections, 1);
    // Flat, on the other side of the edge: no overlap.
    assert_eq!(run(&p, &[[0, 1, 2], [1, 0, 6]]).self_intersections, 0);
    // Sharing vertex 0, the second pierces the first.
    assert_eq!(run(&p, &[[0, 1, 2], [0, 4, 5]]).self_intersections, 1);
    // Sharing vertex 0, apart elsewhere.
    let q = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(-1.0, 0.0, 0.0), DVec3::new(0.0, -1.0, 0.0)];
    assert_eq!(run(&q, &[[0, 1, 2], [0, 3, 4]]).self_intersections, 0);
}

#[test]
fn degenerate_faces_are_exact() {
    let p = vec![DVec3::ZERO, DVec3::new(1.0, 1.0, 1.0), DVec3::new(0.1, 0.1, 0.1), DVec3::new(0.1, 0.1, 0.1 + 1e-17 + 1e-16)];
    let r = run(&p, &[[0, 1, 2], [0, 1, 3], [0, 0, 1]]);
    assert_eq!(r.degenerate_faces, 2);
}

/// The broad phase finds what testing every pair finds, on random soups
/// with shared vertices and huge faces.
#[test]
fn the_broad_phase_equals_every_pair() {
    let mut rng = Xorshift(7);
    for round in 0..40 {
        let n = 30 + round * 3;
        // Coarse coordinates in half the rounds: many coplanar and touching faces.
        let steps = if round % 2 == 0 { 4 } else { 1 << 20 };
        let mut c = || rng.below(steps) as f64 * 4.0 / steps as f64;
        let mut p: Vec<DVec3> = (0..n).map(|_| DVec3::new(c(), c(), c())).collect();
        if round % 4 == 0 {
            p.push(DVec3::splat(-50.0));
            p.push(DVec3::new(60.0, -50.0, 1.0));
        }
        let m = p.len() as u32;
        let t: Vec<[u32; 3]> =
            (0..n).map(|_| [rng.below(m as u64) as u32, rng.below(m as u64) as u32, rng.below(m as u64) as u32]).collect();
        let r = run(&p, &t);
        let (pos, faces) = weld(&p, &t).unwrap();
        let deg: Vec<bool> = faces.iter().map(|f| is_degenerate(&pos, f)).collect();
        let mut brute = Vec::new();
        for a in 0..faces.len() {
            for b in a + 1..faces.len() {
                if !deg[a] && !deg[b] && pairs::faces_meet(&pos, &faces[a], &faces[b]) {
                    brute.push([a as u32, b as u32]);
                }
            }
        }
        assert_eq!(r.self_intersections, brute.len() as u64, "round {round}");
        assert_eq!(r.intersecting_pairs, brute.into_iter().take(MeshCheck::SHOWN).collect::<Vec<_>>());
    }
}
