//! Certifying a voxel set's topology: components, separation, thinness and
//! tunnels (what `voxkit check` reports).
//!
//! Definitions (Laine 2013 §2; Cohen-Or & Kaufman 1995):
//! - A set `V` is *N-separating* for a closed surface iff no N-connected
//!   path of voxels outside `V` joins a voxel whose centre is inside to one
//!   whose centre is outside. Any such path has a step between two
//!   N-adjacent unset voxels of different class, so `V` is N-separating iff
//!   no such pair exists; the first pair found is the witness. Paths stay in
//!   the grid.
//! - *Thin removable*: set voxels whose removal alone keeps the set
//!   6-separating — those whose unset 6-neighbours all share their class.
//! - A *6-tunnel* (18-, 26-tunnel) is a segment joining the centres of two
//!   6-adjacent (18-, 26-adjacent) unset voxels that meets the surface; a set is
//!   tunnel-free iff there is none. This needs no closed surface.
//! - *Thick voxels*: set voxels with a set neighbour along each of the three
//!   axes (zero for a voxelization that is one voxel thin along some axis
//!   everywhere).
//! - *Columns along the dominant axis* (with the mesh): for every triangle
//!   and every pixel of its dominant-axis projection whose centre it
//!   covers, the run of set voxels along that axis through the voxel where
//!   the surface crosses the column (0 if that voxel is unset). Laine's
//!   thinness is "every run is 1".
//!
//! Inside/outside comes from [`super::inside`]; all tests are exact.

use rayon::prelude::*;

use super::inside::{snap_all, ClassifyError, Parity};
use super::runs::{components, Connectivity, Runs};
use crate::geom::fixed::ONE;
use crate::geom::lattice::LatticeTriangle;
use crate::grid::dense::DenseBits;
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;
use crate::voxelize::targets::{fits_i64, TriSetup};

/// Everything `voxkit check` reports.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckReport {
    /// Set voxels.
    pub voxels: u64,
    /// 6-connected components of the set voxels.
    pub components_6: usize,
    /// 26-connected components of the set voxels.
    pub components_26: usize,
    /// Set voxels with set neighbours along all three axes.
    pub thick_voxels: u64,
    /// What needs the source mesh.
    pub mesh: Option<MeshFacts>,
}

/// The checks against the source surface.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshFacts {
    /// Edges (keyed by snapped end points) used by an odd number of triangles.
    pub boundary_edges: usize,
    /// The mesh has triangles and no boundary edges.
    pub closed: bool,
    /// Segments between centres of 6-adjacent unset voxels that meet the surface.
    pub tunnels_6: u64,
    /// Segments between centres of 18-adjacent (face or edge) unset voxels that meet the surface.
    pub tunnels_18: u64,
    /// Segments between centres of 26-adjacent unset voxels that meet the surface.
    pub tunnels_26: u64,
    /// Runs along each triangle's dominant axis where it crosses a column.
    pub columns: ColumnStats,
    /// Separation, only for a closed surface.
    pub separation: Option<Separation>,
}

/// Histogram of the runs of set voxels along each triangle's dominant axis,
/// sampled at the columns whose centre the triangle covers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ColumnStats {
    /// Columns sampled (a column covered by two triangles counts twice).
    pub samples: u64,
    /// The crossing voxel is unset: a hole.
    pub empty: u64,
    /// Runs of exactly one voxel (thin).
    pub one: u64,
    /// Runs of two voxels.
    pub two: u64,
    /// Runs of three or more.
    pub more: u64,
    /// The longest run.
    pub max: u64,
}

impl ColumnStats {
    fn add(mut self, o: ColumnStats) -> ColumnStats {
        self.samples += o.samples;
        self.empty += o.empty;
        self.one += o.one;
        self.two += o.two;
        self.more += o.more;
        self.max = self.max.max(o.max);
        self
    }
}

/// Separation facts for a closed surface.
#[derive(Clone, Debug, PartialEq)]
pub struct Separation {
    /// Voxels (set or not) whose centre is inside.
    pub inside_voxels: u64,
    /// `None` if 6-separating, else an inside and an outside voxel, both
    /// unset and 6-adjacent.
    pub witness_6: Option<[[u32; 3]; 2]>,
    /// The same for 26-adjacency.
    pub witness_26: Option<[[u32; 3]; 2]>,
    /// Set voxels removable one at a time keeping 6-separation.
    pub thin_removable: u64,
}

/// Checks `bits`; with `mesh` (on `grid`), also separation and tunnels.
pub fn certify(bits: &DenseBits, mesh: Option<(MeshRef<'_>, &GridSpec)>) -> Result<CheckReport, ClassifyError> {
    let set_runs = Runs::of(bits, true);
    let (_, components_6) = components(&set_runs, Connectivity::Six);
    let (_, components_26) = components(&set_runs, Connectivity::TwentySix);
    let mut report = CheckReport { voxels: bits.count(), components_6, components_26, thick_voxels: thick_voxels(bits), mesh: None };
    if let Some((mesh, grid)) = mesh {
        let snapped = snap_all(mesh, grid)?;
        let tris = snapped.crossing_triangles();
        let closed = snapped.boundary_edges == 0 && !tris.is_empty();
        let separation = closed.then(|| {
            let parity = Parity::classify(&tris, bits.dims());
            Separation {
                inside_voxels: inside_count(&parity, bits.dims()),
                witness_6: witness(bits, &parity, Connectivity::Six),
                witness_26: witness(bits, &parity, Connectivity::TwentySix),
                thin_removable: thin_removable(bits, &parity),
            }
        });
        let tunnels = tunnels(bits, &tris);
        report.mesh = Some(MeshFacts {
            boundary_edges: snapped.boundary_edges,
            closed,
            tunnels_6: tunnels[0],
            tunnels_18: tunnels[1],
            tunnels_26: tunnels[2],
            columns: columns(bits, &tris),
            separation,
        });
    }
    Ok(report)
}

/// Neighbour offsets `(di, dj, dk)`, each unordered pair once.
fn forward_offsets(conn: Connectivity) -> Vec<[i64; 3]> {
    let mut out = Vec::new();
    for dk in -1..=1i64 {
        for dj in -1..=1i64 {
            for di in -1..=1i64 {
                let n = di.abs() + dj.abs() + dk.abs();
                let forward = (dk, dj, di) > (0, 0, 0);
                if forward && (conn == Connectivity::TwentySix || n == 1) {
                    out.push([di, dj, dk]);
                }
            }
        }
    }
    out
}

/// The forward neighbour offsets with `|di| + |dj| + |dk| <= order`.
fn forward_offsets_upto(order: i64) -> Vec<[i64; 3]> {
    let mut out = Vec::new();
    for dk in -1..=1i64 {
        for dj in -1..=1i64 {
            for di in -1..=1i64 {
                let n = di.abs() + dj.abs() + dk.abs();
                if (dk, dj, di) > (0, 0, 0) && n <= order {
                    out.push([di, dj, dk]);
                }
            }
        }
    }
    out
}

fn inside_count(p: &Parity, dims: [u32; 3]) -> u64 {
    (0..dims[2])
        .into_par_iter()
        .map(|k| {
            (0..dims[1])
                .map(|j| {
                    let t = p.row(j, k);
                    let mut n = 0u64;
                    for c in t.chunks(2) {
                        n += (*c.get(1).unwrap_or(&dims[0]) - c[0]) as u64;
                    }
                    n
                })
                .sum::<u64>()
        })
        .sum()
}

/// The first (in `k`, `j`, `i` order) pair of adjacent unset voxels of
/// different class, as `[inside, outside]`.
fn witness(bits: &DenseBits, p: &Parity, conn: Connectivity) -> Option<[[u32; 3]; 2]> {
    let [nx, ny, nz] = bits.dims();
    let offsets = forward_offsets(conn);
    (0..nz).into_par_iter().find_map_first(|k| {
        for j in 0..ny {
            for d in &offsets {
                let (jj, kk) = (j as i64 + d[1], k as i64 + d[2]);
                if jj < 0 || jj >= ny as i64 || kk >= nz as i64 {
                    continue;
                }
                let (jj, kk) = (jj as u32, kk as u32);
                // The class differs only on intervals bounded by toggles of
                // either row (the second shifted by −di).
                let (tr, tq) = (p.row(j, k), p.row(jj, kk));
                let mut cuts: Vec<i64> = tr.iter().map(|&t| t as i64).chain(tq.iter().map(|&t| t as i64 - d[0])).collect();
                cuts.push(0);
                cuts.push(nx as i64);
                cuts.sort_unstable();
                cuts.dedup();
                for w in cuts.windows(2) {
                    let (a, b) = (w[0].max(0).max(-d[0]), w[1].min(nx as i64).min(nx as i64 - d[0]));
                    if a >= b {
                        continue;
                    }
                    let (ir, iq) = (a as u32, (a + d[0]) as u32);
                    let (cr, cq) = (p.inside(ir, j, k), p.inside(iq, jj, kk));
                    if cr == cq {
                        continue;
                    }
                    for i in a..b {
                        let (ir, iq) = (i as u32, (i + d[0]) as u32);
                        if !bits.get(ir, j, k) && !bits.get(iq, jj, kk) {
                            let (u, v) = ([ir, j, k], [iq, jj, kk]);
                            return Some(if cr { [u, v] } else { [v, u] });
                        }
                    }
                }
            }
        }
        None
    })
}

/// Calls `f(i)` for every set voxel of row `(j, k)`.
#[inline]
fn for_each_set_in_row(bits: &DenseBits, j: u32, k: u32, mut f: impl FnMut(u32)) {
    let wpr = bits.words_per_row();
    let row = (k as usize * bits.dims()[1] as usize + j as usize) * wpr;
    for (wi, &w) in bits.words()[row..row + wpr].iter().enumerate() {
        let mut w = w;
        while w != 0 {
            let b = w.trailing_zeros();
            f(wi as u32 * 64 + b);
            w &= w - 1;
        }
    }
}

/// Sums `f` over every set voxel, in parallel over `k`.
fn sum_over_set(bits: &DenseBits, f: impl Fn(u32, u32, u32) -> bool + Sync) -> u64 {
    let [_, ny, nz] = bits.dims();
    (0..nz)
        .into_par_iter()
        .map(|k| {
            let mut n = 0u64;
            for j in 0..ny {
                for_each_set_in_row(bits, j, k, |i| n += f(i, j, k) as u64);
            }
            n
        })
        .sum()
}

fn thin_removable(bits: &DenseBits, p: &Parity) -> u64 {
    let [nx, ny, nz] = bits.dims();
    let six: Vec<[i64; 3]> = forward_offsets(Connectivity::Six).iter().flat_map(|d| [*d, d.map(|x| -x)]).collect();
    sum_over_set(bits, |i, j, k| {
        let c = p.inside(i, j, k);
        six.iter().all(|d| {
            let q = [i as i64 + d[0], j as i64 + d[1], k as i64 + d[2]];
            if q.iter().zip([nx, ny, nz]).any(|(&x, n)| x < 0 || x >= n as i64) {
                return true;
            }
            let q = q.map(|x| x as u32);
            bits.get(q[0], q[1], q[2]) || p.inside(q[0], q[1], q[2]) == c
        })
    })
}

fn thick_voxels(bits: &DenseBits) -> u64 {
    let get = |i, j, k| bits.get_signed(i, j, k);
    sum_over_set(bits, |i, j, k| {
        let (i, j, k) = (i as i64, j as i64, k as i64);
        (get(i - 1, j, k) || get(i + 1, j, k)) && (get(i, j - 1, k) || get(i, j + 1, k)) && (get(i, j, k - 1) || get(i, j, k + 1))
    })
}

fn columns(bits: &DenseBits, tris: &[LatticeTriangle]) -> ColumnStats {
    tris.par_chunks(256)
        .map(|chunk| {
            let mut st = ColumnStats::default();
            for t in chunk {
                if fits_i64(t) {
                    columns_of::<i64>(bits, t, &mut st);
                } else {
                    columns_of::<i128>(bits, t, &mut st);
                }
            }
            st
        })
        .reduce(ColumnStats::default, ColumnStats::add)
}

fn columns_of<T: crate::geom::fixed::PlaneInt>(bits: &DenseBits, t: &LatticeTriangle, st: &mut ColumnStats) {
    let dims = bits.dims();
    let Some((lo, hi)) = t.voxel_bounds(dims) else { return };
    let (u, v, w) = crate::voxelize::targets::dominant_axes(t);
    let s = TriSetup::<T>::new(t);
    let mut d = [0i64; 3];
    d[w] = ONE;
    let dw = s.dir(t, d);
    let n = t.normal();
    let h = ONE / 2;
    let at = |ijk: [i64; 3]| bits.get(ijk[0] as u32, ijk[1] as u32, ijk[2] as u32);
    for iv in lo[v]..=hi[v] {
        for iu in lo[u]..=hi[u] {
            let mut c = s.a;
            (c[u], c[v]) = (iu * ONE + h, iv * ONE + h);
            let pc = s.local(c);
            let o = s.line_values(&dw, pc);
            let inside = [0, 1, 2].map(|i| o[i] >= dw.be[i]);
            if !(inside[0] == inside[1] && inside[1] == inside[2]) {
                continue;
            }
            let v0 = T::from_i64(n[u]) * pc[u] + T::from_i64(n[v]) * pc[v];
            let tw = s.column_voxel(w, T::from_i64(n[w]), v0).to_i128();
            if tw < 0 || tw >= dims[w] as i128 {
                continue;
            }
            let mut ijk = [0i64; 3];
            (ijk[u], ijk[v], ijk[w]) = (iu, iv, tw as i64);
            st.samples += 1;
            if !at(ijk) {
                st.empty += 1;
                continue;
            }
            let mut run = 1u64;
            for step in [-1i64, 1] {
                let mut q = ijk;
                loop {
                    q[w] += step;
                    if q[w] < 0 || q[w] >= dims[w] as i64 || !at(q) {
                        break;
                    }
                    run += 1;
                }
            }
            match run {
                1 => st.one += 1,
                2 => st.two += 1,
                _ => st.more += 1,
            }
            st.max = st.max.max(run);
        }
    }
}

/// Distinct segments between centres of adjacent unset voxels that meet a
/// triangle (the segments displaced like every target), counted for
/// 6-, 18- and 26-adjacency (neighbours with `|di| + |dj| + |dk|` at most
/// 1, 2 and 3): one pass over the 26-neighbour segments, each found
/// segment counted for every adjacency that contains it.
fn tunnels(bits: &DenseBits, tris: &[LatticeTriangle]) -> [u64; 3] {
    let dims = bits.dims();
    let offsets = forward_offsets_upto(3);
    let mut found: Vec<(u64, u8)> = tris
        .par_chunks(256)
        .flat_map_iter(|chunk| {
            let mut out = Vec::new();
            for t in chunk {
                if fits_i64(t) {
                    tunnels_of::<i64>(bits, t, &offsets, dims, &mut out);
                } else {
                    tunnels_of::<i128>(bits, t, &offsets, dims, &mut out);
                }
            }
            out
        })
        .collect();
    found.par_sort_unstable();
    found.dedup();
    let mut counts = [0u64; 3];
    for &(_, di) in &found {
        let order = offsets[di as usize].iter().map(|x| x.abs()).sum::<i64>() as usize;
        for c in &mut counts[order - 1..] {
            *c += 1;
        }
    }
    counts
}

fn tunnels_of<T: crate::geom::fixed::PlaneInt>(
    bits: &DenseBits,
    t: &LatticeTriangle,
    offsets: &[[i64; 3]],
    dims: [u32; 3],
    out: &mut Vec<(u64, u8)>,
) {
    let (lo, hi) = t.bounds();
    let s = TriSetup::<T>::new(t);
    let h = ONE / 2;
    // Per offset d: the voxels v whose segment [centre(v), centre(v) + d]
    // has a bounding box meeting the triangle's, and the segment's setup.
    let mut boxes = Vec::with_capacity(offsets.len());
    let (mut all_lo, mut all_hi) = ([i64::MAX; 3], [i64::MIN; 3]);
    for d in offsets {
        let mut r = [(0i64, 0i64); 3];
        for a in 0..3 {
            let (smin, smax) = (d[a].min(0) * ONE, d[a].max(0) * ONE);
            // centre = v·ONE + h; need centre + smin <= hi and centre + smax >= lo.
            let first = (lo[a] - smax - h + ONE - 1).div_euclid(ONE).max(0).max(-d[a]);
            let last = (hi[a] - smin - h).div_euclid(ONE).min(dims[a] as i64 - 1).min(dims[a] as i64 - 1 - d[a]);
            r[a] = (first, last);
        }
        if (0..3).any(|a| r[a].0 > r[a].1) {
            boxes.push(None);
            continue;
        }
        for a in 0..3 {
            all_lo[a] = all_lo[a].min(r[a].0);
            all_hi[a] = all_hi[a].max(r[a].1);
        }
        boxes.push(Some((r, s.dir(t, d.map(|x| x * ONE)))));
    }
    if all_lo[0] > all_hi[0] {
        return;
    }
    // A segment from a centre with plane value vp crosses the plane iff
    // vp and vp + n·d fall on different sides of bn: only centres with vp
    // in [bn − max n·d, bn − min n·d) can start one.
    let (mut nd_lo, mut nd_hi) = (T::ZERO, T::ZERO);
    for (_, ds) in boxes.iter().flatten() {
        if ds.nd < nd_lo {
            nd_lo = ds.nd;
        }
        if ds.nd > nd_hi {
            nd_hi = ds.nd;
        }
    }
    let (vp_lo, vp_hi) = (s.bn - nd_hi, s.bn - nd_lo);
    for k in all_lo[2]..=all_hi[2] {
        for j in all_lo[1]..=all_hi[1] {
            for i in all_lo[0]..=all_hi[0] {
                let pc = s.local([i * ONE + h, j * ONE + h, k * ONE + h]);
                let vp = s.plane(pc);
                if vp < vp_lo || vp >= vp_hi || bits.get(i as u32, j as u32, k as u32) {
                    continue;
                }
                for (di, (d, b)) in offsets.iter().zip(&boxes).enumerate() {
                    let Some((r, ds)) = b else { continue };
                    if i < r[0].0 || i > r[0].1 || j < r[1].0 || j > r[1].1 || k < r[2].0 || k > r[2].1 {
                        continue;
                    }
                    if bits.get((i + d[0]) as u32, (j + d[1]) as u32, (k + d[2]) as u32) {
                        continue;
                    }
                    if s.segment_hits_with(ds, pc, vp) {
                        let idx = (k as u64 * dims[1] as u64 + j as u64) * dims[0] as u64 + i as u64;
                        out.push((idx, di as u8));
                    }
                }
            }
        }
    }
}
