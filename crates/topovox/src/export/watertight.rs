//! A watertight mesh of the voxels: the greedy quads of [`super::greedy`]
//! with every T-junction split.
//!
//! Greedy meshing merges faces into large quads, so a vertex of one quad
//! often lies in the middle of a neighbour's edge (a T-junction): the two
//! meshes meet geometrically but share no edge, and tools that check
//! topology (slicers, booleans, `trimesh.is_watertight`) see holes. Here
//! every quad edge is split at every quad corner lying inside it, so each
//! edge of the result is shared by the faces on both sides (twice for a
//! surface, four times where two voxels meet along an edge only). A quad
//! that needed no split stays a quad; a split one becomes a fan of
//! triangles around its centre (no degenerate triangles, no extra
//! vertices on edges).
//!
//! **Guarantee.** The faces cover exactly the greedy quads (the same
//! surface: the boundary of the set voxels), with the same orientation,
//! and no edge is used by a single face. Tested with `trimesh` and by
//! counting edges.
//!
//! **Cost.** One hash entry per quad corner and axis, then a binary search
//! per quad edge.

use std::collections::HashMap;

use super::greedy::Quad;

/// One face of the conformed mesh: a quad or a triangle, vertices in
/// doubled voxel-corner coordinates (`2 × corner`, so quad centres are
/// integers too), counter-clockwise seen from outside.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Face {
    /// Three or four vertices, doubled voxel-corner coordinates.
    pub vertices: Vec<[u32; 3]>,
    /// The class of the quad it came from (palette index + 1, or 0).
    pub class: u32,
    /// Index of the quad it came from.
    pub quad: usize,
}

/// The quads with their T-junctions split, as quads and triangles.
pub fn conform(quads: &[Quad]) -> Vec<Face> {
    // Every corner, on each axis line through it: (axis, the other two
    // coordinates) -> the corner's coordinate along the axis.
    let mut lines: HashMap<(u8, u32, u32), Vec<u32>> = HashMap::with_capacity(quads.len() * 6);
    for q in quads {
        for c in q.corners() {
            for a in 0..3 {
                lines.entry(key(a, c)).or_default().push(c[a]);
            }
        }
    }
    for v in lines.values_mut() {
        v.sort_unstable();
        v.dedup();
    }
    let mut out = Vec::with_capacity(quads.len() + quads.len() / 2);
    let mut ring: Vec<[u32; 3]> = Vec::with_capacity(16);
    for (qi, q) in quads.iter().enumerate() {
        let corners = q.corners();
        ring.clear();
        for e in 0..4 {
            let (p, r) = (corners[e], corners[(e + 1) % 4]);
            ring.push(p);
            let a = (0..3).find(|&a| p[a] != r[a]).unwrap_or(0);
            let on_line = lines.get(&key(a, p)).map(Vec::as_slice).unwrap_or(&[]);
            let (lo, hi) = (p[a].min(r[a]), p[a].max(r[a]));
            let from = on_line.partition_point(|&x| x <= lo);
            let to = on_line.partition_point(|&x| x < hi);
            let inner = &on_line[from..to];
            let mut at = |x: u32| {
                let mut v = p;
                v[a] = x;
                ring.push(v);
            };
            if p[a] < r[a] {
                inner.iter().for_each(|&x| at(x));
            } else {
                inner.iter().rev().for_each(|&x| at(x));
            }
        }
        let doubled = |c: [u32; 3]| c.map(|x| 2 * x);
        if ring.len() == 4 {
            out.push(Face { vertices: ring.iter().map(|&c| doubled(c)).collect(), class: q.class, quad: qi });
            continue;
        }
        // The centre: half the sum of opposite corners, doubled.
        let centre: [u32; 3] = std::array::from_fn(|a| corners[0][a] + corners[2][a]);
        for i in 0..ring.len() {
            out.push(Face { vertices: vec![centre, doubled(ring[i]), doubled(ring[(i + 1) % ring.len()])], class: q.class, quad: qi });
        }
    }
    out
}

#[inline]
fn key(axis: usize, c: [u32; 3]) -> (u8, u32, u32) {
    (axis as u8, c[(axis + 1) % 3], c[(axis + 2) % 3])
}

/// Counts edges by how many faces use them (position-based, as a mesh
/// tool merging vertices sees them): `(used once, used twice, used more)`.
pub fn edge_use(faces: &[Face]) -> (usize, usize, usize) {
    let mut count: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
    for f in faces {
        for i in 0..f.vertices.len() {
            let (a, b) = (f.vertices[i], f.vertices[(i + 1) % f.vertices.len()]);
            *count.entry(if a < b { (a, b) } else { (b, a) }).or_default() += 1;
        }
    }
    let mut r = (0, 0, 0);
    for &n in count.values() {
        match n {
            1 => r.0 += 1,
            2 => r.1 += 1,
            _ => r.2 += 1,
        }
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::greedy::greedy_quads;
    use crate::grid::dense::DenseBits;

    fn bits(dims: [u32; 3], set: &[[u32; 3]]) -> DenseBits {
        let mut b = DenseBits::new(dims);
        for p in set {
            b.set(p[0], p[1], p[2]);
        }
        b
    }

    #[test]
    fn an_l_shape_has_t_junctions_and_they_are_split() {
        // Two voxels side by side and one on top of the first: greedy
        // merges the bottom's side faces into long quads that meet the top
        // voxel's short ones in T-junctions.
        let b = bits([3, 3, 3], &[[0, 0, 0], [1, 0, 0], [0, 1, 0]]);
        let quads = greedy_quads(&b);
        let raw: Vec<Face> = quads
            .iter()
            .enumerate()
            .map(|(i, q)| Face { vertices: q.corners().map(|c| c.map(|x| 2 * x)).to_vec(), class: 0, quad: i })
            .collect();
        assert!(edge_use(&raw).0 > 0, "the greedy quads have T-junctions");
        let faces = conform(&quads);
        assert_eq!(edge_use(&faces).0, 0, "no edge used once");
        // Same area (doubled coordinates: 4x).
        let area = |f: &Face| {
            let v: Vec<[f64; 3]> = f.vertices.iter().map(|c| c.map(|x| x as f64 / 2.0)).collect();
            let mut s = [0.0; 3];
            for i in 1..v.len() - 1 {
                let (a, b) = (
                    [v[i][0] - v[0][0], v[i][1] - v[0][1], v[i][2] - v[0][2]],
                    [v[i + 1][0] - v[0][0], v[i + 1][1] - v[0][1], v[i + 1][2] - v[0][2]],
                );
                s[0] += a[1] * b[2] - a[2] * b[1];
                s[1] += a[2] * b[0] - a[0] * b[2];
                s[2] += a[0] * b[1] - a[1] * b[0];
            }
            (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt() / 2.0
        };
        let total: f64 = faces.iter().map(area).sum();
        assert!((total - 14.0).abs() < 1e-9, "{total}");
    }

    #[test]
    fn a_random_blob_is_closed() {
        let mut set = Vec::new();
        let mut x = 12345u64;
        for i in 0..6 {
            for j in 0..6 {
                for k in 0..6 {
                    x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    if (x >> 33) % 3 != 0 {
                        set.push([i, j, k]);
                    }
                }
            }
        }
        let faces = conform(&greedy_quads(&bits([6, 6, 6], &set)));
        assert_eq!(edge_use(&faces).0, 0);
    }
}
