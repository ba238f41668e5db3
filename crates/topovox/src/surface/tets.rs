//! Marching tetrahedra on Kuhn's triangulation of the lattice: the surface
//! between the inside and outside lattice points, closed and 2-manifold by
//! construction.
//!
//! **Method.** A. Doi and A. Koide, "An Efficient Method of Triangulating
//! Equi-Valued Surfaces by Using Tetrahedral Cells" (1991), on the
//! Freudenthal–Kuhn triangulation (H. W. Kuhn, "Some Combinatorial Lemmas
//! in Topology", 1960): each lattice cube `c + [0,1]³` is split into six
//! tetrahedra `c, c+e_a, c+e_a+e_b, c+(1,1,1)` along its main diagonal,
//! the same split in every cube, so neighbouring cubes agree on their
//! shared faces and every edge of the triangulation is `p → p + e_S` for a
//! non-empty set `S` of axes. Each tetrahedron whose corners are not all
//! inside or all outside gets one triangle (one corner apart) or two (two
//! and two), with a vertex on each edge between an inside and an outside
//! corner. Points outside the grid are outside.
//!
//! **Guarantee.** The surface is the zero set of the piecewise-linear
//! function that is negative on inside points and positive on outside
//! points (whatever point of each crossing edge the caller puts a vertex
//! at, strictly between its ends), a function with no zero at a lattice
//! point: so it is a closed 2-manifold (each edge in two triangles, each
//! vertex's triangles one disk), it separates every inside point from every
//! outside one, and it meets itself only along shared edges and vertices.
//! Triangles are oriented with the inside behind them: the orientation is
//! decided in integers on the lattice (the sign does not depend on where
//! on its edges the caller puts each vertex, see `orient`). Vertex ids
//! number the crossing edges in order of their inside end (layer, row,
//! `i`) and direction, so the result is the same for any thread count.
//!
//! **Cost.** Only cubes around boundary points (inside points with an
//! outside neighbour) are visited, found with word operations on the bit
//! rows: proportional to the surface, not the volume, after one pass over
//! the words.

use rayon::prelude::*;

use crate::grid::dense::DenseBits;
use crate::stop::Stop;

/// The surface's combinatorics: each vertex is a crossing edge (inside
/// lattice point, outside lattice point, signed coordinates), each
/// triangle three vertices, oriented with the inside behind.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Extracted {
    /// The crossing edges, one per vertex: `(inside point, outside point)`.
    pub crossings: Vec<([i64; 3], [i64; 3])>,
    /// Triangles on those vertices.
    pub triangles: Vec<[u32; 3]>,
}

/// The six tetrahedra of a cube, as corner codes (`x = 1, y = 2, z = 4`).
const TETS: [[u8; 4]; 6] = [[0, 1, 3, 7], [0, 1, 5, 7], [0, 2, 3, 7], [0, 2, 6, 7], [0, 4, 5, 7], [0, 4, 6, 7]];

/// A crossing edge by its inside end and direction: `0..7` is
/// `+e_S`, `7..14` is `−e_S`, for the axis set `S = 1 + (dir % 7)`.
type Edge = ([i64; 3], u8);

/// The `±e_S` of a direction.
fn step(dir: u8) -> [i64; 3] {
    let (s, sign) = (dir % 7 + 1, if dir < 7 { 1 } else { -1 });
    [(s & 1) as i64 * sign, (s >> 1 & 1) as i64 * sign, (s >> 2 & 1) as i64 * sign]
}

/// One layer's boundary points (inside points with an outside neighbour
/// among their 26), in `(j, i)` order, with which of their 14 triangulation
/// edges cross and where each point's first vertex id starts.
struct Layer {
    /// `row_start[j]..row_start[j + 1]` index the points of row `j`.
    row_start: Vec<u32>,
    /// The points' `i`.
    i: Vec<u32>,
    /// Crossing edges, one bit per direction.
    mask: Vec<u16>,
    /// Vertex id of each point's first crossing edge.
    first: Vec<u32>,
}

impl Layer {
    /// The vertex id of a crossing edge whose inside end lies in this layer.
    fn id(&self, p: [i64; 3], dir: u8) -> u32 {
        let j = p[1] as usize;
        let row = self.row_start[j] as usize..self.row_start[j + 1] as usize;
        let n = row.start + self.i[row].binary_search(&(p[0] as u32)).expect("a crossing's inside end is a boundary point");
        self.first[n] + (self.mask[n] & ((1u16 << dir) - 1)).count_ones()
    }
}

/// The surface between the set and clear points of `labels`. `None` when
/// `stop` was requested.
pub fn extract(labels: &DenseBits, stop: &Stop) -> Option<Extracted> {
    let mut all = Extracted::default();
    let whole = extract_slabs(labels, labels.dims()[2].max(1), stop, |s| {
        all.crossings.extend(s.crossings);
        all.triangles.extend(s.triangles);
        Ok::<(), std::convert::Infallible>(())
    });
    match whole {
        Ok(done) => done.map(|()| all),
        Err(never) => match never {},
    }
}

/// One slab of the surface ([`extract_slabs`]): the vertices whose inside
/// end lies in its layers, numbered on from `first_vertex`, and the
/// triangles among them and the previous slab's vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Slab {
    /// The id of the first of `crossings`.
    pub first_vertex: u32,
    /// The crossing edges of this slab's vertices, in id order.
    pub crossings: Vec<([i64; 3], [i64; 3])>,
    /// Triangles on this slab's vertices and the previous slab's.
    pub triangles: Vec<[u32; 3]>,
}

/// The same surface as [`extract`], handed to `each` slab by slab, in
/// order: `thickness` layers of vertices at a time, with every triangle
/// whose vertices have all been handed out (the cubes whose upper layer
/// is the slab's last wait for the next slab). Concatenated, the slabs
/// are [`extract`]'s result for any `thickness`; only two slabs' layers
/// are held at once. `Ok(None)` when `stop` was requested; `each`'s first
/// error ends it.
pub fn extract_slabs<E>(
    labels: &DenseBits,
    thickness: u32,
    stop: &Stop,
    mut each: impl FnMut(Slab) -> Result<(), E>,
) -> Result<Option<()>, E> {
    let nz = labels.dims()[2];
    let mut previous: Option<Layer> = None;
    let mut next = 0u32;
    let mut k0 = 0u32;
    while k0 < nz {
        let k1 = k0.saturating_add(thickness.max(1)).min(nz);
        if stop.requested() {
            return Ok(None);
        }
        let mut fresh: Vec<Layer> = (k0..k1).into_par_iter().map(|k| layer(labels, k)).collect();
        // Vertex ids in order of (k, j, i, direction): the same for any
        // threads and any thickness.
        let first_vertex = next;
        for l in &mut fresh {
            for &m in &l.mask {
                l.first.push(next);
                next += m.count_ones();
            }
        }
        let crossings = fresh.par_iter().enumerate().flat_map_iter(|(n, l)| crossings(l, k0 as i64 + n as i64)).collect();
        let window = Window { base: k0 as i64 - previous.is_some() as i64, layers: previous.iter().chain(&fresh).collect() };
        // Cubes k0 − 1 .. k1 − 1 (their upper layer is handed out), and the
        // last layer's cubes, whose upper layer is outside the grid.
        let end = if k1 == nz { k1 as i64 } else { k1 as i64 - 1 };
        let tris: Option<Vec<Vec<[u32; 3]>>> =
            (k0 as i64 - 1..end).into_par_iter().map(|k| (!stop.requested()).then(|| layer_triangles(labels, &window, k))).collect();
        let Some(tris) = tris else { return Ok(None) };
        each(Slab { first_vertex, crossings, triangles: tris.into_iter().flatten().collect() })?;
        previous = fresh.pop();
        k0 = k1;
    }
    Ok(Some(()))
}

/// Consecutive layers from layer `base`.
struct Window<'a> {
    base: i64,
    layers: Vec<&'a Layer>,
}

impl Window<'_> {
    /// Layer `k`, if held.
    fn get(&self, k: i64) -> Option<&Layer> {
        usize::try_from(k - self.base).ok().and_then(|n| self.layers.get(n).copied())
    }
}

/// A layer's crossing edges as (inside point, outside point), in id order.
fn crossings(l: &Layer, k: i64) -> impl Iterator<Item = ([i64; 3], [i64; 3])> + '_ {
    (0..l.row_start.len() - 1).flat_map(move |j| {
        (l.row_start[j] as usize..l.row_start[j + 1] as usize).flat_map(move |n| {
            let p = [l.i[n] as i64, j as i64, k];
            (0..14u8).filter(move |d| l.mask[n] >> d & 1 == 1).map(move |d| {
                let s = step(d);
                (p, [p[0] + s[0], p[1] + s[1], p[2] + s[2]])
            })
        })
    })
}

/// Layer `k`'s boundary points and their crossing edges.
fn layer(labels: &DenseBits, k: u32) -> Layer {
    let ny = labels.dims()[1];
    let points = boundary_points(labels, k);
    let mut row_start = vec![0u32; ny as usize + 1];
    for &(j, _) in &points {
        row_start[j as usize + 1] += 1;
    }
    for j in 0..ny as usize {
        row_start[j + 1] += row_start[j];
    }
    let crossing = |p: [i64; 3], d: u8| {
        let s = step(d);
        !labels.get_signed(p[0] + s[0], p[1] + s[1], p[2] + s[2])
    };
    let mask = points
        .iter()
        .map(|&(j, i)| (0..14u8).filter(|&d| crossing([i as i64, j as i64, k as i64], d)).fold(0u16, |m, d| m | 1 << d))
        .collect();
    Layer { row_start, i: points.iter().map(|&(_, i)| i).collect(), mask, first: Vec::with_capacity(points.len()) }
}

/// The `(j, i)` of layer `k`'s inside points that have an outside point
/// among their 26 neighbours (or lie on the grid's border).
fn boundary_points(labels: &DenseBits, k: u32) -> Vec<(u32, u32)> {
    let [_, ny, nz] = labels.dims();
    let w = labels.words_per_row();
    let row = |j: i64, k: i64| -> Option<&[u64]> {
        ((0..ny as i64).contains(&j) && (0..nz as i64).contains(&k)).then(|| {
            let start = (k as usize * ny as usize + j as usize) * w;
            &labels.words()[start..start + w]
        })
    };
    let mut out = Vec::new();
    let mut interior = vec![0u64; w];
    for j in 0..ny {
        let me = row(j as i64, k as i64).expect("in the grid");
        if me.iter().all(|&x| x == 0) {
            continue;
        }
        interior.fill(!0);
        for dk in -1..=1 {
            for dj in -1..=1 {
                match row(j as i64 + dj, k as i64 + dk) {
                    Some(r) => and_with_neighbours(&mut interior, r),
                    None => interior.fill(0),
                }
            }
        }
        for (n, (&m, &inn)) in me.iter().zip(&interior).enumerate() {
            let mut b = m & !inn;
            while b != 0 {
                out.push((j, (n * 64) as u32 + b.trailing_zeros()));
                b &= b - 1;
            }
        }
    }
    out
}

/// `acc &= r & (r shifted by one either way)`: the points whose row
/// neighbours `i − 1, i, i + 1` are all set in `r`.
fn and_with_neighbours(acc: &mut [u64], r: &[u64]) {
    for (n, a) in acc.iter_mut().enumerate() {
        let [me, left, right] = super::row_words(r, n);
        *a &= me & left & right;
    }
}

/// The triangles of the cubes with lower corner in layer `k` (−1 included)
/// that have a boundary point as a corner.
fn layer_triangles(labels: &DenseBits, layers: &Window<'_>, k: i64) -> Vec<[u32; 3]> {
    let mut cells: Vec<(i64, i64)> = Vec::new();
    for kk in [k, k + 1] {
        if let Some(l) = layers.get(kk) {
            for j in 0..l.row_start.len() - 1 {
                for n in l.row_start[j] as usize..l.row_start[j + 1] as usize {
                    for (dj, di) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                        cells.push((j as i64 - dj, l.i[n] as i64 - di));
                    }
                }
            }
        }
    }
    cells.sort_unstable();
    cells.dedup();
    let mut edges = Vec::new();
    for (j, i) in cells {
        cube_triangles(labels, [i, j, k], &mut edges);
    }
    edges.iter().map(|t| t.map(|(p, d)| layers.get(p[2]).expect("a cube's layers are held").id(p, d))).collect()
}

/// The corner with code `c` (`x = 1, y = 2, z = 4`) of the cube at `at`.
fn corner(at: [i64; 3], c: u8) -> [i64; 3] {
    [at[0] + (c & 1) as i64, at[1] + (c >> 1 & 1) as i64, at[2] + (c >> 2 & 1) as i64]
}

/// The triangles of the cube with lower corner `at`.
fn cube_triangles(labels: &DenseBits, at: [i64; 3], out: &mut Vec<[Edge; 3]>) {
    let inside: [bool; 8] = std::array::from_fn(|c| {
        let p = corner(at, c as u8);
        labels.get_signed(p[0], p[1], p[2])
    });
    if inside.iter().all(|&s| s) || inside.iter().all(|&s| !s) {
        return;
    }
    for tet in TETS {
        // Inside corners first, then outside ones, each in tet order.
        let mut split = tet;
        split.sort_by_key(|&c| !inside[c as usize]);
        let n_in = tet.iter().filter(|&&c| inside[c as usize]).count();
        let (ins, outs) = split.split_at(n_in);
        let edge = |a: u8, b: u8| edge(at, &inside, a, b);
        let mut emit = |apex: u8, t: [(u8, u8); 3]| {
            let mut keys = t.map(|(a, b)| edge(a, b));
            if orient(apex, inside[apex as usize], t) {
                keys.swap(1, 2);
            }
            out.push(keys);
        };
        match (ins, outs) {
            ([a], [b, c, d]) | ([b, c, d], [a]) => emit(*a, [(*a, *b), (*a, *c), (*a, *d)]),
            ([a, b], [c, d]) => {
                emit(*a, [(*a, *c), (*a, *d), (*b, *d)]);
                emit(*b, [(*a, *c), (*b, *d), (*b, *c)]);
            }
            _ => {}
        }
    }
}

/// Whether the triangle on crossing edges `t` (corner codes) must be
/// flipped to have the inside behind it. `apex` is a corner at the end of
/// two of its edges. With `m` the doubled midpoints, `det(m − 2·apex)` has
/// the sign of `n · (p − apex)` for the triangle's normal `n` and any of
/// its points `p`, and keeps that sign wherever the vertices lie strictly
/// inside their edges (it scales by positive factors), so the integer
/// determinant at the midpoints decides the orientation exactly.
fn orient(apex: u8, apex_inside: bool, t: [(u8, u8); 3]) -> bool {
    let v = |c: u8| [(c & 1) as i64, (c >> 1 & 1) as i64, (c >> 2 & 1) as i64];
    let a = v(apex);
    let m = t.map(|(x, y)| {
        let (x, y) = (v(x), v(y));
        [x[0] + y[0] - 2 * a[0], x[1] + y[1] - 2 * a[1], x[2] + y[2] - 2 * a[2]]
    });
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    debug_assert_ne!(det, 0);
    // Inside apex: wanted n·(p − apex) > 0 (the apex behind), so det > 0.
    (det > 0) != apex_inside
}

/// The edge between corners `a` and `b` of the cube at `at`, by its
/// inside end (in Kuhn's triangulation one corner's code is a subset of
/// the other's, so the direction is `±e_S`, `S = a ^ b`).
fn edge(at: [i64; 3], inside: &[bool; 8], a: u8, b: u8) -> Edge {
    let (i, o) = if inside[a as usize] { (a, b) } else { (b, a) };
    debug_assert!(i & o == i || i & o == o);
    let s = i ^ o;
    let dir = if i & o == i { s - 1 } else { 7 + s - 1 };
    (corner(at, i), dir)
}

/// The reference: every cube of the grid and its border, one by one, vertex
/// ids in order of first use. The same triangles as [`extract`] up to the
/// numbering of vertices.
pub mod reference {
    use super::*;

    /// The surface of `labels`, by visiting every cube.
    pub fn extract(labels: &DenseBits) -> Extracted {
        let d = labels.dims().map(|d| d as i64);
        let mut keys = Vec::new();
        for k in -1..d[2] {
            for j in -1..d[1] {
                for i in -1..d[0] {
                    cube_triangles(labels, [i, j, k], &mut keys);
                }
            }
        }
        let mut ids = std::collections::HashMap::new();
        let mut crossings = Vec::new();
        let triangles = keys
            .iter()
            .map(|t| {
                t.map(|(p, d)| {
                    *ids.entry((p, d)).or_insert_with(|| {
                        let s = step(d);
                        crossings.push((p, [p[0] + s[0], p[1] + s[1], p[2] + s[2]]));
                        crossings.len() as u32 - 1
                    })
                })
            })
            .collect();
        Extracted { crossings, triangles }
    }
}
