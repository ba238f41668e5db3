//! Voxelization of 1D input (`line26`, `line6`): polylines, and triangle
//! meshes whose effective dimension is 1 (thin tubes).
//!
//! This work is based on: S. Laine, "A Topological Approach to
//! Voxelization", Computer Graphics Forum 32(4), 2013, §4 (1D input: the
//! target, not the primitive, decides connectivity).
//!
//! **Guarantee.**
//! - `line26`: voxel `(i,j,k)` is set iff some segment or triangle meets one
//!   of the three axis-aligned squares bisecting the voxel. A polyline gives
//!   a 26-connected run of voxels (a path leaving a voxel's bisecting
//!   squares' neighbourhood must cross a neighbour's square).
//! - `line6`: voxel `(i,j,k)` is set iff some segment or triangle meets the
//!   voxel's surface. A polyline gives a 6-connected run; a polyline lying
//!   entirely inside one voxel sets nothing (Laine's point-like input).
//!
//! Targets are displaced by the tie rule of [`crate::geom::perturb`], so a
//! polyline through a voxel corner or along a face is decided consistently.
//! Both are subsets of `cover`. Zero-length segments and zero-area
//! triangles are skipped like everywhere else.
//!
//! **Fast path.** Parallel over z-slabs. `line6` segments: the exact integer
//! line walk ([`super::ilv::lattice_path`]), no per-voxel test. `line26`
//! segments: walk the segment's layers along its dominant axis; in each
//! layer only the voxels within a one-voxel margin of the segment's span
//! are tested, exactly. Triangles:
//! `cover`'s traversal enumerates candidates, each tested exactly.
//!
//! **Reference:** [`reference::line`], the definition for every voxel of
//! each element's bounding box.

use super::cover::cover_triangle;
use super::driver::{run_slabs, Filter, Kernel, Primitive};
use super::ilv::{lattice_path, voxel_of};
use super::targets::{line26_hit, line6_hit, Element};
use super::{Options, Report, Traversal};
use crate::geom::fixed::ONE;
use crate::geom::lattice::{prepare, prepare_segments, LatticeSegment, PrepareStats};
use crate::grid::bricks::{BrickBits, BrickSlab};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

/// Which 1D target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineTarget {
    /// The three bisecting squares: 26-connected.
    Squares26,
    /// The voxel surface: 6-connected.
    Surface6,
}

impl LineTarget {
    /// The definition: does element `e` meet voxel `ijk`'s target?
    pub fn hit(self, e: &Element, ijk: [i64; 3]) -> bool {
        match self {
            LineTarget::Squares26 => line26_hit(e, ijk),
            LineTarget::Surface6 => line6_hit(e, ijk),
        }
    }
}

impl Primitive for Element {
    fn voxel_bounds(&self, dims: [u32; 3]) -> Option<([i64; 3], [i64; 3])> {
        match self {
            Element::Segment(s) => s.voxel_bounds(dims),
            Element::Triangle(t) => t.voxel_bounds(dims),
        }
    }
}

/// Snaps the mesh's segments and triangles (segments first).
pub fn prepare_elements(mesh: MeshRef<'_>, grid: &GridSpec) -> (Vec<Element>, PrepareStats) {
    let (segs, s1) = prepare_segments(mesh, grid);
    let (tris, s2) = prepare(mesh, grid);
    (segs.into_iter().map(Element::Segment).chain(tris.into_iter().map(Element::Triangle)).collect(), s1.merge(s2))
}

/// 1D voxelization, fast path, into sparse brick storage.
pub fn line(mesh: MeshRef<'_>, grid: &GridSpec, target: LineTarget, opts: &Options<'_>) -> (BrickBits, Report) {
    let (elems, prepare_stats) = prepare_elements(mesh, grid);
    let (bits, voxels) = run_slabs(&LineKernel { target, traversal: opts.traversal }, &elems, grid.dims(), opts);
    (bits, Report { prepare: prepare_stats, voxels })
}

/// The fast path on already prepared elements of a grid of `dims` (the
/// tiled driver hands it each tile's elements, translated).
pub fn line_lattice(elems: &[Element], dims: [u32; 3], target: LineTarget, opts: &Options<'_>) -> BrickBits {
    run_slabs(&LineKernel { target, traversal: opts.traversal }, elems, dims, opts).0
}

struct LineKernel {
    target: LineTarget,
    traversal: Traversal,
}

impl Kernel<Element> for LineKernel {
    fn run(&self, e: &Element, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        let keep = |i: i64, j: i64, k: i64| self.target.hit(e, [i, j, k]);
        match e {
            Element::Triangle(t) => cover_triangle(t, lo, hi, self.traversal, &mut Filter { slab, keep }),
            Element::Segment(s) => match self.target {
                LineTarget::Surface6 => surface6_segment(s, lo, hi, slab),
                LineTarget::Squares26 => walk_segment(s, lo, hi, &mut Filter { slab, keep }),
            },
        }
    }
}

/// `line6` for one segment, exactly: the voxels it passes through (the
/// integer line walk of [`super::ilv::lattice_path`]), or none when it stays
/// inside one voxel; those in `[lo, hi]` are set.
fn surface6_segment(s: &LatticeSegment, lo: [i64; 3], hi: [i64; 3], out: &mut impl super::driver::Sink) {
    let (a, b) = (s.v[0], s.v[1]);
    if voxel_of(a) == voxel_of(b) {
        return;
    }
    lattice_path(a, b, |p| {
        if (0..3).all(|x| lo[x] <= p[x] && p[x] <= hi[x]) {
            out.set(p[0] as u32, p[1] as u32, p[2] as u32);
        }
    });
}

/// Emits a superset of the voxels of `[lo, hi]` whose closed box meets the
/// segment: per layer along its dominant axis, the box spanned by the
/// segment's part in that layer, widened by one voxel.
fn walk_segment(s: &LatticeSegment, lo: [i64; 3], hi: [i64; 3], out: &mut impl super::driver::Sink) {
    let (a, b) = (s.v[0], s.v[1]);
    let d: [i64; 3] = std::array::from_fn(|x| b[x] - a[x]);
    let w = (0..3).fold(0, |best, x| if d[x].abs() > d[best].abs() { x } else { best });
    let one = ONE as f64;
    let at = |wc: f64, x: usize| a[x] as f64 + (wc - a[w] as f64) * d[x] as f64 / d[w] as f64;
    let (wmin, wmax) = (a[w].min(b[w]), a[w].max(b[w]));
    for t in lo[w]..=hi[w] {
        let w0 = ((t * ONE).max(wmin)) as f64;
        let w1 = (((t + 1) * ONE).min(wmax)) as f64;
        if w0 > w1 {
            continue;
        }
        let mut r = [(0i64, 0i64); 3];
        r[w] = (t, t);
        for x in (0..3).filter(|&x| x != w) {
            let (p, q) = (at(w0, x), at(w1, x));
            let first = ((p.min(q) / one).floor() as i64 - 1).max(lo[x]);
            let last = ((p.max(q) / one).floor() as i64 + 1).min(hi[x]);
            r[x] = (first, last);
        }
        for k in r[2].0..=r[2].1 {
            for j in r[1].0..=r[1].1 {
                for i in r[0].0..=r[0].1 {
                    out.set(i as u32, j as u32, k as u32);
                }
            }
        }
    }
}

/// The slow, obviously correct definition of `line26` and `line6`.
pub mod reference {
    use super::*;
    use crate::grid::dense::DenseBits;

    /// Brute force over each element's bounding box.
    pub fn line(mesh: MeshRef<'_>, grid: &GridSpec, target: LineTarget) -> (DenseBits, Report) {
        let (elems, prepare_stats) = prepare_elements(mesh, grid);
        let bits = super::super::brute_force(&elems, grid.dims(), |e, ijk| target.hit(e, ijk));
        let voxels = bits.count();
        (bits, Report { prepare: prepare_stats, voxels })
    }
}
