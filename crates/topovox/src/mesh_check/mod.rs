//! The mesh certificate: what a triangle mesh is, each property decided
//! exactly, for any mesh (ours or a peer's).
//!
//! **Definitions.** Vertices with bit-identical coordinates are one vertex
//! (welded; `-0.0` is `0.0`), so files that repeat positions (STL) are
//! judged as the surface they describe. Then:
//! - a face is **degenerate** when its three points are collinear (exact:
//!   all three coordinate-plane `orient2d` signs are zero), a repeated
//!   index included;
//! - an edge is **boundary** with one face, **non-manifold** with more
//!   than two, **inconsistently oriented** with two faces that run it the
//!   same way; the mesh is **closed** with no boundary and no non-manifold
//!   edge, **oriented** with no inconsistent edge;
//! - a vertex is **manifold** when the faces around it form one disk (its
//!   link is one cycle, or one path at a boundary);
//! - two faces **self-intersect** when they meet anywhere but at the
//!   vertices and edge they share ([`intersect`], exact predicates);
//! - **components** are the faces connected through shared vertices;
//!   **genus**, for a closed, oriented, manifold mesh, is the sum over
//!   components of `(2 − χ)/2`, `χ = V − E + F`;
//! - **volume** is the signed volume of the divergence theorem (f64; exact
//!   only up to rounding, the one measured, not decided, number).
//!
//! **Cost.** Sorting the edges and vertices, `O(F log F)`; the
//! self-intersection test bins the faces' boxes in a uniform grid (cells of
//! the mean box size) and tests each pair of faces once, in the first cell
//! both boxes share, in parallel; the count does not depend on threads.

pub mod intersect;
mod pairs;

use glam::DVec3;
use rayon::prelude::*;

use crate::stop::Stop;
use crate::topology::runs::UnionFind;

/// Why a mesh could not be checked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshCheckError {
    /// A face names a vertex that does not exist.
    #[error("face {face} names vertex {index}, but there are {vertices} vertices")]
    Index {
        /// The face.
        face: u64,
        /// The index it names.
        index: u32,
        /// How many vertices there are.
        vertices: u64,
    },
    /// A vertex used by a face has a NaN or infinite coordinate.
    #[error("vertex {0} has a non-finite coordinate")]
    NonFinite(u32),
    /// No faces.
    #[error("the mesh has no faces")]
    Empty,
    /// The stop was requested.
    #[error("stopped")]
    Stopped,
}

/// What [`check_mesh`] found. Counts are exact.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshCheck {
    /// Faces in the input.
    pub faces: u64,
    /// Distinct vertex positions the faces use (after welding).
    pub vertices: u64,
    /// Undirected edges.
    pub edges: u64,
    /// Faces of zero area (collinear or repeated vertices).
    pub degenerate_faces: u64,
    /// Edges with one face.
    pub boundary_edges: u64,
    /// Edges with more than two faces.
    pub non_manifold_edges: u64,
    /// Edges whose two faces run them the same way.
    pub inconsistent_edges: u64,
    /// Vertices whose faces do not form one disk.
    pub non_manifold_vertices: u64,
    /// Pairs of faces that meet beyond what they share.
    pub self_intersections: u64,
    /// The first of those pairs (face indices, at most [`MeshCheck::SHOWN`]).
    pub intersecting_pairs: Vec<[u32; 2]>,
    /// Connected components (through shared vertices).
    pub components: u64,
    /// Euler characteristic `V − E + F`.
    pub euler: i64,
    /// Genus when closed, oriented and manifold.
    pub genus: Option<i64>,
    /// Signed volume (positive when the normals point outwards).
    pub volume: f64,
}

impl MeshCheck {
    /// How many intersecting pairs are listed.
    pub const SHOWN: usize = 10;

    /// Every edge has exactly two faces.
    pub fn closed(&self) -> bool {
        self.boundary_edges == 0 && self.non_manifold_edges == 0
    }

    /// Every edge has at most two faces and every vertex's faces form one disk.
    pub fn manifold(&self) -> bool {
        self.non_manifold_edges == 0 && self.non_manifold_vertices == 0
    }

    /// Every interior edge is run both ways.
    pub fn oriented(&self) -> bool {
        self.inconsistent_edges == 0
    }

    /// Closed, manifold, oriented, no self-intersection, no degenerate face,
    /// and a positive volume (normals outwards).
    pub fn watertight(&self) -> bool {
        self.closed()
            && self.manifold()
            && self.oriented()
            && self.self_intersections == 0
            && self.degenerate_faces == 0
            && self.volume > 0.0
    }
}

/// Checks the mesh of `positions` and `triangles` (see the module doc).
pub fn check_mesh(positions: &[DVec3], triangles: &[[u32; 3]], stop: &Stop) -> Result<MeshCheck, MeshCheckError> {
    if triangles.is_empty() {
        return Err(MeshCheckError::Empty);
    }
    let faces = weld(positions, triangles)?;
    let (pos, faces) = (&faces.0, &faces.1);
    let degenerate: Vec<bool> = faces.iter().map(|f| is_degenerate(pos, f)).collect();
    let mut report = MeshCheck { faces: faces.len() as u64, vertices: pos.len() as u64, ..MeshCheck::default() };
    edge_counts(faces, &mut report);
    report.degenerate_faces = degenerate.iter().filter(|&&d| d).count() as u64;
    report.non_manifold_vertices = non_manifold_vertices(faces);
    report.components = components(pos.len(), faces);
    report.euler = report.vertices as i64 - report.edges as i64 + report.faces as i64;
    if report.closed() && report.manifold() && report.oriented() {
        report.genus = Some((2 * report.components as i64 - report.euler) / 2);
    }
    report.volume = volume(pos, faces);
    let pairs = pairs::intersecting(pos, faces, &degenerate, stop).ok_or(MeshCheckError::Stopped)?;
    report.self_intersections = pairs.len() as u64;
    report.intersecting_pairs = pairs.into_iter().take(MeshCheck::SHOWN).collect();
    Ok(report)
}

/// Welded positions (only those faces use) and the faces on them.
fn weld(positions: &[DVec3], triangles: &[[u32; 3]]) -> Result<(Vec<DVec3>, Vec<[u32; 3]>), MeshCheckError> {
    let n = positions.len() as u64;
    let mut used = vec![false; positions.len()];
    for (f, t) in triangles.iter().enumerate() {
        for &v in t {
            let p = positions.get(v as usize).ok_or(MeshCheckError::Index { face: f as u64, index: v, vertices: n })?;
            if !p.is_finite() {
                return Err(MeshCheckError::NonFinite(v));
            }
            used[v as usize] = true;
        }
    }
    let key = |p: DVec3| [p.x, p.y, p.z].map(|c| if c == 0.0 { 0u64 } else { c.to_bits() });
    let mut order: Vec<u32> = (0..positions.len() as u32).filter(|&v| used[v as usize]).collect();
    order.par_sort_unstable_by_key(|&v| (key(positions[v as usize]), v));
    let mut id = vec![u32::MAX; positions.len()];
    let mut welded: Vec<DVec3> = Vec::new();
    for (n, &v) in order.iter().enumerate() {
        let p = positions[v as usize];
        if n == 0 || key(positions[order[n - 1] as usize]) != key(p) {
            welded.push(p);
        }
        id[v as usize] = welded.len() as u32 - 1;
    }
    Ok((welded, triangles.iter().map(|t| t.map(|v| id[v as usize])).collect()))
}

/// Whether a face has zero area: a repeated vertex, or three collinear points.
pub(crate) fn is_degenerate(pos: &[DVec3], f: &[u32; 3]) -> bool {
    if f[0] == f[1] || f[1] == f[2] || f[0] == f[2] {
        return true;
    }
    let t = [pos[f[0] as usize], pos[f[1] as usize], pos[f[2] as usize]];
    [(0, 1), (1, 2), (2, 0)].iter().all(|&(x, y)| {
        let c = |p: DVec3| robust::Coord { x: p[x], y: p[y] };
        robust::orient2d(c(t[0]), c(t[1]), c(t[2])) == 0.0
    })
}

/// Counts edges: all, boundary, non-manifold, inconsistently oriented.
fn edge_counts(faces: &[[u32; 3]], r: &mut MeshCheck) {
    let mut e: Vec<(u32, u32, bool)> = faces
        .iter()
        .flat_map(|f| [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])])
        .filter(|(a, b)| a != b)
        .map(|(a, b)| (a.min(b), a.max(b), a < b))
        .collect();
    e.par_sort_unstable();
    for run in e.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        r.edges += 1;
        match run.len() {
            1 => r.boundary_edges += 1,
            2 if run[0].2 == run[1].2 => r.inconsistent_edges += 1,
            2 => {}
            _ => r.non_manifold_edges += 1,
        }
    }
}

/// Vertices whose link (the edges opposite them in their faces) is not one
/// cycle or one path.
fn non_manifold_vertices(faces: &[[u32; 3]]) -> u64 {
    let mut link: Vec<(u32, u32, u32)> = Vec::with_capacity(faces.len() * 3);
    for f in faces.iter().filter(|f| f[0] != f[1] && f[1] != f[2] && f[0] != f[2]) {
        for c in 0..3 {
            link.push((f[c], f[(c + 1) % 3], f[(c + 2) % 3]));
        }
    }
    link.par_sort_unstable();
    let stars: Vec<&[(u32, u32, u32)]> = link.chunk_by(|a, b| a.0 == b.0).collect();
    stars.par_iter().filter(|star| !is_disk(star)).count() as u64
}

/// Whether a vertex's link edges form one cycle or one simple path.
fn is_disk(star: &[(u32, u32, u32)]) -> bool {
    let mut ends: Vec<u32> = star.iter().flat_map(|s| [s.1, s.2]).collect();
    ends.sort_unstable();
    ends.dedup();
    let at = |v: u32| ends.binary_search(&v).expect("a link vertex");
    let mut degree = vec![0u32; ends.len()];
    let mut sets = UnionFind::new(ends.len());
    for s in star {
        let (a, b) = (at(s.1), at(s.2));
        degree[a] += 1;
        degree[b] += 1;
        sets.union(a, b);
    }
    let one = (0..ends.len()).all(|x| sets.find(x) == 0);
    let ones = degree.iter().filter(|&&d| d == 1).count();
    one && degree.iter().all(|&d| d == 1 || d == 2) && (ones == 0 || ones == 2)
}

/// Components of the faces, connected through shared vertices.
fn components(n: usize, faces: &[[u32; 3]]) -> u64 {
    let mut sets = UnionFind::new(n);
    for f in faces {
        sets.union(f[0] as usize, f[1] as usize);
        sets.union(f[0] as usize, f[2] as usize);
    }
    (0..n).filter(|&v| sets.find(v) == v).count() as u64
}

/// The signed volume (divergence theorem, about the first vertex).
fn volume(pos: &[DVec3], faces: &[[u32; 3]]) -> f64 {
    let o = pos[0];
    faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| pos[v as usize] - o);
            a.dot(b.cross(c))
        })
        .sum::<f64>()
        / 6.0
}

#[cfg(test)]
mod tests;
