//! Laine's thin 6-separating surface voxelization (`sep6`), from a single
//! 2D projection.
//!
//! This work is based on: S. Laine, "A Topological Approach to
//! Voxelization", Computer Graphics Forum 32(4), 2013, §5.2 (the 3D
//! crosshair target, thinness, and "voxelization with a single 2D
//! projection").
//!
//! **Guarantee.** Voxel `(i,j,k)` is set iff some (snapped, non-degenerate)
//! triangle meets one of the voxel's three crosshair segments (face centre
//! to opposite face centre through the voxel centre), displaced by the tie
//! rule of [`crate::geom::perturb`]. For a closed surface the result is
//! 6-separating; it is thin: a planar triangle sets at most one voxel per
//! column along its normal's dominant axis; it is a subset of `cover`.
//!
//! **Fast path** (Laine's algorithm). Project each triangle along the
//! dominant axis `w` of its normal. For a pixel whose (displaced) centre
//! lies inside the projection, the `w` crosshair segment of exactly one
//! voxel of the column is hit — the one whose segment straddles the plane,
//! found by one exact division — and thinness proves no other voxel of the
//! column is. For a pixel whose square meets the projection but whose centre
//! does not, the two perpendicular crosshair segments are tested exactly for
//! the few voxels around the plane's depth. All tests are exact integers
//! (`i64` relative to the triangle, `i128` for huge triangles).
//!
//! **Reference:** [`reference::sep6`], the definition evaluated with the
//! generic `i128` predicate for every voxel of each triangle's bounding box.

use super::driver::{run_slabs, Kernel};
use super::targets::{fits_i64, TriSetup};
use super::{Options, Report};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::{prepare, LatticeTriangle};
use crate::grid::bricks::{BrickBits, BrickSlab};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

const H: i64 = ONE / 2;

/// Thin 6-separating voxelization, fast path, into sparse brick storage.
pub fn sep6(mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> (BrickBits, Report) {
    let (tris, prepare_stats) = prepare(mesh, grid);
    let (bits, voxels) = run_slabs(&Sep6Kernel, &tris, grid.dims(), opts);
    (bits, Report { prepare: prepare_stats, voxels })
}

struct Sep6Kernel;

impl Kernel<LatticeTriangle> for Sep6Kernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        if fits_i64(tri) {
            project::<i64>(tri, lo, hi, slab);
        } else {
            project::<i128>(tri, lo, hi, slab);
        }
    }
}

fn unit(a: usize) -> [i64; 3] {
    let mut d = [0; 3];
    d[a] = ONE;
    d
}

fn div_floor(n: i128, d: i128) -> i128 {
    let q = n / d;
    if (n % d != 0) && ((n < 0) != (d < 0)) {
        q - 1
    } else {
        q
    }
}

/// Laine's single-projection algorithm for one triangle, restricted to the
/// voxel box `[lo, hi]`.
fn project<T: PlaneInt>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
    let s = TriSetup::<T>::new(tri);
    let n = tri.normal();
    let w = (0..3).fold(0, |best, a| if n[a].abs() > n[best].abs() { a } else { best });
    let (u, v) = ((w + 1) % 3, (w + 2) % 3);
    let (dw, du, dv) = (s.dir(tri, unit(w)), s.dir(tri, unit(u)), s.dir(tri, unit(v)));
    // Inside the projection the w-line's edge values are positive iff n_w > 0.
    let sgn = if n[w] > 0 { T::from_i64(1) } else { T::from_i64(-1) };
    // How much an edge value can grow from the pixel centre to its square.
    let reach: [T; 3] = std::array::from_fn(|i| {
        let e = tri.edge(i);
        T::from_i64(H * ONE * (e[u].abs() + e[v].abs()))
    });
    let (nu, nv, nw) = (n[u] as i128, n[v] as i128, n[w] as i128);
    let emit = |slab: &mut BrickSlab<'_>, iu: i64, iv: i64, t: i64| {
        let mut ijk = [0i64; 3];
        (ijk[u], ijk[v], ijk[w]) = (iu, iv, t);
        slab.set(ijk[0] as u32, ijk[1] as u32, ijk[2] as u32);
    };
    for iv in lo[v]..=hi[v] {
        for iu in lo[u]..=hi[u] {
            // The pixel centre, at the depth of the triangle's first vertex.
            let mut c = s.a;
            (c[u], c[v]) = (iu * ONE + H, iv * ONE + H);
            let pc = s.local(c);
            let o = s.line_values(&dw, pc);
            let inside = [0, 1, 2].map(|i| o[i] >= dw.be[i]);
            if inside[0] == inside[1] && inside[1] == inside[2] {
                // Plane value along the column: V(W) = v0 + n_w·(W − a_w),
                // positive side iff V >= bn. The hit voxel's segment
                // [t·ONE, (t+1)·ONE] straddles the switch.
                let v0 = nu * pc[u].to_i128() + nv * pc[v].to_i128();
                let bn = s.bn.to_i128();
                let aw = s.a[w] as i128;
                let t = if nw > 0 {
                    // above iff W >= a_w + ceil((bn − v0) / n_w)
                    let w_star = aw - div_floor(v0 - bn, nw);
                    div_floor(w_star - 1, ONE as i128)
                } else {
                    // above iff W <= a_w + floor((v0 − bn) / −n_w)
                    let w_star = aw + div_floor(v0 - bn, -nw);
                    div_floor(w_star, ONE as i128)
                };
                if t >= lo[w] as i128 && t <= hi[w] as i128 {
                    emit(slab, iu, iv, t as i64);
                }
                continue;
            }
            // Centre outside: skip pixels whose square misses the projection.
            if (0..3).any(|i| sgn * o[i] + reach[i] < T::ZERO) {
                continue;
            }
            // The plane's depth at the centre; over the pixel it moves by at
            // most one voxel (|n_u|, |n_v| <= |n_w|). The margin keeps the
            // f64 estimate a superset; the tests below are exact.
            let depth = s.a[w] as f64 - (nu as f64 * pc[u].to_f64() + nv as f64 * pc[v].to_f64()) / nw as f64;
            let t0 = (((depth - (ONE + H) as f64) / ONE as f64).floor() as i64 - 1).max(lo[w]);
            let t1 = (((depth + (ONE - H) as f64) / ONE as f64).ceil() as i64 + 1).min(hi[w]);
            for t in t0..=t1 {
                let mut pu = [0i64; 3];
                (pu[u], pu[v], pu[w]) = (iu * ONE, iv * ONE + H, t * ONE + H);
                let mut pv = [0i64; 3];
                (pv[u], pv[v], pv[w]) = (iu * ONE + H, iv * ONE, t * ONE + H);
                if s.segment_hits(&du, s.local(pu)) || s.segment_hits(&dv, s.local(pv)) {
                    emit(slab, iu, iv, t);
                }
            }
        }
    }
}

/// The slow, obviously correct definition of `sep6`.
pub mod reference {
    use super::*;
    use crate::grid::dense::DenseBits;
    use crate::voxelize::targets::sep6_hit;

    /// Brute force over each triangle's bounding box.
    pub fn sep6(mesh: MeshRef<'_>, grid: &GridSpec) -> (DenseBits, Report) {
        super::super::brute_force_triangles(mesh, grid, sep6_hit)
    }
}
