//! Certifying a voxel set's topology: components, separation, thinness and
//! tunnels (what `topovox check` reports).
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
//!
//! # Why it scales
//!
//! Separation needs no flood fill: a leaking path of unset voxels must step
//! between two adjacent unset voxels of different class, and classes change
//! along a row only at the parity toggles, so each pair of neighbouring rows
//! is compared at its toggles (one merged walk per row pair, only for row
//! pairs holding a toggle). Components are union–find over runs along `i`
//! (a few million at 1024³). Tunnels enumerate, per triangle, the
//! centre-to-centre segments whose bounding box meets it, visiting in each
//! row only the voxels whose plane value lets a segment cross. Past memory
//! the same code runs per window of brick layers, so work follows the set
//! voxels and the rows the surface crosses, never the grid's volume.

use std::ops::Range;

use rayon::prelude::*;
use rustc_hash::FxHashMap;

use super::inside::{snap_all, ClassifyError, Parity};
use super::runs::{Connectivity, Runs, StreamedComponents};
use crate::geom::fixed::ONE;
use crate::geom::lattice::LatticeTriangle;
use crate::geom::setup::{fits_i64, TriSetup};
use crate::grid::bricks::{Brick, BrickBits, BRICK};
use crate::grid::dense::DenseBits;
use crate::grid::sparse::SparseBricks;
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

/// Everything `topovox check` reports.
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
    let dims = bits.dims();
    let mut pass = Pass::new(dims, mesh)?;
    // One window, all triangles: moved out for the call (the window reads
    // only its argument), not copied.
    let tris = pass.mesh.as_mut().map(|m| std::mem::take(&mut m.tris)).unwrap_or_default();
    pass.window(bits, 0, 0..dims[2], &tris, &|_, _, _| false);
    Ok(pass.finish())
}

/// [`certify`] of a grid held as sparse bricks, without a dense grid: the
/// grid is checked window by window, each `layers` brick layers (8
/// planes each) thick plus one brick layer of halo on either side, and
/// what crosses a window's border is carried to the next (components by
/// a union–find over the labels of each window's last plane, the first
/// separation witness in `k` order). Memory follows one window and the
/// set voxels; the report equals [`certify`]'s for any `layers`.
pub fn certify_sparse(bits: &SparseBricks, mesh: Option<(MeshRef<'_>, &GridSpec)>, layers: u32) -> Result<CheckReport, ClassifyError> {
    let dims = bits.dims();
    let layers = layers.max(1);
    let mut pass = Pass::new(dims, mesh)?;
    let bz = dims[2].div_ceil(BRICK);
    let windows = sparse_windows(dims, layers) as usize;
    let span = layers * BRICK;
    // Each window's triangles: those within two voxels of its planes, halo
    // included (what the parity rows, tunnels and columns of the window need).
    let mut binned: Vec<Vec<u32>> = vec![Vec::new(); windows];
    if let Some(m) = &pass.mesh {
        for (n, t) in m.tris.iter().enumerate() {
            let (lo, hi) = t.bounds();
            let (klo, khi) = (lo[2].div_euclid(ONE) - 2 - BRICK as i64, hi[2].div_euclid(ONE) + 2 + BRICK as i64);
            if khi < 0 || klo >= dims[2] as i64 {
                continue;
            }
            let (w0, w1) = ((klo.max(0) as u64 / span as u64) as usize, ((khi.min(dims[2] as i64 - 1)) as u64 / span as u64) as usize);
            for bin in &mut binned[w0..=w1.min(windows - 1)] {
                bin.push(n as u32);
            }
        }
    }
    let beyond = |i: u32, j: u32, k: u32| bits.get(i, j, k);
    for (w, bin) in binned.into_iter().enumerate() {
        let owned_layers = w as u32 * layers..((w as u32 + 1) * layers).min(bz);
        let layers_held = owned_layers.start.saturating_sub(1)..(owned_layers.end + 1).min(bz);
        let base = layers_held.start * BRICK;
        let planes = (layers_held.end * BRICK).min(dims[2]) - base;
        let owned = owned_layers.start * BRICK..(owned_layers.end * BRICK).min(dims[2]);
        // A window without voxels (halo included) or triangles holds
        // nothing to count, join or separate: skipped without building its
        // brick index or rows, so an empty stretch of a vast grid costs
        // nothing.
        if bin.is_empty() && !bits.any_in_layers(layers_held.clone()) {
            pass.empty_window(&owned);
            continue;
        }
        let window = BrickWindow::new(bits, layers_held, [dims[0], dims[1], planes]);
        let tris: Vec<LatticeTriangle> = pass.mesh.as_ref().map(|m| bin.iter().map(|&n| m.tris[n as usize]).collect()).unwrap_or_default();
        pass.window(&window, base, owned, &tris, &beyond);
    }
    Ok(pass.finish())
}

/// How many windows [`certify_sparse`] cuts a grid of `dims` into, with
/// windows of `layers` brick layers.
pub fn sparse_windows(dims: [u32; 3], layers: u32) -> u32 {
    dims[2].div_ceil(BRICK).div_ceil(layers.max(1)).max(1)
}

/// What the checks read of one window of planes: a dense grid or the
/// bricks of a sparse one. Coordinates are the window's (`k` from its
/// first plane).
trait WindowBits: Sync {
    /// Voxels along x, y and the window's planes.
    fn dims(&self) -> [u32; 3];
    fn get(&self, i: u32, j: u32, k: u32) -> bool;
    /// [`WindowBits::get`], false outside the window.
    fn get_signed(&self, i: i64, j: i64, k: i64) -> bool {
        let d = self.dims();
        i >= 0 && j >= 0 && k >= 0 && i < d[0] as i64 && j < d[1] as i64 && k < d[2] as i64 && self.get(i as u32, j as u32, k as u32)
    }
    /// The runs of set voxels of the planes `planes`.
    fn runs(&self, planes: Range<u32>) -> Runs;
    /// Sums `f` over the set voxels of the planes `planes`, in parallel.
    fn sum_over_set<F: Fn(u32, u32, u32) -> bool + Sync>(&self, planes: Range<u32>, f: F) -> u64;
}

impl WindowBits for DenseBits {
    fn dims(&self) -> [u32; 3] {
        DenseBits::dims(self)
    }

    #[inline]
    fn get(&self, i: u32, j: u32, k: u32) -> bool {
        DenseBits::get(self, i, j, k)
    }

    fn runs(&self, planes: Range<u32>) -> Runs {
        Runs::of_planes(self, true, planes)
    }

    fn sum_over_set<F: Fn(u32, u32, u32) -> bool + Sync>(&self, planes: Range<u32>, f: F) -> u64 {
        let ny = self.dims()[1];
        planes
            .into_par_iter()
            .map(|k| {
                let mut n = 0u64;
                for j in 0..ny {
                    for_each_set_in_row(self, j, k, |i| n += f(i, j, k) as u64);
                }
                n
            })
            .sum()
    }
}

/// Brick layers of a sparse grid, indexed for random access
/// ([`BrickBits`]) and listed in key order (for runs and sums).
struct BrickWindow {
    dims: [u32; 3],
    index: WindowIndex,
    /// The window's bricks (window brick coordinates), sorted by `(bk, bj, bi)`.
    list: Vec<([u32; 3], Brick)>,
}

/// How [`BrickWindow::get`] finds a brick: a whole-window table (4 bytes
/// per brick of the window: fast) where it is small beside the bricks, a
/// hash map of the bricks where it is not (a few voxels in a 65536²-wide
/// window would need 800 MB of table).
enum WindowIndex {
    Table(BrickBits),
    Map(FxHashMap<[u32; 3], u32>),
}

/// Window bricks per stored brick up to which [`WindowIndex::Table`] is used.
const TABLE_PER_BRICK: u64 = 64;

impl BrickWindow {
    fn new(src: &SparseBricks, layers: Range<u32>, dims: [u32; 3]) -> BrickWindow {
        let mut list = Vec::new();
        src.for_each_brick_in_layers(layers.clone(), |b, bits| list.push(([b[0], b[1], b[2] - layers.start], *bits)));
        let table: u64 = dims.iter().map(|&d| u64::from(d.div_ceil(BRICK))).product();
        let index = if table <= TABLE_PER_BRICK * list.len() as u64 + (1 << 20) {
            let mut bits = BrickBits::new(dims);
            for (b, brick) in &list {
                bits.insert_brick(*b, *brick);
            }
            WindowIndex::Table(bits)
        } else {
            WindowIndex::Map(list.iter().enumerate().map(|(n, (b, _))| (*b, n as u32)).collect())
        };
        BrickWindow { dims, index, list }
    }
}

impl WindowBits for BrickWindow {
    fn dims(&self) -> [u32; 3] {
        self.dims
    }

    #[inline]
    fn get(&self, i: u32, j: u32, k: u32) -> bool {
        match &self.index {
            WindowIndex::Table(bits) => bits.get(i, j, k),
            WindowIndex::Map(map) => {
                assert!(i < self.dims[0] && j < self.dims[1] && k < self.dims[2], "voxel out of range");
                map.get(&[i / BRICK, j / BRICK, k / BRICK])
                    .is_some_and(|&n| (self.list[n as usize].1[(k % BRICK) as usize] >> ((j % BRICK) * BRICK + i % BRICK)) & 1 == 1)
            }
        }
    }

    fn runs(&self, planes: Range<u32>) -> Runs {
        let d = self.dims();
        Runs::of_bricks(d[0], d[1], planes, &self.list)
    }

    fn sum_over_set<F: Fn(u32, u32, u32) -> bool + Sync>(&self, planes: Range<u32>, f: F) -> u64 {
        let (lo, hi) = (
            self.list.partition_point(|(b, _)| b[2] < planes.start / BRICK),
            self.list.partition_point(|(b, _)| b[2] * BRICK < planes.end),
        );
        self.list[lo..hi]
            .par_chunks(1024)
            .map(|chunk| {
                let mut n = 0u64;
                for (b, bits) in chunk {
                    for (z, &word) in bits.iter().enumerate() {
                        let k = b[2] * BRICK + z as u32;
                        if !planes.contains(&k) {
                            continue;
                        }
                        let mut w = word;
                        while w != 0 {
                            let bit = w.trailing_zeros();
                            n += f(b[0] * BRICK + (bit & 7), b[1] * BRICK + (bit >> 3), k) as u64;
                            w &= w - 1;
                        }
                    }
                }
                n
            })
            .sum()
    }
}

/// What the checks gather over the windows of a grid.
struct Pass {
    dims: [u32; 3],
    voxels: u64,
    thick_voxels: u64,
    components: [StreamedComponents; 2],
    mesh: Option<MeshPass>,
}

struct MeshPass {
    tris: Vec<LatticeTriangle>,
    boundary_edges: usize,
    closed: bool,
    inside_voxels: u64,
    witness: [Option<[[u32; 3]; 2]>; 2],
    thin_removable: u64,
    tunnels: [u64; 3],
    columns: ColumnStats,
}

impl Pass {
    fn new(dims: [u32; 3], mesh: Option<(MeshRef<'_>, &GridSpec)>) -> Result<Pass, ClassifyError> {
        let mesh = match mesh {
            Some((mesh, grid)) => {
                let snapped = snap_all(mesh, grid)?;
                let tris = snapped.crossing_triangles();
                let closed = snapped.boundary_edges == 0 && !tris.is_empty();
                Some(MeshPass {
                    tris,
                    boundary_edges: snapped.boundary_edges,
                    closed,
                    inside_voxels: 0,
                    witness: [None; 2],
                    thin_removable: 0,
                    tunnels: [0; 3],
                    columns: ColumnStats::default(),
                })
            }
            None => None,
        };
        Ok(Pass {
            dims,
            voxels: 0,
            thick_voxels: 0,
            components: [StreamedComponents::new(Connectivity::Six), StreamedComponents::new(Connectivity::TwentySix)],
            mesh,
        })
    }

    /// Checks the planes `owned` (grid coordinates) of window `o`, whose
    /// first plane is the grid's `base`; `o` holds the planes next to
    /// `owned` wherever the grid has them. `tris` holds the triangles near
    /// the window; `beyond` reads voxels outside it.
    fn window<O: WindowBits>(
        &mut self,
        o: &O,
        base: u32,
        owned: Range<u32>,
        tris: &[LatticeTriangle],
        beyond: &(dyn Fn(u32, u32, u32) -> bool + Sync),
    ) {
        if owned.is_empty() {
            return;
        }
        let local = owned.start - base..owned.end - base;
        self.voxels += o.sum_over_set(local.clone(), |_, _, _| true);
        self.thick_voxels += thick_voxels(o, local.clone());
        let shared = local.start > 0;
        let runs = o.runs(local.start - shared as u32..local.end);
        for c in &mut self.components {
            c.add(&runs, shared);
        }
        drop(runs);
        let Some(m) = &mut self.mesh else { return };
        if m.closed {
            let parity = Parity::classify_planes(tris, self.dims, base..base + o.dims()[2]);
            m.inside_voxels += inside_count(&parity, o.dims(), local.clone());
            for (w, conn) in m.witness.iter_mut().zip([Connectivity::Six, Connectivity::TwentySix]) {
                if w.is_none() {
                    *w = witness(o, &parity, local.clone(), conn).map(|p| p.map(|v| [v[0], v[1], v[2] + base]));
                }
            }
            m.thin_removable += thin_removable(o, &parity, local.clone());
        }
        let t = tunnels(o, tris, self.dims, base, owned.clone());
        for (a, b) in m.tunnels.iter_mut().zip(t) {
            *a += b;
        }
        m.columns = m.columns.add(columns(o, tris, self.dims, base, owned, beyond));
    }

    /// [`Pass::window`] for a window with no set voxel and no triangle:
    /// nothing to add, and no run of its last plane for the next window to
    /// join.
    fn empty_window(&mut self, owned: &Range<u32>) {
        if owned.is_empty() {
            return;
        }
        for c in &mut self.components {
            c.add_empty();
        }
    }

    fn finish(self) -> CheckReport {
        CheckReport {
            voxels: self.voxels,
            components_6: self.components[0].count(),
            components_26: self.components[1].count(),
            thick_voxels: self.thick_voxels,
            mesh: self.mesh.map(|m| MeshFacts {
                boundary_edges: m.boundary_edges,
                closed: m.closed,
                tunnels_6: m.tunnels[0],
                tunnels_18: m.tunnels[1],
                tunnels_26: m.tunnels[2],
                columns: m.columns,
                separation: m.closed.then_some(Separation {
                    inside_voxels: m.inside_voxels,
                    witness_6: m.witness[0],
                    witness_26: m.witness[1],
                    thin_removable: m.thin_removable,
                }),
            }),
        }
    }
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

/// Voxel centres inside in the planes `planes` of a window.
fn inside_count(p: &Parity, dims: [u32; 3], planes: Range<u32>) -> u64 {
    planes
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
/// different class with the first in the planes `planes`, as `[inside,
/// outside]`. Only row pairs where either row has a toggle can differ in
/// class (a row without toggles is wholly outside).
fn witness<O: WindowBits>(o: &O, p: &Parity, planes: Range<u32>, conn: Connectivity) -> Option<[[u32; 3]; 2]> {
    let [nx, ny, nz] = o.dims();
    let offsets = forward_offsets(conn);
    planes.into_par_iter().find_map_first(|k| {
        // Rows j of plane k paired with a row holding toggles: (j, k)
        // itself, (j + 1, k), and (j + dj, k + 1) for dj in −1..=1.
        let mut rows: Vec<u32> = Vec::new();
        for j in 0..ny {
            if !p.row(j, k).is_empty() {
                rows.extend([j.saturating_sub(1), j]);
            }
            if k + 1 < nz && !p.row(j, k + 1).is_empty() {
                rows.extend([j.saturating_sub(1), j, (j + 1).min(ny - 1)]);
            }
        }
        rows.sort_unstable();
        rows.dedup();
        for &j in &rows {
            for d in &offsets {
                let (jj, kk) = (j as i64 + d[1], k as i64 + d[2]);
                if jj < 0 || jj >= ny as i64 || kk >= nz as i64 {
                    continue;
                }
                let (jj, kk) = (jj as u32, kk as u32);
                let (tr, tq) = (p.row(j, k), p.row(jj, kk));
                if tr.is_empty() && tq.is_empty() {
                    continue;
                }
                if let Some(w) = row_pair_witness(o, [tr, tq], [j, k], [jj, kk], d[0], nx) {
                    return Some(w);
                }
            }
        }
        None
    })
}

/// The first `i` where voxel `(i, r)` and `(i + di, q)` are both unset and
/// of different class, as `[inside, outside]`. The classes change only at
/// toggles (`toggles[0]` of row `r`, `toggles[1]` of row `q`, the latter
/// seen shifted by `−di`): one merged walk over both lists.
fn row_pair_witness<O: WindowBits>(o: &O, toggles: [&[u32]; 2], r: [u32; 2], q: [u32; 2], di: i64, nx: u32) -> Option<[[u32; 3]; 2]> {
    let (lo, hi) = (0i64.max(-di), (nx as i64).min(nx as i64 - di));
    let (tr, tq) = (toggles[0], toggles[1]);
    let (mut a, mut b) = (0usize, 0usize);
    let (mut cr, mut cq) = (false, false);
    let mut pos = lo;
    loop {
        // Classes at `pos`: every toggle at or before it passed.
        while a < tr.len() && tr[a] as i64 <= pos {
            cr = !cr;
            a += 1;
        }
        while b < tq.len() && tq[b] as i64 - di <= pos {
            cq = !cq;
            b += 1;
        }
        let next = tr.get(a).map_or(hi, |&t| t as i64).min(tq.get(b).map_or(hi, |&t| t as i64 - di)).min(hi);
        if cr != cq {
            for i in pos..next {
                let (ir, iq) = (i as u32, (i + di) as u32);
                if !o.get(ir, r[0], r[1]) && !o.get(iq, q[0], q[1]) {
                    let (u, v) = ([ir, r[0], r[1]], [iq, q[0], q[1]]);
                    return Some(if cr { [u, v] } else { [v, u] });
                }
            }
        }
        if next >= hi {
            return None;
        }
        pos = next;
    }
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

fn thin_removable<O: WindowBits>(o: &O, p: &Parity, planes: Range<u32>) -> u64 {
    let [nx, ny, nz] = o.dims();
    let six: Vec<[i64; 3]> = forward_offsets(Connectivity::Six).iter().flat_map(|d| [*d, d.map(|x| -x)]).collect();
    o.sum_over_set(planes, |i, j, k| {
        let c = p.inside(i, j, k);
        six.iter().all(|d| {
            let q = [i as i64 + d[0], j as i64 + d[1], k as i64 + d[2]];
            if q.iter().zip([nx, ny, nz]).any(|(&x, n)| x < 0 || x >= n as i64) {
                return true;
            }
            let q = q.map(|x| x as u32);
            o.get(q[0], q[1], q[2]) || p.inside(q[0], q[1], q[2]) == c
        })
    })
}

fn thick_voxels<O: WindowBits>(o: &O, planes: Range<u32>) -> u64 {
    let get = |i, j, k| o.get_signed(i, j, k);
    o.sum_over_set(planes, |i, j, k| {
        let (i, j, k) = (i as i64, j as i64, k as i64);
        (get(i - 1, j, k) || get(i + 1, j, k)) && (get(i, j - 1, k) || get(i, j + 1, k)) && (get(i, j, k - 1) || get(i, j, k + 1))
    })
}

/// The column statistics of the crossings in the planes `owned` of a grid
/// of `dims`, read from window `o` (first plane `base`) and, for runs
/// leaving it, from `beyond`.
fn columns<O: WindowBits>(
    o: &O,
    tris: &[LatticeTriangle],
    dims: [u32; 3],
    base: u32,
    owned: Range<u32>,
    beyond: &(dyn Fn(u32, u32, u32) -> bool + Sync),
) -> ColumnStats {
    let held = base as i64..(base + o.dims()[2]) as i64;
    let at = |q: [i64; 3]| {
        if held.contains(&q[2]) {
            o.get(q[0] as u32, q[1] as u32, (q[2] - base as i64) as u32)
        } else {
            beyond(q[0] as u32, q[1] as u32, q[2] as u32)
        }
    };
    let owned = owned.start as i64..owned.end as i64;
    tris.par_chunks(256)
        .map(|chunk| {
            let mut st = ColumnStats::default();
            for t in chunk {
                if fits_i64(t) {
                    columns_of::<i64>(&at, dims, &owned, t, &mut st);
                } else {
                    columns_of::<i128>(&at, dims, &owned, t, &mut st);
                }
            }
            st
        })
        .reduce(ColumnStats::default, ColumnStats::add)
}

fn columns_of<T: crate::geom::fixed::PlaneInt>(
    at: &impl Fn([i64; 3]) -> bool,
    dims: [u32; 3],
    owned: &Range<i64>,
    t: &LatticeTriangle,
    st: &mut ColumnStats,
) {
    let Some((mut lo, mut hi)) = t.voxel_bounds(dims) else { return };
    let (u, v, w) = crate::geom::setup::dominant_axes(t);
    if w != 2 {
        lo[2] = lo[2].max(owned.start);
        hi[2] = hi[2].min(owned.end - 1);
        if lo[2] > hi[2] {
            return;
        }
    }
    let s = TriSetup::<T>::new(t);
    let mut d = [0i64; 3];
    d[w] = ONE;
    let dw = s.dir(t, d);
    let n = t.normal();
    let h = ONE / 2;
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
            let tw = s.straddling_step(T::from_i64(n[w]), v0, T::from_i64(s.a[w])).to_i128();
            if tw < 0 || tw >= dims[w] as i128 {
                continue;
            }
            let mut ijk = [0i64; 3];
            (ijk[u], ijk[v], ijk[w]) = (iu, iv, tw as i64);
            if !owned.contains(&ijk[2]) {
                continue;
            }
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
/// Counted for the segments starting in the planes `owned` of a grid of
/// `dims`, read from window `o` whose first plane is `base`.
fn tunnels<O: WindowBits>(o: &O, tris: &[LatticeTriangle], dims: [u32; 3], base: u32, owned: Range<u32>) -> [u64; 3] {
    let offsets = forward_offsets_upto(3);
    let mut found: Vec<(u64, u8)> = tris
        .par_chunks(256)
        .flat_map_iter(|chunk| {
            let mut out = Vec::new();
            for t in chunk {
                if fits_i64(t) {
                    tunnels_of::<i64, O>(o, base, &owned, t, &offsets, dims, &mut out);
                } else {
                    tunnels_of::<i128, O>(o, base, &owned, t, &offsets, dims, &mut out);
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

fn tunnels_of<T: crate::geom::fixed::PlaneInt, O: WindowBits>(
    o: &O,
    base: u32,
    owned: &Range<u32>,
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
    let get = |i: i64, j: i64, k: i64| o.get(i as u32, j as u32, (k - base as i64) as u32);
    // The plane value grows by n_x·ONE per voxel along a row: only the
    // voxels of each row whose value lies in [vp_lo, vp_hi) are visited
    // (work along the plane, not through the box).
    let (lo_v, hi_v, step) = (vp_lo.to_i128(), vp_hi.to_i128(), s.n[0].to_i128() * ONE as i128);
    let ceil_div = |a: i128, b: i128| -((-a).div_euclid(b));
    for k in all_lo[2].max(owned.start as i64)..=all_hi[2].min(owned.end as i64 - 1) {
        for j in all_lo[1]..=all_hi[1] {
            let i0 = all_lo[0];
            let v0 = s.plane(s.local([i0 * ONE + h, j * ONE + h, k * ONE + h])).to_i128();
            let (first, last) = match step.signum() {
                0 if v0 >= lo_v && v0 < hi_v => (0, i128::MAX),
                0 => continue,
                1 => (ceil_div(lo_v - v0, step), (hi_v - 1 - v0).div_euclid(step)),
                _ => (ceil_div(v0 - hi_v + 1, -step), (v0 - lo_v).div_euclid(-step)),
            };
            let (first, last) = (i0 as i128 + first.max(0), (i0 as i128).saturating_add(last).min(all_hi[0] as i128));
            if first > last {
                continue;
            }
            for i in first as i64..=last as i64 {
                let pc = s.local([i * ONE + h, j * ONE + h, k * ONE + h]);
                let vp = s.plane(pc);
                if vp < vp_lo || vp >= vp_hi || get(i, j, k) {
                    continue;
                }
                for (di, (d, b)) in offsets.iter().zip(&boxes).enumerate() {
                    let Some((r, ds)) = b else { continue };
                    if i < r[0].0 || i > r[0].1 || j < r[1].0 || j > r[1].1 || k < r[2].0 || k > r[2].1 {
                        continue;
                    }
                    if get(i + d[0], j + d[1], k + d[2]) {
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
