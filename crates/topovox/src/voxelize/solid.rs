//! Solid voxelization (`solid`): voxels whose centre is inside the mesh.
//!
//! This work is based on: M. Schwarz, H.-P. Seidel, "Fast Parallel Surface
//! and Solid Voxelization on GPUs", ACM TOG 29(6), 2010, §4 (solid
//! voxelization by ray parity along a grid axis, triangle-parallel).
//!
//! **Definition.** With `w(p)` the winding number of the (snapped) mesh
//! around point `p`, voxel `(i,j,k)` is set iff `|w(c + δ)| >= 1/2` for its
//! centre `c`, displaced by the tie rule of [`crate::geom::perturb`]
//! (`δ = −(ε, ε², ε³)`), so centres exactly on faces, edges or vertices are
//! decided consistently: a closed cube whose faces pass through voxel
//! centres takes exactly one of the two boundary layers on each axis.
//!
//! **Methods.**
//! - [`parity()`]: every triangle adds, to each grid row whose centre line it
//!   crosses, a crossing at an exact position (integer predicates, the
//!   displacement decides rows through edges and vertices, so no streaks);
//!   a voxel is inside iff an odd number of crossings lie on its `−x` ray.
//!   For a closed surface that is consistently oriented and does not
//!   intersect itself, `w ∈ {0, 1}` (or `{0, −1}`) and parity equals the
//!   definition. Triangle-parallel with rayon, then one sorted pass per row.
//! - [`reference`](mod@reference): the definition by brute force for closed meshes — for
//!   every voxel centre and every triangle, does the displaced `−x` ray
//!   cross it (the generic exact segment predicate), summing `±1` by the
//!   triangle's orientation: the exact integer winding number.
//!
//! - [`winding_closed`]: the same crossings, signed and summed: the exact
//!   winding number of a watertight mesh, which also fills regions wrapped
//!   twice (self-intersections, same-orientation nested shells).
//!
//! Open or inconsistently oriented meshes need the generalized winding
//! number: [`super::winding`].

use rayon::prelude::*;

use super::Stop;
use crate::geom::fixed::ONE;
use crate::geom::lattice::LatticeTriangle;
use crate::grid::bricks::{Brick, BRICK};
use crate::grid::dense::DenseBits;
use crate::grid::sparse::SparseBricks;
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;
use crate::topology::inside::{row_crossings, row_crossings_in, row_starts, snap_all, ClassifyError, Snapped};

/// What a solid voxelization saw and did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SolidReport {
    /// Triangles with valid, finite vertices (degenerate ones included).
    pub triangles: u64,
    /// Edges used by an odd number of triangles (0: closed).
    pub boundary_edges: u64,
    /// Edges not used equally often in both directions (0: consistently oriented).
    pub unbalanced_edges: u64,
    /// Voxels set.
    pub voxels: u64,
}

impl SolidReport {
    /// Closed and consistently oriented: parity is exact.
    pub fn watertight(&self) -> bool {
        self.boundary_edges == 0 && self.unbalanced_edges == 0 && self.triangles > 0
    }
}

/// What the solid methods report about a snapped mesh before voxelizing
/// (`voxels` is 0): whether it is watertight.
pub fn inspect(s: &Snapped) -> SolidReport {
    SolidReport {
        triangles: s.triangles.len() as u64,
        boundary_edges: s.boundary_edges as u64,
        unbalanced_edges: s.unbalanced_edges() as u64,
        voxels: 0,
    }
}

/// Solid by ray parity (exact; right for closed, consistently oriented,
/// non-self-intersecting meshes). Dense output, parallel over rows.
pub fn parity(mesh: MeshRef<'_>, grid: &GridSpec) -> Result<(DenseBits, SolidReport), ClassifyError> {
    Ok(parity_snapped(&snap_all(mesh, grid)?, grid.dims(), &Stop::new()))
}

/// [`parity`] on an already snapped mesh (see [`snap_all`]); rows are
/// skipped once `stop` is requested.
pub fn parity_snapped(snapped: &Snapped, dims: [u32; 3], stop: &Stop) -> (DenseBits, SolidReport) {
    fill(snapped, dims, Rule::Parity, stop)
}

/// Solid by the exact winding number of a closed mesh: the signed crossings
/// on each voxel's `−x` ray summed (`|w| >= 1`). Equals [`parity`] where
/// the surface does not overlap itself, and fills regions it wraps twice
/// (self-intersections, nested shells of the same orientation), where
/// parity leaves holes. For meshes with boundary edges the sum depends on
/// the ray and callers must not use it (see [`SolidReport::watertight`]).
pub fn winding_closed(mesh: MeshRef<'_>, grid: &GridSpec) -> Result<(DenseBits, SolidReport), ClassifyError> {
    Ok(winding_closed_snapped(&snap_all(mesh, grid)?, grid.dims(), &Stop::new()))
}

/// [`winding_closed`] on an already snapped mesh.
pub fn winding_closed_snapped(snapped: &Snapped, dims: [u32; 3], stop: &Stop) -> (DenseBits, SolidReport) {
    fill(snapped, dims, Rule::Winding, stop)
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Rule {
    /// Inside iff an odd number of crossings.
    Parity,
    /// Inside iff the signed crossings sum to non-zero.
    Winding,
}

/// Calls `span(from, to)` (inclusive) for each maximal run of a row's
/// voxels that `rule` puts inside, from the row's sorted crossings.
fn row_spans(row_hits: &[(u32, u32, i8)], nx: u32, rule: Rule, mut span: impl FnMut(u32, u32)) {
    // State before the first voxel, then the changes voxel by voxel.
    let mut w = 0i64;
    let mut inside = false;
    let mut from = 0u32;
    let mut h = 0;
    while h < row_hits.len() {
        let at = row_hits[h].1;
        let mut e = h;
        while e < row_hits.len() && row_hits[e].1 == at {
            e += 1;
        }
        let group = &row_hits[h..e];
        h = e;
        if at >= nx {
            break;
        }
        let now = match rule {
            Rule::Winding => {
                w += group.iter().map(|c| c.2 as i64).sum::<i64>();
                w != 0
            }
            Rule::Parity => inside ^ (group.len() % 2 == 1),
        };
        if now != inside {
            if inside && at > from {
                span(from, at - 1);
            }
            inside = now;
            from = at;
        }
    }
    if inside && from < nx {
        span(from, nx - 1);
    }
}

/// Shared row filler: per row, walks the crossings in order and fills the
/// spans where `rule` says inside.
fn fill(snapped: &Snapped, dims: [u32; 3], rule: Rule, stop: &Stop) -> (DenseBits, SolidReport) {
    // Zero-area triangles cross no ray (`row_crossings` skips them).
    let hits = row_crossings(&snapped.triangles, dims);
    let mut bits = DenseBits::new(dims);
    let nx = dims[0];
    // Row r's crossings are hits[start[r] .. start[r + 1]].
    let start = row_starts(dims[1] as usize * dims[2] as usize, hits.iter().map(|h| h.0 as usize));
    bits.par_rows_mut().enumerate().filter(|_| !stop.requested()).for_each(|(r, row)| {
        row_spans(&hits[start[r]..start[r + 1]], nx, rule, |a, b| DenseBits::fill_row(row, a, b));
    });
    let mut rep = inspect(snapped);
    rep.voxels = bits.count();
    (bits, rep)
}

/// [`parity_snapped`] without a dense grid: the same voxels as sparse
/// bricks, the interior as runs of full bricks (constant tiles), so memory
/// follows the surface (the crossings and the bricks it cuts), not the
/// volume. Brick rows are skipped once `stop` is requested.
pub fn parity_sparse(snapped: &Snapped, dims: [u32; 3], stop: &Stop) -> (SparseBricks, SolidReport) {
    fill_sparse(snapped, dims, Rule::Parity, stop)
}

/// [`winding_closed_snapped`] without a dense grid (see [`parity_sparse`]).
pub fn winding_closed_sparse(snapped: &Snapped, dims: [u32; 3], stop: &Stop) -> (SparseBricks, SolidReport) {
    fill_sparse(snapped, dims, Rule::Winding, stop)
}

/// Inclusive intervals, sorted and coalesced (overlapping or adjacent).
fn coalesce(mut v: Vec<(u32, u32)>) -> Vec<(u32, u32)> {
    v.sort_unstable();
    let mut out: Vec<(u32, u32)> = Vec::with_capacity(v.len());
    for (a, b) in v {
        match out.last_mut() {
            Some(l) if a <= l.1.saturating_add(1) => l.1 = l.1.max(b),
            _ => out.push((a, b)),
        }
    }
    out
}

/// The intersection of two sorted, disjoint lists of inclusive intervals.
pub(crate) fn intersect(a: &[(u32, u32)], b: &[(u32, u32)]) -> Vec<(u32, u32)> {
    let (mut x, mut y, mut out) = (0, 0, Vec::new());
    while x < a.len() && y < b.len() {
        let (lo, hi) = (a[x].0.max(b[y].0), a[x].1.min(b[y].1));
        if lo <= hi {
            out.push((lo, hi));
        }
        if a[x].1 < b[y].1 {
            x += 1;
        } else {
            y += 1;
        }
    }
    out
}

/// `a` without `b` (sorted, disjoint inclusive intervals; `b` within `a`'s span or not).
fn subtract(a: &[(u32, u32)], b: &[(u32, u32)]) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    let mut y = 0;
    for &(lo, hi) in a {
        let mut lo = lo as u64;
        while y < b.len() && (b[y].1 as u64) < lo {
            y += 1;
        }
        let mut z = y;
        while z < b.len() && b[z].0 as u64 <= hi as u64 {
            if (b[z].0 as u64) > lo {
                out.push((lo as u32, b[z].0 - 1));
            }
            lo = lo.max(b[z].1 as u64 + 1);
            z += 1;
        }
        if lo <= hi as u64 {
            out.push((lo as u32, hi));
        }
    }
    out
}

/// Bricks and full runs of one brick row `(bj, bk)`, in order of `bi`.
pub(crate) type BrickRow = (Vec<([u32; 3], Brick)>, Vec<([u32; 3], u32)>);

/// One brick row of the solid: the spans of its 64 voxel rows; bricks
/// every row covers wholly form full runs; the other bricks any span
/// touches are built bit by bit.
fn brick_row(band: &Band, dims: [u32; 3], bj: u32, bk: u32, rule: Rule) -> BrickRow {
    let [nx, ny, nz] = dims;
    let b = BRICK;
    // spans[dk · 8 + dj]: the inside spans of voxel row (bj·8 + dj, bk·8 + dk).
    let mut spans: [Vec<(u32, u32)>; 64] = std::array::from_fn(|_| Vec::new());
    for dk in 0..b.min(nz - bk * b) {
        for dj in 0..b.min(ny - bj * b) {
            let out = &mut spans[(dk * b + dj) as usize];
            row_spans(band.row(bj * b + dj, bk * b + dk), nx, rule, |f, t| out.push((f, t)));
        }
    }
    bricks_of_spans(&spans, dims, bj, bk)
}

/// Planes per band of the sparse solids (a multiple of [`BRICK`]): the
/// rays' crossings are found and used band by band, so memory holds one
/// band's crossings beside the result rather than the whole grid's (12
/// bytes a crossing: 480 MB for the bunny at 4096, whose result takes 65).
pub(crate) const BAND_PLANES: u32 = 8 * BRICK;

/// The planes `planes` and the crossings of their rows ([`row_crossings_in`]:
/// rows numbered from the band's first plane, sorted).
pub(crate) struct Band {
    planes: std::ops::Range<u32>,
    ny: u32,
    hits: Vec<(u32, u32, i8)>,
}

impl Band {
    /// The crossings of row `(j, k)` (`k` in the band), sorted by `i0`.
    pub(crate) fn row(&self, j: u32, k: u32) -> &[(u32, u32, i8)] {
        let r = (k - self.planes.start) * self.ny + j;
        let h0 = self.hits.partition_point(|h| h.0 < r);
        &self.hits[h0..h0 + self.hits[h0..].partition_point(|h| h.0 == r)]
    }

    /// The brick rows `(bk, bj)` holding a crossing, sorted, each once.
    fn brick_rows(&self) -> Vec<(u32, u32)> {
        let mut out: Vec<(u32, u32)> =
            self.hits.iter().map(|h| ((self.planes.start + h.0 / self.ny) / BRICK, h.0 % self.ny / BRICK)).collect();
        out.dedup();
        out.par_sort_unstable();
        out.dedup();
        out
    }
}

/// A sparse solid built band of planes by band ([`BAND_PLANES`]): for each
/// band, `more(planes)` gives what else its rows need and the brick rows
/// (`(bk, bj)`) that needs; where a triangle of `tris` reaches the band or
/// `more` names rows, the band's crossings, then `row(band, more, bj, bk)`
/// for its brick rows of a crossing or of `more`, in parallel (the others
/// hold nothing). Bands and rows left once `stop` is requested are skipped.
pub(crate) fn by_bands<E: Sync>(
    tris: &[LatticeTriangle],
    dims: [u32; 3],
    stop: &Stop,
    mut more: impl FnMut(std::ops::Range<u32>) -> (E, Vec<(u32, u32)>),
    row: impl Fn(&Band, &E, u32, u32) -> BrickRow + Sync,
) -> SparseBricks {
    let nz = dims[2];
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); nz.div_ceil(BAND_PLANES) as usize];
    for (n, t) in tris.iter().enumerate() {
        // The planes within a voxel of the triangle (more than it can
        // cross; `row_crossings_in` decides exactly).
        let (lo, hi) = t.bounds();
        let first = (lo[2].div_euclid(ONE) - 1).clamp(0, nz as i64 - 1) as u32;
        let last = (hi[2].div_euclid(ONE) + 1).clamp(0, nz as i64 - 1) as u32;
        for b in first / BAND_PLANES..=last / BAND_PLANES {
            bins[b as usize].push(n as u32);
        }
    }
    let (mut bricks, mut full) = (Vec::new(), Vec::new());
    for (b, bin) in bins.iter().enumerate() {
        let planes = b as u32 * BAND_PLANES..((b as u32 + 1) * BAND_PLANES).min(nz);
        if stop.requested() {
            break;
        }
        let (data, extra) = more(planes.clone());
        if bin.is_empty() && extra.is_empty() {
            continue;
        }
        let local: Vec<LatticeTriangle> = bin.iter().map(|&n| tris[n as usize]).collect();
        let band = Band { hits: row_crossings_in(&local, dims, planes.clone()), planes, ny: dims[1] };
        drop(local);
        let mut rows = band.brick_rows();
        rows.extend(extra);
        rows.sort_unstable();
        rows.dedup();
        let built: Vec<BrickRow> =
            rows.into_par_iter().with_min_len(16).filter(|_| !stop.requested()).map(|(bk, bj)| row(&band, &data, bj, bk)).collect();
        for (b, f) in built {
            bricks.extend(b);
            full.extend(f);
        }
    }
    SparseBricks::from_sorted(dims, bricks, full)
}

/// Appends the inclusive span `[first, last]` to `out`, joined with the
/// last span when adjacent (spans come in order, disjoint).
pub(crate) fn push_span(out: &mut Vec<(u32, u32)>, first: u32, last: u32) {
    match out.last_mut() {
        Some(prev) if prev.1 + 1 == first => prev.1 = last,
        _ => out.push((first, last)),
    }
}

/// A sparse grid from its brick rows, given in `(bk, bj)` order.
pub(crate) fn from_brick_rows(dims: [u32; 3], rows: impl IntoIterator<Item = BrickRow>) -> SparseBricks {
    let (mut bricks, mut full) = (Vec::new(), Vec::new());
    for (b, f) in rows {
        bricks.extend(b);
        full.extend(f);
    }
    SparseBricks::from_sorted(dims, bricks, full)
}

/// The brick rows `(bk, bj)` holding the voxel rows `rows` (`k·ny + j`),
/// sorted, each once.
pub(crate) fn brick_rows_of(rows: impl Iterator<Item = u32>, dims: [u32; 3]) -> Vec<(u32, u32)> {
    let ny = dims[1];
    let mut out: Vec<(u32, u32)> = rows.map(|r| (r / ny / BRICK, r % ny / BRICK)).collect();
    out.dedup();
    out.par_sort_unstable();
    out.dedup();
    out
}

/// The bricks of brick row `(bj, bk)` from the inside spans of its 64
/// voxel rows (`spans[dk · 8 + dj]`: sorted, disjoint, inclusive, not
/// adjacent): bricks every row covers wholly form full runs; the other
/// bricks any span touches are built bit by bit.
pub(crate) fn bricks_of_spans(spans: &[Vec<(u32, u32)>; 64], dims: [u32; 3], bj: u32, bk: u32) -> BrickRow {
    let [_, ny, nz] = dims;
    let b = BRICK;
    // A row of this brick row outside the grid: no brick of it is full.
    let mut edge = bj * b + b > ny || bk * b + b > nz;
    if spans.iter().all(Vec::is_empty) {
        return (Vec::new(), Vec::new());
    }
    let touched = coalesce(spans.iter().flatten().map(|&(f, t)| (f / b, t / b)).collect());
    let mut full: Vec<(u32, u32)> = Vec::new();
    for (n, row) in spans.iter().enumerate() {
        // Bricks this row covers wholly (the last, partial brick of a row
        // ending at nx is not whole).
        let whole: Vec<(u32, u32)> =
            row.iter().filter(|&&(f, t)| f.div_ceil(b) < (t + 1) / b).map(|&(f, t)| (f.div_ceil(b), (t + 1) / b - 1)).collect();
        full = if n == 0 { whole } else { intersect(&full, &whole) };
        if full.is_empty() {
            edge = true;
        }
        if edge {
            full.clear();
            break;
        }
    }
    let mut bricks = Vec::new();
    let mut cursor = [0usize; 64];
    for (lo, hi) in subtract(&touched, &full) {
        for bi in lo..=hi {
            let (x0, x1) = (bi * b, bi * b + b - 1);
            let mut brick = [0u64; 8];
            for (n, row) in spans.iter().enumerate() {
                let c = &mut cursor[n];
                while *c < row.len() && row[*c].1 < x0 {
                    *c += 1;
                }
                let mut byte = 0u64;
                for &(f, t) in row[*c..].iter().take_while(|s| s.0 <= x1) {
                    let (a, z) = (f.max(x0) - x0, t.min(x1) - x0);
                    byte |= (0xffu64 >> (7 - (z - a))) << a;
                }
                brick[n / 8] |= byte << ((n % 8) * 8);
            }
            if brick != [0; 8] {
                bricks.push(([bi, bj, bk], brick));
            }
        }
    }
    (bricks, full.iter().map(|&(lo, hi)| ([lo, bj, bk], hi - lo + 1)).collect())
}

/// Shared sparse filler: brick rows in parallel, each from its 64 voxel
/// rows' crossings (found by binary search in the sorted crossings).
fn fill_sparse(snapped: &Snapped, dims: [u32; 3], rule: Rule, stop: &Stop) -> (SparseBricks, SolidReport) {
    // Only brick rows some ray crossing lies in can hold inside voxels (a
    // row without crossings is outside under either rule): the work and
    // memory follow the surface, not the grid's rows. Zero-area triangles
    // cross no ray (`row_crossings` skips them).
    let out = by_bands(&snapped.triangles, dims, stop, |_| ((), Vec::new()), |band, _, bj, bk| brick_row(band, dims, bj, bk, rule));
    let mut rep = inspect(snapped);
    rep.voxels = out.count();
    (out, rep)
}

/// The slow, obviously correct definition for closed meshes.
pub mod reference {
    use super::*;
    use crate::geom::perturb::segment_meets_triangle;

    /// Brute force: the exact integer winding number of every voxel centre
    /// (displaced) from the `−x` ray's signed crossings with every
    /// triangle. Serial; small grids only.
    pub fn solid(mesh: MeshRef<'_>, grid: &GridSpec) -> Result<(DenseBits, SolidReport), ClassifyError> {
        let snapped = snap_all(mesh, grid)?;
        let tris = snapped.crossing_triangles();
        let dims = grid.dims();
        let min_x = tris.iter().flat_map(|t| t.v.iter().map(|p| p[0])).min().unwrap_or(0).min(0);
        let bounds: Vec<([i64; 3], [i64; 3])> = tris.iter().map(|t| t.bounds()).collect();
        let mut bits = DenseBits::new(dims);
        let h = ONE / 2;
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let c = [i as i64 * ONE + h, j as i64 * ONE + h, k as i64 * ONE + h];
                    // The ray as a (displaced) target segment reaching past the mesh.
                    let far = [min_x - ONE, c[1], c[2]];
                    // (A triangle whose y or z range misses the ray's by a
                    // whole unit cannot meet it: skipped before the exact test.)
                    let w: i64 = tris
                        .iter()
                        .zip(&bounds)
                        .filter(|(_, (lo, hi))| (1..3).all(|a| lo[a] - 1 <= c[a] && c[a] <= hi[a] + 1))
                        .map(|(t, _)| t)
                        .filter(|t| segment_meets_triangle([far, c], t.v, true))
                        .map(|t| if t.normal()[0] > 0 { -1 } else { 1 })
                        .sum();
                    if w != 0 {
                        bits.set(i, j, k);
                    }
                }
            }
        }
        let mut rep = inspect(&snapped);
        rep.voxels = bits.count();
        Ok((bits, rep))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fill_row_spans_words() {
        let mut b = DenseBits::new([200, 1, 1]);
        for row in b.rows_mut() {
            DenseBits::fill_row(row, 3, 130);
        }
        assert_eq!(b.count(), 128);
        assert!(b.get(3, 0, 0) && b.get(130, 0, 0) && !b.get(2, 0, 0) && !b.get(131, 0, 0));
    }
}
