//! A mesh of the voxels: the boundary faces of the set voxels, merged into
//! as few rectangles as a greedy sweep finds.
//!
//! This work is based on: the greedy meshing of M. Lysenko, "Meshing in a
//! Minecraft Game" (0 FPS, 2012): per axis and slice, the 2D mask of faces
//! between a set and an unset voxel, covered row by row by maximal runs
//! grown downwards while the next row holds the whole run.
//!
//! **Guarantee.** The quads cover exactly the faces between a set voxel and
//! an unset one (or the outside of the grid), each once, oriented outwards
//! (counter-clockwise seen from outside). So they bound exactly the set
//! voxels: a voxel centre is inside the quads iff the voxel is set. The
//! quads meet in T-junctions (they are not an edge-manifold mesh), which
//! ray-based inside tests and renderers do not mind.
//!
//! **Cost.** Three sweeps of 64-bit row masks over the grid (one over a
//! transposed copy for the faces across x), O(voxels / 64) words each plus
//! the output.

use crate::grid::dense::DenseBits;
use crate::grid::spec::GridSpec;
use crate::mesh::Mesh;

/// One rectangle of boundary faces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Quad {
    /// The axis the quad is perpendicular to.
    pub axis: usize,
    /// The outward normal points along `+axis` (else `-axis`).
    pub positive: bool,
    /// The quad's plane: voxel-corner coordinate along `axis`.
    pub at: u32,
    /// Corner-coordinate range `[start, end)` along axis `(axis + 1) % 3`.
    pub a: (u32, u32),
    /// The same along axis `(axis + 2) % 3`.
    pub b: (u32, u32),
    /// The class of the voxels behind the quad (a palette index for
    /// coloured meshes; 0 when uncoloured). Faces of different classes are
    /// never merged.
    pub class: u32,
}

impl Quad {
    /// The four corners (voxel-corner coordinates), counter-clockwise seen
    /// from the side the normal points to.
    pub fn corners(&self) -> [[u32; 3]; 4] {
        let (d, ax, bx) = (self.axis, (self.axis + 1) % 3, (self.axis + 2) % 3);
        let p = |a: u32, b: u32| {
            let mut c = [0u32; 3];
            (c[d], c[ax], c[bx]) = (self.at, a, b);
            c
        };
        let (a, b) = (self.a, self.b);
        // (ax, bx, d) is right-handed, so (a0,b0) → (a1,b0) → (a1,b1) turns
        // counter-clockwise seen from +d.
        let ccw = [p(a.0, b.0), p(a.1, b.0), p(a.1, b.1), p(a.0, b.1)];
        if self.positive {
            ccw
        } else {
            [ccw[0], ccw[3], ccw[2], ccw[1]]
        }
    }
}

/// The boundary of the set voxels as greedy quads.
pub fn greedy_quads(bits: &DenseBits) -> Vec<Quad> {
    greedy_quads_by_class(bits, &|_, _, _| 0)
}

/// [`greedy_quads`] where a face takes the class `class(i, j, k)` of the
/// set voxel behind it and only faces of one class merge (per-voxel
/// colours survive meshing).
pub fn greedy_quads_by_class(bits: &DenseBits, class: &(dyn Fn(u32, u32, u32) -> u32 + Sync)) -> Vec<Quad> {
    let [nx, ny, nz] = bits.dims();
    let mut quads = Vec::new();
    let wpr = bits.words_per_row();
    let words = bits.words();
    // Faces across z: slices k, rows j, bits i.
    sweep(
        nx,
        ny,
        nz,
        wpr,
        |r, s| &words[(s * ny as usize + r) * wpr..][..wpr],
        &|s, x, r| class(x, r, s),
        |s, x, r, pos, c| {
            quads.push(Quad { axis: 2, positive: pos, at: s, a: x, b: r, class: c });
        },
    );
    // Faces across y: slices j, rows k, bits i.
    sweep(
        nx,
        nz,
        ny,
        wpr,
        |r, s| &words[(r * ny as usize + s) * wpr..][..wpr],
        &|s, x, r| class(x, s, r),
        |s, x, r, pos, c| {
            quads.push(Quad { axis: 1, positive: pos, at: s, a: r, b: x, class: c });
        },
    );
    // Faces across x: a copy with bits along j, rows k, slices i.
    let mut t = DenseBits::new([ny, nz, nx]);
    bits.for_each_set(|i, j, k| t.set(j, k, i));
    let twpr = t.words_per_row();
    let tw = t.words();
    sweep(
        ny,
        nz,
        nx,
        twpr,
        |r, s| &tw[(s * nz as usize + r) * twpr..][..twpr],
        &|s, x, r| class(s, x, r),
        |s, x, r, pos, c| {
            quads.push(Quad { axis: 0, positive: pos, at: s, a: x, b: r, class: c });
        },
    );
    quads
}

/// One axis: for every slice boundary `s` in `0 ..= n`, the masks of faces
/// with the set voxel below (`+` normal) and above (`-` normal), then
/// greedy rectangles `(s, bit range, row range, positive, class)`, one
/// class at a time (`class(slice, bit, row)` of the voxel behind a face).
fn sweep<'a>(
    width: u32,
    height: u32,
    n: u32,
    wpr: usize,
    row: impl Fn(usize, usize) -> &'a [u64],
    class: &dyn Fn(u32, u32, u32) -> u32,
    mut emit: impl FnMut(u32, (u32, u32), (u32, u32), bool, u32),
) {
    let h = height as usize;
    let mut plus = vec![0u64; h * wpr];
    let mut minus = vec![0u64; h * wpr];
    for s in 0..=n as usize {
        let mut any = false;
        for r in 0..h {
            for w in 0..wpr {
                let below = if s > 0 { row(r, s - 1)[w] } else { 0 };
                let above = if s < n as usize { row(r, s)[w] } else { 0 };
                plus[r * wpr + w] = below & !above;
                minus[r * wpr + w] = above & !below;
                any |= (below ^ above) != 0;
            }
        }
        if !any {
            continue;
        }
        for (mask, pos) in [(&mut plus, true), (&mut minus, false)] {
            // The voxel behind a `+` face is in slice s − 1, behind a `−` face in slice s.
            let vs = if pos { s as u32 - (s > 0) as u32 } else { s as u32 };
            let classes = split_by_class(mask, wpr, |x, r| class(vs, x, r as u32));
            match classes {
                None => {
                    let c = class_of_first(mask, wpr, &|x, r| class(vs, x, r));
                    greedy_2d(mask, width, h, wpr, |x, r| emit(s as u32, x, r, pos, c));
                }
                Some(parts) => {
                    for (c, mut m) in parts {
                        greedy_2d(&mut m, width, h, wpr, |x, r| emit(s as u32, x, r, pos, c));
                    }
                    mask.iter_mut().for_each(|w| *w = 0);
                }
            }
        }
    }
}

/// Covers the set bits of `mask` (`h` rows of `wpr` words) with rectangles:
/// each maximal run of a row, grown over the following rows that hold the
/// whole run. Clears the mask.
fn greedy_2d(mask: &mut [u64], width: u32, h: usize, wpr: usize, mut emit: impl FnMut((u32, u32), (u32, u32))) {
    for r in 0..h {
        while let Some(x0) = next_set(&mask[r * wpr..(r + 1) * wpr], 0) {
            let x1 = next_clear(&mask[r * wpr..(r + 1) * wpr], x0, width);
            let mut r1 = r + 1;
            while r1 < h && all_set(&mask[r1 * wpr..(r1 + 1) * wpr], x0, x1) {
                clear(&mut mask[r1 * wpr..(r1 + 1) * wpr], x0, x1);
                r1 += 1;
            }
            clear(&mut mask[r * wpr..(r + 1) * wpr], x0, x1);
            emit((x0, x1), (r as u32, r1 as u32));
        }
    }
}

/// The first set bit at or after `from`.
/// `None` when every face of `mask` has the same class, else one mask per class (ascending).
fn split_by_class(mask: &[u64], wpr: usize, class: impl Fn(u32, usize) -> u32) -> Option<Vec<(u32, Vec<u64>)>> {
    let mut first = None;
    let mut parts: Vec<(u32, Vec<u64>)> = Vec::new();
    for (wi, &w) in mask.iter().enumerate() {
        let mut bits = w;
        while bits != 0 {
            let b = bits.trailing_zeros();
            bits &= bits - 1;
            let (r, x) = (wi / wpr, (wi % wpr) as u32 * 64 + b);
            let c = class(x, r);
            let f = *first.get_or_insert(c);
            if c == f && parts.is_empty() {
                continue;
            }
            if parts.is_empty() {
                // First differing face: bucket every face seen so far, then go on bucketing.
                parts.push((f, mask.iter().map(|_| 0).collect()));
                for (wj, &w2) in mask.iter().enumerate().take(wi + 1) {
                    let keep = if wj == wi { w2 & ((1u64 << b) - 1) } else { w2 };
                    parts[0].1[wj] = keep;
                }
            }
            let at = match parts.iter().position(|p| p.0 == c) {
                Some(at) => at,
                None => {
                    parts.push((c, vec![0; mask.len()]));
                    parts.len() - 1
                }
            };
            parts[at].1[wi] |= 1 << b;
        }
    }
    if parts.is_empty() {
        return None;
    }
    parts.sort_by_key(|p| p.0);
    Some(parts)
}

/// The class of the first face of `mask` (0 if empty): when all faces share one.
fn class_of_first(mask: &[u64], wpr: usize, class: &dyn Fn(u32, u32) -> u32) -> u32 {
    mask.iter().position(|&w| w != 0).map(|wi| class((wi % wpr) as u32 * 64 + mask[wi].trailing_zeros(), (wi / wpr) as u32)).unwrap_or(0)
}

fn next_set(row: &[u64], from: u32) -> Option<u32> {
    let mut w = (from / 64) as usize;
    let mut word = row.get(w)? & (!0u64 << (from % 64));
    loop {
        if word != 0 {
            return Some(w as u32 * 64 + word.trailing_zeros());
        }
        w += 1;
        word = *row.get(w)?;
    }
}

/// The first clear bit at or after `from` (or `width`).
fn next_clear(row: &[u64], from: u32, width: u32) -> u32 {
    let mut w = (from / 64) as usize;
    let mut word = !row[w] & (!0u64 << (from % 64));
    loop {
        if word != 0 {
            return (w as u32 * 64 + word.trailing_zeros()).min(width);
        }
        w += 1;
        if w >= row.len() {
            return width;
        }
        word = !row[w];
    }
}

/// The bits `[x0, x1)` as per-word masks.
fn word_masks(x0: u32, x1: u32) -> impl Iterator<Item = (usize, u64)> {
    let (w0, w1) = ((x0 / 64) as usize, ((x1 - 1) / 64) as usize);
    (w0..=w1).map(move |w| {
        let lo = if w == w0 { x0 % 64 } else { 0 };
        let hi = if w == w1 { (x1 - 1) % 64 } else { 63 };
        (w, (!0u64 >> (63 - hi)) & (!0u64 << lo))
    })
}

fn all_set(row: &[u64], x0: u32, x1: u32) -> bool {
    word_masks(x0, x1).all(|(w, m)| row[w] & m == m)
}

fn clear(row: &mut [u64], x0: u32, x1: u32) {
    for (w, m) in word_masks(x0, x1) {
        row[w] &= !m;
    }
}

/// The quads as a triangle mesh in world coordinates (two triangles per
/// quad, four vertices each).
pub fn quads_to_mesh(quads: &[Quad], grid: &GridSpec) -> Mesh {
    let mut positions = Vec::with_capacity(quads.len() * 4);
    let mut triangles = Vec::with_capacity(quads.len() * 2);
    let (o, s) = (grid.origin(), grid.voxel_size().0);
    for q in quads {
        let base = positions.len() as u32;
        for c in q.corners() {
            positions.push(o + glam::DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * s);
        }
        triangles.push([base, base + 1, base + 2]);
        triangles.push([base, base + 2, base + 3]);
    }
    Mesh { positions, triangles, segments: Vec::new() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::voxelize::solid;
    use glam::DVec3;

    fn blob(dims: [u32; 3], seed: u64, fill: u64) -> DenseBits {
        let mut b = DenseBits::new(dims);
        let mut rng = crate::test_rng::Xorshift(seed | 1);
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    if rng.below(100) < fill {
                        b.set(i, j, k);
                    }
                }
            }
        }
        b
    }

    #[test]
    fn classed_quads_cover_each_face_once_with_the_class_of_its_voxel() {
        for (seed, dims) in [(3u64, [7u32, 5, 6]), (11, [70, 3, 4]), (5, [4, 66, 3])] {
            let b = blob(dims, seed, 45);
            let class = |i: u32, j: u32, k: u32| (i * 7 + j * 3 + k) % 3;
            let quads = greedy_quads_by_class(&b, &class);
            let mut seen = std::collections::HashSet::new();
            for q in &quads {
                let (d, ax, bx) = (q.axis, (q.axis + 1) % 3, (q.axis + 2) % 3);
                for a in q.a.0..q.a.1 {
                    for c in q.b.0..q.b.1 {
                        let mut v = [0i64; 3];
                        v[d] = q.at as i64 - q.positive as i64;
                        v[ax] = a as i64;
                        v[bx] = c as i64;
                        let mut front = v;
                        front[d] += if q.positive { 1 } else { -1 };
                        assert!(b.get_signed(v[0], v[1], v[2]) && !b.get_signed(front[0], front[1], front[2]));
                        assert_eq!(class(v[0] as u32, v[1] as u32, v[2] as u32), q.class, "{q:?}");
                        assert!(seen.insert((v, q.axis, q.positive)), "face covered twice");
                    }
                }
            }
            let mut faces = 0;
            b.for_each_set(|i, j, k| {
                for d in 0..3 {
                    for s in [-1i64, 1] {
                        let mut n = [i as i64, j as i64, k as i64];
                        n[d] += s;
                        faces += !b.get_signed(n[0], n[1], n[2]) as usize;
                    }
                }
            });
            assert_eq!(seen.len(), faces);
            assert!(quads.len() >= greedy_quads(&b).len());
        }
    }

    #[test]
    fn one_voxel_is_six_outward_quads() {
        let mut b = DenseBits::new([3, 3, 3]);
        b.set(1, 1, 1);
        let q = greedy_quads(&b);
        assert_eq!(q.len(), 6);
        for quad in &q {
            let c = quad.corners();
            let e1 = [0, 1, 2].map(|a| c[1][a] as i64 - c[0][a] as i64);
            let e2 = [0, 1, 2].map(|a| c[2][a] as i64 - c[0][a] as i64);
            let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
            let want = if quad.positive { 1 } else { -1 };
            assert_eq!(n[quad.axis], want, "{quad:?}");
            assert_eq!(quad.at, if quad.positive { 2 } else { 1 });
        }
    }

    #[test]
    fn a_full_box_is_six_quads() {
        let mut b = DenseBits::new([70, 5, 4]);
        for k in 0..4 {
            for j in 0..5 {
                for i in 0..70 {
                    b.set(i, j, k);
                }
            }
        }
        assert_eq!(greedy_quads(&b).len(), 6);
    }

    #[test]
    fn the_quads_bound_exactly_the_set_voxels() {
        // Re-voxelizing the quads as a solid (centres inside) gives the voxels back.
        for (seed, dims, fill) in [(1u64, [9u32, 7, 8], 30u64), (2, [70, 5, 6], 55), (3, [4, 66, 5], 80), (4, [6, 5, 130], 45)] {
            let b = blob(dims, seed, fill);
            let quads = greedy_quads(&b);
            let grid = GridSpec::new(DVec3::new(-1.5, 2.0, 0.25), 0.5, dims.map(u64::from)).unwrap();
            let mesh = quads_to_mesh(&quads, &grid);
            let (solid, _) = solid::parity(mesh.as_ref(), &grid).unwrap();
            assert_eq!(solid.first_difference(&b), None, "seed {seed}: {} quads", quads.len());
            let faces: usize = quads.iter().map(|q| ((q.a.1 - q.a.0) * (q.b.1 - q.b.0)) as usize).sum();
            // Every boundary face once.
            let mut want = 0;
            b.for_each_set(|i, j, k| {
                for (d, s) in [(0usize, -1i64), (0, 1), (1, -1), (1, 1), (2, -1), (2, 1)] {
                    let mut p = [i as i64, j as i64, k as i64];
                    p[d] += s;
                    if !b.get_signed(p[0], p[1], p[2]) {
                        want += 1;
                    }
                }
            });
            assert_eq!(faces, want, "seed {seed}");
        }
    }
}
