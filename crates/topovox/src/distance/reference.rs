//! The distance field by brute force: for every voxel centre, the minimum
//! over every triangle and segment of the exact point–piece distance, in
//! f64, by a formula independent of the fast paths': the projection onto
//! the triangle's plane when it falls inside the triangle (signs of the
//! three sub-triangles' normals), else the nearest of the three edges;
//! segments and degenerate triangles by their edges. Not Ericson's
//! closest point (`geom/closest.rs`): by Voronoi regions it is off on
//! sliver triangles, which the tests' soups hold, where this is exact. Cost: voxels × pieces (planes in parallel); for tests on small
//! grids.

use glam::DVec3;
use rayon::prelude::*;

use super::{DistanceError, Pieces};
use crate::{GridSpec, MeshRef};

fn segment(a: DVec3, b: DVec3, q: DVec3) -> f64 {
    let ab = b - a;
    let t = if ab == DVec3::ZERO { 0.0 } else { ((q - a).dot(ab) / ab.dot(ab)).clamp(0.0, 1.0) };
    (a + ab * t - q).length()
}

fn piece(p: [DVec3; 3], q: DVec3) -> f64 {
    let [a, b, c] = p;
    let n = (b - a).cross(c - a);
    let edges = segment(a, b, q).min(segment(b, c, q)).min(segment(c, a, q));
    if n == DVec3::ZERO {
        return edges;
    }
    let foot = q - n * ((q - a).dot(n) / n.dot(n));
    let inside = [(a, b), (b, c), (c, a)].iter().all(|&(u, v)| (v - u).cross(foot - u).dot(n) >= 0.0);
    if inside {
        ((q - a).dot(n) / n.length()).abs()
    } else {
        edges
    }
}

/// The distance from `q` to the nearest of `pieces`, by this formula.
pub fn distance_at(pieces: &Pieces, q: DVec3) -> f64 {
    pieces.items.iter().map(|p| piece(p.p, q)).fold(f64::INFINITY, f64::min)
}

/// The unsigned distance of every voxel of `grid` to `mesh`, C order
/// (`[i][j][k]`).
pub fn distances(mesh: MeshRef<'_>, grid: &GridSpec) -> Result<Vec<f64>, DistanceError> {
    let pieces = Pieces::of(mesh)?;
    let [nx, ny, nz] = grid.dims();
    // Planes in parallel; each voxel alone, in order.
    let planes: Vec<Vec<f64>> = (0..nx)
        .into_par_iter()
        .map(|i| {
            let mut out = Vec::with_capacity(ny as usize * nz as usize);
            for j in 0..ny {
                for k in 0..nz {
                    let q = grid.voxel_center([i, j, k]);
                    out.push(distance_at(&pieces, q));
                }
            }
            out
        })
        .collect();
    let out = planes.concat();
    Ok(out)
}
