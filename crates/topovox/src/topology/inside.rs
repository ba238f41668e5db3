//! Exact inside/outside classification of voxel centres by ray parity, and
//! the closedness test it needs.
//!
//! This work is based on: M. Schwarz, H.-P. Seidel, "Fast Parallel Surface
//! and Solid Voxelization on GPUs", ACM TOG 29(6), 2010, §4 (solid
//! voxelization by counting crossings along a grid axis), with ties decided
//! by the perturbation of [`crate::geom::perturb`].
//!
//! **Definition.** A voxel is *inside* iff the ray from its (displaced)
//! centre towards `−x` crosses the snapped surface an odd number of times.
//! For a closed surface (every edge, keyed by its snapped end points, is
//! shared by an even number of triangles) the parity does not depend on the
//! ray, and the displacement means a ray never grazes an edge or vertex, so
//! no streaks appear. Zero-area triangles are counted for closedness and
//! cross nothing.
//!
//! Used by `topovox check` to certify separation; every triangle counts,
//! also those outside the grid (they change the parity inside it).

use rayon::prelude::*;
use rustc_hash::FxHashMap;

use crate::geom::fixed::{snap, PlaneInt, DIRECT_LIMIT_VOXELS, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::geom::setup::TriSetup;
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

const H: i64 = ONE / 2;

/// The mesh snapped for classification: every triangle, degenerate ones
/// included, no clipping.
#[derive(Clone, Debug)]
pub struct Snapped {
    /// All triangles with valid, finite vertices.
    pub triangles: Vec<LatticeTriangle>,
    /// Edges (by snapped end points) used by an odd number of triangles.
    pub boundary_edges: usize,
    /// Edges not used equally often in both directions (none for a closed,
    /// consistently oriented surface), as `(a, b, uses a → b − uses b →
    /// a)` with `a < b` (lexicographic), sorted: the boundary a closed
    /// surface lacks.
    pub net_edges: Vec<NetEdge>,
    /// The voxel's edges over its smallest edge: lattice differences times
    /// this have the world's shape (solid angles are measured in it).
    pub scale: glam::DVec3,
}

/// An edge `(a, b)`, `a < b`, and how many more times it is used from `a`
/// to `b` than back ([`Snapped::net_edges`]).
pub type NetEdge = ([i64; 3], [i64; 3], i64);

impl Snapped {
    /// How many edges are not used equally often in both directions.
    pub fn unbalanced_edges(&self) -> usize {
        self.net_edges.len()
    }

    /// The triangles that can cross a ray: all but the zero-area ones.
    pub fn crossing_triangles(&self) -> Vec<LatticeTriangle> {
        self.triangles.iter().filter(|t| !t.is_degenerate()).copied().collect()
    }
}

/// Offsets of each row's entries in a list sorted by row: entries of row
/// `r` are `[starts[r], starts[r + 1])`. `row_of` yields each entry's row,
/// in order.
pub fn row_starts(rows: usize, row_of: impl Iterator<Item = usize>) -> Vec<usize> {
    let mut start = vec![0usize; rows + 1];
    for r in row_of {
        start[r + 1] += 1;
    }
    for r in 0..rows {
        start[r + 1] += start[r];
    }
    start
}

/// Why a mesh cannot be classified.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ClassifyError {
    /// Some vertex lies beyond the lattice range around this grid.
    #[error("the mesh reaches more than {0} voxels from the grid, beyond the exact lattice; use a coarser or larger grid")]
    TooFar(u64),
}

/// Snaps every triangle of `mesh` (invalid and non-finite ones are
/// skipped) and counts boundary edges.
///
/// Each position is snapped once. Edges are keyed by point numbers (one
/// per distinct snapped point, so positions that snap to one point are one
/// end) and bucketed by their lower end; the direction of use is the order
/// of the numbers (any order of the points gives the same counts).
pub fn snap_all(mesh: MeshRef<'_>, grid: &GridSpec) -> Result<Snapped, ClassifyError> {
    let corners: Vec<Corner> = mesh
        .positions
        .par_iter()
        .with_min_len(4096)
        .map(|p| {
            let g = grid.to_grid_units(*p);
            if !g.is_finite() {
                Corner::Invalid
            } else if g.abs().max_element() > DIRECT_LIMIT_VOXELS {
                Corner::TooFar
            } else {
                Corner::At([snap(g.x), snap(g.y), snap(g.z)])
            }
        })
        .collect();
    // Point numbers, in the order of first use by a position.
    let mut numbers: FxHashMap<[i64; 3], u32> = FxHashMap::with_capacity_and_hasher(corners.len(), Default::default());
    let number: Vec<u32> = corners
        .iter()
        .map(|c| match c {
            Corner::At(p) => {
                let next = numbers.len() as u32;
                *numbers.entry(*p).or_insert(next)
            }
            _ => u32::MAX,
        })
        .collect();
    let mut triangles = Vec::with_capacity(mesh.triangles.len());
    let mut ends: Vec<[u32; 3]> = Vec::with_capacity(mesh.triangles.len());
    for t in mesh.triangles {
        let mut v = [[0i64; 3]; 3];
        let mut ok = true;
        for (c, &idx) in t.iter().enumerate() {
            match corners.get(idx as usize) {
                Some(Corner::At(p)) => v[c] = *p,
                Some(Corner::TooFar) => return Err(ClassifyError::TooFar(DIRECT_LIMIT_VOXELS as u64)),
                Some(Corner::Invalid) | None => ok = false,
            }
        }
        if ok {
            triangles.push(LatticeTriangle { v });
            ends.push(t.map(|i| number[i as usize]));
        }
    }
    let (boundary_edges, net) = count_edges(&ends, numbers.len());
    let mut point = vec![[0i64; 3]; numbers.len()];
    for (p, n) in numbers {
        point[n as usize] = p;
    }
    let mut net_edges: Vec<NetEdge> = net
        .into_iter()
        .map(|(lo, hi, balance)| {
            let (a, b) = (point[lo as usize], point[hi as usize]);
            if a < b {
                (a, b, balance)
            } else {
                (b, a, -balance)
            }
        })
        .collect();
    net_edges.sort_unstable();
    let size = grid.voxel_size().0;
    Ok(Snapped { triangles, boundary_edges, net_edges, scale: size / size.min_element() })
}

/// A mesh position on the lattice (see [`snap_all`]).
#[derive(Clone, Copy)]
enum Corner {
    /// Not finite: triangles using it are skipped.
    Invalid,
    /// Beyond the exact lattice: a triangle using it is an error.
    TooFar,
    /// Its lattice point.
    At([i64; 3]),
}

/// The edges of triangles with corners numbered `ends` (numbers below
/// `points`) used an odd number of times, and those not used equally
/// often in both directions, as `(lo, hi, uses lo → hi − uses hi → lo)`.
/// An edge joining a point to itself is none.
pub(crate) fn count_edges(ends: &[[u32; 3]], points: usize) -> (usize, Vec<(u32, u32, i64)>) {
    let edges = || ends.iter().flat_map(|e| (0..3).map(move |i| (e[i], e[(i + 1) % 3]))).filter(|(a, b)| a != b);
    // Each edge in the bucket of its lower end.
    let start = row_starts(points, edges().map(|(a, b)| a.min(b) as usize));
    let mut fill = start.clone();
    // Each use as `hi · 2 + (1 if from the higher end)`.
    let mut bucket = vec![0u64; start[points]];
    for (a, b) in edges() {
        let (lo, use_) = if a < b { (a, (b as u64) << 1) } else { (b, (a as u64) << 1 | 1) };
        bucket[fill[lo as usize]] = use_;
        fill[lo as usize] += 1;
    }
    let (mut boundary, mut unbalanced) = (0, Vec::new());
    for p in 0..points {
        let b = &mut bucket[start[p]..start[p + 1]];
        b.sort_unstable();
        for uses in b.chunk_by(|x, y| x >> 1 == y >> 1) {
            boundary += uses.len() % 2;
            let back = uses.iter().filter(|&&u| u & 1 == 1).count() as i64;
            let balance = uses.len() as i64 - 2 * back;
            if balance != 0 {
                unbalanced.push((p as u32, (uses[0] >> 1) as u32, balance));
            }
        }
    }
    (boundary, unbalanced)
}

/// Per row `(j, k)` of a grid, the sorted voxel indices `i` at which the
/// inside/outside state toggles: voxel `i` is inside iff an odd number of
/// toggles are `<= i`.
#[derive(Clone, Debug)]
pub struct Parity {
    ny: u32,
    row_start: Vec<u32>,
    toggles: Vec<u32>,
}

impl Parity {
    /// Classifies every voxel centre of `grid` against `tris`.
    pub fn classify(tris: &[LatticeTriangle], dims: [u32; 3]) -> Parity {
        Parity::classify_planes(tris, dims, 0..dims[2])
    }

    /// Classifies the voxel centres of the planes `planes` of a grid of
    /// `dims`; row `(j, k)` of the result is the grid's `(j, planes.start + k)`.
    /// `tris` must hold every triangle crossing those planes' rows.
    pub fn classify_planes(tris: &[LatticeTriangle], dims: [u32; 3], planes: std::ops::Range<u32>) -> Parity {
        let [nx, ny, _] = dims;
        let hits: Vec<(u32, u32)> = row_crossings_in(tris, dims, planes.clone()).into_iter().map(|(r, i, _)| (r, i)).collect();
        // Toggles at the same voxel cancel in pairs.
        let rows = ny as usize * planes.len();
        let mut row_start = Vec::with_capacity(rows + 1);
        let mut toggles = Vec::new();
        let mut h = 0;
        for r in 0..rows as u32 {
            row_start.push(toggles.len() as u32);
            while h < hits.len() && hits[h].0 == r {
                let mut e = h;
                while e < hits.len() && hits[e] == hits[h] {
                    e += 1;
                }
                if (e - h) % 2 == 1 && hits[h].1 < nx {
                    toggles.push(hits[h].1);
                }
                h = e;
            }
        }
        row_start.push(toggles.len() as u32);
        Parity { ny, row_start, toggles }
    }

    /// The toggles of row `(j, k)`.
    pub fn row(&self, j: u32, k: u32) -> &[u32] {
        let r = k as usize * self.ny as usize + j as usize;
        &self.toggles[self.row_start[r] as usize..self.row_start[r + 1] as usize]
    }

    /// Is voxel `(i, j, k)` inside?
    pub fn inside(&self, i: u32, j: u32, k: u32) -> bool {
        self.row(j, k).partition_point(|&t| t <= i) % 2 == 1
    }
}

/// Every crossing of the rows' centre lines with the triangles, as
/// `(row, i0, sign)` sorted by row and `i0`: voxels `i >= i0` of the row
/// have this crossing on their `−x` ray, and `sign` is its contribution to
/// the winding number (`+1` where the ray leaves through an outward face,
/// i.e. `−sign(n_x)`).
pub fn row_crossings(tris: &[LatticeTriangle], dims: [u32; 3]) -> Vec<(u32, u32, i8)> {
    row_crossings_in(tris, dims, 0..dims[2])
}

/// [`row_crossings`] of the rows in the planes `planes` only, numbered
/// from the first of them (`row = (k − planes.start)·ny + j`).
pub fn row_crossings_in(tris: &[LatticeTriangle], dims: [u32; 3], planes: std::ops::Range<u32>) -> Vec<(u32, u32, i8)> {
    let hits: Vec<(u32, u32, i8)> = tris
        .par_chunks(1024)
        .flat_map_iter(|chunk| {
            let mut out = Vec::new();
            for t in chunk {
                crossings(t, dims, &planes, &mut out);
            }
            out
        })
        .collect();
    // By row, then each row's few by `i0`: a counting sort where the rows
    // are few beside the hits; a plain sort where a per-row table would
    // follow the grid rather than the surface (a small mesh in a 65536³
    // grid would need 32 GiB of it). Both give the tuples in order.
    let rows = dims[1] as usize * planes.len();
    if rows > 4 * hits.len() + 4096 {
        let mut hits = hits;
        hits.par_sort_unstable();
        return hits;
    }
    let start = row_starts(rows, hits.iter().map(|h| h.0 as usize));
    let mut fill = start.clone();
    let mut sorted = vec![(0, 0, 0); hits.len()];
    for h in hits {
        sorted[fill[h.0 as usize]] = h;
        fill[h.0 as usize] += 1;
    }
    for r in 0..rows {
        sorted[start[r]..start[r + 1]].sort_unstable();
    }
    sorted
}

/// Appends `(row, i0, sign)` for every row whose centre line crosses `t`,
/// where `i0` is the first voxel whose displaced centre lies beyond the
/// crossing (clamped to `[0, nx]`; voxels `>= i0` see one more crossing).
fn crossings(t: &LatticeTriangle, dims: [u32; 3], planes: &std::ops::Range<u32>, out: &mut Vec<(u32, u32, i8)>) {
    let n = t.normal();
    if n[0] == 0 {
        // Parallel to the rays: a displaced ray misses it.
        return;
    }
    let (lo, hi) = t.bounds();
    let rows = |a: usize, range: (i64, i64)| {
        // Rows whose centre coordinate lies in [lo, hi] (with one of margin
        // for the displacement; the exact test decides): the first is
        // ceil((lo − 1 − H) / ONE).
        let first = (-(H + 1 - lo[a]).div_euclid(ONE)).max(range.0);
        let last = ((hi[a] - H + 1).div_euclid(ONE)).min(range.1 - 1);
        first..=last
    };
    let (rj, rk) = (rows(1, (0, dims[1] as i64)), rows(2, (planes.start as i64, planes.end as i64)));
    if rj.is_empty() || rk.is_empty() {
        // No row's centre line within reach (most small triangles).
        return;
    }
    if crate::geom::setup::fits_i64(t) {
        crossings_in::<i64>(t, n, dims, planes.start, rj, rk, out);
    } else {
        crossings_in::<i128>(t, n, dims, planes.start, rj, rk, out);
    }
}

fn crossings_in<T: PlaneInt>(
    t: &LatticeTriangle,
    n: [i64; 3],
    dims: [u32; 3],
    k0: u32,
    rows_j: std::ops::RangeInclusive<i64>,
    rows_k: std::ops::RangeInclusive<i64>,
    out: &mut Vec<(u32, u32, i8)>,
) {
    let s = TriSetup::<T>::new(t);
    let dx = s.dir(t, [ONE, 0, 0]);
    let nx = n[0] as i128;
    let bn = s.bn.to_i128();
    for k in rows_k {
        for j in rows_j.clone() {
            let p = s.local([s.a[0], j * ONE + H, k * ONE + H]);
            let o = s.line_values(&dx, p);
            let inside = [0, 1, 2].map(|e| o[e] >= dx.be[e]);
            if !(inside[0] == inside[1] && inside[1] == inside[2]) {
                continue;
            }
            // Plane value along the row: V(X) = v0 + n_x·(X − a_x); the
            // displaced point at X is beyond the crossing iff
            // (V >= bn) == (n_x > 0).
            let v0 = n[1] as i128 * p[1].to_i128() + n[2] as i128 * p[2].to_i128();
            let ax = s.a[0] as i128;
            let x_star = if nx > 0 { ax - (v0 - bn).div_euclid(nx) } else { ax + (v0 - bn).div_euclid(-nx) + 1 };
            // First i with i·ONE + H >= x_star.
            let i0 = (x_star - H as i128 + ONE as i128 - 1).div_euclid(ONE as i128).clamp(0, dims[0] as i128);
            out.push((((k - k0 as i64) as u64 * dims[1] as u64 + j as u64) as u32, i0 as u32, if nx > 0 { -1 } else { 1 }));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use glam::DVec3;

    fn cube(lo: f64, hi: f64) -> Mesh {
        let p = |x: usize, y: usize, z: usize| DVec3::new([lo, hi][x], [lo, hi][y], [lo, hi][z]);
        let positions: Vec<DVec3> = (0..8).map(|c| p(c & 1, (c >> 1) & 1, (c >> 2) & 1)).collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let triangles = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        Mesh { positions, triangles, segments: Vec::new() }
    }

    #[test]
    fn cube_on_voxel_centres_classifies_consistently() {
        // Faces exactly through voxel centres: the displacement decides, and
        // every row agrees.
        let m = cube(2.5, 6.5);
        let grid = GridSpec::new(DVec3::ZERO, 1.0, [9, 9, 9]).unwrap();
        let s = snap_all(m.as_ref(), &grid).unwrap();
        assert_eq!(s.boundary_edges, 0);
        let p = Parity::classify(&s.triangles, grid.dims());
        let mut count = 0;
        for k in 0..9 {
            for j in 0..9 {
                for i in 0..9 {
                    if p.inside(i, j, k) {
                        count += 1;
                    }
                }
            }
        }
        // Centres 2.5..6.5 on each axis: the displacement −δ takes exactly
        // one of the two boundary layers per axis.
        assert_eq!(count, 4 * 4 * 4);
    }

    #[test]
    fn cube_between_centres_is_exact() {
        let m = cube(2.0, 6.0);
        let grid = GridSpec::new(DVec3::ZERO, 1.0, [9, 9, 9]).unwrap();
        let s = snap_all(m.as_ref(), &grid).unwrap();
        let p = Parity::classify(&s.triangles, grid.dims());
        for k in 0..9 {
            for j in 0..9 {
                for i in 0..9 {
                    let want = [i, j, k].iter().all(|&c| (2..6).contains(&c));
                    assert_eq!(p.inside(i, j, k), want, "{i} {j} {k}");
                }
            }
        }
    }

    #[test]
    fn an_open_mesh_has_boundary_edges() {
        let mut m = cube(2.0, 6.0);
        m.triangles.pop();
        let grid = GridSpec::new(DVec3::ZERO, 1.0, [9, 9, 9]).unwrap();
        assert_eq!(snap_all(m.as_ref(), &grid).unwrap().boundary_edges, 3);
    }
    /// The closedness counts by their definition: every use of an edge
    /// keyed by its two snapped points, sorted.
    fn counts_by_points(s: &Snapped) -> (usize, Vec<NetEdge>) {
        let mut edges: Vec<([i64; 3], [i64; 3], i64)> = s
            .triangles
            .iter()
            .flat_map(|t| (0..3).map(move |i| (t.v[i], t.v[(i + 1) % 3])))
            .filter(|(a, b)| a != b)
            .map(|(a, b)| if a < b { (a, b, 1) } else { (b, a, -1) })
            .collect();
        edges.sort();
        let (mut boundary, mut net) = (0, Vec::new());
        for uses in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            boundary += uses.len() % 2;
            let balance = uses.iter().map(|u| u.2).sum::<i64>();
            if balance != 0 {
                net.push((uses[0].0, uses[0].1, balance));
            }
        }
        (boundary, net)
    }

    #[test]
    fn edge_counts_match_their_definition() {
        // Positions on a coarse lattice, some repeated and some a hair apart
        // (one snapped point), a non-finite one and indices past the end;
        // triangles in random orientations, repeated, and degenerate.
        let mut rng = crate::test_rng::Xorshift(0x9e37_79b9_7f4a_7c15);
        let mut r = |n: u64| rng.below(n);
        let grid = GridSpec::new(DVec3::ZERO, 1.0, [8, 8, 8]).unwrap();
        for round in 0..200 {
            let mut positions: Vec<DVec3> =
                (0..6 + r(10)).map(|_| DVec3::new(r(4) as f64, r(4) as f64, r(3) as f64) * 0.5 + DVec3::splat(1.0)).collect();
            for i in 0..r(4) as usize {
                let p = positions[i];
                positions.push(p + DVec3::splat(1e-12));
            }
            if round % 5 == 0 {
                positions.push(DVec3::new(f64::NAN, 1.0, 1.0));
            }
            let n = positions.len() as u64;
            let triangles: Vec<[u32; 3]> = (0..2 + r(20)).map(|_| [r(n + 1), r(n), r(n)].map(|i| i as u32)).collect();
            let mesh = Mesh { positions, triangles, segments: Vec::new() };
            let s = snap_all(mesh.as_ref(), &grid).unwrap();
            assert_eq!((s.boundary_edges, s.net_edges.clone()), counts_by_points(&s), "round {round}");
        }
        // A closed cube, then one face turned over: the same boundary, two
        // unbalanced edges per turned triangle's shared edges.
        let mut m = cube(2.0, 6.0);
        let s = snap_all(m.as_ref(), &grid).unwrap();
        assert_eq!((s.boundary_edges, s.unbalanced_edges()), (0, 0));
        m.triangles[0].swap(1, 2);
        let s = snap_all(m.as_ref(), &grid).unwrap();
        assert_eq!((s.boundary_edges, s.net_edges.clone()), counts_by_points(&s));
        assert_eq!(s.boundary_edges, 0);
        assert!(s.unbalanced_edges() > 0);
    }
}
