//! Triangle meshes: an owned [`Mesh`] and a borrowed [`MeshRef`].

use glam::DVec3;
use rayon::prelude::*;

use crate::aabb::Aabb;

/// The largest coordinate magnitude topovox computes with: 2¹⁰⁰ (about
/// 1.27e30). Past it a squared distance (2²⁰⁰) is still finite but the
/// exact predicates' products of three coordinate differences (2³⁰⁰) come
/// near the end of `f64`'s range, and one more factor overflows; meshes,
/// grids and query points past it are refused (or, for a point, answered
/// as a point that is not finite), never computed with into inf or NaN.
pub const COORDINATE_LIMIT: f64 = 1_267_650_600_228_229_401_496_703_205_376.0;

/// The smallest voxel size a grid may have: 2⁻¹⁰⁰ (about 7.9e-31), so that
/// products of three voxel-sized differences (2⁻³⁰⁰) stay far from
/// underflow, which would make exact tests inexact.
pub const MIN_VOXEL_SIZE: f64 = 1.0 / COORDINATE_LIMIT;

/// Whether every coordinate of `p` is finite and within ±[`COORDINATE_LIMIT`].
#[inline]
pub fn in_range(p: DVec3) -> bool {
    p.is_finite() && p.abs().max_element() <= COORDINATE_LIMIT
}

/// An indexed triangle mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions (world space).
    pub positions: Vec<DVec3>,
    /// Triangles as indices into `positions`, in winding order.
    pub triangles: Vec<[u32; 3]>,
    /// Line segments (polyline input, OBJ `l` records) as indices into `positions`.
    pub segments: Vec<[u32; 2]>,
}

impl Mesh {
    /// A borrowed view.
    pub fn as_ref(&self) -> MeshRef<'_> {
        MeshRef { positions: &self.positions, triangles: &self.triangles, segments: &self.segments }
    }

    /// Applies `f` to every position (for rotations and transforms in tests and readers).
    pub fn transform(&mut self, f: impl Fn(DVec3) -> DVec3) {
        for p in &mut self.positions {
            *p = f(*p);
        }
    }
}

/// A borrowed view of an indexed triangle mesh.
///
/// Invalid indices and non-finite coordinates are allowed here; the
/// voxelizers skip such triangles and count them in their report.
#[derive(Clone, Copy, Debug)]
pub struct MeshRef<'a> {
    /// Vertex positions.
    pub positions: &'a [DVec3],
    /// Triangles as indices into `positions`.
    pub triangles: &'a [[u32; 3]],
    /// Line segments as indices into `positions`.
    pub segments: &'a [[u32; 2]],
}

impl MeshRef<'_> {
    /// Bounding box of the vertices used by triangles and segments (finite ones only).
    ///
    /// Where the items name at least a quarter as many corners as there
    /// are vertices (every mesh read from a file), the used vertices are
    /// marked first and the box is taken over the positions in order, in
    /// fixed chunks on all threads: no scattered reads, and the same box
    /// (to the sign of a zero) for any thread count.
    pub fn bounds(&self) -> Aabb {
        let corners = 3 * self.triangles.len() + 2 * self.segments.len();
        if corners < self.positions.len() / 4 {
            let mut b = Aabb::EMPTY;
            for &i in self.corners() {
                if let Some(p) = self.positions.get(i as usize).filter(|p| p.is_finite()) {
                    b.grow(*p);
                }
            }
            return b;
        }
        let mut used = vec![false; self.positions.len()];
        for &i in self.corners() {
            if let Some(u) = used.get_mut(i as usize) {
                *u = true;
            }
        }
        let chunk = |(ps, us): (&[DVec3], &[bool])| {
            let mut b = Aabb::EMPTY;
            for (p, &u) in ps.iter().zip(us) {
                if u && p.is_finite() {
                    b.grow(*p);
                }
            }
            b
        };
        let parts: Vec<Aabb> = if self.positions.len() <= PASS_CHUNK {
            vec![chunk((self.positions, &used))]
        } else {
            self.positions.par_chunks(PASS_CHUNK).zip(used.par_chunks(PASS_CHUNK)).map(chunk).collect()
        };
        let mut b = Aabb::EMPTY;
        for part in parts.iter().filter(|p| !p.is_empty()) {
            b.grow(part.min);
            b.grow(part.max);
        }
        b
    }

    /// Every index of every triangle, then of every segment.
    fn corners(&self) -> impl Iterator<Item = &u32> {
        self.triangles.iter().flatten().chain(self.segments.iter().flatten())
    }

    /// Triangles with two equal indices or zero area (exactly, in f64).
    pub fn degenerate_count(&self) -> usize {
        self.bounds_and_degenerate_count().1
    }

    /// [`bounds`](Self::bounds) and [`degenerate_count`](Self::degenerate_count)
    /// in one pass over the triangles (what a reader reports): each
    /// triangle's corners are read once for both. The same box as
    /// `bounds` (to the sign of a zero), for any thread count.
    pub fn bounds_and_degenerate_count(&self) -> (Aabb, usize) {
        let per_chunk = |c: &[[u32; 3]]| {
            let (mut b, mut degenerate) = (Aabb::EMPTY, 0);
            for t in c {
                let corners = t.map(|i| self.positions.get(i as usize));
                for p in corners.iter().flatten().filter(|p| p.is_finite()) {
                    b.grow(**p);
                }
                let zero = match corners {
                    _ if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] => true,
                    [Some(a), Some(b), Some(c)] => (*b - *a).cross(*c - *a) == DVec3::ZERO,
                    _ => false,
                };
                degenerate += zero as usize;
            }
            (b, degenerate)
        };
        let parts: Vec<(Aabb, usize)> = if self.triangles.len() <= PASS_CHUNK {
            vec![per_chunk(self.triangles)]
        } else {
            self.triangles.par_chunks(PASS_CHUNK).map(per_chunk).collect()
        };
        let (mut b, mut degenerate) = (Aabb::EMPTY, 0);
        for (part, n) in &parts {
            degenerate += n;
            if !part.is_empty() {
                b.grow(part.min);
                b.grow(part.max);
            }
        }
        for p in self.segments.iter().flatten().filter_map(|&i| self.positions.get(i as usize)).filter(|p| p.is_finite()) {
            b.grow(*p);
        }
        (b, degenerate)
    }
}

/// Items per task of the whole-mesh passes ([`MeshRef::bounds`],
/// [`MeshRef::bounds_and_degenerate_count`]): fixed, so results never depend on the
/// thread count, and large enough that a small mesh is one task, done on
/// the caller's thread (waking the pool costs more than a small pass).
const PASS_CHUNK: usize = 1 << 15;

#[cfg(test)]
mod tests {
    use super::*;

    /// The passes against their definitions, sequential and over every
    /// corner: small and past one chunk (parallel), with unused vertices,
    /// non-finite ones, out-of-range indices, repeated indices and
    /// collinear corners.
    #[test]
    fn bounds_and_degenerate_count_are_their_definitions() {
        let mut state = 7u64;
        let mut next = move || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 33) as u32
        };
        for (vertices, triangles) in [(40, 30), (1000, 3 * PASS_CHUNK + 17), (200_000, 2 * PASS_CHUNK)] {
            let mut positions: Vec<DVec3> =
                (0..vertices).map(|_| DVec3::new(next() as f64, next() as f64, -(next() as f64)) / 1e6).collect();
            positions[3] = DVec3::new(f64::NAN, 1.0, 2.0);
            positions[5] = DVec3::new(1e9, 1e9, 1e9); // used by no triangle
            positions[6..9].copy_from_slice(&[DVec3::ZERO, DVec3::ONE, DVec3::splat(2.0)]); // collinear
            let mut tris: Vec<[u32; 3]> =
                (0..triangles).map(|_| [0, 1, 2].map(|_| next() % vertices as u32)).filter(|t| !t.contains(&5)).collect();
            tris.extend([[6, 7, 8], [1, 1, 2], [0, 1, vertices as u32 + 4], [3, 4, 9]]);
            let segments = vec![[2, 9], [vertices as u32, 1]];
            let m = MeshRef { positions: &positions, triangles: &tris, segments: &segments };
            let mut want = Aabb::EMPTY;
            for &i in tris.iter().flatten().chain(segments.iter().flatten()) {
                if let Some(p) = positions.get(i as usize).filter(|p| p.is_finite()) {
                    want.grow(*p);
                }
            }
            let degenerate = tris
                .iter()
                .filter(|t| {
                    let p = t.map(|i| positions.get(i as usize));
                    t[0] == t[1]
                        || t[1] == t[2]
                        || t[0] == t[2]
                        || matches!(p, [Some(a), Some(b), Some(c)] if (*b - *a).cross(*c - *a) == DVec3::ZERO)
                })
                .count();
            assert_eq!(m.bounds(), want, "{vertices} {triangles}");
            assert_eq!(m.bounds_and_degenerate_count(), (want, degenerate), "{vertices} {triangles}");
            assert!(degenerate >= 2 && want.max.x < 1e9);
        }
    }
}
