//! Exact point queries: distance, closest point, winding number and
//! inside, at any point, by the rules the grids use.
//!
//! A [`Query`] is built once per mesh and shared by threads.
//! - **Distance** is the definition of [`crate::distance`]: the minimum of
//!   exact f64 point–piece distances (a degenerate triangle counts as its
//!   edges), found by the same bounding-volume hierarchy
//!   ([`crate::distance::nearest::Hierarchy`]); the nearest piece is the
//!   lowest numbered among equally near ones, whatever the order of the
//!   points. At a voxel centre it is the value `sdf` stores, bit for bit
//!   after rounding to f32.
//! - **Inside** follows [`Sign`]: ray parity ([`ray`]), the integer
//!   winding number of a closed mesh, or the generalized winding number
//!   `|w| ≥ ½` ([`caps`]); `Auto` is the winding number of the mesh as
//!   [`orient`] turns it (nonzero where closed, `|w| ≥ ½` otherwise) — the
//!   rule of `voxelize --mode solid`. It is decided on the vertices as given, in
//!   exact arithmetic, with the grids' tie rule; the grids decide on the
//!   vertices snapped to their 1/4096-voxel lattice, so at a voxel centre
//!   the two agree exactly whenever the mesh's vertices lie on that
//!   lattice, and otherwise can differ only within about 1/8192 voxel of
//!   the surface (or, for open meshes, where `|w − ½| < 10⁻³`).
//! - **Signed distance** is `−d` inside and `d` outside; a point on the
//!   surface that counts as inside gets `−2⁻¹⁴⁹`, the value `sdf` stores
//!   there (the sign alone says inside).
//!
//! Points that are not finite give NaN distances and winding numbers, are
//! not inside, and have no nearest element (`u32::MAX`).

pub mod caps;
pub mod grid;
pub mod inside;
pub mod orient;
pub mod ray;
pub mod sample;

use glam::DVec3;
use rayon::prelude::*;

use crate::distance::nearest::Hierarchy;
use crate::distance::{DistanceError, Pieces};
use crate::MeshRef;
pub use inside::Inside;

/// Which rule decides inside.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Sign {
    /// The winding number on the mesh oriented by [`orient`]: nonzero
    /// where it is closed (the union of overlapping shells), `|w| ≥ ½`
    /// otherwise.
    #[default]
    Auto,
    /// Ray parity: an odd number of crossings.
    Parity,
    /// The (generalized) winding number: `|w| ≥ ½`.
    Winding,
}

/// The nearest point of the mesh to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Closest {
    /// The point.
    pub point: DVec3,
    /// Its distance (the value [`Query::distance`] gives).
    pub distance: f64,
    /// The element it lies on: triangle `t`, or segment `s` as
    /// `triangles + s`; `u32::MAX` for a point that is not finite.
    pub element: u32,
    /// Its barycentric weights on the element's corners (a segment's two
    /// ends are the first two, the third weight is 0).
    pub weights: [f64; 3],
}

/// What a query object knows of its mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct QueryFacts {
    /// Elements measured to (triangles and segments).
    pub elements: u64,
    /// Triangles and segments left out for an index out of range.
    pub skipped: u64,
    /// Closed and consistently oriented (no boundary, every edge used
    /// equally often both ways).
    pub watertight: bool,
    /// Boundary cycles closed by caps for the winding number.
    pub cycles: u64,
    /// The rule `Auto` resolved to.
    pub sign: Sign,
    /// What orienting the mesh did (`None` under parity).
    pub orientation: Option<orient::OrientReport>,
}

/// A mesh prepared for point queries (see the module doc).
pub struct Query {
    pieces: Pieces,
    tree: Hierarchy,
    inside: Inside,
    facts: QueryFacts,
    /// The mesh's triangle count (valid or not): segment numbers start here.
    triangles: usize,
}

impl Query {
    /// Prepares `mesh` (world coordinates); `sign` picks the inside rule.
    pub fn new(mesh: MeshRef<'_>, sign: Sign) -> Result<Query, DistanceError> {
        let pieces = Pieces::of(mesh)?;
        let mesh_triangles = mesh.triangles.len();
        let tree = Hierarchy::new(&pieces);
        let inside = Inside::new(mesh, sign);
        let facts = QueryFacts {
            elements: pieces.items.len() as u64,
            skipped: pieces.skipped,
            watertight: inside.watertight(),
            cycles: inside.cycles(),
            sign: inside.sign(),
            orientation: inside.orientation(),
        };
        Ok(Query { pieces, tree, inside, facts, triangles: mesh_triangles })
    }

    /// The mesh's triangles with valid indices, in mesh order (world
    /// coordinates), as the samples draw from them.
    pub fn triangles(&self) -> Vec<[DVec3; 3]> {
        self.faces().into_iter().map(|(_, t)| t).collect()
    }

    /// [`Query::triangles`] with each one's number in the mesh.
    pub fn faces(&self) -> Vec<(u32, [DVec3; 3])> {
        self.pieces.items.iter().zip(&self.pieces.element).filter(|(_, &e)| (e as usize) < self.triangles).map(|(p, &e)| (e, p.p)).collect()
    }

    /// What the query knows of its mesh.
    pub fn facts(&self) -> QueryFacts {
        self.facts
    }

    /// The squared distance to the nearest piece and that piece's number.
    fn nearest(&self, q: DVec3, seed: u32) -> (f64, u32) {
        let start = match self.pieces.items.get(seed as usize) {
            // Slightly above the seed's distance, so the seed itself is
            // measured again and equal ties go to the lowest number.
            Some(p) => (p.distance_squared(q) * (1.0 + 1e-12) + f64::MIN_POSITIVE, seed),
            None => (f64::INFINITY, u32::MAX),
        };
        self.tree.nearest(q, start)
    }

    /// The distance from `q` to the mesh (NaN for a point not finite or
    /// past ±[`crate::COORDINATE_LIMIT`], as every answer of a query).
    pub fn distance(&self, q: DVec3) -> f64 {
        if !crate::in_range(q) {
            return f64::NAN;
        }
        self.nearest(q, u32::MAX).0.sqrt()
    }

    /// The nearest point of the mesh to `q`.
    pub fn closest(&self, q: DVec3) -> Closest {
        self.closest_from(q, u32::MAX).0
    }

    /// [`Query::closest`] with a piece to start from, and the nearest piece.
    fn closest_from(&self, q: DVec3, seed: u32) -> (Closest, u32) {
        if !crate::in_range(q) {
            return (Closest { point: DVec3::NAN, distance: f64::NAN, element: u32::MAX, weights: [f64::NAN; 3] }, seed);
        }
        let (d2, n) = self.nearest(q, seed);
        let piece = &self.pieces.items[n as usize];
        let element = self.pieces.element[n as usize];
        let mut weights = piece.closest(q);
        if element as usize >= self.triangles {
            // A segment `[a, b, b]`: its two ends.
            weights = [weights[0], weights[1] + weights[2], 0.0];
        }
        (Closest { point: piece.point(weights), distance: d2.sqrt(), element, weights }, n)
    }

    /// The winding number at `q`: an exact integer for a closed mesh, the
    /// generalized winding number otherwise (NaN for a point not finite).
    pub fn winding_number(&self, q: DVec3) -> f64 {
        self.inside.winding_number(q)
    }

    /// Whether `q` is inside, by the query's rule (false when not finite).
    pub fn contains(&self, q: DVec3) -> bool {
        self.inside.contains(q)
    }

    /// The signed distance at `q`: negative inside (see the module doc).
    pub fn signed_distance(&self, q: DVec3) -> f64 {
        signed(self.distance(q), self.contains(q))
    }
}

/// `d` with the sign of `inside`; `−2⁻¹⁴⁹` for an inside point whose
/// distance rounds to zero in f32 (the value `sdf` stores there).
#[inline]
pub fn signed(d: f64, inside: bool) -> f64 {
    if !inside {
        d
    } else if (d as f32) > 0.0 {
        -d
    } else {
        -f64::from(f32::from_bits(1))
    }
}

/// What to compute for a batch of points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ask {
    /// Unsigned distance.
    Distance,
    /// Signed distance.
    SignedDistance,
    /// Inside (1.0) or not (0.0).
    Contains,
    /// The winding number.
    WindingNumber,
}

/// Points per task (in Morton order).
const CHUNK: usize = 2048;

impl Query {
    /// `ask` at every point, into `out` (same length); parallel, and the
    /// same values for any thread count or order.
    pub fn batch(&self, points: &[DVec3], ask: Ask, out: &mut [f64]) {
        match ask {
            Ask::Contains => {
                out.par_iter_mut().zip(points).with_min_len(256).for_each(|(o, &q)| *o = f64::from(u8::from(self.contains(q))))
            }
            Ask::WindingNumber => out.par_iter_mut().zip(points).with_min_len(256).for_each(|(o, &q)| *o = self.winding_number(q)),
            Ask::Distance | Ask::SignedDistance => {
                let signed = ask == Ask::SignedDistance;
                self.in_order(points, out, |q, c| if signed { self::signed(c.distance, self.contains(q)) } else { c.distance });
            }
        }
    }

    /// The nearest point to every point, into `out` (same length); parallel.
    pub fn closest_batch(&self, points: &[DVec3], out: &mut [Closest]) {
        self.in_order(points, out, |_, c| c);
    }

    /// `out[n] = f(points[n], closest point)` for every point: the points
    /// are visited in Morton order, in runs of [`CHUNK`] per task, so each
    /// one's nearest piece bounds the next one's search.
    fn in_order<T: Send + Copy>(&self, points: &[DVec3], out: &mut [T], f: impl Fn(DVec3, Closest) -> T + Sync) {
        let (lo, hi) = self.tree.bounds();
        let scale = (hi - lo).max(DVec3::splat(f64::MIN_POSITIVE)).recip() * 1023.0;
        let mut order: Vec<(u32, u32)> = points
            .par_iter()
            .with_min_len(4096)
            .enumerate()
            .map(|(n, &q)| {
                let c = ((q - lo) * scale).clamp(DVec3::ZERO, DVec3::splat(1023.0));
                // NaN clamps to NaN, which casts to 0.
                (morton(c.x as u32, c.y as u32, c.z as u32), n as u32)
            })
            .collect();
        order.par_sort_unstable();
        let done: Vec<Vec<T>> = order
            .par_chunks(CHUNK)
            .map(|run| {
                let mut seed = u32::MAX;
                run.iter()
                    .map(|&(_, n)| {
                        let q = points[n as usize];
                        let (c, piece) = self.closest_from(q, seed);
                        seed = piece;
                        f(q, c)
                    })
                    .collect()
            })
            .collect();
        for (&(_, n), v) in order.iter().zip(done.into_iter().flatten()) {
            out[n as usize] = v;
        }
    }
}

/// Interleaves the low ten bits of `x`, `y`, `z`.
fn morton(x: u32, y: u32, z: u32) -> u32 {
    let spread = |v: u32| {
        let mut v = v & 0x3ff;
        v = (v | v << 16) & 0x030000ff;
        v = (v | v << 8) & 0x0300f00f;
        v = (v | v << 4) & 0x030c30c3;
        (v | v << 2) & 0x09249249
    };
    spread(x) | spread(y) << 1 | spread(z) << 2
}

#[cfg(test)]
mod tests;
