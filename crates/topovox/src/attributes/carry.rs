//! Carrying colour, material, normal and coverage from triangles into voxels.
//!
//! For every triangle, the voxels it touches are enumerated exactly (the
//! `cover` traversal on the snapped triangle, so every set voxel of every
//! surface mode — all subsets of `cover` — is reached). Each voxel box then
//! clips the triangle (Sutherland–Hodgman, f64, grid units) and the part
//! inside is what the voxel gets:
//! - **coverage**: the clipped polygon's area in index space (each axis in
//!   units of its voxel edge), so a piece spanning the voxel parallel to a
//!   face has coverage 1 whichever face it is; on a box grid that is the
//!   world area divided by the area of the voxel's cross-section in the
//!   piece's plane direction, `|(sy·sz·nx, sx·sz·ny, sx·sy·nz)|` for its
//!   index-space unit normal `n` (for cubes, `s²`);
//! - **colour**: the clipped polygon is sampled on a regular barycentric
//!   subdivision fine enough to visit every texel it covers (nearest-texel
//!   lookups, up to 24² samples per fan triangle), each sample weighted by
//!   its share of the area. [`ColourRule::Dominant`] keeps the colour with
//!   the most area (ties: the smaller `0xRRGGBB`), so it only produces
//!   colours of the source; [`ColourRule::Blend`] takes the area-weighted
//!   mean in linear light;
//! - **material**: the material with the most area (ties: the smaller id);
//! - **normal**: the coverage-weighted mean of the triangles' world-space
//!   unit normals (on box grids, the index-space normal times the inverse
//!   transpose of the world-to-index map).
//!
//! A voxel that a triangle only touches (zero area inside) uses that touch
//! as a point sample, and only when no triangle has area inside it. Voxels
//! no triangle touches (solid interiors, `pos`'s off-surface voxels) take the
//! attributes of the nearest voxel that has them: a breadth-first search
//! over 26-neighbours from all surface voxels at once, in key order, so ties
//! resolve the same way on every run. Contributions are reduced in
//! (voxel, triangle) order, so results do not depend on the thread count.

use glam::DVec3;
use rayon::prelude::*;

use super::colour::{from_linear, linear_to_rgb, pack, to_linear, unpack};
use super::{Appearance, ColourRule, Texture, VoxelAttributes, NO_MATERIAL};
use crate::geom::clip::{clip_to_slab, ClipPoly, CLIPPED_MAX};
use crate::geom::closest::closest_point;
use crate::geom::lattice::{prepare_triangle, LatticeTriangle};
use crate::voxelize::cover::cover_triangle;
use crate::voxelize::driver::Sink;
use crate::voxelize::Traversal;
use crate::{GridSpec, MeshRef, VoxelSource};

/// What to compute.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CarryOptions {
    /// How colours inside a voxel combine.
    pub rule: ColourRule,
    /// Compute the average normal.
    pub normals: bool,
}

/// The colour a voxel gets when the mesh has none of its own (the renderer's clay).
pub const DEFAULT_COLOUR: [u8; 3] = [200, 200, 200];

/// Most samples along a fan triangle's side.
const MAX_SUBDIV: u32 = 24;

struct Contribution {
    /// The voxel, relative to its slab's first key.
    slot: u32,
    tri: u32,
    area: f64,
    /// Total weight of the colour samples (the area, or 1 for a touch).
    w: f64,
    /// Blend: weighted linear RGB.
    lin: [f64; 3],
    /// Dominant: area per `0xRRGGBB`, `hist_len` entries of the slab's
    /// histogram list from `hist_start`, in the order colours were first seen.
    hist_start: u32,
    hist_len: u32,
}

impl Contribution {
    /// Adds weight `w` to colour `c` in this contribution's histogram, the
    /// last entries of `hist`.
    #[inline]
    fn add_colour(&mut self, hist: &mut Vec<(u32, f64)>, c: u32, w: f64) {
        let start = self.hist_start as usize;
        if let Some(h) = hist[start..].iter_mut().find(|h| h.0 == c) {
            h.1 += w;
        } else {
            hist.push((c, w));
            self.hist_len += 1;
        }
    }

    fn hist<'h>(&self, hist: &'h [(u32, f64)]) -> &'h [(u32, f64)] {
        &hist[self.hist_start as usize..(self.hist_start + self.hist_len) as usize]
    }
}

/// Attributes of the set voxels of `voxels` (on `grid`) from the triangles of `mesh`.
/// Colour is present when `appearance` has colour, material ids when it has
/// materials, normals when asked; coverage always.
///
/// The work is cut into z-slabs of whole layers, about 2 k set voxels each (a
/// contiguous range of keys each). Triangles are snapped once and binned by
/// the slabs their voxel box meets; each slab runs `cover` on its triangles
/// clipped to the slab, in triangle order, and reduces its own
/// contributions. Every (voxel, triangle) pair is visited exactly once, in
/// the same order whatever the slabs, so the result does not depend on them
/// or on the thread count, and memory stays at one slab per thread.
pub fn carry(
    mesh: MeshRef<'_>,
    appearance: &Appearance,
    grid: &GridSpec,
    voxels: &dyn VoxelSource,
    opts: &CarryOptions,
) -> VoxelAttributes {
    let dims = grid.dims();
    let keys = VoxelAttributes::keys_of(voxels);
    let ctx = Ctx::new(mesh, appearance, grid, &keys, opts);
    let n = keys.len();
    let mut arrays = ctx.arrays();
    if n > 0 {
        let slabs = Slab::cut(&keys, dims);
        // Snap every triangle once, in order; each lattice triangle remembers its source.
        let prepared: Vec<(u32, LatticeTriangle)> = (0..mesh.triangles.len())
            .into_par_iter()
            .with_min_len(256)
            .flat_map_iter(|t| {
                let mut out = Vec::new();
                prepare_triangle(mesh.positions, &mesh.triangles[t], grid, &mut out);
                out.into_iter().map(move |lt| (t as u32, lt))
            })
            .collect();
        // Bin them (indices into `prepared`, ascending) by the slabs their voxel box meets.
        // Layers past the last slab hold no set voxel: their triangles go to the last slab, which clips them away.
        let mut slab_of_k = vec![slabs.len() as u32 - 1; dims[2] as usize];
        for (s, slab) in slabs.iter().enumerate() {
            slab_of_k[slab.k0 as usize..slab.k1 as usize].fill(s as u32);
        }
        let mut bins: Vec<Vec<u32>> = vec![Vec::new(); slabs.len()];
        for (e, (_, lt)) in prepared.iter().enumerate() {
            if let Some((lo, hi)) = lt.voxel_bounds(dims) {
                for s in slab_of_k[lo[2] as usize]..=slab_of_k[hi[2] as usize] {
                    bins[s as usize].push(e as u32);
                }
            }
        }
        let mut parts = Vec::with_capacity(slabs.len());
        let mut rest = arrays.outputs();
        for slab in &slabs {
            let (part, tail) = rest.split(slab.s1 - slab.s0);
            parts.push(part);
            rest = tail;
        }
        slabs.par_iter().zip(parts).zip(&bins).with_max_len(1).for_each_init(Scratch::default, |scratch, ((slab, mut out), bin)| {
            ctx.slab(slab, bin, &prepared, scratch);
            ctx.reduce(scratch, &mut out);
        });
    }
    arrays.finish(keys, dims)
}

/// The attribute arrays being filled, one entry per set voxel (those not
/// asked for empty).
struct Arrays {
    has: Vec<bool>,
    colour: Option<Vec<[u8; 3]>>,
    material: Option<Vec<u32>>,
    normal: Option<Vec<[f32; 3]>>,
    coverage: Vec<f32>,
}

impl Arrays {
    fn new(n: usize, colour: bool, materials: bool, normals: bool) -> Arrays {
        Arrays {
            has: vec![false; n],
            colour: colour.then(|| vec![DEFAULT_COLOUR; n]),
            material: materials.then(|| vec![NO_MATERIAL; n]),
            normal: normals.then(|| vec![[0f32; 3]; n]),
            coverage: vec![0f32; n],
        }
    }

    fn outputs(&mut self) -> Outputs<'_> {
        Outputs {
            has: &mut self.has,
            colour: self.colour.as_deref_mut().unwrap_or_default(),
            material: self.material.as_deref_mut().unwrap_or_default(),
            normal: self.normal.as_deref_mut().unwrap_or_default(),
            coverage: &mut self.coverage,
        }
    }

    /// Fills voxels without surface from the nearest that has some, and
    /// hands the arrays over with their `keys`.
    fn finish(mut self, keys: Vec<u64>, dims: [u32; 3]) -> VoxelAttributes {
        let out = self.outputs();
        fill_from_nearest(&keys, dims, out.has, out.colour, out.material, out.normal);
        VoxelAttributes { dims, keys, colour: self.colour, material: self.material, normal: self.normal, coverage: Some(self.coverage) }
    }
}

/// About how many set voxels one slab of [`carry`] holds.
const SLAB_VOXELS: usize = 1 << 11;

/// Largest row table of a slab, in rows per set voxel (beyond it, the slab's
/// keys are binary searched instead).
const ROWS_PER_VOXEL: usize = 4;

/// A z-slab `k0..k1` of the grid and its keys `s0..s1`.
struct Slab {
    k0: u32,
    k1: u32,
    s0: usize,
    s1: usize,
}

impl Slab {
    /// Slabs of whole z-layers from 0 to the last key's layer, each holding
    /// about [`SLAB_VOXELS`] of the sorted `keys` (fewer when there are
    /// few keys; non-empty).
    fn cut(keys: &[u64], dims: [u32; 3]) -> Vec<Slab> {
        let layer = dims[0] as u64 * dims[1] as u64;
        // Enough slabs for every thread to have several (small grids carry
        // many texels per voxel, so their work is not in proportion to voxels).
        let per = keys.len().div_ceil(8 * rayon::current_num_threads()).clamp(1, SLAB_VOXELS);
        let mut slabs = Vec::new();
        let (mut k0, mut s0) = (0u32, 0usize);
        while s0 < keys.len() {
            // The slab ends after the layer of its `per`-th key.
            let last = (s0 + per).min(keys.len()) - 1;
            let k1 = (keys[last] / layer) as u32 + 1;
            let s1 = s0 + keys[s0..].partition_point(|&key| key < k1 as u64 * layer);
            slabs.push(Slab { k0, k1, s0, s1 });
            (k0, s0) = (k1, s1);
        }
        slabs
    }
}

/// Buffers one thread reuses from slab to slab.
#[derive(Default)]
struct Scratch {
    contribs: Vec<Contribution>,
    /// The contributions' colour histograms, one after another.
    hist: Vec<(u32, f64)>,
    voxels: Vec<[u32; 3]>,
    order: Vec<u64>,
}

/// Mutable views of the attribute arrays (empty ones stay empty).
struct Outputs<'a> {
    has: &'a mut [bool],
    colour: &'a mut [[u8; 3]],
    material: &'a mut [u32],
    normal: &'a mut [[f32; 3]],
    coverage: &'a mut [f32],
}

impl<'a> Outputs<'a> {
    /// The first `n` slots and the rest.
    fn split(self, n: usize) -> (Outputs<'a>, Outputs<'a>) {
        fn cut<T>(v: &mut [T], n: usize) -> (&mut [T], &mut [T]) {
            if v.is_empty() {
                (&mut [], &mut [])
            } else {
                v.split_at_mut(n)
            }
        }
        let (has, has_r) = cut(self.has, n);
        let (colour, colour_r) = cut(self.colour, n);
        let (material, material_r) = cut(self.material, n);
        let (normal, normal_r) = cut(self.normal, n);
        let (coverage, coverage_r) = cut(self.coverage, n);
        (
            Outputs { has, colour, material, normal, coverage },
            Outputs { has: has_r, colour: colour_r, material: material_r, normal: normal_r, coverage: coverage_r },
        )
    }
}

/// Finds the slot of a voxel among one slab's keys: through the offsets of
/// each `(j, k)` row where the table is small, else by binary search.
struct SlotIndex<'a> {
    keys: &'a [u64],
    /// First key of the slab's first layer.
    base: u64,
    nx: u64,
    /// `rows[r]..rows[r + 1]`: the keys of row `r` (counted from `base`), if tabled.
    rows: Vec<u32>,
}

impl<'a> SlotIndex<'a> {
    fn new(keys: &'a [u64], dims: [u32; 3], k0: u32, k1: u32) -> SlotIndex<'a> {
        let nx = dims[0] as u64;
        let base = k0 as u64 * nx * dims[1] as u64;
        let n_rows = (k1 - k0) as usize * dims[1] as usize;
        let mut rows = Vec::new();
        if n_rows <= ROWS_PER_VOXEL * keys.len() + 1024 && keys.len() < u32::MAX as usize {
            rows = vec![0u32; n_rows + 1];
            for &key in keys {
                rows[((key - base) / nx) as usize + 1] += 1;
            }
            for r in 0..n_rows {
                rows[r + 1] += rows[r];
            }
        }
        SlotIndex { keys, base, nx, rows }
    }

    #[inline]
    fn slot(&self, key: u64) -> Option<usize> {
        if self.rows.is_empty() {
            return self.keys.binary_search(&key).ok();
        }
        let r = ((key - self.base) / self.nx) as usize;
        let (a, b) = (self.rows[r] as usize, self.rows[r + 1] as usize);
        self.keys[a..b].binary_search(&key).ok().map(|s| a + s)
    }
}

/// The key with the largest summed weight (ties: the smallest key). Sorts `v`.
fn argmax(v: &mut [(u32, f64)]) -> Option<u32> {
    v.sort_unstable_by_key(|a| a.0);
    let mut best: Option<(u32, f64)> = None;
    for run in v.chunk_by(|a, b| a.0 == b.0) {
        let w: f64 = run.iter().map(|r| r.1).sum();
        if best.is_none_or(|(_, bw)| w > bw) {
            best = Some((run[0].0, w));
        }
    }
    best.map(|b| b.0)
}

/// Breadth-first search from every voxel that has attributes, over
/// 26-neighbours among the set voxels; each reached voxel copies its parent.
fn fill_from_nearest(
    keys: &[u64],
    dims: [u32; 3],
    has: &mut [bool],
    colour: &mut [[u8; 3]],
    material: &mut [u32],
    normal: &mut [[f32; 3]],
) {
    if has.iter().all(|&h| h) || !has.iter().any(|&h| h) {
        return;
    }
    let probe = VoxelAttributes { dims, ..VoxelAttributes::default() };
    let mut queue: std::collections::VecDeque<usize> = (0..keys.len()).filter(|&s| has[s]).collect();
    while let Some(s) = queue.pop_front() {
        let v = probe.voxel(keys[s]).map(|c| c as i64);
        for dz in -1..=1i64 {
            for dy in -1..=1i64 {
                for dx in -1..=1i64 {
                    let q = [v[0] + dx, v[1] + dy, v[2] + dz];
                    if (0..3).any(|a| q[a] < 0 || q[a] >= dims[a] as i64) {
                        continue;
                    }
                    let key = VoxelAttributes::key(dims, q[0] as u32, q[1] as u32, q[2] as u32);
                    let Ok(t) = keys.binary_search(&key) else { continue };
                    if has[t] {
                        continue;
                    }
                    has[t] = true;
                    if !colour.is_empty() {
                        colour[t] = colour[s];
                    }
                    if !material.is_empty() {
                        material[t] = material[s];
                    }
                    if !normal.is_empty() {
                        normal[t] = normal[s];
                    }
                    queue.push_back(t);
                }
            }
        }
    }
}

struct Ctx<'a> {
    mesh: MeshRef<'a>,
    app: &'a Appearance,
    grid: &'a GridSpec,
    keys: &'a [u64],
    rule: ColourRule,
    colour: bool,
    normals: bool,
}

struct Collect<'a>(&'a mut Vec<[u32; 3]>);

impl Sink for Collect<'_> {
    fn set(&mut self, i: u32, j: u32, k: u32) {
        self.0.push([i, j, k]);
    }
}

impl<'a> Ctx<'a> {
    fn new(mesh: MeshRef<'a>, app: &'a Appearance, grid: &'a GridSpec, keys: &'a [u64], opts: &CarryOptions) -> Ctx<'a> {
        Ctx { mesh, app, grid, keys, rule: opts.rule, colour: app.has_colour(), normals: opts.normals }
    }

    /// Empty attribute arrays for the keys: those this run fills.
    fn arrays(&self) -> Arrays {
        Arrays::new(self.keys.len(), self.colour, self.app.has_materials(), self.normals)
    }

    fn corners(&self, t: usize) -> Option<[DVec3; 3]> {
        let tri = self.mesh.triangles[t];
        let mut p = [DVec3::ZERO; 3];
        for c in 0..3 {
            p[c] = self.grid.to_grid_units(*self.mesh.positions.get(tri[c] as usize)?);
        }
        p.iter().all(|q| q.is_finite()).then_some(p)
    }

    /// The world-space unit normal: the index-space normal `n` taken back
    /// by the inverse transpose of `u = (p - origin) / s`, which is `n / s`.
    fn unit_normal(&self, t: usize) -> DVec3 {
        let n = self.corners(t).map(|p| (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero()).unwrap_or(DVec3::ZERO);
        match self.grid.voxel_size().cube() {
            Some(_) => n,
            None => (n / self.grid.voxel_size().0).normalize_or_zero(),
        }
    }

    /// The contributions of one slab: its binned lattice triangles (indices
    /// into `prepared`, ascending), grouped by source triangle, each
    /// traversed inside the slab; slots are relative to the slab's first key.
    fn slab(&self, slab: &Slab, bin: &[u32], prepared: &[(u32, LatticeTriangle)], scratch: &mut Scratch) {
        let dims = self.grid.dims();
        let index = SlotIndex::new(&self.keys[slab.s0..slab.s1], dims, slab.k0, slab.k1);
        let out = &mut scratch.contribs;
        out.clear();
        scratch.hist.clear();
        let mut voxels = Collect(&mut scratch.voxels);
        for group in bin.chunk_by(|&a, &b| prepared[a as usize].0 == prepared[b as usize].0) {
            let t = prepared[group[0] as usize].0 as usize;
            voxels.0.clear();
            for &e in group {
                let lt = &prepared[e as usize].1;
                if let Some((mut lo, mut hi)) = lt.voxel_bounds(dims) {
                    lo[2] = lo[2].max(slab.k0 as i64);
                    hi[2] = hi[2].min(slab.k1 as i64 - 1);
                    if lo[2] <= hi[2] {
                        cover_triangle(lt, lo, hi, Traversal::Auto, &mut voxels);
                    }
                }
            }
            if voxels.0.is_empty() {
                continue;
            }
            voxels.0.sort_unstable();
            if group.len() > 1 {
                voxels.0.dedup();
            }
            self.triangle(t, voxels.0, &index, out, &mut scratch.hist);
        }
    }

    /// Appends the contributions of triangle `t` to `voxels` (those it
    /// touches, sorted).
    fn triangle(&self, t: usize, voxels: &[[u32; 3]], index: &SlotIndex<'_>, out: &mut Vec<Contribution>, hist: &mut Vec<(u32, f64)>) {
        let Some(p) = self.corners(t) else { return };
        let dims = self.grid.dims();
        let shader = Shader::new((self.mesh, self.app, self.rule), t, p);
        // Voxels in (i, j, k) order: the triangle clipped to the voxel's x
        // slab is shared along i, to its x and y slabs along (i, j), so each
        // voxel clips only along z (the same polygons as clipping to the box).
        let (mut x_poly, mut xy_poly, mut clipped) = (ClipPoly::default(), ClipPoly::default(), ClipPoly::default());
        let (mut x_at, mut xy_at) = (None, None);
        for v in voxels {
            let Some(slot) = index.slot(VoxelAttributes::key(dims, v[0], v[1], v[2])) else { continue };
            let lo = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
            if x_at != Some(v[0]) {
                clip_to_slab(&p, 0, lo.x, lo.x + 1.0, &mut x_poly);
                x_at = Some(v[0]);
                xy_at = None;
            }
            if xy_at != Some(v[1]) {
                clip_to_slab(x_poly.vertices(), 1, lo.y, lo.y + 1.0, &mut xy_poly);
                xy_at = Some(v[1]);
            }
            clip_to_slab(xy_poly.vertices(), 2, lo.z, lo.z + 1.0, &mut clipped);
            out.push(self.contribution(&shader, t, &p, slot, lo, clipped.vertices(), hist));
        }
    }

    /// What triangle `t` (corners `p`, grid units) gives voxel `slot`
    /// (low corner `lo`), whose box clips it to `poly`; colour samples go
    /// to the end of `hist`.
    #[allow(clippy::too_many_arguments)]
    fn contribution(
        &self,
        shader: &Shader<'_>,
        t: usize,
        p: &[DVec3; 3],
        slot: usize,
        lo: DVec3,
        poly: &[DVec3],
        hist: &mut Vec<(u32, f64)>,
    ) -> Contribution {
        assert!(
            hist.len() < u32::MAX as usize && slot < u32::MAX as usize,
            "too many voxels or colour samples in one slab to carry attributes"
        );
        let mut c =
            Contribution { slot: slot as u32, tri: t as u32, area: 0.0, w: 0.0, lin: [0.0; 3], hist_start: hist.len() as u32, hist_len: 0 };
        // Texture coordinates of the polygon's vertices, each computed once for its fan triangles.
        let mut uvs = [[0.0; 2]; CLIPPED_MAX];
        if let (true, Some((_, uv))) = (self.colour, &shader.texture) {
            for (q, at) in uvs.iter_mut().zip(poly) {
                *q = Shader::uv(uv, shader.bary(*at));
            }
        }
        for w in 1..poly.len().saturating_sub(1) {
            let (a, b, d) = (poly[0], poly[w], poly[w + 1]);
            let area = 0.5 * (b - a).cross(d - a).length();
            if area > 0.0 {
                c.area += area;
                if self.colour {
                    shader.sample([a, b, d], [uvs[0], uvs[w], uvs[w + 1]], area, &mut c, hist);
                }
            }
        }
        if c.area <= 0.0 && self.colour {
            // A touch: one point sample where it touches (or, if the f64
            // clip lost it, the voxel's nearest point of the triangle's plane).
            let at = if poly.is_empty() { closest_point(p, lo + DVec3::splat(0.5)) } else { centroid(poly) };
            shader.add(at, 1.0, &mut c, hist);
        }
        c
    }

    /// Reduces one slab's contributions into its outputs, per voxel in
    /// triangle order.
    fn reduce(&self, scratch: &mut Scratch, out: &mut Outputs<'_>) {
        let contribs = &scratch.contribs;
        // Contributions come in triangle order, so sorting `slot << 32 |
        // index` (8 bytes, not the contributions themselves) orders them by
        // voxel, then triangle.
        assert!(contribs.len() < 1 << 32, "too many (triangle, voxel) pairs in one slab to carry attributes");
        let order = &mut scratch.order;
        order.clear();
        order.extend(contribs.iter().enumerate().map(|(i, c)| (c.slot as u64) << 32 | i as u64));
        order.sort_unstable();
        let materials = !out.material.is_empty();
        let mut hist: Vec<(u32, f64)> = Vec::new();
        let mut mats: Vec<(u32, f64)> = Vec::new();
        let mut group: Vec<&Contribution> = Vec::new();
        for run in order.chunk_by(|a, b| a >> 32 == b >> 32) {
            group.clear();
            group.extend(run.iter().map(|o| &contribs[(o & 0xffff_ffff) as usize]));
            let group = &group[..];
            let slot = group[0].slot as usize;
            out.has[slot] = true;
            let any_area = group.iter().any(|c| c.area > 0.0);
            let used = || group.iter().copied().filter(move |c| !any_area || c.area > 0.0);
            let weight = |c: &Contribution| if any_area { c.area } else { 1.0 };
            out.coverage[slot] = group.iter().map(|c| c.area).sum::<f64>() as f32;
            if self.colour {
                out.colour[slot] = match self.rule {
                    ColourRule::Blend => {
                        let mut sum = [0.0; 3];
                        let mut w = 0.0;
                        for c in used() {
                            (0..3).for_each(|a| sum[a] += c.lin[a]);
                            w += c.w;
                        }
                        linear_to_rgb(sum.map(|s| if w > 0.0 { s / w } else { 0.0 }))
                    }
                    ColourRule::Dominant => {
                        hist.clear();
                        for c in used() {
                            hist.extend_from_slice(c.hist(&scratch.hist));
                        }
                        unpack(argmax(&mut hist).unwrap_or(pack(DEFAULT_COLOUR)))
                    }
                };
            }
            if materials {
                mats.clear();
                mats.extend(used().map(|c| (self.app.triangle_material.get(c.tri as usize).copied().unwrap_or(NO_MATERIAL), weight(c))));
                out.material[slot] = argmax(&mut mats).unwrap_or(NO_MATERIAL);
            }
            if self.normals {
                let mut s = DVec3::ZERO;
                for c in used() {
                    s += self.unit_normal(c.tri as usize) * weight(c);
                }
                out.normal[slot] = s.normalize_or_zero().as_vec3().to_array();
            }
        }
    }
}

/// The slow, obviously correct way to carry attributes: the same
/// definition (per voxel, the triangles' pieces inside its box, sampled and
/// reduced in triangle order) computed directly — every triangle in order
/// over the whole grid, each voxel's piece clipped to its box at once, each
/// slot found by a binary search over every key, one reduction. Serial.
/// [`carry`] must give exactly the same attributes.
pub mod reference {
    use super::*;
    use crate::geom::clip::clip_triangle_to_box;

    /// [`super::carry`], directly.
    pub fn carry(
        mesh: MeshRef<'_>,
        appearance: &Appearance,
        grid: &GridSpec,
        voxels: &dyn VoxelSource,
        opts: &CarryOptions,
    ) -> VoxelAttributes {
        let dims = grid.dims();
        let keys = VoxelAttributes::keys_of(voxels);
        let ctx = Ctx::new(mesh, appearance, grid, &keys, opts);
        let mut arrays = ctx.arrays();
        let mut scratch = Scratch::default();
        for t in 0..mesh.triangles.len() {
            let mut lattice = Vec::new();
            prepare_triangle(mesh.positions, &mesh.triangles[t], grid, &mut lattice);
            let mut found = Vec::new();
            for lt in &lattice {
                if let Some((lo, hi)) = lt.voxel_bounds(dims) {
                    cover_triangle(lt, lo, hi, Traversal::Auto, &mut Collect(&mut found));
                }
            }
            found.sort_unstable();
            found.dedup();
            let Some(p) = ctx.corners(t) else { continue };
            let shader = Shader::new((ctx.mesh, ctx.app, ctx.rule), t, p);
            for v in found {
                let Ok(slot) = keys.binary_search(&VoxelAttributes::key(dims, v[0], v[1], v[2])) else { continue };
                let lo = DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
                let mut clipped = [DVec3::ZERO; CLIPPED_MAX];
                let m = clip_triangle_to_box(&p, lo, lo + DVec3::ONE, &mut clipped);
                let c = ctx.contribution(&shader, t, &p, slot, lo, &clipped[..m], &mut scratch.hist);
                scratch.contribs.push(c);
            }
        }
        ctx.reduce(&mut scratch, &mut arrays.outputs());
        arrays.finish(keys, dims)
    }
}

fn centroid(poly: &[DVec3]) -> DVec3 {
    poly.iter().copied().sum::<DVec3>() / poly.len() as f64
}

/// The colour of `mesh`'s triangle `t` at barycentric weights `b`, as
/// sRGB: its texture's nearest texel, its vertex colours interpolated in
/// linear light and its material's factor, multiplied (the `blend` rule's
/// colour at one point); white where the triangle has none. What surface
/// samples carry.
pub fn colour_at(mesh: MeshRef<'_>, app: &Appearance, t: usize, b: [f64; 3]) -> [u8; 3] {
    let p = mesh.triangles[t].map(|v| mesh.positions[v as usize]);
    linear_to_rgb(Shader::new((mesh, app, ColourRule::Blend), t, p).linear_colour(b))
}

/// The colour of one triangle at a point: texture × factor × vertex colour.
struct Shader<'a> {
    rule: ColourRule,
    p0: DVec3,
    e1: DVec3,
    e2: DVec3,
    d: [f64; 4],
    texture: Option<(&'a Texture, [[f64; 2]; 3])>,
    factor: Option<[f64; 3]>,
    vertex: Option<[[u8; 3]; 3]>,
}

impl<'a> Shader<'a> {
    fn new((mesh, app, rule): (MeshRef<'a>, &'a Appearance, ColourRule), t: usize, p: [DVec3; 3]) -> Shader<'a> {
        let material = app.triangle_material.get(t).and_then(|&m| app.materials.get(m as usize));
        let uv = app.triangle_uv.get(t).map(|uv| uv.map(|c| [c[0] as f64, c[1] as f64]));
        let texture = match (material.and_then(|m| m.texture).and_then(|i| app.textures.get(i as usize)), uv) {
            (Some(tex), Some(uv)) if uv.iter().flatten().all(|c| c.is_finite()) && tex.width > 0 && tex.height > 0 => Some((tex, uv)),
            _ => None,
        };
        let factor = material.map(|m| m.factor.map(|f| f as f64)).filter(|f| *f != [1.0; 3]);
        let tri = mesh.triangles[t];
        let vertex = if app.vertex_colour.is_empty() {
            None
        } else {
            let get = |c: usize| app.vertex_colour.get(tri[c] as usize).copied().unwrap_or([255; 3]);
            Some([get(0), get(1), get(2)])
        };
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        Shader { rule, p0: p[0], e1, e2, d: [d00, d01, d11, d00 * d11 - d01 * d01], texture, factor, vertex }
    }

    /// Barycentric coordinates of `q` (on the triangle's plane), clamped.
    fn bary(&self, q: DVec3) -> [f64; 3] {
        let [d00, d01, d11, den] = self.d;
        if den <= 0.0 || !den.is_finite() {
            return [1.0, 0.0, 0.0];
        }
        let v = q - self.p0;
        let (d20, d21) = (v.dot(self.e1), v.dot(self.e2));
        let b1 = ((d11 * d20 - d01 * d21) / den).clamp(0.0, 1.0);
        let b2 = ((d00 * d21 - d01 * d20) / den).clamp(0.0, 1.0 - b1);
        [1.0 - b1 - b2, b1, b2]
    }

    fn uv(uv: &[[f64; 2]; 3], b: [f64; 3]) -> [f64; 2] {
        [0, 1].map(|a| b[0] * uv[0][a] + b[1] * uv[1][a] + b[2] * uv[2][a])
    }

    /// Samples the fan triangle `(a, b, c)` of area `area` (its corners'
    /// texture coordinates `uvs`, when there is a texture) on an `n × n`
    /// barycentric subdivision (`n²` cells of equal area, one sample at each centroid).
    fn sample(&self, [a, b, c]: [DVec3; 3], [ua, ub, uc]: [[f64; 2]; 3], area: f64, out: &mut Contribution, hist: &mut Vec<(u32, f64)>) {
        let n = match &self.texture {
            Some((tex, _)) => {
                let cross = (ub[0] - ua[0]) * (uc[1] - ua[1]) - (ub[1] - ua[1]) * (uc[0] - ua[0]);
                let texels = 0.5 * cross.abs() * tex.width as f64 * tex.height as f64;
                ((2.0 * texels).sqrt().ceil() as u32).clamp(1, MAX_SUBDIV)
            }
            None if self.vertex.is_some() => 4,
            None => 1,
        };
        let w = area / (n * n) as f64;
        let nf = n as f64;
        let (e1, e2) = (b - a, c - a);
        for i in 0..n {
            for j in 0..n - i {
                let (fi, fj) = (i as f64, j as f64);
                self.add(a + e1 * ((fi + 1.0 / 3.0) / nf) + e2 * ((fj + 1.0 / 3.0) / nf), w, out, hist);
                if i + j + 1 < n {
                    self.add(a + e1 * ((fi + 2.0 / 3.0) / nf) + e2 * ((fj + 2.0 / 3.0) / nf), w, out, hist);
                }
            }
        }
    }

    /// Adds one sample of weight `w` at `q`.
    fn add(&self, q: DVec3, w: f64, out: &mut Contribution, hist: &mut Vec<(u32, f64)>) {
        let b = self.bary(q);
        out.w += w;
        match self.rule {
            ColourRule::Dominant => {
                out.add_colour(hist, pack(self.dominant_colour(b)), w);
            }
            ColourRule::Blend => {
                let l = self.linear_colour(b);
                (0..3).for_each(|a| out.lin[a] += l[a] * w);
            }
        }
    }

    /// The exact source colour at `b`: the nearest texel, the nearest
    /// vertex's colour; multiplied in linear light only when there is a
    /// factor or both a texture and vertex colours.
    fn dominant_colour(&self, b: [f64; 3]) -> [u8; 3] {
        let texel = self.texture.map(|(tex, uv)| {
            let [u, v] = Self::uv(&uv, b);
            tex.texel(u, v)
        });
        let vertex = self.vertex.map(|vc| {
            let nearest = if b[0] >= b[1] && b[0] >= b[2] {
                0
            } else if b[1] >= b[2] {
                1
            } else {
                2
            };
            vc[nearest]
        });
        match (texel, vertex, self.factor) {
            (Some(c), None, None) | (None, Some(c), None) => c,
            (None, None, None) => [255; 3],
            (t, v, f) => {
                let mut l = [1.0; 3];
                for c in [t, v].into_iter().flatten() {
                    (0..3).for_each(|a| l[a] *= to_linear(c[a]));
                }
                if let Some(f) = f {
                    (0..3).for_each(|a| l[a] *= f[a]);
                }
                l.map(from_linear)
            }
        }
    }

    /// The colour at `b` in linear light, vertex colours interpolated.
    fn linear_colour(&self, b: [f64; 3]) -> [f64; 3] {
        let mut l = self.factor.unwrap_or([1.0; 3]);
        if let Some((tex, uv)) = self.texture {
            let [u, v] = Self::uv(&uv, b);
            let c = tex.texel(u, v);
            (0..3).for_each(|a| l[a] *= to_linear(c[a]));
        }
        if let Some(vc) = self.vertex {
            (0..3).for_each(|a| l[a] *= b[0] * to_linear(vc[0][a]) + b[1] * to_linear(vc[1][a]) + b[2] * to_linear(vc[2][a]));
        }
        l
    }
}
