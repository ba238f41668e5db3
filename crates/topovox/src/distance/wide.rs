//! The hierarchy of [`super::nearest`] four children wide, for its
//! nearest-piece queries: each node holds its children's boxes side by
//! side, so one query tests four boxes at once in f32 (vectorized), where
//! the binary tree tested one box per node in f64.
//!
//! **Method.** The binary tree is collapsed top-down (each node takes its
//! children, then replaces the child with the largest box by that child's
//! two children until it has four or only leaves; I. Wald, C. Benthin and
//! S. Boulos, "Getting Rid of Packets — Efficient SIMD Single-Ray
//! Traversal using Multi-branching BVHs", 2008; the collapse as in
//! embree's BVH4). A query visits nearer children first and skips a child
//! whose box lies farther than the best distance found.
//!
//! **Guarantee.** The f32 box distance is made a lower bound of the exact
//! one: each axis's gap is reduced by a slack that covers rounding the
//! point to f32 and the subtraction (2⁻²¹ of the coordinates' magnitude),
//! and the sum of squares by 2⁻²⁰ of itself for its roundings. A child is
//! skipped only when that bound exceeds the best squared distance, so no
//! piece that is as near is ever skipped and the result (the nearest
//! piece, the lowest numbered among equally near ones) is the binary
//! tree's, bit for bit. Coordinates past 10¹⁸ (whose squares could
//! overflow f32) are left to the binary tree.

use glam::{DVec3, Vec3};

/// A lane without a child.
const EMPTY: u32 = u32::MAX;

/// Coordinates (of the tree or the point) past which the binary tree
/// answers: their squares stay far below f32's largest.
pub(super) const WIDE_REACH: f64 = 1e18;

/// Four children's boxes (per axis, per lane) and what each is: a wide
/// node (`count == 0`, `child` its index) or a leaf (`count > 0`, `child`
/// its number in the list [`widen`] returns); `child == EMPTY` for an
/// unused lane.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Wide {
    lo: [[f32; 4]; 3],
    hi: [[f32; 4]; 3],
    child: [u32; 4],
    count: [u32; 4],
}

/// A binary node as [`super::nearest`] builds it: its box, and either its
/// pieces (`count > 0`) or its two children at `start` and `start + 1`.
pub(super) trait Binary {
    fn bounds(&self) -> (Vec3, Vec3);
    fn start(&self) -> u32;
    fn count(&self) -> u32;
}

/// The wide tree of a binary one (`nodes[0]` its root), and its leaves
/// (`start`, `count` of each, numbered as the lanes name them).
pub(super) fn widen<N: Binary>(nodes: &[N]) -> (Vec<Wide>, Vec<[u32; 2]>) {
    let mut leaves = Vec::new();
    let empty = Wide { lo: [[f32::INFINITY; 4]; 3], hi: [[f32::NEG_INFINITY; 4]; 3], child: [EMPTY; 4], count: [0; 4] };
    let mut wide = vec![empty];
    let mut todo = vec![(0usize, 0usize)];
    while let Some((b, w)) = todo.pop() {
        let n = &nodes[b];
        let mut kids: Vec<usize> = if n.count() > 0 { vec![b] } else { vec![n.start() as usize, n.start() as usize + 1] };
        while kids.len() < 4 {
            // The inner child with the largest box gives way to its two.
            let area = |k: usize| {
                let (lo, hi) = nodes[k].bounds();
                let e = (hi - lo).max(Vec3::ZERO);
                e.x * e.y + e.y * e.z + e.z * e.x
            };
            let open = (0..kids.len()).filter(|&i| nodes[kids[i]].count() == 0).max_by(|&a, &b| area(kids[a]).total_cmp(&area(kids[b])));
            let Some(i) = open else { break };
            let s = nodes[kids[i]].start() as usize;
            kids[i] = s;
            kids.push(s + 1);
        }
        let mut node = empty;
        for (lane, &k) in kids.iter().enumerate() {
            let (lo, hi) = nodes[k].bounds();
            for a in 0..3 {
                (node.lo[a][lane], node.hi[a][lane]) = (lo[a], hi[a]);
            }
            if nodes[k].count() > 0 {
                (node.child[lane], node.count[lane]) = (leaves.len() as u32, nodes[k].count());
                leaves.push([nodes[k].start(), nodes[k].count()]);
            } else {
                node.child[lane] = wide.len() as u32;
                todo.push((k, wide.len()));
                wide.push(empty);
            }
        }
        wide[w] = node;
    }
    (wide, leaves)
}

/// The pieces under each wide node, `[start, end)` in leaf order (a
/// subtree's leaves are adjacent there).
pub(super) fn spans(wide: &[Wide], leaves: &[[u32; 2]]) -> Vec<[u32; 2]> {
    let mut out = vec![[u32::MAX, 0]; wide.len()];
    // Children come after their parents: the last ones first.
    for w in (0..wide.len()).rev() {
        let mut span = [u32::MAX, 0];
        for l in 0..4 {
            let (c, n) = (wide[w].child[l], wide[w].count[l]);
            let s = match (c, n) {
                (EMPTY, _) => continue,
                (c, 0) => out[c as usize],
                (c, _) => [leaves[c as usize][0], leaves[c as usize][0] + leaves[c as usize][1]],
            };
            span = [span[0].min(s[0]), span[1].max(s[1])];
        }
        out[w] = span;
    }
    out
}

/// Lower bounds of the squared distances from `q` to a node's four boxes
/// (see the module doc); `slack` covers `q`'s rounding to f32.
#[inline(always)]
fn gaps(node: &Wide, q: [f32; 3], slack: f32) -> [f32; 4] {
    let mut d2 = [0f32; 4];
    for ((lo, hi), &qa) in node.lo.iter().zip(&node.hi).zip(&q) {
        for ((d, &l), &h) in d2.iter_mut().zip(lo).zip(hi) {
            let g = ((l - qa).max(qa - h) - slack).max(0.0);
            *d += g * g;
        }
    }
    d2.map(|d| d * (1.0 - 1.0 / (1u32 << 20) as f32))
}

/// The nearest piece to `q` by the wide tree: `visit(leaf, best)`
/// measures a leaf's pieces against the best so far and returns it;
/// `cut(node, best)` may skip a wide node by a bound of its own.
/// `reach` is the largest coordinate magnitude of the tree's boxes.
#[inline]
pub(super) fn nearest(
    wide: &[Wide],
    reach: f64,
    q: DVec3,
    mut best: (f64, u32),
    mut visit: impl FnMut(u32, (f64, u32)) -> (f64, u32),
    cut: impl Fn(u32, f64) -> bool,
) -> (f64, u32) {
    let qf = [q.x as f32, q.y as f32, q.z as f32];
    let slack = ((q.abs().max_element() + reach) / (1u64 << 21) as f64) as f32;
    // Each level pops one entry and pushes at most four; the binary tree
    // has at most 32 levels, so fewer than 128 entries are ever held.
    let mut stack = [(0u32, 0u32, 0f32); 128];
    let mut top = 1;
    while top > 0 {
        top -= 1;
        let (child, count, bound) = stack[top];
        // Checked again: the best may have improved since it was pushed.
        if f64::from(bound) > best.0 {
            continue;
        }
        if count > 0 {
            best = visit(child, best);
            continue;
        }
        if cut(child, best.0) {
            continue;
        }
        let node = &wide[child as usize];
        let d = gaps(node, qf, slack);
        // The lanes to visit, farthest first onto the stack, so the
        // nearest is popped first.
        let mut lanes = [(0f32, 0usize); 4];
        let mut n = 0;
        for (l, &dl) in d.iter().enumerate() {
            if node.child[l] != EMPTY && f64::from(dl) <= best.0 {
                lanes[n] = (dl, l);
                n += 1;
            }
        }
        // Farthest first (at most four: insertion, in place).
        for i in 1..n {
            let mut j = i;
            while j > 0 && lanes[j - 1].0 < lanes[j].0 {
                lanes.swap(j - 1, j);
                j -= 1;
            }
        }
        for &(dl, l) in &lanes[..n] {
            stack[top] = (node.child[l], node.count[l], dl);
            top += 1;
        }
    }
    best
}
