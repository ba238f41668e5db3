//! Proptest strategies aimed at the edge cases of voxelization: vertices on
//! voxel faces, edges and corners, a few ulps off grid planes, axis-aligned,
//! sliver and zero-area triangles. Coordinates are in grid units of a grid
//! with origin 0 and voxel size 1.

use glam::DVec3;
use proptest::prelude::*;

/// One coordinate in `[-2, 10]`: integers, halves, values a few ulps
/// off an integer, or arbitrary.
pub fn coord() -> impl Strategy<Value = f64> {
    prop_oneof![
        (-2i32..=10).prop_map(|i| i as f64),
        (-4i32..=20).prop_map(|i| i as f64 * 0.5),
        ((-2i32..=10), (-3i64..=3)).prop_map(|(i, u)| {
            let x = i as f64;
            f64::from_bits((x.to_bits() as i64 + u) as u64)
        }),
        (-2.0f64..10.0),
    ]
}

/// A point of [`coord`]s.
pub fn point() -> impl Strategy<Value = DVec3> {
    (coord(), coord(), coord()).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

/// A small offset in `[-3, 3]` voxels: whole and half voxels, a few
/// ulps off them, or arbitrary.
pub fn offset() -> impl Strategy<Value = f64> {
    prop_oneof![(-3i32..=3).prop_map(|i| i as f64), (-6i32..=6).prop_map(|i| i as f64 * 0.5), (-3.0f64..3.0), (0.0f64..0.3),]
}

/// A triangle spanning at most a few voxels — what the short paths for
/// small triangles take: a vertex from [`point`] (often on a grid
/// plane), the others offset from it by [`offset`]s, so vertices share
/// planes, straddle them by ulps or lie exactly on them.
pub fn small_triangle() -> impl Strategy<Value = [DVec3; 3]> {
    (point(), (offset(), offset(), offset()), (offset(), offset(), offset()))
        .prop_map(|(a, (x1, y1, z1), (x2, y2, z2))| [a, a + DVec3::new(x1, y1, z1), a + DVec3::new(x2, y2, z2)])
}

/// A triangle: general, axis-aligned (one coordinate shared), sliver
/// (third vertex near an edge), zero-area (collinear or repeated), or
/// tiny around a lattice point.
pub fn triangle() -> impl Strategy<Value = [DVec3; 3]> {
    prop_oneof![
        3 => (point(), point(), point()).prop_map(|(a, b, c)| [a, b, c]),
        2 => (point(), point(), point(), 0usize..3, coord()).prop_map(|(mut a, mut b, mut c, axis, v)| {
            a[axis] = v;
            b[axis] = v;
            c[axis] = v;
            [a, b, c]
        }),
        1 => (point(), point(), 0.0f64..1.0, -1e-3f64..1e-3).prop_map(|(a, b, t, e)| {
            let c = a + (b - a) * t + DVec3::splat(e);
            [a, b, c]
        }),
        1 => (point(), point(), 0.0f64..1.0).prop_map(|(a, b, t)| [a, b, a + (b - a) * t]),
        1 => (point(), point()).prop_map(|(a, b)| [a, b, a]),
        1 => ((-1i32..=9), (-1i32..=9), (-1i32..=9), point(), point()).prop_map(|(i, j, k, p, q)| {
            let c = DVec3::new(i as f64, j as f64, k as f64);
            [c, c + (p - c) * 1e-3, c + (q - c) * 1e-3]
        }),
    ]
}
