//! Triangles on the fixed-point lattice, and turning a mesh into them.
//!
//! [`prepare`] is shared by every voxelization path, so all of them see the
//! same snapped triangles and skip the same degenerate ones.

use glam::DVec3;
use rayon::prelude::*;

use super::clip::{clip_polygon_to_box, clip_segment_to_box};
use super::fixed::{snap, voxel_span, DIRECT_LIMIT_VOXELS, MAX_ABS};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

/// A triangle with vertices on the lattice (grid units × 4096).
///
/// # Guarantees
/// Built by [`prepare`]: every coordinate is within `±MAX_ABS` and the
/// triangle has non-zero area.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LatticeTriangle {
    /// The three vertices, in the mesh's winding order.
    pub v: [[i64; 3]; 3],
}

impl LatticeTriangle {
    /// Edge `i` runs from vertex `i` to vertex `i+1 (mod 3)`.
    #[inline]
    pub fn edge(&self, i: usize) -> [i64; 3] {
        let a = self.v[i];
        let b = self.v[(i + 1) % 3];
        [b[0] - a[0], b[1] - a[1], b[2] - a[2]]
    }

    /// The (unnormalised) normal `e0 × e1`; exact, fits in `i64` under the lattice bound.
    #[inline]
    pub fn normal(&self) -> [i64; 3] {
        cross(self.edge(0), self.edge(1))
    }

    /// The triangle moved by `shift` lattice units (the tiled driver moves
    /// triangles by whole voxels).
    pub fn translated(&self, shift: [i64; 3]) -> LatticeTriangle {
        LatticeTriangle { v: self.v.map(|p| add(p, shift)) }
    }

    /// Zero area: the three vertices are collinear (or coincide).
    pub fn is_degenerate(&self) -> bool {
        // Component by component: compared as an array, the three values
        // just computed were stored and reloaded as one wide load, which
        // stalled on the stores (store forwarding; 5 % of `cover` at 128³).
        let n = self.normal();
        (n[0] | n[1] | n[2]) == 0
    }

    /// Per-axis `(min, max)` lattice coordinates.
    #[inline]
    pub fn bounds(&self) -> ([i64; 3], [i64; 3]) {
        let mut lo = self.v[0];
        let mut hi = self.v[0];
        for p in &self.v[1..] {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        (lo, hi)
    }

    /// The inclusive range of voxel indices per axis whose closed boxes meet
    /// the triangle's bounding box, clamped to `dims`; `None` if empty.
    #[inline]
    pub fn voxel_bounds(&self, dims: [u32; 3]) -> Option<([i64; 3], [i64; 3])> {
        bounds_to_voxels(self.bounds(), dims)
    }
}

/// A segment of polyline input with end points on the lattice.
///
/// # Guarantees
/// Built by [`prepare_segments`]: coordinates within `±MAX_ABS`, non-zero length.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LatticeSegment {
    /// The two end points.
    pub v: [[i64; 3]; 2],
}

impl LatticeSegment {
    /// The segment moved by `shift` lattice units.
    pub fn translated(&self, shift: [i64; 3]) -> LatticeSegment {
        LatticeSegment { v: self.v.map(|p| add(p, shift)) }
    }

    /// Per-axis `(min, max)` lattice coordinates.
    #[inline]
    pub fn bounds(&self) -> ([i64; 3], [i64; 3]) {
        let (a, b) = (self.v[0], self.v[1]);
        (std::array::from_fn(|i| a[i].min(b[i])), std::array::from_fn(|i| a[i].max(b[i])))
    }

    /// Like [`LatticeTriangle::voxel_bounds`].
    pub fn voxel_bounds(&self, dims: [u32; 3]) -> Option<([i64; 3], [i64; 3])> {
        bounds_to_voxels(self.bounds(), dims)
    }
}

fn bounds_to_voxels((lo, hi): ([i64; 3], [i64; 3]), dims: [u32; 3]) -> Option<([i64; 3], [i64; 3])> {
    let mut a = [0i64; 3];
    let mut b = [0i64; 3];
    for ax in 0..3 {
        let (s, e) = voxel_span(lo[ax], hi[ax]);
        a[ax] = s.max(0);
        b[ax] = e.min(dims[ax] as i64 - 1);
        if a[ax] > b[ax] {
            return None;
        }
    }
    Some((a, b))
}

/// `a + b`, per coordinate.
#[inline]
fn add(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Exact cross product of two lattice vectors (inputs below 2^31 in magnitude).
#[inline]
pub fn cross(a: [i64; 3], b: [i64; 3]) -> [i64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// What [`prepare`] did with the input triangles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PrepareStats {
    /// Triangles in the input.
    pub input: u64,
    /// Skipped: an index past the end of the positions.
    pub invalid_index: u64,
    /// Skipped: a NaN or infinite coordinate.
    pub non_finite: u64,
    /// Skipped: zero area after snapping (the documented tie rule: a
    /// degenerate triangle draws nothing).
    pub degenerate: u64,
    /// Not voxelized because they lie entirely outside the grid.
    pub outside: u64,
    /// Reached beyond the lattice range and were clipped before snapping.
    pub clipped: u64,
    /// Lattice triangles produced (clipping may produce several per input).
    pub output: u64,
}

impl PrepareStats {
    /// Sums two reports.
    pub fn merge(mut self, o: PrepareStats) -> PrepareStats {
        self.input += o.input;
        self.invalid_index += o.invalid_index;
        self.non_finite += o.non_finite;
        self.degenerate += o.degenerate;
        self.outside += o.outside;
        self.clipped += o.clipped;
        self.output += o.output;
        self
    }
}

/// Snaps every triangle of `mesh` to the lattice of `grid`, skipping (and
/// counting) invalid, non-finite, degenerate and fully outside triangles.
/// The output order follows the input order, whatever the thread count.
pub fn prepare(mesh: MeshRef<'_>, grid: &GridSpec) -> (Vec<LatticeTriangle>, PrepareStats) {
    const CHUNK: usize = 4096;
    let snapped = SnappedMesh::new(mesh, grid);
    let parts: Vec<(Vec<LatticeTriangle>, PrepareStats)> = mesh
        .triangles
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut out = Vec::with_capacity(chunk.len());
            let mut st = PrepareStats::default();
            for tri in chunk {
                snapped.triangle(tri, &mut st, |t, _, _| out.push(*t));
            }
            (out, st)
        })
        .collect();
    let mut stats = PrepareStats::default();
    let mut tris = Vec::with_capacity(parts.iter().map(|p| p.0.len()).sum());
    for (t, s) in parts {
        tris.extend(t);
        stats = stats.merge(s);
    }
    (tris, stats)
}

/// Snaps one triangle (`tri` indexes `positions`) to the lattice of `grid`
/// exactly as [`prepare`] does, appending its lattice triangles (none if it
/// is skipped, several if it was clipped) to `out`.
pub fn prepare_triangle(positions: &[DVec3], tri: &[u32; 3], grid: &GridSpec, out: &mut Vec<LatticeTriangle>) {
    prepare_one(positions, tri, grid, out, &mut PrepareStats::default());
}

fn prepare_one(positions: &[DVec3], tri: &[u32; 3], grid: &GridSpec, out: &mut Vec<LatticeTriangle>, st: &mut PrepareStats) {
    st.input += 1;
    let mut g = [DVec3::ZERO; 3];
    for (c, &idx) in tri.iter().enumerate() {
        let Some(p) = positions.get(idx as usize) else {
            st.invalid_index += 1;
            return;
        };
        g[c] = grid.to_grid_units(*p);
    }
    if !g.iter().all(|p| p.is_finite()) {
        st.non_finite += 1;
        return;
    }
    let dims = DVec3::new(grid.dims()[0] as f64, grid.dims()[1] as f64, grid.dims()[2] as f64);
    // Cull triangles far from the grid's closed box [0, dims]. The margin of
    // one voxel keeps this f64 test conservative; the exact decision is made
    // on the snapped triangle by `voxel_bounds`.
    let lo = g[0].min(g[1]).min(g[2]);
    let hi = g[0].max(g[1]).max(g[2]);
    if hi.cmplt(DVec3::splat(-1.0)).any() || lo.cmpgt(dims + DVec3::ONE).any() {
        st.outside += 1;
        return;
    }
    let fits = g.iter().all(|p| p.abs().max_element() <= DIRECT_LIMIT_VOXELS);
    let before = out.len();
    if fits {
        push_snapped(g[0], g[1], g[2], grid.dims(), out, st);
    } else {
        clip_and_push(&g, grid.dims(), out, st);
        if out.len() == before {
            return;
        }
    }
    st.output += (out.len() - before) as u64;
}

/// The far branch of [`prepare_one`]: `g` (grid units, finite, not culled)
/// reaches beyond the lattice range, so it is clipped to the grid grown by
/// one voxel, fanned and snapped. Counts `clipped` and, if nothing is left,
/// `outside`; the caller counts `output`.
fn clip_and_push(g: &[DVec3; 3], dims_u: [u32; 3], out: &mut Vec<LatticeTriangle>, st: &mut PrepareStats) {
    let dims = DVec3::new(dims_u[0] as f64, dims_u[1] as f64, dims_u[2] as f64);
    st.clipped += 1;
    let poly = clip_polygon_to_box(g, DVec3::splat(-1.0), dims + DVec3::ONE);
    if poly.len() < 3 {
        st.outside += 1;
        return;
    }
    for w in 1..poly.len() - 1 {
        push_snapped(poly[0], poly[w], poly[w + 1], dims_u, out, st);
    }
}

fn push_snapped(a: DVec3, b: DVec3, c: DVec3, dims: [u32; 3], out: &mut Vec<LatticeTriangle>, st: &mut PrepareStats) {
    let s = |p: DVec3| [snap(p.x), snap(p.y), snap(p.z)];
    let t = LatticeTriangle { v: [s(a), s(b), s(c)] };
    debug_assert!(t.v.iter().flatten().all(|c| c.abs() <= MAX_ABS));
    if t.is_degenerate() {
        st.degenerate += 1;
        return;
    }
    if t.voxel_bounds(dims).is_none() {
        st.outside += 1;
        return;
    }
    out.push(t);
}

/// A mesh vertex in grid units, snapped once for all the triangles that
/// use it, with what [`prepare`]'s per-triangle tests need to know of it.
#[derive(Clone, Copy, Debug, Default)]
struct SnappedVertex {
    /// The snapped coordinates (valid when `flags & (NON_FINITE | FAR) == 0`;
    /// `|c| <= MAX_ABS < 2^31`).
    p: [i32; 3],
    /// [`NON_FINITE`], [`FAR`], and per axis `a` bit `BELOW << a` (grid
    /// units `< -1`) and `ABOVE << a` (`> dims + 1`).
    flags: u32,
}

const NON_FINITE: u32 = 1;
const FAR: u32 = 2;
const BELOW: u32 = 4;
const ABOVE: u32 = 32;
const CULL: u32 = (0b111 * BELOW) | (0b111 * ABOVE);

/// A mesh whose vertices are snapped to a grid's lattice, once each; its
/// triangles are then prepared exactly as [`prepare`] defines, without a
/// second conversion per corner. The triangle-parallel driver prepares
/// triangles through it one at a time, without storing them.
pub struct SnappedMesh<'a> {
    positions: &'a [DVec3],
    grid: GridSpec,
    verts: Vec<SnappedVertex>,
}

impl<'a> SnappedMesh<'a> {
    /// Snaps every vertex of `mesh` (in parallel).
    pub fn new(mesh: MeshRef<'a>, grid: &GridSpec) -> SnappedMesh<'a> {
        let g = *grid;
        let lim = DVec3::new(grid.dims()[0] as f64, grid.dims()[1] as f64, grid.dims()[2] as f64) + DVec3::ONE;
        let mut verts = vec![SnappedVertex::default(); mesh.positions.len()];
        verts.par_chunks_mut(8192).zip(mesh.positions.par_chunks(8192)).for_each(|(out, pos)| {
            for (o, p) in out.iter_mut().zip(pos) {
                let u = g.to_grid_units(*p);
                *o = if !u.is_finite() {
                    SnappedVertex { p: [0; 3], flags: NON_FINITE }
                } else {
                    let mut flags = 0;
                    for a in 0..3 {
                        flags |= ((u[a] < -1.0) as u32 * (BELOW << a)) | ((u[a] > lim[a]) as u32 * (ABOVE << a));
                    }
                    if u.abs().max_element() > DIRECT_LIMIT_VOXELS {
                        SnappedVertex { p: [0; 3], flags: flags | FAR }
                    } else {
                        SnappedVertex { p: [snap(u.x) as i32, snap(u.y) as i32, snap(u.z) as i32], flags }
                    }
                };
            }
        });
        SnappedMesh { positions: mesh.positions, grid: *grid, verts }
    }

    /// Prepares triangle `tri` as [`prepare`] does: counts it in `st` and
    /// calls `emit(triangle, lo, hi)` for each lattice triangle it yields
    /// (none if it is skipped, several if it was clipped), with its
    /// inclusive voxel box clamped to the grid.
    #[inline]
    pub fn triangle(&self, tri: &[u32; 3], st: &mut PrepareStats, mut emit: impl FnMut(&LatticeTriangle, [i64; 3], [i64; 3])) {
        let (Some(a), Some(b), Some(c)) =
            (self.verts.get(tri[0] as usize), self.verts.get(tri[1] as usize), self.verts.get(tri[2] as usize))
        else {
            st.input += 1;
            st.invalid_index += 1;
            return;
        };
        let any = a.flags | b.flags | c.flags;
        if any & (NON_FINITE | FAR | CULL) != 0 {
            if any & NON_FINITE == 0 && a.flags & b.flags & c.flags & CULL != 0 {
                // Every corner beyond the grid's margin on one side of one axis.
                st.input += 1;
                st.outside += 1;
                return;
            }
            if any & (NON_FINITE | FAR) != 0 {
                // Rare: the per-corner definition decides (and counts).
                let mut out = Vec::new();
                prepare_one(self.positions, tri, &self.grid, &mut out, st);
                let dims = self.grid.dims();
                for t in &out {
                    if let Some((lo, hi)) = t.voxel_bounds(dims) {
                        emit(t, lo, hi);
                    }
                }
                return;
            }
        }
        st.input += 1;
        let t = LatticeTriangle { v: [a.p.map(i64::from), b.p.map(i64::from), c.p.map(i64::from)] };
        if t.is_degenerate() {
            st.degenerate += 1;
            return;
        }
        let Some((lo, hi)) = t.voxel_bounds(self.grid.dims()) else {
            st.outside += 1;
            return;
        };
        st.output += 1;
        emit(&t, lo, hi);
    }
}

/// A world-space segment on the lattice of a grid, or why it is not.
pub(crate) enum SnappedSegment {
    /// A coordinate is NaN or infinite.
    NonFinite,
    /// It misses the grid grown by one voxel (`clipped`: found by clipping).
    Outside { clipped: bool },
    /// The snapped end points (possibly equal); `clipped` if it reached too
    /// far to snap directly and was clipped to the grown grid first.
    Ok { v: [[i64; 3]; 2], clipped: bool },
}

/// Snaps the segment `a → b` (world space) to `grid`'s lattice, clipping it
/// to the grid grown by one voxel only where it reaches too far to snap.
pub(crate) fn snap_segment(grid: &GridSpec, a: DVec3, b: DVec3) -> SnappedSegment {
    let dims = DVec3::new(grid.dims()[0] as f64, grid.dims()[1] as f64, grid.dims()[2] as f64);
    let (mut a, mut b) = (grid.to_grid_units(a), grid.to_grid_units(b));
    if !(a.is_finite() && b.is_finite()) {
        return SnappedSegment::NonFinite;
    }
    if a.max(b).cmplt(DVec3::splat(-1.0)).any() || a.min(b).cmpgt(dims + DVec3::ONE).any() {
        return SnappedSegment::Outside { clipped: false };
    }
    let clipped = a.abs().max_element() > DIRECT_LIMIT_VOXELS || b.abs().max_element() > DIRECT_LIMIT_VOXELS;
    if clipped {
        let Some((p, q)) = clip_segment_to_box(a, b, DVec3::splat(-1.0), dims + DVec3::ONE) else {
            return SnappedSegment::Outside { clipped: true };
        };
        (a, b) = (p, q);
    }
    let s = |p: DVec3| [snap(p.x), snap(p.y), snap(p.z)];
    SnappedSegment::Ok { v: [s(a), s(b)], clipped }
}

/// Snaps every segment of `mesh` to the lattice of `grid`, like [`prepare`]
/// does for triangles (zero-length segments count as degenerate).
pub fn prepare_segments(mesh: MeshRef<'_>, grid: &GridSpec) -> (Vec<LatticeSegment>, PrepareStats) {
    let mut st = PrepareStats::default();
    let mut out = Vec::with_capacity(mesh.segments.len());
    for seg in mesh.segments {
        st.input += 1;
        let (Some(a), Some(b)) = (mesh.positions.get(seg[0] as usize), mesh.positions.get(seg[1] as usize)) else {
            st.invalid_index += 1;
            continue;
        };
        let l = match snap_segment(grid, *a, *b) {
            SnappedSegment::NonFinite => {
                st.non_finite += 1;
                continue;
            }
            SnappedSegment::Outside { clipped } => {
                st.clipped += clipped as u64;
                st.outside += 1;
                continue;
            }
            SnappedSegment::Ok { v, clipped } => {
                st.clipped += clipped as u64;
                LatticeSegment { v }
            }
        };
        if l.v[0] == l.v[1] {
            st.degenerate += 1;
        } else if l.voxel_bounds(grid.dims()).is_none() {
            st.outside += 1;
        } else {
            out.push(l);
            st.output += 1;
        }
    }
    (out, st)
}
