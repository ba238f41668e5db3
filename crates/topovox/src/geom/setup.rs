//! The triangle setup of the exact target tests: a lattice triangle's
//! plane and edges relative to its first vertex (`TriSetup`), per target
//! direction (`DirSetup`), and per pivot point (`PivotCross`), in `i64`
//! where the triangle is small enough (`fits_i64`) and `i128` otherwise.
//! Every decision is Laine's (2013) test of a displaced target segment
//! against the triangle, with the tie rule of [`crate::geom::perturb`];
//! the algorithm files (`voxelize/`) and the certificates (`topology/`)
//! share it.

use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::LatticeTriangle;
use crate::geom::perturb::{bias, P3};

/// Half a voxel on the lattice.
const H: i64 = ONE / 2;

/// Largest `extent + 2 voxels` for which `TriSetup` is exact in `i64`:
/// relative coordinates stay below `2^19`; normals, `A × B` and `e × d`
/// below `2^38`; plane and orientation values below `2^58`.
pub(crate) const I64_TARGET_LIMIT: i64 = 1 << 18;

/// One triangle, set up for exact tests against displaced target segments
/// of fixed directions. Coordinates are relative to the triangle's first
/// vertex, in `T` (`i64` for small triangles, `i128` otherwise).
#[derive(Clone, Copy, Debug)]
pub(crate) struct TriSetup<T> {
    /// The first vertex (absolute lattice coordinates).
    pub a: P3,
    /// The vertices relative to `a`.
    pub rel: [[T; 3]; 3],
    /// The normal `e0 × e1`.
    pub n: [T; 3],
    /// Plane bias: a displaced point `p` is on the positive side iff `n·(p−a) >= bn`.
    pub bn: T,
}

/// Per-direction data of [`TriSetup::segment_hits`]: the direction and the
/// tie bias of each edge's orientation test.
#[derive(Clone, Copy, Debug)]
pub(crate) struct DirSetup<T> {
    /// `n·d`: the plane value's change from a segment's start to its end.
    pub nd: T,
    /// Edge orientation `O_e(p) = c_e − p·m_e` with `m_e = e × d` and
    /// `c_e = d·(A × B)` (`A`, `B` the edge's end points relative to `a`).
    m: [[T; 3]; 3],
    c: [T; 3],
    /// Tie bias of each edge's orientation test.
    pub be: [T; 3],
    /// `n·d > 0`: the orientation tests of a segment crossing the
    /// triangle's interior are all positive (else all negative).
    pos: bool,
}

/// Per edge `i` of a triangle: `W_i = (A_i − p) × (A_{i+1} − p)` for a
/// pivot point `p`. A line through `p` along `d` passes the edge on the
/// side of the sign of `d·W_i` (the orientation of the line and the edge,
/// the same for every point of the line), so all the targets on lines
/// through one point (a voxel's centre for `sep26`, `sep6`, `diagonal` and
/// the tunnels, its random point for `bubble`) are decided from one of
/// these by three dot products each, with no per-direction setup.
pub(crate) type PivotCross<T> = [[T; 3]; 3];

#[inline(always)]
pub(crate) fn dot<T: PlaneInt>(a: [T; 3], b: [T; 3]) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn crs<T: PlaneInt>(a: [T; 3], b: [T; 3]) -> [T; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// The side of an edge a displaced target line passes on, from its
/// orientation value `o` against the edge (as `d·W_i` of [`PivotCross`]):
/// positive, or on a tie (`o = 0`) the bias of the tie rule's
/// displacement, `−(e × d)`, with `e_x_d` giving `e × d` (only needed on
/// a tie).
#[inline(always)]
pub(crate) fn edge_side<T: PlaneInt>(o: T, e_x_d: impl FnOnce() -> P3) -> bool {
    if o != T::ZERO {
        o > T::ZERO
    } else {
        // `o >= be` with the tie bias `be` (0 or 1) of −(e × d).
        let m = e_x_d();
        bias([-m[0], -m[1], -m[2]]) == 0
    }
}

/// Does a line pass inside the triangle: on one side of all three edges
/// (`side(i)` for edge `i`, as [`edge_side`])?
#[inline(always)]
pub(crate) fn all_one_side(side: impl Fn(usize) -> bool) -> bool {
    let s0 = side(0);
    s0 == side(1) && s0 == side(2)
}

impl<T: PlaneInt> DirSetup<T> {
    /// How [`TriSetup::line_values`] change when the line's point moves
    /// one voxel (`ONE`) along `axis`.
    #[inline(always)]
    pub fn line_steps(&self, axis: usize) -> [T; 3] {
        let one = T::from_i64(ONE);
        self.m.map(|m| T::ZERO - m[axis] * one)
    }

    /// Does a segment of this direction that crosses the displaced plane,
    /// with these [`TriSetup::line_values`], meet the triangle?
    #[inline(always)]
    pub fn inside(&self, o: &[T; 3]) -> bool {
        ((o[0] >= self.be[0]) == self.pos) & ((o[1] >= self.be[1]) == self.pos) & ((o[2] >= self.be[2]) == self.pos)
    }
}

impl<T: PlaneInt> TriSetup<T> {
    /// Setup for `t`.
    #[inline(always)]
    pub fn new(t: &LatticeTriangle) -> TriSetup<T> {
        let a = t.v[0];
        let n = t.normal();
        // Element by element: as `map`s, these were a call of their own
        // (`try_map`, not inlined; `bubble` at 32³: 4 % of the time).
        let rel = |p: P3| [T::from_i64(p[0] - a[0]), T::from_i64(p[1] - a[1]), T::from_i64(p[2] - a[2])];
        TriSetup {
            a,
            rel: [rel(t.v[0]), rel(t.v[1]), rel(t.v[2])],
            n: [T::from_i64(n[0]), T::from_i64(n[1]), T::from_i64(n[2])],
            bn: T::from_i64(bias(n)),
        }
    }

    /// Setup for target segments of direction `d` (lattice units).
    pub fn dir(&self, t: &LatticeTriangle, d: P3) -> DirSetup<T> {
        // orient(p+δ, q+δ, A, B) = O − δ·(e × d): its tie is decided by −(e × d).
        let m64: [[i64; 3]; 3] = std::array::from_fn(|i| crate::geom::lattice::cross(t.edge(i), d));
        let be = m64.map(|m| T::from_i64(bias([-m[0], -m[1], -m[2]])));
        let dt = d.map(T::from_i64);
        let m = m64.map(|m| m.map(T::from_i64));
        let c = std::array::from_fn(|i| dot(dt, crs(self.rel[i], self.rel[(i + 1) % 3])));
        let nd = dot(self.n, dt);
        DirSetup { nd, m, c, be, pos: nd > T::ZERO }
    }

    /// A lattice point relative to `a`.
    #[inline(always)]
    pub fn local(&self, p: P3) -> [T; 3] {
        std::array::from_fn(|c| T::from_i64(p[c] - self.a[c]))
    }

    /// [`Self::segment_hits_with`], skipping the edges flagged `safe`: those
    /// the caller knows the crossing point lies strictly inside of (for
    /// a crossing segment, a point outside the triangle is outside at least
    /// one edge, so testing the other edges against the expected sign
    /// decides).
    #[inline(always)]
    pub fn segment_hits_unsafe_edges(&self, ds: &DirSetup<T>, p: [T; 3], vp: T, safe: [bool; 3]) -> bool {
        if (vp >= self.bn) == (vp + ds.nd >= self.bn) {
            return false;
        }
        (0..3).all(|i| safe[i] || (ds.c[i] - dot(p, ds.m[i]) >= ds.be[i]) == ds.pos)
    }

    /// The plane value `n·p` of a point `p` relative to `a` (its displaced
    /// copy is on the positive side iff the value is `>= bn`).
    #[inline(always)]
    pub fn plane(&self, p: [T; 3]) -> T {
        dot(self.n, p)
    }

    /// Does the displaced target segment from `p` (relative to `a`) to
    /// `p + d` meet the triangle? Same decision as
    /// [`crate::geom::perturb::segment_meets_triangle`] with the segment as target.
    #[inline(always)]
    pub fn segment_hits(&self, ds: &DirSetup<T>, p: [T; 3]) -> bool {
        self.segment_hits_with(ds, p, self.plane(p))
    }

    /// [`Self::segment_hits`] given the start's plane value `vp = plane(p)`.
    #[inline(always)]
    pub fn segment_hits_with(&self, ds: &DirSetup<T>, p: [T; 3], vp: T) -> bool {
        if (vp >= self.bn) == (vp + ds.nd >= self.bn) {
            return false;
        }
        let o = |i: usize| ds.c[i] - dot(p, ds.m[i]) >= ds.be[i];
        let o0 = o(0);
        o0 == o(1) && o0 == o(2)
    }

    /// [`Self::segment_hits_with`] for a segment tested once (its direction
    /// `d` differs from every other's, as `bubble`'s random targets do),
    /// without [`Self::dir`]'s setup: the edge sides of its line from the
    /// [`PivotCross`] of its start.
    #[inline(always)]
    pub fn segment_hits_once(&self, t: &LatticeTriangle, p: [T; 3], d: P3, vp: T) -> bool {
        let dt = d.map(T::from_i64);
        if (vp >= self.bn) == (vp + dot(self.n, dt) >= self.bn) {
            return false;
        }
        self.line_hits(t, &self.pivot_cross(p), dt, d)
    }

    /// The [`PivotCross`] of the centre of the voxel whose low corner is
    /// `pc` (relative to `a`).
    #[inline(always)]
    pub fn centre_cross(&self, pc: [T; 3]) -> PivotCross<T> {
        let h = T::from_i64(H);
        self.pivot_cross(pc.map(|x| x + h))
    }

    /// The [`PivotCross`] of a point `p` relative to `a`.
    #[inline(always)]
    pub fn pivot_cross(&self, p: [T; 3]) -> PivotCross<T> {
        std::array::from_fn(|i| {
            let (a, b) = (self.rel[i], self.rel[(i + 1) % 3]);
            crs(std::array::from_fn(|c| a[c] - p[c]), std::array::from_fn(|c| b[c] - p[c]))
        })
    }

    /// Does the displaced line along `d` (as `dt`, or any positive multiple
    /// of it) through the pivot of `w` pass inside the triangle's three
    /// edges? With a plane test on a segment of the line, the same
    /// decision as [`crate::geom::perturb::segment_meets_triangle`]: the edge orientations of
    /// the segment are `d·W_i`, and a tie (0) takes the bias of the tie
    /// rule's displacement, `−(e_i × d)`, as [`DirSetup`] does.
    #[inline(always)]
    pub fn line_hits(&self, t: &LatticeTriangle, w: &PivotCross<T>, dt: [T; 3], d: P3) -> bool {
        all_one_side(|i| edge_side(dot(dt, w[i]), || crate::geom::lattice::cross(t.edge(i), d)))
    }

    /// Along a line `p + λ·u` (`u` of steps −1, 0, 1, `λ` in lattice
    /// units, so the line moves one voxel per `ONE` of `λ` on every axis
    /// `u` moves on) whose plane value (relative to `a`) is
    /// `v0 + (λ − at)·g` (`g ≠ 0`): the `m` whose displaced segment
    /// `λ ∈ [m·ONE, (m + 1)·ONE]` straddles the plane (exactly one does).
    /// A diagonal's line from a lattice point has `at = 0`; a crosshair's
    /// `w`-line has `λ = W`, `g = n_w` and `at = a_w`, and `m` is the voxel
    /// index of the one voxel of the column `sep6` sets (Laine's column
    /// rule).
    #[inline(always)]
    pub fn straddling_step(&self, g: T, v0: T, at: T) -> T {
        let one = T::from_i64(ONE);
        if g > T::ZERO {
            // Positive iff λ >= at + ceil((bn − v0) / g).
            let first = at - (v0 - self.bn).div_floor(g);
            (first - T::from_i64(1)).div_floor(one)
        } else {
            // Positive iff λ <= at + floor((v0 − bn) / −g).
            (at + (v0 - self.bn).div_floor(-g)).div_floor(one)
        }
    }

    /// The three edge orientation values of the target line through `p`
    /// (relative to `a`) with direction `ds`. The displaced line meets the
    /// triangle iff the three `values[i] >= ds.be[i]` agree.
    #[inline(always)]
    pub fn line_values(&self, ds: &DirSetup<T>, p: [T; 3]) -> [T; 3] {
        std::array::from_fn(|i| ds.c[i] - dot(p, ds.m[i]))
    }
}

/// The dominant axis `w` of the triangle's normal (the first of equal
/// largest components) and the projection axes `(u, v)` after it.
pub(crate) fn dominant_axes(t: &LatticeTriangle) -> (usize, usize, usize) {
    let n = t.normal();
    let w = (0..3).fold(0, |best, a| if n[a].abs() > n[best].abs() { a } else { best });
    ((w + 1) % 3, (w + 2) % 3, w)
}

/// Is a triangle with these lattice bounds small enough for `i64` setups?
pub(crate) fn fits_i64(t: &LatticeTriangle) -> bool {
    let (lo, hi) = t.bounds();
    (0..3).map(|a| hi[a] - lo[a]).max().unwrap_or(0) + 2 * ONE <= I64_TARGET_LIMIT
}
