//! Sutherland–Hodgman clipping of a convex polygon against an axis-aligned box.
//!
//! This work is based on: I. Sutherland, G. Hodgman, "Reentrant polygon
//! clipping", CACM 1974.
//!
//! Used only for triangles that reach beyond the fixed-point lattice range
//! ([`crate::geom::fixed::DIRECT_LIMIT_VOXELS`]): such a triangle is clipped,
//! in f64 grid units, to the grid enlarged by one voxel on every side, then
//! fan-triangulated and snapped. Voxels of the grid lie at least one voxel
//! away from the clipping planes, so clipping never changes which of them the
//! triangle meets (up to the lattice snapping every triangle undergoes).

use glam::DVec3;

/// Clips the convex polygon `poly` to the box `[lo, hi]` (closed).
/// Returns the clipped polygon; fewer than 3 vertices means nothing is left.
pub fn clip_polygon_to_box(poly: &[DVec3], lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    if poly.len() > MAX_IN {
        return clip_general(poly, lo, hi);
    }
    // Each plane adds at most one vertex: two fixed buffers, no allocation until the end.
    let mut a = [DVec3::ZERO; MAX_IN + 6];
    let mut b = [DVec3::ZERO; MAX_IN + 6];
    a[..poly.len()].copy_from_slice(poly);
    let mut n = poly.len();
    for axis in 0..3 {
        for (bound, keep_below) in [(lo[axis], false), (hi[axis], true)] {
            if n == 0 {
                return Vec::new();
            }
            n = clip_plane(&a[..n], axis, bound, keep_below, &mut b);
            std::mem::swap(&mut a, &mut b);
        }
    }
    a[..n].to_vec()
}

/// Largest input polygon clipped without allocating.
const MAX_IN: usize = 8;

/// Most vertices [`clip_triangle_to_box`] can return (3 + one per plane).
pub const CLIPPED_MAX: usize = 9;

/// A convex polygon of at most [`CLIPPED_MAX`] vertices, with room to clip it.
#[derive(Clone, Copy, Debug)]
pub struct ClipPoly {
    v: [DVec3; CLIPPED_MAX + 1],
    n: usize,
}

impl Default for ClipPoly {
    fn default() -> ClipPoly {
        ClipPoly { v: [DVec3::ZERO; CLIPPED_MAX + 1], n: 0 }
    }
}

impl ClipPoly {
    /// The vertices.
    pub fn vertices(&self) -> &[DVec3] {
        &self.v[..self.n]
    }
}

/// Clips the convex polygon `poly` (at most [`CLIPPED_MAX`] vertices) to the
/// slab `lo <= p[axis] <= hi`, into `out`: the `lo` plane, then the `hi`
/// plane, each skipped when the polygon lies entirely on its kept side.
/// Clipping a triangle to the slabs along x, then y, then z is
/// [`clip_triangle_to_box`], so a caller visiting many boxes in x, y, z
/// order may keep the partial results and get the same polygons.
#[inline]
pub fn clip_to_slab(poly: &[DVec3], axis: usize, lo: f64, hi: f64, out: &mut ClipPoly) {
    let poly = &poly[..poly.len().min(CLIPPED_MAX)];
    // A plane adds at most one vertex to a convex polygon; `clip_plane`
    // stops at the buffer's end should rounding ever make one non-convex.
    let mut tmp = [DVec3::ZERO; CLIPPED_MAX + 1];
    let first: &[DVec3] = if poly.iter().all(|p| p[axis] >= lo) {
        poly
    } else {
        let m = clip_plane(poly, axis, lo, false, &mut tmp).min(CLIPPED_MAX);
        &tmp[..m]
    };
    if first.is_empty() || first.iter().all(|p| p[axis] <= hi) {
        out.v[..first.len()].copy_from_slice(first);
        out.n = first.len();
    } else {
        out.n = clip_plane(first, axis, hi, true, &mut out.v).min(CLIPPED_MAX);
    }
}

/// [`clip_polygon_to_box`] for a triangle, into a fixed array (no
/// allocation: the attribute carrier clips one triangle per voxel it
/// touches). Returns the number of vertices in `out`.
#[inline]
pub fn clip_triangle_to_box(tri: &[DVec3; 3], lo: DVec3, hi: DVec3, out: &mut [DVec3; CLIPPED_MAX]) -> usize {
    let (mut x, mut y, mut z) = (ClipPoly::default(), ClipPoly::default(), ClipPoly::default());
    clip_to_slab(tri, 0, lo.x, hi.x, &mut x);
    clip_to_slab(x.vertices(), 1, lo.y, hi.y, &mut y);
    clip_to_slab(y.vertices(), 2, lo.z, hi.z, &mut z);
    out[..z.n].copy_from_slice(z.vertices());
    z.n
}

fn clip_general(poly: &[DVec3], lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    let mut cur: Vec<DVec3> = poly.to_vec();
    for axis in 0..3 {
        for (bound, keep_below) in [(lo[axis], false), (hi[axis], true)] {
            let mut next = vec![DVec3::ZERO; cur.len() + 1];
            let n = clip_plane(&cur, axis, bound, keep_below, &mut next);
            next.truncate(n);
            cur = next;
        }
    }
    cur
}

/// One Sutherland–Hodgman pass: `cur` clipped to the half-space kept by
/// the plane `p[axis] = bound` into `out` (room for `cur.len() + 1`, what a
/// convex polygon needs; vertices beyond `out` are dropped); returns the count.
fn clip_plane(cur: &[DVec3], axis: usize, bound: f64, keep_below: bool, out: &mut [DVec3]) -> usize {
    // Signed distance, non-negative on the kept side.
    let dist = |p: DVec3| if keep_below { bound - p[axis] } else { p[axis] - bound };
    let mut n = 0;
    for idx in 0..cur.len() {
        let a = cur[idx];
        let b = if idx + 1 < cur.len() { cur[idx + 1] } else { cur[0] };
        let (da, db) = (dist(a), dist(b));
        if da >= 0.0 && n < out.len() {
            out[n] = a;
            n += 1;
        }
        if (da >= 0.0) != (db >= 0.0) && n < out.len() {
            let t = da / (da - db);
            let mut p = a + (b - a) * t;
            p[axis] = bound; // exact on the plane
            out[n] = p;
            n += 1;
        }
    }
    n
}

/// Clips the segment `[a, b]` to the closed box `[lo, hi]` (Liang–Barsky);
/// `None` if nothing is left.
pub fn clip_segment_to_box(a: DVec3, b: DVec3, lo: DVec3, hi: DVec3) -> Option<(DVec3, DVec3)> {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let d = b - a;
    for axis in 0..3 {
        for (p, q) in [(-d[axis], a[axis] - lo[axis]), (d[axis], hi[axis] - a[axis])] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let r = q / p;
                if p < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
            }
        }
    }
    // Clamping puts the end points exactly on the planes they were cut at.
    (t0 <= t1).then(|| ((a + d * t0).clamp(lo, hi), (a + d * t1).clamp(lo, hi)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_inside_is_unchanged() {
        let t = [DVec3::new(1.0, 1.0, 1.0), DVec3::new(2.0, 1.0, 1.0), DVec3::new(1.0, 2.0, 1.0)];
        let c = clip_polygon_to_box(&t, DVec3::ZERO, DVec3::splat(4.0));
        assert_eq!(c, t.to_vec());
    }

    #[test]
    fn huge_triangle_is_cut_to_the_box() {
        let t = [DVec3::new(-1e9, -1e9, 0.5), DVec3::new(1e9, -1e9, 0.5), DVec3::new(0.0, 1e9, 0.5)];
        let c = clip_polygon_to_box(&t, DVec3::ZERO, DVec3::splat(4.0));
        assert!(c.len() >= 3);
        for p in &c {
            assert!(p.x >= 0.0 && p.x <= 4.0 && p.y >= 0.0 && p.y <= 4.0);
            assert_eq!(p.z, 0.5);
        }
    }

    #[test]
    fn segment_is_cut_to_the_box() {
        let (a, b) = clip_segment_to_box(DVec3::new(-1e9, 1.0, 1.0), DVec3::new(1e9, 1.0, 1.0), DVec3::ZERO, DVec3::splat(4.0)).unwrap();
        assert_eq!((a.x, b.x), (0.0, 4.0));
        assert!(clip_segment_to_box(DVec3::new(-1e9, 9.0, 1.0), DVec3::new(1e9, 9.0, 1.0), DVec3::ZERO, DVec3::splat(4.0)).is_none());
    }

    use proptest::prelude::*;

    proptest::proptest! {
        /// Clipping slab by slab (what the attribute carrier shares between
        /// neighbouring voxels) gives exactly the polygon of clipping to all
        /// six planes in turn: vertices on a coarse lattice now and then, so
        /// they land on the box's planes.
        #[test]
        fn slab_by_slab_equals_clipping_to_the_box(
            v in proptest::array::uniform3(proptest::array::uniform3(proptest::prop_oneof![(-8i32..=24).prop_map(|c| c as f64 * 0.25), -2.0f64..6.0])),
            lo in proptest::array::uniform3(-1i32..4),
        ) {
            let tri = v.map(DVec3::from_array);
            let lo = DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64);
            let hi = lo + DVec3::ONE;
            let mut out = [DVec3::ZERO; CLIPPED_MAX];
            let n = clip_triangle_to_box(&tri, lo, hi, &mut out);
            let want = clip_polygon_to_box(&tri, lo, hi);
            prop_assert_eq!(&out[..n], &want[..]);
        }
    }

    #[test]
    fn triangle_outside_vanishes() {
        let t = [DVec3::new(10.0, 10.0, 10.0), DVec3::new(11.0, 10.0, 10.0), DVec3::new(10.0, 11.0, 10.0)];
        assert!(clip_polygon_to_box(&t, DVec3::ZERO, DVec3::splat(4.0)).len() < 3);
    }
}
