//! Schwarz & Seidel's 6-separating surface voxelization (`ss6`).
//!
//! This work is based on: M. Schwarz, H.-P. Seidel, "Fast Parallel Surface
//! and Solid Voxelization on GPUs", ACM TOG 29(6), 2010, §3.2 (6-separating
//! surface voxelization: the plane test against the voxel's inscribed
//! octahedron, and 2D "diamond" edge tests in the three axis projections).
//!
//! **Definition.** With voxel centre `m`, half size `h` and triangle normal
//! `n`, voxel `(i,j,k)` is set iff for some (snapped, non-degenerate)
//! triangle whose bounding box meets the voxel:
//! - plane test: `|n·(m − v₀)| <= h·max(|nx|, |ny|, |nz|)` (the plane meets
//!   the octahedron spanned by the face centres), and
//! - for each axis plane `xy`, `yz`, `zx` and each edge `i`, with the edge's
//!   2D normal `nₑ` turned inward by the sign of the dropped normal
//!   component (`+` when it is zero): `nₑ·(m − vᵢ) + h·max(|nₑ|) >= 0` (the
//!   projected edge's half-plane meets the pixel's diamond).
//!
//! Ties follow [`crate::geom::perturb`] (the voxel's octahedron and
//! diamonds displaced by `δ`; a test whose value does not depend on the
//! displacement passes when it is `>= 0`).
//!
//! **Guarantee.** 6-separating for closed surfaces (Laine 2013 §5.2.2: the
//! octahedron test contains the crosshair target), so `sep6 ⊆ ss6`, and not
//! minimal; a subset of `cover`.
//!
//! **Fast path.** `cover`'s exact traversal enumerates candidates; each gets
//! the test above in `i64` (relative to the voxel box) or `i128`.
//!
//! **Reference:** [`reference::ss6`], the formulas above in `i128` with
//! the perturbation evaluated symbolically, for every voxel of each
//! triangle's bounding box.

use super::cover::cover_triangle;
use super::driver::{run_mesh, Filter, Kernel};
use super::targets::fits_i64;
use super::{Options, Report, Traversal};
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::geom::perturb::bias;
use crate::grid::bricks::{BrickBits, BrickSlab};
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

const H: i64 = ONE / 2;

/// Schwarz–Seidel 6-separating voxelization, fast path, into sparse bricks.
pub fn ss6(mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> (BrickBits, Report) {
    run_mesh(&Ss6Kernel { traversal: opts.traversal }, mesh, grid, opts)
}

/// The fast path on already prepared triangles.
pub fn ss6_lattice(tris: &[LatticeTriangle], dims: [u32; 3], opts: &Options<'_>) -> BrickBits {
    super::driver::run_slabs(&Ss6Kernel { traversal: opts.traversal }, tris, dims, opts).0
}

struct Ss6Kernel {
    traversal: Traversal,
}

impl Kernel<LatticeTriangle> for Ss6Kernel {
    fn run(&self, tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
        if fits_i64(tri) {
            filtered::<i64>(tri, lo, hi, self.traversal, slab);
        } else {
            filtered::<i128>(tri, lo, hi, self.traversal, slab);
        }
    }
}

/// A linear test `g·(m − a) + c >= bias` on the voxel centre `m`, with `a`
/// the triangle's first vertex.
#[derive(Clone, Copy)]
struct Lin<T> {
    g: [T; 3],
    c: T,
}

fn filtered<T: PlaneInt>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], traversal: Traversal, slab: &mut BrickSlab<'_>) {
    let a = tri.v[0];
    let n = tri.normal();
    let r = H * n.iter().map(|c| c.abs()).max().unwrap_or(0);
    let t = T::from_i64;
    // On the stack: at small grids a heap allocation per triangle shows.
    let mut tests = [Lin { g: [T::ZERO; 3], c: T::ZERO }; 11];
    // Plane: n·d + r >= bias(n) and −n·d + r >= bias(−n).
    tests[0] = Lin { g: n.map(t), c: t(r - bias(n)) };
    tests[1] = Lin { g: n.map(|c| t(-c)), c: t(r - bias(n.map(|c| -c))) };
    for (c, &nc) in n.iter().enumerate() {
        let (p, q) = ((c + 1) % 3, (c + 2) % 3);
        let sgn = if nc >= 0 { 1 } else { -1 };
        for i in 0..3 {
            let e = tri.edge(i);
            let mut g = [0i64; 3];
            g[p] = -e[q] * sgn;
            g[q] = e[p] * sgn;
            // Relative to a: g·(m − vᵢ) = g·(m − a) − g·(vᵢ − a).
            let vi = tri.v[i];
            let off = g[p] * (vi[p] - a[p]) + g[q] * (vi[q] - a[q]);
            let c0 = H * g[p].abs().max(g[q].abs()) - off - bias(g);
            tests[2 + 3 * c + i] = Lin { g: g.map(t), c: t(c0) };
        }
    }
    let keep = |ijk: [i64; 3]| {
        let d: [T; 3] = std::array::from_fn(|x| t(ijk[x] * ONE + H - a[x]));
        tests.iter().all(|l| l.g[0] * d[0] + l.g[1] * d[1] + l.g[2] * d[2] + l.c >= T::ZERO)
    };
    cover_triangle(tri, lo, hi, traversal, &mut Filter { slab, keep });
}

/// The slow, obviously correct definition of `ss6`.
pub mod reference {
    use super::*;
    use crate::geom::perturb::displaced_sign;
    use crate::grid::dense::DenseBits;

    /// Brute force over each triangle's bounding box.
    pub fn ss6(mesh: MeshRef<'_>, grid: &GridSpec) -> (DenseBits, Report) {
        super::super::brute_force_triangles(mesh, grid, ss6_hit)
    }

    /// The formulas of the module documentation, with the displacement `δ`
    /// carried symbolically: a test `f(m + δ) >= 0` on an affine `f` with
    /// gradient `g` is `displaced_sign(f(m), g) >= 0`.
    pub fn ss6_hit(t: &LatticeTriangle, ijk: [i64; 3]) -> bool {
        let m: [i128; 3] = ijk.map(|c| (c * ONE + H) as i128);
        let v: [[i128; 3]; 3] = t.v.map(|p| p.map(|c| c as i128));
        let n: [i128; 3] = t.normal().map(|c| c as i128);
        let h = H as i128;
        let r = h * n.iter().map(|c| c.abs()).max().unwrap_or(0);
        let d: i128 = (0..3).map(|x| n[x] * (m[x] - v[0][x])).sum();
        if displaced_sign(d + r, n) < 0 || displaced_sign(r - d, n.map(|c| -c)) < 0 {
            return false;
        }
        for (c, &nc) in n.iter().enumerate() {
            let (p, q) = ((c + 1) % 3, (c + 2) % 3);
            let sgn = if nc >= 0 { 1 } else { -1 };
            for i in 0..3 {
                let (vi, vj) = (v[i], v[(i + 1) % 3]);
                let mut g = [0i128; 3];
                g[p] = -(vj[q] - vi[q]) * sgn;
                g[q] = (vj[p] - vi[p]) * sgn;
                let f = g[p] * (m[p] - vi[p]) + g[q] * (m[q] - vi[q]) + h * g[p].abs().max(g[q].abs());
                if displaced_sign(f, g) < 0 {
                    return false;
                }
            }
        }
        true
    }
}
