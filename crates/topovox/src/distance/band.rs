//! The narrow band: every voxel whose centre lies within `W·h` of the mesh,
//! with its exact distance (the definition is in [`super`]).
//!
//! **Method** (a scan conversion after S. Mauch, "A Fast Algorithm for
//! Computing the Closest Point and Distance Transform", 2000, with boxes
//! for his polyhedra). Each piece's bounding box, grown by the band's
//! radius `R = W·h`, holds every voxel centre within `R` of it. The pieces
//! are binned by the 8³ bricks those boxes touch (a brick whose centre
//! lies farther than `R` plus its half-diagonal from the piece is left
//! out), the bins sorted by brick, and each brick computed on its own, in
//! parallel: for each of its pieces, each voxel of the piece's grown box
//! whose centre is nearer to that box than the best distance so far gets
//! the exact distance to the piece, and keeps the minimum. A voxel is in
//! the band when that minimum is `< R`.
//!
//! **Cost.** About `(size of a piece + 2W)³` distance evaluations per
//! piece, so proportional to the triangle count, not the grid; memory is
//! the bins (8 bytes per piece and brick) and 4 bytes per band voxel.
//!
//! **Guarantee.** The stored value is the f64 minimum over every piece
//! within `R` of the voxel, which is the minimum over all pieces whenever
//! it is `< R`: the same value as [`super::nearest::dense`] and, within
//! rounding, [`super::reference`]. Results do not depend on the thread
//! count (each brick is computed by one thread, the minimum is exact).

use glam::DVec3;
use rayon::prelude::*;

use super::Pieces;
use crate::grid::brick::{set_in_brick, Brick};
use crate::stop::Stop;
use crate::GridSpec;

/// One brick of the band: its brick coordinates, which of its voxels are
/// in the band (the bit layout of [`Brick`]), and where its values start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BandBrick {
    /// Brick coordinates `[bi, bj, bk]`.
    pub at: [u32; 3],
    /// The voxels in the band.
    pub mask: Brick,
    /// Index of its first value in [`Band::values`].
    pub first: usize,
}

/// The narrow band of a distance field: unsigned distances (world units)
/// of the voxels nearer than `radius` to the mesh, brick by brick.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Band {
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// The band's half width in world units (`W·h`).
    pub radius: f64,
    /// Bricks holding band voxels, in order of `bk`, then `bj`, then `bi`.
    pub bricks: Vec<BandBrick>,
    /// The distances, brick by brick; within a brick in bit order (word
    /// `z`, then bit `y·8 + x`).
    pub values: Vec<f32>,
}

impl Band {
    /// Number of voxels in the band.
    pub fn count(&self) -> u64 {
        self.values.len() as u64
    }

    /// The band brick at brick coordinates `at`, if any.
    pub fn brick(&self, at: [u32; 3]) -> Option<(&BandBrick, &[f32])> {
        let key = |b: &[u32; 3]| (b[2], b[1], b[0]);
        let n = self.bricks.binary_search_by_key(&key(&at), |b| key(&b.at)).ok()?;
        Some((&self.bricks[n], self.brick_values(n)))
    }

    /// The values of the `n`-th brick.
    pub fn brick_values(&self, n: usize) -> &[f32] {
        let end = self.bricks.get(n + 1).map_or(self.values.len(), |b| b.first);
        &self.values[self.bricks[n].first..end]
    }

    /// Every voxel of a grid as a band: `values` in C order (`[i][j][k]`,
    /// as [`super::nearest::dense`] gives them), each brick's voxels in the
    /// grid stored.
    pub fn from_dense(dims: [u32; 3], radius: f64, values: &[f32]) -> Band {
        let [ny, nz] = [dims[1] as usize, dims[2] as usize];
        let nb = dims.map(|d| d.div_ceil(8));
        let mut out = Band { dims, radius, bricks: Vec::new(), values: Vec::with_capacity(values.len()) };
        for bk in 0..nb[2] {
            for bj in 0..nb[1] {
                for bi in 0..nb[0] {
                    let mut mask: Brick = [0; 8];
                    let first = out.values.len();
                    for k in bk * 8..(bk * 8 + 8).min(dims[2]) {
                        for j in bj * 8..(bj * 8 + 8).min(dims[1]) {
                            for i in bi * 8..(bi * 8 + 8).min(dims[0]) {
                                set_in_brick(&mut mask, i, j, k);
                                out.values.push(values[(i as usize * ny + j as usize) * nz + k as usize]);
                            }
                        }
                    }
                    out.bricks.push(BandBrick { at: [bi, bj, bk], mask, first });
                }
            }
        }
        out
    }

    /// Calls `f(i, j, k, distance)` for every band voxel, brick by brick.
    pub fn for_each(&self, mut f: impl FnMut(u32, u32, u32, f32)) {
        for (n, b) in self.bricks.iter().enumerate() {
            let mut vals = self.brick_values(n).iter();
            for (z, &w) in b.mask.iter().enumerate() {
                let mut w = w;
                while w != 0 {
                    let bit = w.trailing_zeros();
                    w &= w - 1;
                    let v = *vals.next().expect("one value per band voxel");
                    f(b.at[0] * 8 + (bit & 7), b.at[1] * 8 + (bit >> 3), b.at[2] * 8 + z as u32, v);
                }
            }
        }
    }
}

/// Brick key in the order of `bk`, then `bj`, then `bi`.
fn key(b: [u32; 3]) -> u64 {
    (b[2] as u64) << 40 | (b[1] as u64) << 20 | b[0] as u64
}

fn unkey(k: u64) -> [u32; 3] {
    [(k & 0xf_ffff) as u32, (k >> 20 & 0xf_ffff) as u32, (k >> 40) as u32]
}

/// The voxels whose centres lie in `[lo, hi]` (world), clamped to the
/// grid, as inclusive index ranges; `None` when there are none. The box is
/// widened by a millionth of a voxel so rounding never drops a centre.
pub(crate) fn centre_range(grid: &GridSpec, lo: DVec3, hi: DVec3) -> Option<([u32; 3], [u32; 3])> {
    let (a, b) = (grid.to_grid_units(lo) - 0.5 - 1e-6, grid.to_grid_units(hi) - 0.5 + 1e-6);
    let dims = grid.dims();
    let mut out = ([0u32; 3], [0u32; 3]);
    for ax in 0..3 {
        let first = a[ax].ceil().max(0.0);
        let last = b[ax].floor().min(dims[ax] as f64 - 1.0);
        // Empty, or not a number (never for finite boxes): no voxels.
        if !matches!(first.partial_cmp(&last), Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)) {
            return None;
        }
        (out.0[ax], out.1[ax]) = (first as u32, last as u32);
    }
    Some(out)
}

/// The narrow band of `pieces` on `grid`: the voxels whose centres lie
/// nearer than `width` voxels (`width · h` in world units, `h` the largest
/// voxel edge, so a box grid's band is at least `width` voxels deep along
/// every axis) to the mesh. `None` when `stop` was requested.
///
/// A band that covers the whole grid is computed as the dense field
/// ([`super::nearest::dense`], the same values): brick by brick it would
/// evaluate every piece's grown box, many times the grid (issue 54: band 3
/// on a 16×1×13 grid took 21.6 s where the dense field took 0.7 s).
pub fn band(pieces: &Pieces, grid: &GridSpec, width: f64, stop: &Stop) -> Option<Band> {
    let radius = width * grid.voxel_size().0.max_element();
    if covers_grid(pieces, grid, radius) {
        return super::nearest::dense(pieces, grid, stop).map(|d| Band::from_dense(grid.dims(), radius, &d));
    }
    by_bricks(pieces, grid, radius, stop)
}

/// True when every voxel centre of `grid` lies nearer than `radius` to the
/// mesh: nearer than that to one of its corners (the farthest centre from a
/// point is a corner of the centres' box), with a margin for rounding.
pub(crate) fn covers_grid(pieces: &Pieces, grid: &GridSpec, radius: f64) -> bool {
    let Some(p) = pieces.items.first().map(|piece| piece.p[0]) else { return false };
    let [lo, hi] = [grid.voxel_center([0; 3]), grid.voxel_center(grid.dims().map(|d| d - 1))];
    let far = (lo - p).abs().max((hi - p).abs());
    far.length() < radius * (1.0 - 1e-9)
}

/// [`band`] brick by brick, whatever the grid.
pub(crate) fn by_bricks(pieces: &Pieces, grid: &GridSpec, radius: f64, stop: &Stop) -> Option<Band> {
    let bins = bin(pieces, grid, radius);
    if stop.requested() {
        return None;
    }
    let groups: Vec<(u64, std::ops::Range<usize>)> = runs(&bins);
    let mut out = Band { dims: grid.dims(), radius, ..Default::default() };
    // A few thousand bricks at a time: their values are held twice (each
    // brick's, then the band's) only that long.
    for chunk in groups.chunks(1 << 13) {
        let bricks: Vec<Option<(Brick, Vec<f32>)>> = chunk
            .par_iter()
            .map(|(k, r)| {
                if stop.requested() {
                    return None;
                }
                let ids = bins[r.clone()].iter().map(|&(_, p)| p as usize);
                Some(brick(pieces, ids, grid, unkey(*k), radius))
            })
            .collect();
        for ((k, _), b) in chunk.iter().zip(bricks) {
            let (mask, vals) = b?;
            if !vals.is_empty() {
                out.bricks.push(BandBrick { at: unkey(*k), mask, first: out.values.len() });
                out.values.extend_from_slice(&vals);
            }
        }
    }
    (!stop.requested()).then_some(out)
}

/// `(brick key, piece)` for every brick a piece's grown box reaches that
/// can hold a centre within `radius` of it, sorted.
fn bin(pieces: &Pieces, grid: &GridSpec, radius: f64) -> Vec<(u64, u32)> {
    let h = grid.voxel_size().0;
    // A brick's centres lie within this of the brick's centre.
    let half_diagonal = 3.5 * h.length();
    let mut bins: Vec<(u64, u32)> = pieces
        .items
        .par_iter()
        .enumerate()
        .with_min_len(256)
        .flat_map_iter(|(n, p)| {
            let mut out = Vec::new();
            if let Some((lo, hi)) = centre_range(grid, p.lo - radius, p.hi + radius) {
                let (blo, bhi) = (lo.map(|c| c / 8), hi.map(|c| c / 8));
                let reach = radius + half_diagonal;
                for bk in blo[2]..=bhi[2] {
                    for bj in blo[1]..=bhi[1] {
                        for bi in blo[0]..=bhi[0] {
                            let c = grid.voxel_min([bi * 8, bj * 8, bk * 8]) + 4.0 * h;
                            if p.distance_squared(c) <= reach * reach * (1.0 + 1e-9) {
                                out.push((key([bi, bj, bk]), n as u32));
                            }
                        }
                    }
                }
            }
            out
        })
        .collect();
    bins.par_sort_unstable();
    bins
}

/// Ranges of equal keys in sorted `(key, _)` pairs.
fn runs(bins: &[(u64, u32)]) -> Vec<(u64, std::ops::Range<usize>)> {
    let mut out = Vec::new();
    let mut start = 0;
    for n in 1..=bins.len() {
        if n == bins.len() || bins[n].0 != bins[start].0 {
            out.push((bins[start].0, start..n));
            start = n;
        }
    }
    out
}

/// One brick: the minimum distance of each voxel over `ids`, and the
/// voxels below `radius` with their values in bit order.
fn brick(pieces: &Pieces, ids: impl Iterator<Item = usize>, grid: &GridSpec, at: [u32; 3], radius: f64) -> (Brick, Vec<f32>) {
    let r2 = radius * radius;
    let mut best = [r2; 512];
    let origin = at.map(|c| c * 8);
    let dims = grid.dims();
    let size: [usize; 3] = std::array::from_fn(|a| (dims[a] - origin[a]).min(8) as usize);
    // The centres' coordinates, as `GridSpec::voxel_center` computes them.
    let (o, h) = (grid.origin(), grid.voxel_size().0);
    let axis = |a: usize| -> [f64; 8] { std::array::from_fn(|x| o[a] + (origin[a] + x as u32) as f64 * h[a] + 0.5 * h[a]) };
    let (xs, ys, zs) = (axis(0), axis(1), axis(2));
    // Nearest pieces first: their distances make the box test below turn
    // most farther pieces away before any exact distance is computed.
    let centre = grid.voxel_min(origin) + 4.0 * h;
    let mut ids: Vec<(f64, usize)> = ids.map(|n| (pieces.items[n].distance_squared(centre), n)).collect();
    ids.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let gap = |lo: f64, hi: f64, c: f64| {
        let d = (lo - c).max(c - hi).max(0.0);
        d * d
    };
    for (_, n) in ids {
        let p = &pieces.items[n];
        // The brick's part of the piece's box grown by the radius.
        let Some((lo, hi)) = centre_range(grid, p.lo - radius, p.hi + radius) else { continue };
        let span = |a: usize| {
            let first = lo[a].saturating_sub(origin[a]) as usize;
            let end = ((hi[a] + 1).saturating_sub(origin[a]) as usize).min(size[a]);
            first..end.max(first)
        };
        let (sx, sy, sz) = (span(0), span(1), span(2));
        for z in sz {
            let cz = zs[z];
            let dz = gap(p.lo.z, p.hi.z, cz);
            if dz >= r2 {
                continue;
            }
            for y in sy.clone() {
                let cy = ys[y];
                let dyz = dz + gap(p.lo.y, p.hi.y, cy);
                if dyz >= r2 {
                    continue;
                }
                for x in sx.clone() {
                    let cx = xs[x];
                    let slot = z * 64 + y * 8 + x;
                    // The box's distance: a lower bound of the piece's.
                    if dyz + gap(p.lo.x, p.hi.x, cx) >= best[slot] {
                        continue;
                    }
                    best[slot] = best[slot].min(p.distance_squared(DVec3::new(cx, cy, cz)));
                }
            }
        }
    }
    let mut mask: Brick = [0; 8];
    let mut vals = Vec::new();
    for (slot, &d2) in best.iter().enumerate() {
        if d2 < r2 {
            let s = slot as u32;
            set_in_brick(&mut mask, s & 7, s >> 3 & 7, s >> 6);
            vals.push(d2.sqrt() as f32);
        }
    }
    (mask, vals)
}
