//! The grid solids decided on the vertices as given: the voxels whose
//! decision snapping could change, found and decided again by [`Inside`].
//!
//! The solids ([`crate::voxelize::solid`], [`crate::voxelize::winding`])
//! decide on vertices snapped to the grid's 1/4096-voxel lattice, each
//! moved by at most `h/8192` per axis. Moving the vertices along straight
//! lines from the snapped to the given positions sweeps only points within
//! that distance of the mesh, and a winding number (so parity) changes only
//! where the surface passes; so a voxel centre farther than that from the
//! mesh keeps its parity and its integer winding number. The generalized
//! winding number of an open mesh moves by less than 10⁻³ farther than
//! 0.02 voxel from the mesh, and the lattice solid flags every voxel it
//! decided within its error bound of a half-integer
//! ([`crate::voxelize::winding::WindingReport::near_half`]). So deciding
//! again, with [`Inside`], every centre within [`RADIUS`] voxel of the
//! mesh and every flagged voxel gives the solid of the vertices as given:
//! what [`super::Query::contains`] says at every centre.

use glam::DVec3;
use rayon::prelude::*;

use super::Inside;
use crate::distance::Piece;
use crate::{GridSpec, MeshRef};

/// Voxels (of the smallest edge) around the mesh decided again: above the
/// snapping's reach (`√3/8192`) and where the caps' winding number of an
/// open mesh can move by 10⁻³.
pub const RADIUS: f64 = 0.02;

/// The voxel centres within `radius` voxels (of the smallest edge) of
/// triangle `t` (world coordinates; without area, as its edges).
fn near_triangle(t: &[DVec3; 3], grid: &GridSpec, radius: f64) -> Vec<[u32; 3]> {
    let s = grid.voxel_size().0;
    // In index units a world distance d is at least d / max edge… and at
    // most d / min edge: the radius there covers every axis.
    let r = radius * s.max_element() / s.min_element();
    let piece = Piece::new(t.map(|p| grid.to_grid_units(p)));
    let mut found = Vec::new();
    if piece.flat {
        for e in 0..3 {
            along_segment(&piece, e, r, grid.dims(), &mut found);
        }
    } else {
        across_plane(&piece, r, grid.dims(), &mut found);
    }
    found
}

/// The voxels whose decision snapping could change (within [`RADIUS`] of
/// `mesh`'s triangles, and `flagged`) where `inside` decides otherwise than `is_set`
/// (the lattice solid): the changes, sorted, and how many decisions were
/// made. Only the changes are kept (a voxel near two triangles may be
/// decided twice), so memory follows them, not the surface.
pub fn changes(
    mesh: MeshRef<'_>,
    inside: &Inside,
    grid: &GridSpec,
    flagged: &[[u32; 3]],
    is_set: impl Fn([u32; 3]) -> bool + Sync,
) -> (u64, Vec<([u32; 3], bool)>) {
    let decide = |v: [u32; 3]| {
        let want = inside.contains(grid.voxel_center(v));
        (want != is_set(v)).then_some((v, want))
    };
    let checked = std::sync::atomic::AtomicU64::new(flagged.len() as u64);
    let mut out: Vec<([u32; 3], bool)> = super::inside::triangles(mesh)
        .par_iter()
        .with_min_len(64)
        .flat_map_iter(|t| {
            let near = near_triangle(t, grid, RADIUS);
            checked.fetch_add(near.len() as u64, std::sync::atomic::Ordering::Relaxed);
            near.into_iter().filter_map(decide).collect::<Vec<_>>()
        })
        .collect();
    out.extend(flagged.par_iter().filter_map(|&v| decide(v)).collect::<Vec<_>>());
    out.sort_unstable_by_key(|(v, _)| [v[2], v[1], v[0]]);
    out.dedup();
    (checked.into_inner(), out)
}

/// Centre indices along one axis whose centres `i + ½` lie in `[lo, hi]`.
fn centres(lo: f64, hi: f64, n: u32) -> std::ops::Range<u32> {
    let first = (lo - 0.5).ceil().max(0.0);
    let last = (hi - 0.5).floor().min(n as f64 - 1.0);
    // Empty, or not a number (never for finite triangles).
    if first.partial_cmp(&last).is_none_or(|o| o == std::cmp::Ordering::Greater) {
        return 0..0;
    }
    first as u32..last as u32 + 1
}

fn push_if_near(piece: &Piece, c: [u32; 3], r: f64, out: &mut Vec<[u32; 3]>) {
    let q = DVec3::new(c[0] as f64 + 0.5, c[1] as f64 + 0.5, c[2] as f64 + 0.5);
    if piece.distance_squared(q) <= r * r {
        out.push(c);
    }
}

/// A triangle with a normal: for each row of centres along the normal's
/// largest axis, the few centres within `r` of its plane.
fn across_plane(piece: &Piece, r: f64, dims: [u32; 3], out: &mut Vec<[u32; 3]>) {
    let [a, b, c] = piece.p;
    let n = (b - a).cross(c - a);
    let ax = n.abs().max_position();
    let (u, v) = ((ax + 1) % 3, (ax + 2) % 3);
    let half = r * n.length() / n[ax].abs();
    for iu in centres(piece.lo[u] - r, piece.hi[u] + r, dims[u]) {
        for iv in centres(piece.lo[v] - r, piece.hi[v] + r, dims[v]) {
            let (cu, cv) = (iu as f64 + 0.5, iv as f64 + 0.5);
            let x = a[ax] - (n[u] * (cu - a[u]) + n[v] * (cv - a[v])) / n[ax];
            for ia in centres(x - half, x + half, dims[ax]) {
                let mut at = [0; 3];
                (at[ax], at[u], at[v]) = (ia, iu, iv);
                push_if_near(piece, at, r, out);
            }
        }
    }
}

/// Edge `e` of a piece without area: for each centre plane across the
/// edge's largest axis, the centres within `2r` of the edge's point there
/// (a centre within `r` of the edge lies within `2r` of that point on the
/// other axes, the edge sloping at most 1 to its largest axis).
fn along_segment(piece: &Piece, e: usize, r: f64, dims: [u32; 3], out: &mut Vec<[u32; 3]>) {
    let (a, b) = (piece.p[e], piece.p[(e + 1) % 3]);
    let d = b - a;
    let ax = d.abs().max_position();
    let (u, v) = ((ax + 1) % 3, (ax + 2) % 3);
    for ia in centres(a[ax].min(b[ax]) - r, a[ax].max(b[ax]) + r, dims[ax]) {
        let t = if d[ax] == 0.0 { 0.0 } else { ((ia as f64 + 0.5 - a[ax]) / d[ax]).clamp(0.0, 1.0) };
        let p = a + d * t;
        for iu in centres(p[u] - 2.0 * r, p[u] + 2.0 * r, dims[u]) {
            for iv in centres(p[v] - 2.0 * r, p[v] + 2.0 * r, dims[v]) {
                let mut at = [0; 3];
                (at[ax], at[u], at[v]) = (ia, iu, iv);
                push_if_near(piece, at, r, out);
            }
        }
    }
}
