//! Distance fields: the Euclidean distance, in world units, from each
//! voxel's centre to the nearest point of a mesh.
//!
//! **Definition.** For voxel `(i, j, k)` with centre `c` (see
//! [`crate::GridSpec::voxel_center`]), `d = min over pieces p of |c − nearest(p, c)|`,
//! where the pieces are the mesh's triangles (a triangle of zero area
//! counts as its three edges, so a degenerate triangle is a segment or a
//! point; so does a sliver thinner than 1e-10 of its longest edge, whose
//! normal rounding makes meaningless) and its segments, in world
//! coordinates as given (not snapped to
//! the lattice), in f64. Triangles with an index out of range are left out,
//! as the voxelizers leave them out; a non-finite vertex is an error.
//!
//! **Narrow band** ([`band::band`]): the voxels with `d < W·h` (`W` in
//! voxels, `h` the voxel size), kept sparsely per 8³ brick, computed by
//! scattering each piece over the voxels within `W·h` of its box (the
//! scan conversion of S. Mauch, "A Fast Algorithm for Computing the Closest
//! Point and Distance Transform", 2000, without its polyhedra: a piece's
//! box grown by `W·h` is the superset, and each voxel keeps the minimum).
//! **Every voxel** ([`nearest::dense`]): a bounding-volume hierarchy over
//! the pieces answers each centre's nearest-piece query exactly (branch and
//! bound; the previous voxel's nearest piece starts the bound).
//!
//! Both give, for every voxel they store, the same f64 minimum over the
//! same per-piece distances (rounded once to f32), so the two paths agree
//! bit for bit and neither depends on the thread count. The brute-force
//! [`reference`](mod@reference) computes the same definition with an independent formula
//! (plane projection and edge distances); the tests hold every path within
//! 1e-5 voxel of it (plus f32 rounding of the stored value).
//!
//! The sign (inside negative) is not decided here: it is the solid
//! voxelization's (`topovox-job`), so that `d < 0` holds on exactly the
//! voxels the solid sets.

pub mod band;
pub mod field;
pub mod nearest;
pub mod reference;
mod wide;

use glam::DVec3;

use crate::MeshRef;

/// Why distances could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DistanceError {
    /// A vertex used by a triangle or segment has a NaN or infinite
    /// coordinate, or one past ±[`crate::COORDINATE_LIMIT`].
    #[error("vertex {0} has a non-finite coordinate or one past ±2^100 (1.27e30), the range topovox computes in")]
    NonFinite(u32),
    /// No triangle or segment to measure to.
    #[error("the mesh has no triangles or segments to measure a distance to")]
    Empty,
}

/// One piece of the mesh: a triangle, or (`flat`) the union of its three
/// edges; a segment `[a, b]` is `[a, b, b]`, a point `[a, a, a]`. What the
/// distance needs of it is computed once: edges, their inverse squared
/// lengths, the normal and the edges' inward normals in its plane.
#[derive(Clone, Copy, Debug)]
pub struct Piece {
    /// Corners, world coordinates.
    pub p: [DVec3; 3],
    /// Edges `b − a`, `c − b`, `a − c`.
    e: [DVec3; 3],
    /// `1 / |e|²` (0 for an edge of zero length).
    inv: [f64; 3],
    /// The normal `(b − a) × (c − a)`, and `1 / |n|²`.
    n: DVec3,
    inv_n: f64,
    /// `n × e`: points into the triangle from each edge, in its plane.
    m: [DVec3; 3],
    /// No area to speak of (height below 1e-10 of the longest edge, zero
    /// included): measured to the edges, where a normal is meaningless.
    pub flat: bool,
    /// Bounding box.
    pub lo: DVec3,
    /// Bounding box.
    pub hi: DVec3,
}

impl Piece {
    pub fn new(p: [DVec3; 3]) -> Piece {
        let e = [p[1] - p[0], p[2] - p[1], p[0] - p[2]];
        let len2 = e.map(|e| e.length_squared());
        let inv = len2.map(|l| if l > 0.0 { 1.0 / l } else { 0.0 });
        let n = e[0].cross(p[2] - p[0]);
        let longest = len2.into_iter().fold(0.0, f64::max);
        // |n| = longest edge × height.
        let flat = n.length_squared() <= 1e-20 * longest * longest;
        let inv_n = if flat { 0.0 } else { 1.0 / n.length_squared() };
        let m = e.map(|e| n.cross(e));
        Piece { p, e, inv, n, inv_n, m, flat, lo: p[0].min(p[1]).min(p[2]), hi: p[0].max(p[1]).max(p[2]) }
    }

    /// The squared distance from `q` to edge `e` (from corner `e`).
    #[inline(always)]
    fn edge(&self, e: usize, q: DVec3) -> f64 {
        let d = q - self.p[e];
        let t = (d.dot(self.e[e]) * self.inv[e]).clamp(0.0, 1.0);
        (d - self.e[e] * t).length_squared()
    }

    /// The squared distance from `q` to the piece: to the plane when the
    /// foot of the perpendicular lies in the triangle (on the inner side
    /// of all three edges), else to the nearest edge it lies outside of
    /// (the nearest boundary point of a convex polygon faces the point).
    #[inline]
    pub fn distance_squared(&self, q: DVec3) -> f64 {
        if self.flat {
            return self.edge(0, q).min(self.edge(1, q)).min(self.edge(2, q));
        }
        // The foot and q differ along n, so the sides agree for both.
        let d0 = q - self.p[0];
        let s = [self.m[0].dot(d0), self.m[1].dot(q - self.p[1]), self.m[2].dot(q - self.p[2])];
        if s[0] >= 0.0 && s[1] >= 0.0 && s[2] >= 0.0 {
            let t = d0.dot(self.n);
            return t * t * self.inv_n;
        }
        let mut d = f64::INFINITY;
        if s[0] < 0.0 {
            d = self.edge(0, q);
        }
        if s[1] < 0.0 {
            d = d.min(self.edge(1, q));
        }
        if s[2] < 0.0 {
            d = d.min(self.edge(2, q));
        }
        d
    }

    /// The point of the piece nearest to `q`, as barycentric weights of
    /// its three corners, by the same case split as
    /// [`Piece::distance_squared`] (so the point is the one that distance
    /// measures): the foot of the perpendicular, else the nearest point of
    /// the first nearest edge.
    pub fn closest(&self, q: DVec3) -> [f64; 3] {
        let edge = |e: usize| -> [f64; 3] {
            let t = ((q - self.p[e]).dot(self.e[e]) * self.inv[e]).clamp(0.0, 1.0);
            let mut w = [0.0; 3];
            w[e] += 1.0 - t;
            w[(e + 1) % 3] += t;
            w
        };
        let nearest_of = |edges: &[usize]| {
            let mut best = (f64::INFINITY, edges[0]);
            for &e in edges {
                let d = self.edge(e, q);
                if d < best.0 {
                    best = (d, e);
                }
            }
            edge(best.1)
        };
        if self.flat {
            return nearest_of(&[0, 1, 2]);
        }
        let s = [self.m[0].dot(q - self.p[0]), self.m[1].dot(q - self.p[1]), self.m[2].dot(q - self.p[2])];
        if s.iter().all(|&s| s >= 0.0) {
            // Weight of each corner: the edge opposite it, over |n|².
            return [s[1] * self.inv_n, s[2] * self.inv_n, s[0] * self.inv_n];
        }
        let outside: Vec<usize> = (0..3).filter(|&e| s[e] < 0.0).collect();
        nearest_of(&outside)
    }

    /// The point with barycentric weights `w`; the foot of the
    /// perpendicular when `w` came from inside the triangle.
    pub fn point(&self, w: [f64; 3]) -> DVec3 {
        self.p[0] * w[0] + self.p[1] * w[1] + self.p[2] * w[2]
    }

    /// The squared distance from `q` to the piece's bounding box (a lower bound).
    #[inline]
    pub fn box_distance_squared(&self, q: DVec3) -> f64 {
        box_distance_squared(self.lo, self.hi, q)
    }
}

/// The squared distance from `q` to the box `[lo, hi]`.
#[inline]
pub fn box_distance_squared(lo: DVec3, hi: DVec3, q: DVec3) -> f64 {
    let d = (lo - q).max(q - hi).max(DVec3::ZERO);
    d.length_squared()
}

/// The pieces of a mesh (see the module doc), and how many triangles and
/// segments were left out for an index out of range.
#[derive(Clone, Debug)]
pub struct Pieces {
    /// Triangles first, in mesh order, then segments.
    pub items: Vec<Piece>,
    /// Triangles and segments with an index out of range.
    pub skipped: u64,
    /// Per piece, what it came from: triangle `t` is `t`, segment `s` is
    /// `triangles + s` (the numbering of [`Piece::closest`]'s callers).
    pub element: Vec<u32>,
}

impl Pieces {
    /// The pieces of `mesh`.
    pub fn of(mesh: MeshRef<'_>) -> Result<Pieces, DistanceError> {
        let mut items = Vec::with_capacity(mesh.triangles.len() + mesh.segments.len());
        let mut skipped = 0;
        let mut element = Vec::with_capacity(items.capacity());
        let at = |i: u32| -> Result<Option<DVec3>, DistanceError> {
            match mesh.positions.get(i as usize) {
                Some(p) if crate::in_range(*p) => Ok(Some(*p)),
                Some(_) => Err(DistanceError::NonFinite(i)),
                None => Ok(None),
            }
        };
        for (n, t) in mesh.triangles.iter().enumerate() {
            match (at(t[0])?, at(t[1])?, at(t[2])?) {
                (Some(a), Some(b), Some(c)) => {
                    items.push(Piece::new([a, b, c]));
                    element.push(n as u32);
                }
                _ => skipped += 1,
            }
        }
        for (n, s) in mesh.segments.iter().enumerate() {
            match (at(s[0])?, at(s[1])?) {
                (Some(a), Some(b)) => {
                    items.push(Piece::new([a, b, b]));
                    element.push((mesh.triangles.len() + n) as u32);
                }
                _ => skipped += 1,
            }
        }
        if items.is_empty() {
            return Err(DistanceError::Empty);
        }
        Ok(Pieces { items, skipped, element })
    }
}

#[cfg(test)]
mod tests;
