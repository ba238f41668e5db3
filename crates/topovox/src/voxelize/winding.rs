//! Solid voxelization of imperfect meshes by the generalized winding number.
//!
//! This work is based on: A. Jacobson, L. Kavan, O. Sorkine-Hornung,
//! "Robust Inside-Outside Segmentation using Generalized Winding Numbers",
//! ACM TOG 32(4), 2013 (the winding number as a sum of signed solid angles,
//! thresholded at 1/2); far caps are bounded in the spirit of G. Barill et
//! al., "Fast Winding Numbers for Soups and Clouds", ACM TOG 37(4), 2018.
//!
//! **Definition.** Voxel `(i,j,k)` is set iff `|w(c)| >= 1/2` at its centre
//! `c`, with `w(q) = Σ_T Ω_T(q) / 4π` over the snapped triangles
//! (Van Oosterom–Strackee solid angles), measured in the world's shape (on
//! a grid of boxes, lattice coordinates scaled by the voxel's edges: solid
//! angles are not kept by stretching). Right for holes, open boundaries,
//! nested or overlapping shells and inconsistent orientation; for a
//! watertight mesh it is the integer winding number.
//!
//! **How, exactly where it can be.** The mesh's oriented boundary (the
//! edges not cancelled by an opposite use) is split into cycles, and each
//! cycle is closed by a fan of *cap* triangles. Mesh + caps has no
//! boundary, so its winding number is an exact integer `J`: the signed
//! crossings of each voxel's `−x` ray, computed with the exact,
//! perturbation-decided row crossings of [`super::solid`]. Then
//! `w = J − w_caps`. Far from every cap, `|w_caps| < 1/2` is guaranteed by
//! a bound (`area / 4π d²` per cap cycle, over blocks of 64³ voxels halved
//! as needed), so the
//! voxel is inside iff `J ≠ 0`: no solid angles at all. Only voxels of
//! blocks near a cap sum the caps' solid angles (cycles whose bound is
//! below 10⁻³ are neglected; the error is below 10⁻² in `w`). Blocks are
//! settled by `w_cap` at their centre plus a Lipschitz bound from the cap's
//! boundary cycle (Biot–Savart: off the cap, `∇w_cap` depends only on the
//! cycle), so only a thin layer of voxels along each cap is evaluated; a
//! cap's solid angle is summed with one `atan2` (a running complex product
//! that counts its turns). A centre
//! exactly on a cap takes the side given by the exact perturbed
//! orientation, like `J`. For a watertight mesh there are no caps and the
//! result equals [`super::solid::winding_closed`].
//!
//! **Reference:** [`reference::winding`], the direct sum over all triangles
//! for every voxel centre (small grids).

use glam::DVec3;
use rayon::prelude::*;

use super::solid::{brick_rows_of, bricks_of_spans, by_bands, push_span, SolidReport, BAND_PLANES};
use super::Stop;
use crate::geom::fixed::ONE;
use crate::geom::lattice::LatticeTriangle;
use crate::geom::perturb::P3;
use crate::grid::bricks::BRICK;
use crate::grid::dense::DenseBits;
use crate::grid::sparse::SparseBricks;
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;
use crate::topology::cycles::{boundary_cycles, triangulate};
use crate::topology::inside::{row_crossings, snap_all, ClassifyError, Snapped};

/// What the winding-number solid did beyond [`SolidReport`].
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WindingReport {
    /// Closedness facts and the voxel count.
    pub solid: SolidReport,
    /// Boundary cycles closed by caps.
    pub cycles: u64,
    /// Cap triangles added.
    pub cap_triangles: u64,
    /// Voxels whose decision needed the caps' solid angles.
    pub evaluated: u64,
    /// Voxels whose winding number came within its error bound (the
    /// neglected far caps, rounding) of a half-integer: the only voxels off
    /// the surface whose decision a nearby mesh (such as the mesh before
    /// snapping) can change; the job decides them again exactly.
    pub near_half: Vec<[u32; 3]>,
}

/// Edge (voxels) of the blocks the far-field refinement starts from (a
/// power of two: blocks halve down to single voxels).
const TOP: u32 = 64;
/// The edge of the pieces [`Plan::needed_in`] hands to the threads.
const PIECE: u32 = 16;
/// Cycles whose bound at a voxel is below this are neglected there.
const NEGLECT: f64 = 1e-3;

/// Solid angle of triangle `t` (lattice) seen from lattice point `q`,
/// divided by 4π: the triangle's contribution to the winding number. A
/// point in the triangle's plane takes the limit from its displaced copy
/// ([`crate::geom::solid_angle::solid_angle`], whose exact predicates the lattice
/// coordinates, exact in f64, feed).
pub fn winding_of(t: &[P3; 3], q: P3, scale: DVec3) -> f64 {
    let f = |p: P3| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
    crate::geom::solid_angle::solid_angle_in(&t.map(f), f(q), scale) / (4.0 * std::f64::consts::PI)
}

/// A boundary cycle's cap: triangles over the cycle's vertices and a
/// bounding sphere (voxel units).
struct Cap {
    tris: Vec<[P3; 3]>,
    /// The cycle's vertices (lattice), reversed against the boundary.
    verts: Vec<P3>,
    /// Per triangle: indices into `verts`.
    index: Vec<[u32; 3]>,
    /// `verts` in voxel units.
    verts_f: Vec<DVec3>,
    /// Per triangle: vertices and area (voxel units).
    float: Vec<([DVec3; 3], f64)>,
    /// Per triangle: a bounding sphere (centroid, radius), voxel units.
    spheres: Vec<(DVec3, f64)>,
    centre: DVec3,
    radius: f64,
    area: f64,
    /// Lattice differences times this have the world's shape
    /// ([`Snapped::scale`]); every float here is in that metric.
    scale: DVec3,
}

impl Cap {
    /// `w` of the cap at lattice point `q`: the sum of its triangles' solid
    /// angles / 4π, each `2·atan2(det, denom)` (Van Oosterom–Strackee),
    /// summed with one `atan2`: the arguments of `denom + i·det` add under
    /// complex multiplication, and the turns the running product makes
    /// around the origin are counted from the signs of its imaginary part
    /// (a factor off the real axis moves the argument by less than π, so a
    /// wrap shows as the product crossing the negative real axis). Triangles
    /// whose plane (numerically) holds `q` take [`winding_of`]'s exact side.
    fn winding(&self, q: P3, scratch: &mut Vec<(DVec3, f64)>) -> f64 {
        let s = ONE as f64;
        scratch.clear();
        scratch.extend(self.verts.iter().map(|p| {
            let r = DVec3::new((p[0] - q[0]) as f64 / s, (p[1] - q[1]) as f64 / s, (p[2] - q[2]) as f64 / s) * self.scale;
            (r, r.length())
        }));
        // Two running products (even and odd triangles) so that the
        // multiplications do not wait on each other.
        let mut acc = [Product::default(); 2];
        let mut aside = 0.0;
        for (n, (t, ix)) in self.tris.iter().zip(&self.index).enumerate() {
            let (a, la) = scratch[ix[0] as usize];
            let (b, lb) = scratch[ix[1] as usize];
            let (c, lc) = scratch[ix[2] as usize];
            let l3 = la * lb * lc;
            let det = a.dot(b.cross(c));
            if det.abs() <= 1e-12 * l3 {
                aside += winding_of(t, q, self.scale);
                continue;
            }
            let denom = l3 + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            // Divided by l³: the factor's size lies in [10⁻¹², 4].
            let inv = 1.0 / l3;
            acc[n & 1].mul(denom * inv, det * inv);
            if n % 16 == 15 {
                acc.iter_mut().for_each(Product::rescale);
            }
        }
        acc[0].turns() + acc[1].turns() + aside
    }

    /// Bound on the gradient of `w_cap` over a ball of radius `rho` around
    /// `q`, infinite when the ball meets the cap (where `w_cap` jumps by 1).
    /// Off the cap, `∇w_cap` is the Biot–Savart integral over the cap's
    /// boundary cycle, `(1/4π) ∮ (l − q) × dl / |l − q|³`, so it is at most
    /// `Σ |edge| / (4π d²)`, `d` the distance from the ball to the edge:
    /// it depends on the cycle, not on how near the (smooth) cap is.
    fn lipschitz(&self, q: DVec3, rho: f64) -> f64 {
        for ((t, _), &(c, r)) in self.float.iter().zip(&self.spheres) {
            let reach = r + rho;
            if q.distance_squared(c) <= reach * reach && point_triangle_distance(q, t) <= rho {
                return f64::INFINITY;
            }
        }
        let n = self.verts_f.len();
        let mut l = 0.0;
        for e in 0..n {
            let (a, b) = (self.verts_f[e], self.verts_f[(e + 1) % n]);
            let d = point_segment_distance(q, a, b) - rho;
            if d <= 0.0 {
                return f64::INFINITY;
            }
            l += a.distance(b) / (4.0 * std::f64::consts::PI * d * d);
        }
        l
    }
}

/// A product of complex numbers `denom + i·det` kept as its value and the
/// whole turns its argument made: the sum of the factors' arguments is
/// `arg(value) + 2π·turns`.
#[derive(Clone, Copy)]
struct Product {
    re: f64,
    im: f64,
    turns: i64,
}

impl Default for Product {
    fn default() -> Self {
        Product { re: 1.0, im: 0.0, turns: 0 }
    }
}

impl Product {
    /// Multiplies by `re + i·im` (`im ≠ 0`: the factor's argument lies in
    /// (−π, 0) ∪ (0, π), so the sum leaves (−π, π] by at most one turn, and
    /// it does exactly when the product crosses the negative real axis).
    #[inline]
    fn mul(&mut self, re: f64, im: f64) {
        let (pr, pi) = (self.re * re - self.im * im, self.re * im + self.im * re);
        if im > 0.0 {
            if self.im >= 0.0 && pi < 0.0 {
                self.turns += 1;
            }
        } else if self.im < 0.0 && pi >= 0.0 {
            self.turns -= 1;
        }
        // (+0.0 makes a zero imaginary part positive: argument π, not −π.)
        (self.re, self.im) = (pr, pi + 0.0);
    }

    /// Keeps the value away from overflow and underflow (a positive scale
    /// leaves the argument alone). Sixteen factors of sizes in
    /// `[10⁻¹², 4]` stay in range between calls.
    fn rescale(&mut self) {
        let m = self.re.abs().max(self.im.abs());
        if !(1e-60..=1e60).contains(&m) {
            (self.re, self.im) = (self.re / m, self.im / m);
        }
    }

    /// The sum of the factors' arguments over 2π.
    fn turns(&self) -> f64 {
        self.im.atan2(self.re) / std::f64::consts::TAU + self.turns as f64
    }
}

/// Distance from `p` to the segment `ab`.
fn point_segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 { ((p - a).dot(ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    p.distance(a + ab * t)
}

fn caps(cycles: &[Vec<P3>], scale: DVec3) -> Vec<Cap> {
    let s = ONE as f64;
    let f = |p: P3| DVec3::new(p[0] as f64 / s, p[1] as f64 / s, p[2] as f64 / s) * scale;
    cycles
        .iter()
        .filter(|c| c.len() >= 3)
        .map(|c| {
            // Reversed against the boundary, so ∂(mesh + caps) = 0; split in
            // halves recursively (rather than fanned) so that most cap
            // triangles are small and their distance bounds tight.
            let verts: Vec<P3> = c.iter().rev().copied().collect();
            let order: Vec<u32> = (0..verts.len() as u32).collect();
            let mut index = Vec::with_capacity(c.len() - 2);
            triangulate(&order, &mut index);
            let tris: Vec<[P3; 3]> = index.iter().map(|ix| ix.map(|i| verts[i as usize])).collect();
            let centre = c.iter().map(|&p| f(p)).sum::<DVec3>() / c.len() as f64;
            let radius = c.iter().map(|&p| f(p).distance(centre)).fold(0.0, f64::max);
            let float: Vec<([DVec3; 3], f64)> = tris
                .iter()
                .map(|t| {
                    let v = t.map(f);
                    (v, (v[1] - v[0]).cross(v[2] - v[0]).length() / 2.0)
                })
                .collect();
            let area = float.iter().map(|s| s.1).sum();
            let spheres = float
                .iter()
                .map(|(v, _)| {
                    let c = (v[0] + v[1] + v[2]) / 3.0;
                    (c, v.iter().map(|p| p.distance(c)).fold(0.0, f64::max))
                })
                .collect();
            let verts_f = verts.iter().map(|&p| f(p)).collect();
            Cap { tris, verts, index, verts_f, float, spheres, centre, radius, area, scale }
        })
        .collect()
}

/// Distance from `p` to the closed triangle `t` (Ericson, "Real-Time
/// Collision Detection", §5.1.5).
fn point_triangle_distance(p: DVec3, t: &[DVec3; 3]) -> f64 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return p.distance(a);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return p.distance(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return p.distance(a + ab * v);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return p.distance(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return p.distance(a + ac * w);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return p.distance(b + (c - b) * w);
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    if !(v.is_finite() && w.is_finite()) {
        // Degenerate (zero-area) triangle: the nearest of its edges' ends.
        return p.distance(a).min(p.distance(b)).min(p.distance(c));
    }
    p.distance(a + ab * v + ac * w)
}

/// Bound on `|w_cap|` over a ball of radius `rho` around `q`.
fn bound(cap: &Cap, q: DVec3, rho: f64) -> f64 {
    let d = q.distance(cap.centre) - cap.radius - rho;
    if d <= 0.0 {
        f64::INFINITY
    } else {
        cap.area / (4.0 * std::f64::consts::PI * d * d)
    }
}

/// A run of voxels in one row whose decision differs from the default
/// "inside iff `J ≠ 0`".
#[derive(Clone, Copy, Debug)]
struct Span {
    row: u32,
    i0: u32,
    len: u32,
    rule: Rule,
    /// `Rule::Exact` with `w` within its error bound of a half-integer.
    near: bool,
}

#[derive(Clone, Copy, Debug)]
enum Rule {
    /// `w_cap` is within `(m − 1/2, m + 1/2)` over the span: inside iff `J ≠ m`.
    Offset(i64),
    /// `w_cap` at this voxel's centre: inside iff `|J − w_cap| >= 1/2`.
    Exact(f64),
}

/// Refines the block at `min` of edge `size` (clipped to the grid), pushing
/// the spans whose rule is not the default.
/// The top blocks (of `TOP`³ voxels, by their index) that [`refine`] may
/// not settle at once: those within reach of some cap. A block farther
/// from every cap than the distance at which that cap's bound drops below
/// 0.49 / (number of caps) is settled by the bounds' sum, so only the
/// blocks around the caps are visited, however large the grid.
fn blocks_near_caps(caps: &[Cap], dims: [u32; 3]) -> Vec<[u32; 3]> {
    let nb = dims.map(|d| d.div_ceil(TOP));
    let scale = caps.first().map_or(DVec3::ONE, |c| c.scale);
    let rho = TOP as f64 * scale.length() / 2.0;
    let share = 0.49 / caps.len().max(1) as f64;
    let mut blocks = Vec::new();
    for c in caps {
        // bound < share once d > sqrt(area / (4π·share)), d = |q − centre| − radius − rho.
        let reach = c.radius + rho + (c.area / (4.0 * std::f64::consts::PI * share)).sqrt() + 1.0;
        let range: Vec<std::ops::Range<u32>> = (0..3)
            .map(|a| {
                let lo = ((c.centre[a] - reach) / scale[a] / TOP as f64).floor().max(0.0);
                let hi = ((c.centre[a] + reach) / scale[a] / TOP as f64).floor() + 1.0;
                (lo.min(nb[a] as f64) as u32)..(hi.min(nb[a] as f64) as u32)
            })
            .collect();
        for k in range[2].clone() {
            for j in range[1].clone() {
                for i in range[0].clone() {
                    blocks.push([i, j, k]);
                }
            }
        }
    }
    blocks.sort_unstable_by_key(|b| [b[2], b[1], b[0]]);
    blocks.dedup();
    blocks
}

/// Refines the block at `min` of edge `size` down to voxels (see
/// [`Plan::needed_in`]), its spans to `out`.
fn refine(caps: &[Cap], min: [u32; 3], size: u32, dims: [u32; 3], out: &mut Vec<Span>) {
    let mut todo = vec![(min, size)];
    while let Some((min, size)) = todo.pop() {
        refine_step(caps, min, size, dims, out, &mut todo);
    }
}

/// One step of [`refine`]: the block's spans to `out` when it is settled
/// (or a voxel), else its eight children to `children`.
fn refine_step(caps: &[Cap], min: [u32; 3], size: u32, dims: [u32; 3], out: &mut Vec<Span>, children: &mut Vec<([u32; 3], u32)>) {
    if (0..3).any(|a| min[a] >= dims[a]) {
        return;
    }
    // Centre (voxel units) and a lattice point for the exact-sided solid angles.
    let half = size as f64 / 2.0;
    let scale = caps.first().map_or(DVec3::ONE, |c| c.scale);
    let q = DVec3::new(min[0] as f64 + half, min[1] as f64 + half, min[2] as f64 + half) * scale;
    let ql = min.map(|m| (2 * m as i64 + size as i64) * (ONE / 2));
    let rho = half * scale.length();
    if size > 1 && caps.iter().map(|c| bound(c, q, rho)).sum::<f64>() < 0.49 {
        return;
    }
    // How much w_cap can vary over the block (and the neglected far caps),
    // before any solid angle: a block the caps pass through, or too close
    // to them, is refined without evaluating its centre.
    let mut spread = 0.0;
    let mut used = Vec::with_capacity(caps.len());
    for c in caps {
        let b = bound(c, q, rho);
        if b < NEGLECT {
            spread += b;
            continue;
        }
        used.push(c);
        if size > 1 {
            spread += c.lipschitz(q, rho) * rho;
        }
    }
    let spread = spread + 1e-3;
    if size > 1 && spread >= 0.49 {
        return split(min, size, children);
    }
    let mut scratch = Vec::new();
    let w: f64 = used.iter().map(|c| c.winding(ql, &mut scratch)).sum();
    if size == 1 {
        if w.abs() + spread >= 0.49 {
            let off_half = (w - 0.5 - (w - 0.5).round()).abs();
            let near = off_half < spread + 1e-3;
            out.push(Span { row: min[2] * dims[1] + min[1], i0: min[0], len: 1, rule: Rule::Exact(w), near });
        }
        return;
    }
    // Settled if [w − spread, w + spread] holds no half-integer.
    let (lo, hi) = (w - spread, w + spread);
    if (hi - 0.5).floor() >= (lo - 0.5).ceil() {
        return split(min, size, children);
    }
    let m = w.round() as i64;
    if m != 0 {
        let len = size.min(dims[0] - min[0]);
        for k in min[2]..(min[2] + size).min(dims[2]) {
            for j in min[1]..(min[1] + size).min(dims[1]) {
                out.push(Span { row: k * dims[1] + j, i0: min[0], len, rule: Rule::Offset(m), near: false });
            }
        }
    }
}

fn split(min: [u32; 3], size: u32, children: &mut Vec<([u32; 3], u32)>) {
    let h = size / 2;
    for dk in [0, h] {
        for dj in [0, h] {
            for di in [0, h] {
                children.push(([min[0] + di, min[1] + dj, min[2] + dk], h));
            }
        }
    }
}

/// Solid by the generalized winding number (see the module documentation).
pub fn winding(mesh: MeshRef<'_>, grid: &GridSpec) -> Result<(DenseBits, WindingReport), ClassifyError> {
    Ok(winding_snapped(&snap_all(mesh, grid)?, grid.dims(), &Stop::new()))
}

/// [`winding`] on an already snapped mesh; the work left is skipped once
/// `stop` is requested.
pub fn winding_snapped(snapped: &Snapped, dims: [u32; 3], stop: &Stop) -> (DenseBits, WindingReport) {
    let plan = Plan::new(snapped, dims);
    let hits = row_crossings(&plan.closed, dims);
    let needed = plan.needed_in(0..dims[2], stop);
    let mut bits = DenseBits::new(dims);
    bits.par_rows_mut().enumerate().filter(|_| !stop.requested()).for_each_init(Vec::new, |spans, (r, row)| {
        spans.clear();
        let r = r as u32;
        let h0 = hits.partition_point(|h| h.0 < r);
        plan.row(&hits[h0..h0 + hits[h0..].partition_point(|h| h.0 == r)], &needed, r, spans);
        for &(f, t) in spans.iter() {
            DenseBits::fill_row(row, f, t);
        }
    });
    let voxels = bits.count();
    let mut report = plan.report(snapped, voxels, evaluated(&needed));
    report.near_half = near_half(&needed, dims).collect();
    (bits, report)
}

/// [`winding_snapped`] without a dense grid, for grids past memory: the
/// same rows' inside spans, turned brick row by brick row into sparse
/// bricks with the interior as runs of full bricks. The same voxels.
pub fn winding_sparse(snapped: &Snapped, dims: [u32; 3], stop: &Stop) -> (SparseBricks, WindingReport) {
    let plan = Plan::new(snapped, dims);
    // The spans that need the caps, band by band (blocks are TOP planes
    // high, bands a whole number of blocks), so that at most one band's
    // are held.
    let mut evaluated_voxels = 0;
    let mut near = Vec::new();
    let needed_in = |planes: std::ops::Range<u32>| {
        let needed = plan.needed_in(planes, stop);
        evaluated_voxels += evaluated(&needed);
        near.extend(near_half(&needed, dims));
        let rows = brick_rows_of(needed.iter().map(|s| s.row), dims);
        (needed, rows)
    };
    let out = by_bands(&plan.closed, dims, stop, needed_in, |band, needed, bj, bk| {
        let mut spans: [Vec<(u32, u32)>; 64] = std::array::from_fn(|_| Vec::new());
        for dk in 0..BRICK.min(dims[2] - bk * BRICK) {
            for dj in 0..BRICK.min(dims[1] - bj * BRICK) {
                let (j, k) = (bj * BRICK + dj, bk * BRICK + dk);
                plan.row(band.row(j, k), needed, k * dims[1] + j, &mut spans[(dk * BRICK + dj) as usize]);
            }
        }
        bricks_of_spans(&spans, dims, bj, bk)
    });
    let voxels = out.count();
    let mut report = plan.report(snapped, voxels, evaluated_voxels);
    report.near_half = near;
    (out, report)
}

/// The voxels among `needed` where the caps' winding number is evaluated.
fn evaluated(needed: &[Span]) -> u64 {
    needed.iter().filter(|s| matches!(s.rule, Rule::Exact(_))).count() as u64
}

/// The voxels among `needed` near a half-integer ([`WindingReport::near_half`]).
fn near_half(needed: &[Span], dims: [u32; 3]) -> impl Iterator<Item = [u32; 3]> + '_ {
    needed.iter().filter(|s| s.near).map(move |s| [s.i0, s.row % dims[1], s.row / dims[1]])
}

const _: () = assert!(BAND_PLANES % TOP == 0, "a block of TOP planes lies in one band");

/// What both storages need: the mesh closed by its caps (whose rays'
/// crossings give `J`), the caps, and the blocks near them, where spans
/// may need the caps to decide ([`Plan::needed_in`]).
struct Plan {
    dims: [u32; 3],
    cycles: u64,
    /// The mesh's triangles and the caps'.
    closed: Vec<LatticeTriangle>,
    caps: Vec<Cap>,
    /// Blocks of TOP³ voxels near a cap, sorted by `z`.
    blocks: Vec<[u32; 3]>,
}

impl Plan {
    fn new(snapped: &Snapped, dims: [u32; 3]) -> Plan {
        let cycles = boundary_cycles(&snapped.net_edges);
        let caps = caps(&cycles, snapped.scale);
        let mut closed = snapped.triangles.clone();
        for c in &caps {
            closed.extend(c.tris.iter().map(|&v| LatticeTriangle { v }));
        }
        let mut blocks = if caps.is_empty() { Vec::new() } else { blocks_near_caps(&caps, dims) };
        blocks.sort_unstable_by_key(|b| (b[2], b[1], b[0]));
        Plan { dims, cycles: cycles.len() as u64, closed, caps, blocks }
    }

    /// The spans of the planes `planes` (whole blocks) whose decision needs
    /// `w_cap`, sorted by row: octree refinement from the blocks of TOP³
    /// voxels there. A block is settled (inside iff J ≠ 0) when |w_cap|
    /// stays below 1/2 over it, by each cap's sphere bound or by w_cap at
    /// its centre plus a Lipschitz bound; otherwise its eight children are
    /// refined, down to single voxels, where w_cap at the centre is the
    /// value used. With the rows of a crossing (of `closed`) the rows of
    /// these spans are all that can hold inside voxels: elsewhere `J = 0`
    /// and the caps are settled below ½ (outside). Blocks left once `stop`
    /// is requested are skipped.
    fn needed_in(&self, planes: std::ops::Range<u32>, stop: &Stop) -> Vec<Span> {
        let b0 = self.blocks.partition_point(|b| b[2] * TOP < planes.start);
        let b1 = self.blocks.partition_point(|b| b[2] * TOP < planes.end);
        // The top levels here, so that the pieces left (PIECE³ voxels at
        // most, cheap and many) balance across the threads even where a
        // band holds few blocks.
        let mut needed = Vec::new();
        let mut pieces: Vec<([u32; 3], u32)> = self.blocks[b0..b1].iter().map(|b| (b.map(|x| x * TOP), TOP)).collect();
        while pieces.iter().any(|p| p.1 > PIECE) {
            let mut next = Vec::with_capacity(pieces.len() * 8);
            for (min, size) in pieces {
                if size > PIECE {
                    refine_step(&self.caps, min, size, self.dims, &mut needed, &mut next);
                } else {
                    next.push((min, size));
                }
            }
            pieces = next;
        }
        let rest: Vec<Span> = pieces
            .par_iter()
            .filter(|_| !stop.requested())
            .flat_map_iter(|&(min, size)| {
                let mut out = Vec::new();
                refine(&self.caps, min, size, self.dims, &mut out);
                out
            })
            .collect();
        needed.extend(rest);
        needed.par_sort_unstable_by_key(|s| (s.row, s.i0));
        needed
    }

    /// Appends the inside spans of row `r` (`k·ny + j`), whose crossings
    /// are `row_hits` (sorted by `i0`) and whose spans that need the caps
    /// are among `needed` (sorted by row), to `out`, in order, maximal
    /// (adjacent spans joined).
    fn row(&self, row_hits: &[(u32, u32, i8)], needed: &[Span], r: u32, out: &mut Vec<(u32, u32)>) {
        let nx = self.dims[0];
        // Sorted by row: the row's spans found by binary search (a per-row
        // table would follow the grid, not the surface).
        let n0 = needed.partition_point(|s| s.row < r);
        let spans = &needed[n0..n0 + needed[n0..].partition_point(|s| s.row == r)];
        let (mut ptr, mut sp) = (0, 0);
        let mut w = 0i64;
        let mut i = 0u32;
        while i < nx {
            while ptr < row_hits.len() && row_hits[ptr].1 <= i {
                w += row_hits[ptr].2 as i64;
                ptr += 1;
            }
            if let Some(s) = spans.get(sp).filter(|s| s.i0 <= i) {
                let inside = match s.rule {
                    Rule::Offset(m) => w != m,
                    Rule::Exact(v) => (w as f64 - v).abs() >= 0.5,
                };
                if inside {
                    push_span(out, i, i);
                }
                i += 1;
                if i >= s.i0 + s.len {
                    sp += 1;
                }
                continue;
            }
            let next_hit = row_hits.get(ptr).map_or(nx, |x| x.1.min(nx));
            let next_span = spans.get(sp).map_or(nx, |s| s.i0);
            let next = next_hit.min(next_span).min(nx).max(i + 1);
            if w != 0 {
                push_span(out, i, next - 1);
            }
            i = next;
        }
    }

    fn report(&self, snapped: &Snapped, voxels: u64, evaluated: u64) -> WindingReport {
        let cap_triangles = self.caps.iter().map(|c| c.tris.len() as u64).sum();
        let mut solid = super::solid::inspect(snapped);
        solid.voxels = voxels;
        WindingReport { solid, cycles: self.cycles, cap_triangles, evaluated, near_half: Vec::new() }
    }
}

/// The slow, obviously correct definition.
pub mod reference {
    use super::*;

    /// `w` at every voxel centre by the direct sum over all triangles.
    /// Serial; small grids only.
    pub fn winding_numbers(mesh: MeshRef<'_>, grid: &GridSpec) -> Result<Vec<f64>, ClassifyError> {
        let snapped = snap_all(mesh, grid)?;
        let (tris, scale) = (snapped.crossing_triangles(), snapped.scale);
        let dims = grid.dims();
        let h = ONE / 2;
        let mut out = Vec::with_capacity(dims.iter().map(|&d| d as usize).product());
        for k in 0..dims[2] as i64 {
            for j in 0..dims[1] as i64 {
                for i in 0..dims[0] as i64 {
                    let q = [i * ONE + h, j * ONE + h, k * ONE + h];
                    out.push(tris.iter().map(|t| winding_of(&t.v, q, scale)).sum());
                }
            }
        }
        Ok(out)
    }

    /// The solid `|w| >= 1/2` from [`winding_numbers`].
    pub fn winding(mesh: MeshRef<'_>, grid: &GridSpec) -> Result<DenseBits, ClassifyError> {
        let dims = grid.dims();
        let w = winding_numbers(mesh, grid)?;
        let mut bits = DenseBits::new(dims);
        for (idx, w) in w.iter().enumerate() {
            if w.abs() >= 0.5 {
                let (i, j, k) =
                    (idx % dims[0] as usize, (idx / dims[0] as usize) % dims[1] as usize, idx / (dims[0] as usize * dims[1] as usize));
                bits.set(i as u32, j as u32, k as u32);
            }
        }
        Ok(bits)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-`atan2` sum equals the triangles' solid angles summed one by
    /// one, for twisted, self-crossing cycles seen from points all around
    /// (including points in a cap triangle's plane and on its vertices).
    #[test]
    fn cap_winding_equals_the_sum_of_its_triangles() {
        let mut rng = crate::test_rng::Xorshift(0x9e37_79b9_7f4a_7c15);
        let mut scratch = Vec::new();
        let mut wrapped = 0;
        for round in 0..200 {
            let n = 3 + (round % 40) as usize;
            let cycle: Vec<P3> = (0..n).map(|_| [rng.signed(8) * ONE / 2, rng.signed(8) * ONE / 2, rng.signed(2) * ONE / 2]).collect();
            let cap = &caps(&[cycle], DVec3::ONE)[0];
            for _ in 0..50 {
                let q = [rng.signed(12) * ONE / 2, rng.signed(12) * ONE / 2, rng.signed(4) * ONE / 2];
                let slow: f64 = cap.tris.iter().map(|t| winding_of(t, q, DVec3::ONE)).sum();
                let fast = cap.winding(q, &mut scratch);
                assert!((slow - fast).abs() < 1e-9, "cycle {round}: {slow} vs {fast} at {q:?}");
                wrapped += usize::from(slow.abs() > 0.5);
            }
        }
        // Sums past a half turn: the product went around the origin.
        assert!(wrapped > 100, "{wrapped}");
    }
}
