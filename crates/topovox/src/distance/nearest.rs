//! Every voxel's exact distance: a bounding-volume hierarchy over the
//! pieces answers each voxel centre's nearest-piece query by branch and
//! bound (the definition is in [`super`]).
//!
//! **Method.** The hierarchy is built top-down, splitting each node's
//! pieces at the median of their box centres along the longest axis of
//! those centres' box, down to four pieces per leaf (as in I. Wald, "On
//! fast Construction of SAH-based Bounding Volume Hierarchies", 2007, with
//! the median for the surface-area heuristic: queries, not rays, visit
//! it). A query descends nearer child first and skips every node whose box
//! lies no nearer than the best distance found; queries walk the same tree
//! collapsed four children wide (`wide.rs`), which tests four boxes
//! at once and finds the same piece. Voxels are visited a row
//! (`k`) at a time, and the previous voxel's nearest piece gives the first
//! bound, so most queries open only the few nodes around that piece.
//!
//! **Guarantee.** A node is skipped only when no piece in it can be
//! strictly nearer, so each value is the minimum over all pieces of the
//! same per-piece distance the narrow band computes: equal bit for bit.
//! Rows are computed independently, so the thread count changes nothing.

use glam::{DVec3, Vec3};
use rayon::prelude::*;

use super::wide::{self, Wide, WIDE_REACH};
use super::{box_distance_squared, Piece, Pieces};
use crate::stop::Stop;
use crate::GridSpec;

const LEAF: usize = 4;

/// A node: its box; a leaf holds `order[start .. start + count]`, an
/// inner node (`count == 0`) its children at `start` and `start + 1`.
/// Boxes are f32, rounded outwards (so each holds its f64 box): 32 bytes
/// a node, two to a cache line.
#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    start: u32,
    count: u32,
}

/// `[lo, hi]` as f32, rounded outwards.
fn outward(lo: DVec3, hi: DVec3) -> (Vec3, Vec3) {
    // One f32 step towards −∞ (+∞ when `up`): the bits of a finite float
    // count its steps away from zero. (`f32::next_up` is newer than the MSRV.)
    let step = |f: f32, up: bool| -> f32 {
        if !f.is_finite() {
            return f;
        }
        if f == 0.0 {
            return if up { f32::from_bits(1) } else { -f32::from_bits(1) };
        }
        let b = f.to_bits();
        f32::from_bits(if (f > 0.0) == up { b + 1 } else { b - 1 })
    };
    let down = |v: f64| {
        let f = v as f32;
        if f as f64 > v {
            step(f, false)
        } else {
            f
        }
    };
    let up = |v: f64| {
        let f = v as f32;
        if (f as f64) < v {
            step(f, true)
        } else {
            f
        }
    };
    (Vec3::new(down(lo.x), down(lo.y), down(lo.z)), Vec3::new(up(hi.x), up(hi.y), up(hi.z)))
}

/// The squared distance from `q` to the f32 box `[lo, hi]` (a lower bound
/// of the distance to anything inside it).
#[inline(always)]
fn box_gap(lo: Vec3, hi: Vec3, q: DVec3) -> f64 {
    box_distance_squared(lo.as_dvec3(), hi.as_dvec3(), q)
}

/// Relative slack of an oriented box's bound (see [`Oriented::gap`]).
const ORIENTED_SLACK: f64 = 1e-12;

/// Wide nodes over at most this many pieces get an oriented box too.
const ORIENTED_MAX: u32 = 256;

/// A leaf: its pieces `start .. start + count` in leaf order, bounded.
#[derive(Clone, Copy, Debug)]
struct Leaf {
    start: u32,
    count: u32,
    bound: Oriented,
}

/// Pieces in a box oriented by the normal of their largest triangle: on
/// a smooth surface a few neighbouring pieces lie in a thin slab along
/// that normal, so a point beside them is bounded by its
/// height above the slab as well as its distance across, where the axis
/// box of triangles tilted against the axes lies well within the
/// distance. (The oriented-box idea of S. Gottschalk, M. C. Lin and D.
/// Manocha, "OBBTree", SIGGRAPH 1996, as a distance bound.)
#[derive(Clone, Copy, Debug)]
struct Oriented {
    /// Unit axes: two across, the normal last.
    axes: [DVec3; 3],
    /// The pieces' corners' extent along each axis, grown by a slack.
    lo: DVec3,
    hi: DVec3,
}

impl Oriented {
    fn new(pieces: &[Piece], reach: f64) -> Oriented {
        let widest = pieces
            .iter()
            .filter(|p| !p.flat)
            .map(|p| (p.p[1] - p.p[0]).cross(p.p[2] - p.p[0]))
            .max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()));
        let axes = match widest.map(DVec3::normalize).filter(|n| n.is_finite()) {
            Some(n) => {
                let u = if n.x.abs() < 0.9 { n.cross(DVec3::X) } else { n.cross(DVec3::Y) }.normalize();
                [u, n.cross(u).normalize(), n]
            }
            None => [DVec3::X, DVec3::Y, DVec3::Z],
        };
        let frame = |p: DVec3| DVec3::new(axes[0].dot(p), axes[1].dot(p), axes[2].dot(p));
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for c in pieces.iter().flat_map(|p| p.p) {
            (lo, hi) = (lo.min(frame(c)), hi.max(frame(c)));
        }
        let grow = DVec3::splat(reach * ORIENTED_SLACK);
        Oriented { axes, lo: lo - grow, hi: hi + grow }
    }

    /// A lower bound of the squared distance from `q` to the pieces: the
    /// distance to the oriented box, less `slack` an axis (it covers `q`'s
    /// rounding in the frame, as the growth covers the corners'; the axes
    /// are unit and orthogonal to within 10⁻¹⁵, so the frame keeps lengths
    /// to that), less 10⁻¹² of itself.
    #[inline(always)]
    fn gap(&self, q: DVec3, slack: f64) -> f64 {
        let f = DVec3::new(self.axes[0].dot(q), self.axes[1].dot(q), self.axes[2].dot(q));
        let d = ((self.lo - f).max(f - self.hi) - DVec3::splat(slack)).max(DVec3::ZERO);
        d.length_squared() * (1.0 - 1e-12)
    }
}

/// A bounding-volume hierarchy over the pieces of a mesh.
pub struct Hierarchy {
    nodes: Vec<Node>,
    order: Vec<u32>,
    /// The pieces' boxes in leaf order (f32, outwards): tested before a
    /// piece's own data is touched.
    boxes: Vec<(Vec3, Vec3)>,
    /// The pieces in leaf order, so a leaf's pieces are adjacent in memory.
    sorted: Vec<Piece>,
    /// The same tree four children wide ([`wide`]), which queries walk.
    wide: Vec<Wide>,
    /// Its leaves, each in an oriented box.
    leaves: Vec<Leaf>,
    /// The oriented box of each wide node over at most [`ORIENTED_MAX`]
    /// pieces.
    oriented: Vec<Option<Oriented>>,
    /// The largest coordinate magnitude of the root's box.
    reach: f64,
}

impl wide::Binary for Node {
    fn bounds(&self) -> (Vec3, Vec3) {
        (self.lo, self.hi)
    }
    fn start(&self) -> u32 {
        self.start
    }
    fn count(&self) -> u32 {
        self.count
    }
}

impl Hierarchy {
    /// Builds the hierarchy over `pieces`.
    pub fn new(pieces: &Pieces) -> Hierarchy {
        let mut order: Vec<u32> = (0..pieces.items.len() as u32).collect();
        let centres: Vec<DVec3> = pieces.items.iter().map(|p| (p.lo + p.hi) * 0.5).collect();
        let empty = Node { lo: Vec3::ZERO, hi: Vec3::ZERO, start: 0, count: 0 };
        let mut nodes = vec![empty];
        let mut todo = vec![(0usize, 0usize, order.len())];
        while let Some((node, start, end)) = todo.pop() {
            let ids = &mut order[start..end];
            let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            let (mut clo, mut chi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for &n in ids.iter() {
                let p = &pieces.items[n as usize];
                (lo, hi) = (lo.min(p.lo), hi.max(p.hi));
                let c = centres[n as usize];
                (clo, chi) = (clo.min(c), chi.max(c));
            }
            let (flo, fhi) = outward(lo, hi);
            if ids.len() <= LEAF {
                nodes[node] = Node { lo: flo, hi: fhi, start: start as u32, count: ids.len() as u32 };
                continue;
            }
            let ext = chi - clo;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let mid = ids.len() / 2;
            // Ties broken by piece number: the tree depends on the input only.
            ids.select_nth_unstable_by(mid, |&a, &b| centres[a as usize][axis].total_cmp(&centres[b as usize][axis]).then(a.cmp(&b)));
            let first = nodes.len();
            nodes.push(empty);
            nodes.push(empty);
            nodes[node] = Node { lo: flo, hi: fhi, start: first as u32, count: 0 };
            todo.push((first, start, start + mid));
            todo.push((first + 1, start + mid, end));
        }
        let sorted: Vec<Piece> = order.iter().map(|&n| pieces.items[n as usize]).collect();
        let boxes = sorted.iter().map(|p| outward(p.lo, p.hi)).collect();
        let (wide, spans) = wide::widen(&nodes);
        let reach = nodes[0].lo.abs().max(nodes[0].hi.abs()).max_element() as f64;
        let leaves = spans
            .iter()
            .map(|&[start, count]| Leaf { start, count, bound: Oriented::new(&sorted[start as usize..(start + count) as usize], reach) })
            .collect();
        let oriented = wide::spans(&wide, &spans)
            .iter()
            .map(|&[a, b]| (b - a <= ORIENTED_MAX).then(|| Oriented::new(&sorted[a as usize..b as usize], reach)))
            .collect();
        Hierarchy { nodes, order, boxes, sorted, wide, leaves, oriented, reach }
    }

    /// The box of every piece.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        (self.nodes[0].lo.as_dvec3(), self.nodes[0].hi.as_dvec3())
    }

    /// The squared distance from `q` to the nearest piece and that piece,
    /// given a piece whose squared distance `bound` is known (or
    /// `(f64::INFINITY, u32::MAX)`): only nearer pieces, or equally near
    /// ones with a smaller number, replace it. So among equally near pieces
    /// the lowest numbered is found, whatever the start.
    pub fn nearest(&self, q: DVec3, best: (f64, u32)) -> (f64, u32) {
        if self.reach <= WIDE_REACH && q.abs().max_element() <= WIDE_REACH {
            let slack = (q.abs().max_element() + self.reach) * ORIENTED_SLACK;
            let visit = |leaf: u32, best: (f64, u32)| {
                let l = &self.leaves[leaf as usize];
                if l.bound.gap(q, slack) > best.0 {
                    best
                } else {
                    self.leaf(l.start, l.count, q, best)
                }
            };
            let cut = |node: u32, best: f64| self.oriented[node as usize].as_ref().is_some_and(|o| o.gap(q, slack) > best);
            wide::nearest(&self.wide, self.reach, q, best, visit, cut)
        } else {
            self.nearest_binary(q, best)
        }
    }

    /// The best of `best` and the leaf's pieces `start .. start + count`.
    #[inline(always)]
    fn leaf(&self, start: u32, count: u32, q: DVec3, mut best: (f64, u32)) -> (f64, u32) {
        let leaf = start as usize..(start + count) as usize;
        for (i, (b, &n)) in leaf.clone().zip(self.boxes[leaf.clone()].iter().zip(&self.order[leaf])) {
            if box_gap(b.0, b.1, q) <= best.0 {
                let d = self.sorted[i].distance_squared(q);
                if d < best.0 || (d == best.0 && n < best.1) {
                    best = (d, n);
                }
            }
        }
        best
    }

    /// [`Hierarchy::nearest`] by the binary tree (coordinates past
    /// 10¹⁸, whose squares could overflow the wide walk's f32; and the
    /// reference the wide walk is tested against).
    pub fn nearest_binary(&self, q: DVec3, mut best: (f64, u32)) -> (f64, u32) {
        // Median splits of < 2^32 pieces make at most 32 levels, each
        // leaving one node on the stack: 64 slots never fill.
        let mut stack: [u32; 64] = [0; 64];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            // Checked again: the best may have improved since it was pushed.
            if box_gap(node.lo, node.hi, q) > best.0 {
                continue;
            }
            if node.count > 0 {
                best = self.leaf(node.start, node.count, q, best);
                continue;
            }
            let (a, b) = (node.start, node.start + 1);
            let (na, nb) = (&self.nodes[a as usize], &self.nodes[b as usize]);
            let (da, db) = (box_gap(na.lo, na.hi, q), box_gap(nb.lo, nb.hi, q));
            // Nearer child on top of the stack, visited first; a child no
            // nearer than the best found is not pushed at all.
            let ((far, df), (near, dn)) = if da <= db { ((b, db), (a, da)) } else { ((a, da), (b, db)) };
            if df <= best.0 {
                stack[top] = far;
                top += 1;
            }
            if dn <= best.0 {
                stack[top] = near;
                top += 1;
            }
        }
        best
    }
}

/// The distance from every voxel centre of `grid` to the nearest piece,
/// world units, as f32 in C order (`[i][j][k]`, `k` fastest, the layout of
/// `.npy`). `None` when `stop` was requested.
pub fn dense(pieces: &Pieces, grid: &GridSpec, stop: &Stop) -> Option<Vec<f32>> {
    let tree = Hierarchy::new(pieces);
    let [nx, ny, nz] = grid.dims().map(|d| d as usize);
    let mut out = vec![0f32; nx * ny * nz];
    out.par_chunks_mut(nz).enumerate().for_each(|(row, values)| {
        if stop.requested() {
            return;
        }
        let (i, j) = ((row / ny) as u32, (row % ny) as u32);
        let mut best = (f64::INFINITY, u32::MAX);
        for (k, v) in values.iter_mut().enumerate() {
            let q = grid.voxel_center([i, j, k as u32]);
            // The previous voxel's nearest piece bounds this one's distance.
            let start = if best.1 == u32::MAX {
                best
            } else {
                (pieces.items[best.1 as usize].distance_squared(q) * (1.0 + 1e-12) + f64::MIN_POSITIVE, best.1)
            };
            best = tree.nearest(q, start);
            *v = best.0.sqrt() as f32;
        }
    });
    (!stop.requested()).then_some(out)
}
