//! Exact triangle–triangle intersection for the mesh certifier.
//!
//! **Method.** Every decision is the sign of Shewchuk's adaptive-precision
//! `orient3d` / `orient2d` ("Adaptive Precision Floating-Point Arithmetic
//! and Fast Robust Geometric Predicates", 1997; the `robust` crate), so
//! each answer is exact for the f64 coordinates given. Two non-coplanar
//! triangles meet exactly when an edge of one meets the other (the ends of
//! their common segment lie on edges); coplanar ones are projected onto a
//! coordinate plane along which they do not collapse (an affine bijection
//! of their plane, so incidence is kept) and meet when an edge crosses an
//! edge or a vertex lies in the other triangle.
//!
//! **Shared vertices.** Triangles of a mesh that share vertices (by welded
//! index) touch there by design; [`improper`] reports only what more they
//! share: a fold (two triangles on one edge, coplanar and on the same
//! side), a crossing beyond the shared vertex, or a repeated face.
//! Degenerate (zero-area) triangles are the certifier's other count and are
//! never passed here.
//!
//! No crate offers exact triangle–triangle tests with shared-vertex rules
//! (`parry`'s are floating-point and tolerance-based), hence this file.

use glam::DVec3;
use robust::{orient2d, orient3d, Coord, Coord3D};

fn c3(p: DVec3) -> Coord3D<f64> {
    Coord3D { x: p.x, y: p.y, z: p.z }
}

/// The sign of `orient3d(a, b, c, d)`: −1, 0 or 1.
pub fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> i8 {
    let v = orient3d(c3(a), c3(b), c3(c), c3(d));
    (v > 0.0) as i8 - (v < 0.0) as i8
}

/// A projection onto a coordinate plane: the two kept axes.
#[derive(Clone, Copy)]
struct Plane(usize, usize);

impl Plane {
    fn of(p: DVec3, pl: Plane) -> Coord<f64> {
        Coord { x: p[pl.0], y: p[pl.1] }
    }

    fn orient(self, a: DVec3, b: DVec3, c: DVec3) -> i8 {
        let v = orient2d(Plane::of(a, self), Plane::of(b, self), Plane::of(c, self));
        (v > 0.0) as i8 - (v < 0.0) as i8
    }

    /// A plane onto which triangle `t` does not collapse (`None`: `t` is degenerate).
    fn for_triangle(t: &[DVec3; 3]) -> Option<Plane> {
        [Plane(0, 1), Plane(1, 2), Plane(2, 0)].into_iter().find(|pl| pl.orient(t[0], t[1], t[2]) != 0)
    }

    /// Whether the closed segments `pq` and `rs` (coplanar) meet.
    fn segments_meet(self, p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> bool {
        let (o1, o2) = (self.orient(p, q, r), self.orient(p, q, s));
        let (o3, o4) = (self.orient(r, s, p), self.orient(r, s, q));
        if o1 * o2 < 0 && o3 * o4 < 0 {
            return true;
        }
        let on = |a: DVec3, b: DVec3, x: DVec3, o: i8| o == 0 && self.within(a, b, x);
        on(p, q, r, o1) || on(p, q, s, o2) || on(r, s, p, o3) || on(r, s, q, o4)
    }

    /// Whether `x`, collinear with `a` and `b`, lies on the closed segment `ab`.
    fn within(self, a: DVec3, b: DVec3, x: DVec3) -> bool {
        let (a, b, x) = (Plane::of(a, self), Plane::of(b, self), Plane::of(x, self));
        x.x >= a.x.min(b.x) && x.x <= a.x.max(b.x) && x.y >= a.y.min(b.y) && x.y <= a.y.max(b.y)
    }

    /// Whether `x` lies in the closed triangle `t` (coplanar, not degenerate here).
    fn in_triangle(self, t: &[DVec3; 3], x: DVec3) -> bool {
        let o = [self.orient(t[0], t[1], x), self.orient(t[1], t[2], x), self.orient(t[2], t[0], x)];
        o.iter().all(|&s| s >= 0) || o.iter().all(|&s| s <= 0)
    }
}

/// The edges of a triangle.
fn edges(t: &[DVec3; 3]) -> [(DVec3, DVec3); 3] {
    [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]
}

/// Whether the closed segment `pq` meets the closed triangle `t`
/// (`None`: the segment lies in `t`'s plane; the caller decides in 2D).
fn segment_meets(t: &[DVec3; 3], p: DVec3, q: DVec3) -> Option<bool> {
    let (o1, o2) = (orient(t[0], t[1], t[2], p), orient(t[0], t[1], t[2], q));
    if o1 == 0 && o2 == 0 {
        return None;
    }
    if o1 * o2 > 0 {
        return Some(false);
    }
    let s = [orient(p, q, t[0], t[1]), orient(p, q, t[1], t[2]), orient(p, q, t[2], t[0])];
    Some(s.iter().all(|&v| v >= 0) || s.iter().all(|&v| v <= 0))
}

/// Whether two triangles in one plane meet (closed sets).
fn coplanar_meet(a: &[DVec3; 3], b: &[DVec3; 3], pl: Plane) -> bool {
    edges(a).iter().any(|&(p, q)| edges(b).iter().any(|&(r, s)| pl.segments_meet(p, q, r, s)))
        || pl.in_triangle(b, a[0])
        || pl.in_triangle(a, b[0])
}

/// Whether the closed triangles `a` and `b` (neither degenerate) meet.
pub fn meet(a: &[DVec3; 3], b: &[DVec3; 3]) -> bool {
    let sides = [orient(a[0], a[1], a[2], b[0]), orient(a[0], a[1], a[2], b[1]), orient(a[0], a[1], a[2], b[2])];
    if sides.iter().all(|&s| s > 0) || sides.iter().all(|&s| s < 0) {
        return false;
    }
    if sides.iter().all(|&s| s == 0) {
        return Plane::for_triangle(a).is_some_and(|pl| coplanar_meet(a, b, pl));
    }
    let hits = |t: &[DVec3; 3], other: &[DVec3; 3]| edges(other).iter().any(|&(p, q)| segment_meets(t, p, q).unwrap_or(false));
    hits(a, b) || hits(b, a)
}

/// Whether triangles `a` and `b`, sharing the vertices where `shared`
/// pairs their corners (`(corner of a, corner of b)`, one or two pairs),
/// meet anywhere but there: a fold over the shared edge, or a crossing
/// beyond the shared vertex. Three shared corners (a repeated face) and no
/// shared corner are decided by the caller ([`meet`]).
pub fn improper(a: &[DVec3; 3], b: &[DVec3; 3], shared: &[(usize, usize)]) -> bool {
    match shared {
        [(i, _), (j, _)] => {
            // a = (u, v, c), b = (u, v, d): only a coplanar fold overlaps.
            let c = a[3 - i - j];
            let (bi, bj) = (shared[0].1, shared[1].1);
            let d = b[3 - bi - bj];
            let (u, v) = (a[*i], a[*j]);
            if orient(u, v, c, d) != 0 {
                return false;
            }
            // Degenerate by the projection although not by the caller's
            // test (a product that underflowed): reported, never certified.
            let Some(pl) = Plane::for_triangle(a) else { return true };
            pl.orient(u, v, c) == pl.orient(u, v, d)
        }
        [(i, j)] => {
            let (ao, bo) = (opposite(a, *i), opposite(b, *j));
            let v = a[*i];
            match (segment_meets(b, ao.0, ao.1), segment_meets(a, bo.0, bo.1)) {
                (Some(true), _) | (_, Some(true)) => true,
                (Some(false), Some(false)) => false,
                // An opposite edge in the other's plane, with the shared
                // vertex: the two triangles are coplanar.
                _ => coplanar_beyond(a, b, v, ao, bo),
            }
        }
        _ => unreachable!("improper takes one or two shared corners"),
    }
}

/// The edge of `t` opposite its corner `i`.
fn opposite(t: &[DVec3; 3], i: usize) -> (DVec3, DVec3) {
    (t[(i + 1) % 3], t[(i + 2) % 3])
}

/// Two coplanar triangles sharing vertex `v`: whether they meet beyond it.
fn coplanar_beyond(a: &[DVec3; 3], b: &[DVec3; 3], v: DVec3, ao: (DVec3, DVec3), bo: (DVec3, DVec3)) -> bool {
    let Some(pl) = Plane::for_triangle(a) else { return true };
    let (ea, eb) = ([(v, ao.0), (v, ao.1), ao], [(v, bo.0), (v, bo.1), bo]);
    // Pairs of edges through v meet at v by design: skip those.
    let crossing = ea
        .iter()
        .enumerate()
        .any(|(x, &(p, q))| eb.iter().enumerate().any(|(y, &(r, s))| (x == 2 || y == 2) && pl.segments_meet(p, q, r, s)));
    crossing || pl.in_triangle(b, ao.0) || pl.in_triangle(b, ao.1) || pl.in_triangle(a, bo.0) || pl.in_triangle(a, bo.1)
}
