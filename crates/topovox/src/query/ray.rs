//! Exact crossings of a point's `−x` ray with triangles, in world
//! coordinates: the integer winding number of a closed surface at any point.
//!
//! This work is based on: M. Schwarz, H.-P. Seidel, "Fast Parallel Surface
//! and Solid Voxelization on GPUs", ACM TOG 29(6), 2010, §4 (inside by the
//! crossings of an axis-parallel ray), with J. R. Shewchuk's exact
//! predicates ("Adaptive Precision Floating-Point Arithmetic and Fast
//! Robust Geometric Predicates", 1997; the `robust` crate) and the tie rule
//! of [`crate::geom::perturb`]: the point is displaced by `δ = −(ε, ε², ε³)`.
//!
//! **Definition.** The displaced point `q + δ` never lies on a triangle's
//! edge or plane, so its ray crosses triangle `abc` iff `q + δ` lies
//! strictly inside the triangle's projection on the `yz` plane (the three
//! edge orientations agree; a triangle whose projection has no area is
//! never crossed) and strictly beyond the triangle's plane in `+x`. A
//! crossing counts `+1` where the triangle faces `−x` (the ray leaves a
//! closed outward-facing surface through it), else `−1`; the sum is the
//! integer winding number of a closed surface, its parity the ray parity.
//! Each orientation is Shewchuk's exact sign, and where it is zero the
//! sign of the first non-zero coefficient of its expansion in `ε` (exact
//! differences and 2×2 orientations of the input floats).
//!
//! The grid solids ([`crate::voxelize::solid`]) decide by the same rule on
//! the 1/4096 lattice; on a mesh whose vertices lie on that lattice the two
//! agree at every voxel centre (tested).
//!
//! **Index.** Triangles are binned by the cells of a `yz` grid their
//! projections' boxes touch; a point tests the triangles of its cell whose
//! box holds it in `y` and `z` and starts at or before it in `x`.

use glam::DVec3;
use robust::{orient2d, Coord};

use crate::geom::solid_angle::{normal_signs, plane_side, sign};

/// Exact sign of `(v − u) × (q − u)` in the `yz` plane, with `q`
/// displaced by `δ` (its `y` by `−ε²`, its `z` by `−ε³`): the value, else
/// `v.z − u.z`, else `u.y − v.y`.
#[inline]
pub(crate) fn yz_side(u: DVec3, v: DVec3, q: DVec3) -> i32 {
    let c = |p: DVec3| Coord { x: p.y, y: p.z };
    let s = sign(orient2d(c(u), c(v), c(q)));
    if s != 0 {
        return s;
    }
    if v.z != u.z {
        return if v.z > u.z { 1 } else { -1 };
    }
    sign(u.y - v.y)
}

/// The most index entries per triangle (see [`RayIndex::fit_cells`]);
/// a mesh's triangles, smaller than its cells, touch one to four.
const MAX_ENTRIES_PER_TRIANGLE: u64 = 16;

/// A triangle as the index keeps it.
#[derive(Clone, Copy, Debug)]
struct RayTri {
    p: [DVec3; 3],
    lo: DVec3,
    hi: DVec3,
}

impl RayTri {
    fn new(p: [DVec3; 3]) -> RayTri {
        RayTri { p, lo: p[0].min(p[1]).min(p[2]), hi: p[0].max(p[1]).max(p[2]) }
    }
}

/// The crossing count and signed sum at a point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Crossings {
    /// Triangles the displaced `−x` ray crosses.
    pub count: u32,
    /// Their signed sum: the winding number of a closed surface.
    pub winding: i64,
}

/// Triangles binned by `yz` cells (see the module doc).
#[derive(Clone, Debug)]
pub struct RayIndex {
    tris: Vec<RayTri>,
    lo: [f64; 2],
    hi: [f64; 2],
    scale: [f64; 2],
    cells: [usize; 2],
    /// Cell `c`'s triangles are `items[start[c] .. start[c + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
    /// Each triangle's tag ([`RayIndex::tagged`]; empty otherwise).
    tags: Vec<u32>,
}

impl RayIndex {
    /// The index over `tris` (world coordinates); triangles whose `yz`
    /// projection has no area are left out (no ray crosses them).
    pub fn new(tris: impl Iterator<Item = [DVec3; 3]>) -> RayIndex {
        let tris: Vec<RayTri> = tris.filter(|t| normal_signs(t)[0] != 0).map(RayTri::new).collect();
        RayIndex::of(tris, Vec::new())
    }

    /// The index over `tris`, each with a tag that
    /// [`RayIndex::crossed_tags`] reports.
    pub fn tagged(tris: impl Iterator<Item = ([DVec3; 3], u32)>) -> RayIndex {
        let (tris, tags): (Vec<RayTri>, Vec<u32>) =
            tris.filter(|t| normal_signs(&t.0)[0] != 0).map(|(p, tag)| (RayTri::new(p), tag)).unzip();
        RayIndex::of(tris, tags)
    }

    fn of(tris: Vec<RayTri>, tags: Vec<u32>) -> RayIndex {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for t in &tris {
            for a in 0..2 {
                lo[a] = lo[a].min(t.lo[a + 1]);
                hi[a] = hi[a].max(t.hi[a + 1]);
            }
        }
        // About two cells per triangle, shaped like the box.
        let ext = [(hi[0] - lo[0]).max(f64::MIN_POSITIVE), (hi[1] - lo[1]).max(f64::MIN_POSITIVE)];
        let n = (tris.len() as f64 * 2.0).max(1.0);
        let side = (ext[0] * ext[1] / n).sqrt().max(ext[0].max(ext[1]) / 4096.0);
        let mut out = RayIndex { tris, lo, hi, scale: [1.0; 2], cells: [1, 1], start: Vec::new(), items: Vec::new(), tags };
        if !out.tris.is_empty() {
            // Nothing to bin (a closed mesh's caps) keeps one cell, not a
            // grid sized by an empty box.
            out.fit_cells(ext, side);
        }
        out.bin();
        out
    }

    /// Cells of about `side`, made coarser until the entries (a triangle
    /// per cell its box touches) number at most [`MAX_ENTRIES_PER_TRIANGLE`]
    /// per triangle: a soup of large triangles crossing each other would
    /// otherwise put each in 10⁵ cells (10¹¹ entries for 10⁶ triangles).
    /// Coarser cells cost queries time, never memory; one cell holds
    /// every triangle once.
    fn fit_cells(&mut self, ext: [f64; 2], mut side: f64) {
        let limit = (self.tris.len() as u64).saturating_mul(MAX_ENTRIES_PER_TRIANGLE).clamp(1 << 22, u64::from(u32::MAX));
        loop {
            self.cells = [(ext[0] / side).ceil().clamp(1.0, 4096.0) as usize, (ext[1] / side).ceil().clamp(1.0, 4096.0) as usize];
            self.scale = [self.cells[0] as f64 / ext[0], self.cells[1] as f64 / ext[1]];
            let entries = self.entries();
            if entries <= limit || self.cells == [1, 1] {
                return;
            }
            side *= (entries as f64 / limit as f64).sqrt().max(1.25);
        }
    }

    /// How many (cell, triangle) entries the current cells give.
    fn entries(&self) -> u64 {
        self.tris
            .iter()
            .map(|t| {
                let y = (self.cell(0, t.hi.y) - self.cell(0, t.lo.y) + 1) as u64;
                let z = (self.cell(1, t.hi.z) - self.cell(1, t.lo.z) + 1) as u64;
                y * z
            })
            .sum()
    }

    /// The cell range `[first, last]` along `yz` axis `a` of coordinate `v`
    /// (clamped; monotone in `v`, so a box's cells hold every point of it).
    #[inline]
    fn cell(&self, a: usize, v: f64) -> usize {
        (((v - self.lo[a]) * self.scale[a]).max(0.0) as usize).min(self.cells[a] - 1)
    }

    fn bin(&mut self) {
        let count = self.cells[0] * self.cells[1];
        let mut start = vec![0u32; count + 1];
        let width = self.cells[0];
        let range = |s: &RayIndex, t: &RayTri| {
            let (y0, y1) = (s.cell(0, t.lo.y), s.cell(0, t.hi.y));
            let (z0, z1) = (s.cell(1, t.lo.z), s.cell(1, t.hi.z));
            (z0..=z1).flat_map(move |z| (y0..=y1).map(move |y| z * width + y))
        };
        for t in &self.tris {
            for c in range(self, t) {
                start[c + 1] += 1;
            }
        }
        for c in 0..count {
            start[c + 1] += start[c];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; start[count] as usize];
        for (n, t) in self.tris.iter().enumerate() {
            for c in range(self, t) {
                items[fill[c] as usize] = n as u32;
                fill[c] += 1;
            }
        }
        (self.start, self.items) = (start, items);
    }

    /// The crossings of `q`'s displaced `−x` ray (`q` finite).
    pub fn crossings(&self, q: DVec3) -> Crossings {
        let mut out = Crossings::default();
        self.each_crossing(q, |_, s| {
            out.count += 1;
            out.winding -= s as i64;
        });
        out
    }

    /// The tag of each triangle `q`'s displaced `−x` ray crosses (an index
    /// made by [`RayIndex::tagged`]; nothing otherwise).
    pub fn crossed_tags(&self, q: DVec3, mut tag: impl FnMut(u32)) {
        if !self.tags.is_empty() {
            self.each_crossing(q, |n, _| tag(self.tags[n]));
        }
    }

    /// Calls `f(triangle, sign of its n_x)` for each crossing.
    fn each_crossing(&self, q: DVec3, mut f: impl FnMut(usize, i32)) {
        if self.tris.is_empty() || q.y < self.lo[0] || q.y > self.hi[0] || q.z < self.lo[1] || q.z > self.hi[1] {
            return;
        }
        let c = self.cell(1, q.z) * self.cells[0] + self.cell(0, q.y);
        for &n in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
            let t = &self.tris[n as usize];
            if t.lo.x > q.x || q.y < t.lo.y || q.y > t.hi.y || q.z < t.lo.z || q.z > t.hi.z {
                continue;
            }
            if let Some(s) = crosses(&t.p, q) {
                f(n as usize, s);
            }
        }
    }
}

/// `Some(sign of the triangle's n_x)` when the displaced `−x` ray from `q`
/// crosses triangle `t`, else `None`.
#[inline]
pub fn crosses(t: &[DVec3; 3], q: DVec3) -> Option<i32> {
    let s = yz_side(t[0], t[1], q);
    if s == 0 || yz_side(t[1], t[2], q) != s || yz_side(t[2], t[0], q) != s {
        return None;
    }
    // Inside the projection, so n_x has sign s; q + δ lies beyond the
    // plane in +x iff n · (q + δ − a) has that sign too.
    (plane_side(t, q) == s).then_some(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Xorshift;

    /// Large triangles crossing each other (a soup filling a box) would
    /// put each in every cell: the index coarsens its cells to a bounded
    /// number of entries, and still finds every crossing.
    #[test]
    fn a_soup_of_large_triangles_keeps_the_index_bounded_and_exact() {
        let mut rng = Xorshift(11);
        let mut point = || DVec3::new(rng.below(4096) as f64, rng.below(4096) as f64, rng.below(4096) as f64) / 1024.0;
        let tris: Vec<[DVec3; 3]> = (0..3000).map(|_| [point(), point(), point()]).collect();
        let index = RayIndex::new(tris.iter().copied());
        assert!(index.items.len() as u64 <= 1 << 22, "{} entries for {} triangles", index.items.len(), tris.len());
        assert!(index.cells[0] * index.cells[1] > 1, "coarsened to a single cell");
        for _ in 0..200 {
            let q = point();
            let mut want = Crossings::default();
            for t in &tris {
                if let Some(s) = crosses(t, q) {
                    want.count += 1;
                    want.winding -= s as i64;
                }
            }
            assert_eq!(index.crossings(q), want, "{q}");
        }
    }
}
