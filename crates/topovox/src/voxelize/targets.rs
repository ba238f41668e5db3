//! Intersection targets (Laine 2013) and the exact tests against them.
//!
//! This work is based on: S. Laine, "A Topological Approach to
//! Voxelization", Computer Graphics Forum 32(4), 2013. A voxel is set iff
//! the input meets the voxel's *target*; the target's shape, not the
//! primitive, decides the topology of the result:
//!
//! | target | voxel `(i,j,k)`, corner `c = (i,j,k)·s`, centre `m = c + s/2` | used by |
//! |---|---|---|
//! | space diagonals | the four segments joining opposite corners | `sep26` (26-separating) |
//! | 3D crosshair | the three axis-parallel segments through `m` from face centre to face centre | `sep6` (6-separating, thin) |
//! | bisecting squares | the three axis-aligned squares through `m` spanning the voxel | `line26` (26-connected) |
//! | voxel surface | the six closed faces | `line6` (6-connected) |
//!
//! Every target lies in the closed voxel, so each mode is a subset of
//! `cover`, and fast paths may enumerate `cover`'s voxels as candidates.
//! Ties follow [`crate::geom::perturb`]: targets are displaced by
//! `δ = −(ε, ε², ε³)`.
//!
//! The `*_hit` functions here are the definitions, in `i128` via the generic
//! orientation predicate; `TriSetup` is the same test specialised for one
//! triangle and a fixed segment direction, for the fast paths, and
//! `LazyTargets` decides the targets of a voxel that lie on lines through
//! its centre from one cross product per triangle edge.
//!
//! # Implementation notes
//!
//! Laine's targets (diagonals, crosshair, bisecting
//! squares, faces), their definitional `*_hit` tests, and `TriSetup`, the
//! same segment test specialised per triangle and direction in `i64`.
//! Every target of `sep26`, `sep6`, `diagonal` and the tunnels lies on a
//! line through its voxel's centre `c`, so one `PivotCross` per voxel
//! (`(A_i − c) × (A_{i+1} − c)` per edge) decides all of them by dot
//! products, with no per-direction setup (`edge_side` holds the tie rule
//! for a line's side of an edge). `TargetSet` holds a kernel's targets:
//! whether they are centred, their unit steps, whether they come in
//! opposite pairs, and per box of reached forms which are live (a table).
//! `PairedTargets` (the tunnels) asks per line through the centre, one
//! comparison of `|n·d|` each, whether one of its two targets crosses the
//! plane, then the crossing lines' edge sides all at once: the sign of
//! `u·W` for every unit direction `u` follows from `W`'s signs and six
//! comparisons of its magnitudes (`sign_key`), so a table per key gives
//! each edge's positive lines (for triangles in a box of at most 64
//! voxels; larger ones, and ties, go one line at a time and stop at the
//! first hit); `LazyTargets` tests one target at a
//! time (`diagonal`'s big triangles), and other sets take
//! `segment_hits_once`, the same test from the segment's start (`bubble`
//! pivots at each voxel's random point, which all seven of its targets'
//! lines pass through; for triangles in a box of at most 27 voxels the
//! points come from a per-thread cache of recent voxels, not the hash,
//! and the seven plane tests make a mask rather than seven branches).
//! `diagonal_lines` walks the diagonals' lines through voxel corners for
//! small triangles, one instance per direction so its products with the
//! steps fold away: all of them for `sep26`,
//! only those through all-even corners for `diagonal` (they carry exactly
//! each voxel's own diagonal). `straddling_step` finds the one target on
//! a line that straddles the plane (Laine's column rule is its axis case);
//! `forms_reached` and `TargetSet::may_meet` are integer
//! tests on a triangle's box that rule out crosshair, tunnel or diagonal
//! targets before any setup (most triangles at 32³): each target of a
//! `TargetSet` needs some invariant forms (a coordinate on a voxel
//! mid-plane, `x_p ± x_q` on a multiple of `ONE`) that the box must
//! reach.
//!
//! The target modes' fast paths (`sep26.rs`, `sep6.rs`, `ss6.rs`, `line.rs`):
//!
//! - `ss6`: its plane test passes exactly one voxel per column of the
//!   dominant projection, tracked along each row by a remainder (`columns`);
//!   pixels strictly inside the projection set it untested, the others run
//!   the nine edge tests on it. Boxes of at most 27 voxels take `cover`'s
//!   traversal with the test as a `Filter`.
//! - `line*` on triangles: `cover`'s traversal enumerates each
//!   triangle's candidates (every target lies in the closed voxel, and the
//!   perturbed hit implies the closed touch), and a `Filter` applies the
//!   mode's exact test.
//! - `sep26`: its own walk of the dominant projection's columns; per column
//!   the two to four voxels around the plane's depth get an exact corner-sign
//!   test (a plane that separates a voxel's corners crosses one of its space
//!   diagonals: opposite corners average to the centre's value), then the
//!   diagonal tests (the steepest diagonal first: it crosses wherever any
//!   does; none for a voxel a neighbour has set), skipping the edges whose
//!   half-plane contains the whole pixel.
//! - `sep6`: Laine's single 2D projection. Pixels whose displaced centre is
//!   inside the projection emit exactly one voxel, found by one exact
//!   division (thinness proves no other voxel of the column is hit); pixels
//!   whose square meets the projection test the two perpendicular crosshair
//!   segments for the two or three voxels around the plane's depth.
//! - `line*` on segments: each layer along the segment's dominant axis tests
//!   the voxels within one voxel of its span there.
//!
//! Tiny triangles: in `sep26.rs` and `sep6.rs`, triangles in a box of at
//! most 27 voxels go by their targets' lines one by one (the crosshair's
//! axis lines through pixel centres, the diagonals' lines through corners
//! found in an oblique projection), each line meeting the triangle setting
//! its one straddling voxel; larger ones: `sep26` by Laine's single
//! projection, `sep6` by `line_spans.rs`, Laine's single projection only
//! beyond `i64`.

use super::driver::box_volume;
use crate::geom::divide::Divisor;
use crate::geom::fixed::{PlaneInt, ONE};
use crate::geom::lattice::{LatticeSegment, LatticeTriangle};
use crate::geom::perturb::{segment_meets_square, segment_meets_triangle, triangle_meets_square, P3};
use crate::geom::setup::{all_one_side, dot, edge_side, DirSetup, PivotCross, TriSetup};
use crate::grid::bricks::BrickSlab;

const H: i64 = ONE / 2;

fn corner(ijk: [i64; 3]) -> P3 {
    ijk.map(|c| c * ONE)
}

fn add(a: P3, b: P3) -> P3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Start offsets (from the voxel's low corner) and directions of the four
/// space diagonals.
pub const DIAGONALS: [(P3, P3); 4] =
    [([0, 0, 0], [ONE, ONE, ONE]), ([ONE, 0, 0], [-ONE, ONE, ONE]), ([0, ONE, 0], [ONE, -ONE, ONE]), ([0, 0, ONE], [ONE, ONE, -ONE])];

/// Start offsets and directions of the three crosshair segments (along x, y, z).
pub const CROSSHAIR: [(P3, P3); 3] = [([0, H, H], [ONE, 0, 0]), ([H, 0, H], [0, ONE, 0]), ([H, H, 0], [0, 0, ONE])];

/// The four space diagonals of voxel `ijk`.
pub fn diagonals(ijk: [i64; 3]) -> [[P3; 2]; 4] {
    DIAGONALS.map(|(o, d)| {
        let p = add(corner(ijk), o);
        [p, add(p, d)]
    })
}

/// The three crosshair segments of voxel `ijk`.
pub fn crosshair(ijk: [i64; 3]) -> [[P3; 2]; 3] {
    CROSSHAIR.map(|(o, d)| {
        let p = add(corner(ijk), o);
        [p, add(p, d)]
    })
}

/// The square perpendicular to `axis` at offset `at` (lattice units from
/// the voxel's low corner), spanning the voxel, corners in order.
fn square(ijk: [i64; 3], axis: usize, at: i64) -> [P3; 4] {
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let c = corner(ijk);
    let pt = |du: i64, dv: i64| {
        let mut p = c;
        p[axis] += at;
        p[u] += du;
        p[v] += dv;
        p
    };
    [pt(0, 0), pt(ONE, 0), pt(ONE, ONE), pt(0, ONE)]
}

/// The three axis-aligned squares bisecting voxel `ijk`.
pub fn bisecting_squares(ijk: [i64; 3]) -> [[P3; 4]; 3] {
    std::array::from_fn(|a| square(ijk, a, H))
}

/// The six faces of voxel `ijk`.
pub fn faces(ijk: [i64; 3]) -> [[P3; 4]; 6] {
    std::array::from_fn(|f| square(ijk, f / 2, (f % 2) as i64 * ONE))
}

/// `sep26` definition: the triangle meets one of the voxel's space diagonals.
pub fn sep26_hit(t: &LatticeTriangle, ijk: [i64; 3]) -> bool {
    diagonals(ijk).iter().any(|s| segment_meets_triangle(*s, t.v, true))
}

/// `sep6` definition: the triangle meets one of the voxel's crosshair segments.
pub fn sep6_hit(t: &LatticeTriangle, ijk: [i64; 3]) -> bool {
    crosshair(ijk).iter().any(|s| segment_meets_triangle(*s, t.v, true))
}

/// An input element of the line modes: a segment, or a triangle (whose
/// effective dimension may be 1, e.g. a thin tube).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Element {
    /// A polyline segment.
    Segment(LatticeSegment),
    /// A triangle.
    Triangle(LatticeTriangle),
}

impl Element {
    /// The element moved by `shift` lattice units.
    pub fn translated(&self, shift: P3) -> Element {
        match self {
            Element::Segment(s) => Element::Segment(s.translated(shift)),
            Element::Triangle(t) => Element::Triangle(t.translated(shift)),
        }
    }

    fn meets_square(&self, q: [P3; 4]) -> bool {
        match self {
            Element::Segment(s) => segment_meets_square(s.v, q),
            Element::Triangle(t) => triangle_meets_square(t.v, q),
        }
    }
}

/// `line26` definition: the element meets one of the three bisecting squares.
pub fn line26_hit(e: &Element, ijk: [i64; 3]) -> bool {
    bisecting_squares(ijk).iter().any(|q| e.meets_square(*q))
}

/// `line6` definition: the element meets the voxel's surface.
pub fn line6_hit(e: &Element, ijk: [i64; 3]) -> bool {
    faces(ijk).iter().any(|q| e.meets_square(*q))
}

/// The pixel test of the `w` projection: the `w`-line edge values at a
/// pixel centre, multiplied by `sign`, are all `> 0` at every point of
/// the pixel iff each exceeds its `reach` (how much an edge value changes
/// from the centre to the square's corners).
pub(crate) struct PixelTest<T> {
    /// Direction setup of the `w` lines.
    pub dw: DirSetup<T>,
    /// `+1` if `n_w > 0`, else `−1`: inside the projection the signed values are positive.
    pub sign: T,
    /// Per edge: the largest change of its value over half a pixel each way.
    pub reach: [T; 3],
}

impl<T: PlaneInt> PixelTest<T> {
    /// Setup for `t` projected along `w` (with `(u, v, w)` from [`dominant_axes`]).
    pub fn new(s: &TriSetup<T>, t: &LatticeTriangle, (u, v, w): (usize, usize, usize)) -> PixelTest<T> {
        let mut d = [0; 3];
        d[w] = ONE;
        let sign = if t.normal()[w] > 0 { T::from_i64(1) } else { T::from_i64(-1) };
        let reach = std::array::from_fn(|i| {
            let e = t.edge(i);
            T::from_i64(H * ONE * (e[u].abs() + e[v].abs()))
        });
        PixelTest { dw: s.dir(t, d), sign, reach }
    }

    /// Does the closed pixel square around centre `pc` (relative, any `w`)
    /// miss the projected triangle?
    #[inline(always)]
    pub fn misses(&self, o: &[T; 3]) -> bool {
        (0..3).any(|i| self.sign * o[i] + self.reach[i] < T::ZERO)
    }

    /// The [`PixelBounds`] of the pixel centred at `p` (relative, any `w`).
    #[inline(always)]
    pub fn bounds(&self, s: &TriSetup<T>, p: [T; 3]) -> PixelBounds<T> {
        let o = s.line_values(&self.dw, p);
        PixelBounds(std::array::from_fn(|i| {
            let (e, r) = (i % 3, self.reach[i % 3]);
            self.sign * o[e] + if i < 3 { -r } else { r }
        }))
    }
}

/// How [`PixelBounds`] change from one pixel of a row to the next, with
/// the magnitudes of the changes [`PixelBounds::row_span`] divides by
/// (once per row) as [`Divisor`]s, made once per triangle.
#[derive(Clone, Copy)]
pub(crate) struct RowDelta<T> {
    step: [T; 6],
    div: [Divisor<T>; 3],
}

/// A pixel's three edge values signed so that the projection's inside is
/// positive, less (`[0..3]`) and plus (`[3..6]`) each edge's reach: the
/// decision of [`PixelTest::misses`] and whether the square lies strictly
/// inside each edge, without multiplications, stepped along a row by
/// additions ([`Self::step`]).
#[derive(Clone, Copy)]
pub(crate) struct PixelBounds<T>(pub [T; 6]);

impl<T: PlaneInt> PixelBounds<T> {
    /// Does the closed pixel square miss the projected triangle?
    #[inline(always)]
    pub fn misses(&self) -> bool {
        let b = &self.0;
        b[3] < T::ZERO || b[4] < T::ZERO || b[5] < T::ZERO
    }

    /// Per edge: does the closed square lie strictly on the inner side?
    #[inline(always)]
    pub fn strictly_inside_edges(&self) -> [bool; 3] {
        let b = &self.0;
        [b[0] > T::ZERO, b[1] > T::ZERO, b[2] > T::ZERO]
    }

    /// The difference `next − self` (both of one row), for [`Self::step`].
    #[inline(always)]
    pub fn delta(&self, next: &PixelBounds<T>) -> RowDelta<T> {
        let step: [T; 6] = std::array::from_fn(|i| next.0[i] - self.0[i]);
        let div = std::array::from_fn(|i| {
            let d = step[3 + i];
            Divisor::new(if d < T::ZERO {
                T::ZERO - d
            } else if d > T::ZERO {
                d
            } else {
                T::from_i64(1)
            })
        });
        RowDelta { step, div }
    }

    /// The pixels `lo ..= hi` of a row, the first of which these bounds
    /// are, that meet the projected triangle (empty if `lo > hi` on
    /// return): the bounds [`Self::misses`] reads are affine along the
    /// row (`delta` per pixel), each solved for the pixel with one exact
    /// division, so pixels outside need not be visited.
    #[inline(always)]
    pub fn row_span(&self, delta: &RowDelta<T>, lo: i64, hi: i64) -> (i64, i64) {
        let (mut a0, mut a1) = (lo, hi);
        for ((&r, &d), div) in self.0[3..].iter().zip(&delta.step[3..]).zip(&delta.div) {
            if d > T::ZERO {
                a0 = a0.max(lo + div.ceil(T::ZERO - r));
            } else if d < T::ZERO {
                a1 = a1.min(lo + div.floor(r));
            } else if r < T::ZERO {
                a1 = a0 - 1;
            }
        }
        (a0, a1)
    }

    /// Moves `k` pixels along the row.
    #[inline(always)]
    pub fn advance(&mut self, delta: &RowDelta<T>, k: T) {
        #[allow(clippy::needless_range_loop)]
        for i in 0..6 {
            self.0[i] = self.0[i] + delta.step[i] * k;
        }
    }

    /// Moves to the next pixel of the row.
    #[inline(always)]
    pub fn step(&mut self, delta: &RowDelta<T>) {
        #[allow(clippy::needless_range_loop)]
        for i in 0..6 {
            self.0[i] = self.0[i] + delta.step[i];
        }
    }
}

/// Per axis `a`: does the closed lattice box `[lo, hi]`, grown by one
/// lattice unit (the tie rule's displacement is infinitesimal), hold one
/// of the voxels' mid-planes `x_a = m·ONE + H`? Every target of `sep6`
/// (the crosshair) lies on two mid-planes and every target of `tunnel18`
/// on at least one, so a triangle whose box holds fewer meets none of
/// them: at 32³ most triangles are an eighth of a voxel wide and are
/// decided here by a few integer comparisons, before any setup.
#[inline(always)]
pub(crate) fn mid_planes(lo: P3, hi: P3) -> [bool; 3] {
    std::array::from_fn(|a| (lo[a] - 1 - H + ONE - 1).div_euclid(ONE) <= (hi[a] + 1 - H).div_euclid(ONE))
}

/// The invariant forms whose values the closed lattice box `[lo, hi]`
/// (grown by one lattice unit for the tie rule) reaches, as bits: bit `a`
/// (`a` < 3) if `x_a ≡ H (mod ONE)` somewhere (a voxel mid-plane, as in
/// [`mid_planes`]); bit `3 + 2i` (`3 + 2i + 1`) if `x_p + x_q` (`x_p −
/// x_q`) reaches a multiple of `ONE`, for the `i`-th axis pair `(p, q)`.
/// A target that needs a form the box misses cannot meet the triangle
/// ([`TargetSet`]).
#[inline(always)]
pub(crate) fn forms_reached(lo: P3, hi: P3) -> u16 {
    let (l, h) = (lo.map(|c| c - 1), hi.map(|c| c + 1));
    let mut bits = 0u16;
    for (a, m) in mid_planes(lo, hi).into_iter().enumerate() {
        bits |= (m as u16) << a;
    }
    for (i, &(p, q)) in PAIRS.iter().enumerate() {
        // x_p + x_q over [l_p + l_q, h_p + h_q]; x_p − x_q over [l_p − h_q, h_p − l_q].
        let plus = (l[p] + l[q] + ONE - 1).div_euclid(ONE) <= (h[p] + h[q]).div_euclid(ONE);
        let minus = (l[p] - h[q] + ONE - 1).div_euclid(ONE) <= (h[p] - l[q]).div_euclid(ONE);
        bits |= (plus as u16) << (3 + 2 * i) | (minus as u16) << (4 + 2 * i);
    }
    bits
}

/// The common magnitude of `d`'s non-zero components, or 0 if they differ
/// (or `d` is 0).
pub(crate) const fn even_step(d: P3) -> i64 {
    let mut m = 0;
    let mut c = 0;
    while c < 3 {
        let a = d[c].abs();
        if a != 0 {
            if m != 0 && a != m {
                return 0;
            }
            m = a;
        }
        c += 1;
    }
    m
}

/// A fixed list of target segments (start offset from the voxel's low
/// corner, direction) with what the tests need of them, computed once per
/// kernel rather than per triangle (tunnels have 26 directions).
#[derive(Clone, Copy, Debug)]
pub(crate) struct TargetSet<const N: usize> {
    seg: [(P3, P3); N],
    /// Per target: its direction over its [`even_step`] (components −1,
    /// 0, 1; centred sets only).
    unit: [P3; N],
    /// Every target is of even step and lies on a line through its voxel's
    /// centre ([`LazyTargets`] then tests edge sides from the centre's
    /// [`PivotCross`]).
    centred: bool,
    /// The [`even_step`] every target shares (centred sets), else 0.
    common_step: i64,
    /// For a set of opposite pairs (the tunnels': centred, one start and
    /// one step, each target's opposite in the set too), the number of
    /// lines through the centre they lie on, else 0.
    lines: usize,
    /// Per line `l < 13`: its `+` target's index in [`unit_table`]; past
    /// [`Self::lines`], the zero direction's (13), whose `n·u` is 0.
    pair_unit: [u8; 13],
    /// Per line `l < 13` ([`PairedTargets`]): the unit direction and the
    /// step of its `+` target, indexed by `l & 31` (no bounds check).
    line_unit: [P3; 32],
    line_d: [P3; 32],
    /// Per target: the [`forms_reached`] bits every triangle that meets
    /// one of its translates by whole voxels must have.
    needs: [u16; N],
    /// Per value of [`forms_reached`]: the live targets (bit `n`), those
    /// whose [`Self::needs`] it has, and their lines (bit `l`).
    live_of: [u32; 512],
    lines_live_of: [u16; 512],
    /// Per [`sign_key`] of a vector `W` with no ties: the lines `l` whose
    /// unit direction has `u·W > 0` (bit `l`; paired sets only).
    line_positive: [u16; 512],
    len: usize,
}

/// Every [`forms_reached`] bit.
pub(crate) const ALL_FORMS: u16 = (1 << 9) - 1;

/// The axis pairs of the [`forms_reached`] pair forms.
const PAIRS: [(usize, usize); 3] = [(0, 1), (1, 2), (0, 2)];

impl<const N: usize> TargetSet<N> {
    /// The set of `list` (at most `N`, and at most 32, targets).
    pub const fn new(list: &[(P3, P3)]) -> Self {
        assert!(list.len() <= N && N <= 32, "too many targets for the set");
        let mut seg = [([0; 3], [0; 3]); N];
        let mut needs = [0u16; N];
        let mut unit = [[0; 3]; N];
        let mut centred = true;
        let mut common_start = true;
        let mut common_step = even_step(list[0].1);
        let mut line = [0u8; N];
        let mut n = 0;
        while n < list.len() {
            seg[n] = list[n];
            let (o, d) = list[n];
            needs[n] = Self::needs(o, d);
            let o0 = list[0].0;
            if o[0] != o0[0] || o[1] != o0[1] || o[2] != o0[2] {
                common_start = false;
            }
            let m = even_step(d);
            // The line through `o` along `d` holds the centre iff
            // (centre − o) × d = 0.
            let r = [H - o[0], H - o[1], H - o[2]];
            if m == 0 || r[1] * d[2] != r[2] * d[1] || r[2] * d[0] != r[0] * d[2] || r[0] * d[1] != r[1] * d[0] {
                centred = false;
            } else {
                let u = [d[0] / m, d[1] / m, d[2] / m];
                unit[n] = u;
                line[n] = (9 * (u[2] + 1) + 3 * (u[1] + 1) + (u[0] + 1)) as u8;
            }
            if m != common_step {
                common_step = 0;
            }
            n += 1;
        }
        if !centred {
            common_step = 0;
        }
        let (lines, pair) = Self::pairs(&unit, list.len(), centred && common_start && common_step != 0);
        let mut pair_unit = [13u8; 13];
        let mut line_unit = [[0i64; 3]; 32];
        let mut line_d = [[0i64; 3]; 32];
        let mut l = 0;
        while l < lines {
            let a = pair[l].0 as usize;
            pair_unit[l] = line[a];
            line_unit[l] = unit[a];
            line_d[l] = seg[a].1;
            l += 1;
        }
        let mut live_of = [0u32; 512];
        let mut lines_live_of = [0u16; 512];
        let mut r = 0;
        while r < 512 {
            let mut n = 0;
            while n < list.len() {
                if needs[n] & !(r as u16) == 0 {
                    live_of[r] |= 1 << n;
                }
                n += 1;
            }
            let mut l = 0;
            while l < lines {
                let (a, b) = pair[l];
                if (live_of[r] >> a | live_of[r] >> b) & 1 != 0 {
                    lines_live_of[r] |= 1 << l;
                }
                l += 1;
            }
            r += 1;
        }
        let mut line_positive = [0u16; 512];
        let mut key = 0;
        while key < 512 {
            let mut l = 0;
            while l < lines {
                if unit_positive(line_unit[l], key) {
                    line_positive[key] |= 1 << l;
                }
                l += 1;
            }
            key += 1;
        }
        TargetSet {
            seg,
            unit,
            centred,
            common_step,
            lines,
            pair_unit,
            line_unit,
            line_d,
            live_of,
            lines_live_of,
            line_positive,
            needs,
            len: list.len(),
        }
    }

    /// The lines of a set of opposite pairs ([`Self::lines`]), if `maybe`
    /// and every unit direction's opposite is in the set once.
    const fn pairs(unit: &[P3; N], len: usize, maybe: bool) -> (usize, [(u8, u8); 13]) {
        let mut pair = [(0u8, 0u8); 13];
        let mut lines = 0;
        let mut n = 0;
        while maybe && n < len {
            let u = unit[n];
            let (mut found, mut m) = (0, 0);
            while m < len {
                let v = unit[m];
                if v[0] == -u[0] && v[1] == -u[1] && v[2] == -u[2] {
                    found += 1;
                    if m > n && lines < 13 {
                        pair[lines] = (n as u8, m as u8);
                        lines += 1;
                    }
                }
                m += 1;
            }
            if found != 1 {
                return (0, [(0, 0); 13]);
            }
            n += 1;
        }
        if 2 * lines != len {
            return (0, [(0, 0); 13]);
        }
        (lines, pair)
    }

    /// The [`forms_reached`] bits a triangle meeting a whole-voxel
    /// translate of the segment from `o` along `d` must have. Along the
    /// segment a coordinate `x_q` with `d_q = 0` stays `o_q`, and where
    /// `|d_p| = |d_q| ≠ 0`, `x_p + σ·x_q` with `σ = −sign(d_p·d_q)` stays
    /// `o_p + σ·o_q`; translates add multiples of `ONE`. Only the forms
    /// the bits stand for (`x_q ≡ H`, `x_p ± x_q ≡ 0`) are required; a
    /// segment of unequal non-zero steps requires none.
    const fn needs(o: P3, d: P3) -> u16 {
        if even_step(d) == 0 {
            return 0;
        }
        let mut bits = 0u16;
        let mut c = 0;
        while c < 3 {
            if d[c] == 0 && o[c].rem_euclid(ONE) == H {
                bits |= 1 << c;
            }
            c += 1;
        }
        let mut i = 0;
        while i < 3 {
            let (p, q) = PAIRS[i];
            if d[p] != 0 && d[q] != 0 {
                let sigma = -d[p].signum() * d[q].signum();
                if (o[p] + sigma * o[q]).rem_euclid(ONE) == 0 {
                    bits |= 1 << (3 + 2 * i + (sigma < 0) as usize);
                }
            }
            i += 1;
        }
        bits
    }

    /// The targets, in order.
    pub fn segments(&self) -> &[(P3, P3)] {
        &self.seg[..self.len]
    }

    /// Is it a set of opposite pairs ([`PairedTargets`])?
    pub fn paired(&self) -> bool {
        self.lines > 0
    }

    /// Can one of the targets, in some voxel, meet a triangle whose
    /// vertices lie in the closed lattice box `[lo, hi]`? Only if the box
    /// reaches every form one target [`Self::needs`] ([`forms_reached`]).
    /// Decides most triangles much smaller than a voxel (at 32³) by a few
    /// integer comparisons, before any setup.
    #[inline(always)]
    pub fn may_meet(&self, lo: P3, hi: P3) -> bool {
        // Not by the table: for a set known at compile time only the
        // forms its targets need are computed (sep6 at 32: −7 %).
        let reached = forms_reached(lo, hi);
        self.needs[..self.len].iter().any(|n| n & !reached == 0)
    }

    /// [`Self::may_meet`] given the box's [`forms_reached`] bits, by
    /// table (for a set of many targets).
    #[inline(always)]
    pub fn may_meet_reached(&self, reached: u16) -> bool {
        self.live_of[reached as usize] != 0
    }
}

/// The sign pattern of a vector `W = (x, y, z)` that decides the sign of
/// `u·W` for every `u` of components −1, 0, 1, as bits: 0–2, `x`, `y`, `z`
/// negative; 3–8, with `a, b, c = |x|, |y|, |z|`, each of `a − b`,
/// `b − c`, `a − c`, `a + b − c`, `a + c − b`, `b + c − a` positive. With it
/// a tie flag: one of `a, b, c` or of those six is 0 (then some `u·W` may
/// be 0 and the key does not decide it).
#[inline(always)]
fn sign_key<T: PlaneInt>(w: [T; 3]) -> (usize, bool) {
    let z = T::ZERO;
    let abs = |x: T| if x < z { -x } else { x };
    let (a, b, c) = (abs(w[0]), abs(w[1]), abs(w[2]));
    let d = [a - b, b - c, a - c, a + b - c, a + c - b, b + c - a];
    let mut key = (w[0] < z) as usize | ((w[1] < z) as usize) << 1 | ((w[2] < z) as usize) << 2;
    let mut tie = (a == z) | (b == z) | (c == z);
    for (bit, &v) in d.iter().enumerate() {
        key |= ((v > z) as usize) << (3 + bit);
        tie |= v == z;
    }
    (key, tie)
}

/// Is `u·W > 0` for a `W` of [`sign_key`] `key` (no ties)? The signs flip
/// `u` into `u'` against `(a, b, c)`; with both signs among its components
/// the sign is that of one of the key's six differences.
const fn unit_positive(u: P3, key: usize) -> bool {
    let s = [u[0] * if key & 1 != 0 { -1 } else { 1 }, u[1] * if key & 2 != 0 { -1 } else { 1 }, u[2] * if key & 4 != 0 { -1 } else { 1 }];
    let (mut pos, mut neg) = (0usize, 0usize);
    let mut c = 0;
    while c < 3 {
        if s[c] > 0 {
            pos |= 1 << c;
        } else if s[c] < 0 {
            neg |= 1 << c;
        }
        c += 1;
    }
    if neg == 0 {
        return pos != 0;
    }
    // Both signs: `u'·(a, b, c)` is the sum over `pos` less the sum over
    // `neg`, one of the key's differences (bit `b`, as `KEY_SIDES[b]`)
    // or its negation.
    let mut b = 0;
    while b < 6 {
        let (p, n) = KEY_SIDES[b];
        if pos == p && neg == n {
            return key_bit(key, b);
        }
        if pos == n && neg == p {
            return !key_bit(key, b);
        }
        b += 1;
    }
    false
}

/// The axes (bit `c` for `a, b, c`) summed on the positive and on the
/// negative side of each of [`sign_key`]'s six differences: `a − b`,
/// `b − c`, `a − c`, `a + b − c`, `a + c − b`, `b + c − a`.
const KEY_SIDES: [(usize, usize); 6] = [(0b001, 0b010), (0b010, 0b100), (0b001, 0b100), (0b011, 0b100), (0b101, 0b010), (0b110, 0b001)];

/// Difference `b` of a [`sign_key`]: positive?
const fn key_bit(key: usize, b: usize) -> bool {
    key >> (3 + b) & 1 != 0
}

/// `v·u` for the 27 directions `u` of components −1, 0, 1, at index
/// `9(u_z + 1) + 3(u_y + 1) + (u_x + 1)`, by additions.
#[inline(always)]
fn unit_table<T: PlaneInt>(v: [T; 3]) -> [T; 27] {
    let (x, y, z) = ([-v[0], T::ZERO, v[0]], [-v[1], T::ZERO, v[1]], [-v[2], T::ZERO, v[2]]);
    std::array::from_fn(|i| z[i / 9] + y[i / 3 % 3] + x[i % 3])
}

/// [`DIAGONALS`] as a [`TargetSet`].
pub(crate) const DIAGONAL_SET: TargetSet<4> = TargetSet::new(&DIAGONALS);

/// [`CROSSHAIR`] as a [`TargetSet`].
pub(crate) const CROSSHAIR_SET: TargetSet<3> = TargetSet::new(&CROSSHAIR);

/// One triangle against a fixed set of target segments, one target at a
/// time ([`Self::hits`]; the alternating-diagonal mode's test). First the
/// plane test, from the target's end plane values made once per triangle;
/// then the edge sides: for a [centred set](TargetSet) three dot products
/// with the voxel centre's [`PivotCross`], with no per-direction setup
/// (cheaper than a segment/triangle-box filter in front: −7 to −14 % at
/// 128³ without one); for any other set, [`TriSetup::segment_hits_once`].
/// All of a voxel's targets at once, for a set of opposite pairs:
/// [`PairedTargets`].
pub(crate) struct LazyTargets<'t, T, const N: usize> {
    tri: &'t LatticeTriangle,
    s: TriSetup<T>,
    set: &'t TargetSet<N>,
    /// Per target: the plane values `n·o` and `n·(o + d)` of its start
    /// and end offsets `o`, `o + d`. It crosses the plane in the voxel with
    /// low corner `c` iff exactly one is `>= t = bn − n·(c − a)`.
    start: [T; N],
    end: [T; N],
    /// The targets that may meet the triangle (bit `n`): for small
    /// triangles, those whose [`TargetSet`] forms the box reaches.
    live: u32,
}

impl<'t, T: PlaneInt, const N: usize> LazyTargets<'t, T, N> {
    /// Setup for `tri` against the targets of `set` (`N` is sized by the
    /// caller, as a few bytes per triangle matter at small grids).
    #[inline(always)]
    pub fn new(tri: &'t LatticeTriangle, set: &'t TargetSet<N>) -> Self {
        let (lo, hi) = tri.bounds();
        // Triangles under half a voxel (most at 32³) miss most forms; at
        // about a voxel (128³) they reach nearly all, and the test cost 3 %.
        let reached = if (0..3).all(|c| hi[c] - lo[c] <= H) { forms_reached(lo, hi) } else { ALL_FORMS };
        let s = TriSetup::new(tri);
        let (mut start, mut end) = ([T::ZERO; N], [T::ZERO; N]);
        for (n, (o, d)) in set.segments().iter().enumerate() {
            start[n] = dot(s.n, o.map(T::from_i64));
            end[n] = start[n] + dot(s.n, d.map(T::from_i64));
        }
        LazyTargets { tri, s, set, start, end, live: set.live_of[reached as usize] }
    }

    /// Does the line of target `n` (through the voxel's centre) pass the
    /// triangle, given the centre's [`PivotCross`]?
    #[inline(always)]
    fn centre_line_hits(&self, n: usize, w: &PivotCross<T>) -> bool {
        self.s.line_hits(self.tri, w, self.set.unit[n].map(T::from_i64), self.set.seg[n].1)
    }

    /// The edge tests of a crossing target `n` of a set that is not
    /// centred, from the voxel's low corner `pc` relative to the triangle
    /// and its plane value `vc`.
    #[inline(always)]
    fn edges_once(&self, n: usize, pc: [T; 3], vc: T) -> bool {
        let (o, d) = self.set.seg[n];
        let ot = o.map(T::from_i64);
        let p = std::array::from_fn(|a| pc[a] + ot[a]);
        self.s.segment_hits_once(self.tri, p, d, vc + self.s.plane(ot))
    }

    /// Does the displaced target `n` of voxel `ijk` meet the triangle?
    /// The same decision as [`segment_meets_triangle`].
    #[inline]
    pub fn hits(&self, n: usize, ijk: [i64; 3]) -> bool {
        let c = corner(ijk);
        let pc = self.s.local(c);
        let vc = self.s.plane(pc);
        let t = self.s.bn - vc;
        if self.live >> n & 1 == 0 || (self.start[n] >= t) == (self.end[n] >= t) {
            return false;
        }
        if self.set.centred {
            self.centre_line_hits(n, &self.s.centre_cross(pc))
        } else {
            self.edges_once(n, pc, vc)
        }
    }
}

/// Does any of a voxel's targets meet one triangle, for a set of opposite
/// pairs ([`TargetSet::paired`]: the tunnels'), line by line. With `x`
/// the common start's plane value less the voxel's threshold, the target
/// along `u` crosses the plane iff `x >= 0` and `x + k < 0` or the other
/// way round (`k = n·d`); its opposite, the same with `−k`. So one of a
/// line's two crosses iff `|k| > x` (`x >= 0`) or `|k| >= −x`: one
/// comparison per line, not per target. A line that crosses the plane is not parallel to it, and then
/// its edge sides along `−u` are those along `u` flipped, ties included,
/// so [`TriSetup::line_hits`] along one direction decides the line and
/// with it the crossing target. Keeps per triangle only `|k|` per line.
///
/// The edge sides of every line at once: the sign of `u·W` for each of
/// the lines' unit directions `u` (components −1, 0, 1) follows from the
/// signs of `W`'s components and six comparisons of their magnitudes
/// ([`sign_key`]), so a table per key gives the lines on the positive side
/// of each edge, and the lines inside all three are those whose three bits
/// agree. Where some `u·W` may be 0 (a tie, decided by the tie rule's
/// bias), the lines are tested one by one as above. At 128³ on the bunny
/// a failing voxel had about seven crossing lines to test one by one.
pub(crate) struct PairedTargets<'t, T, const N: usize> {
    tri: &'t LatticeTriangle,
    s: TriSetup<T>,
    set: &'t TargetSet<N>,
    /// The common start's plane value `n·o`.
    start: T,
    /// Per line `l` of the set: `|n·d|` of its targets (0 past
    /// the set's lines).
    kabs: [T; 13],
    /// The lines one of whose targets may meet the triangle (bit `l`).
    live: u32,
}

impl<'t, T: PlaneInt, const N: usize> PairedTargets<'t, T, N> {
    /// Setup for `tri` against `set` (a set of opposite pairs), given the
    /// [`forms_reached`] bits of the triangle's bounds.
    #[inline(always)]
    pub fn new(tri: &'t LatticeTriangle, set: &'t TargetSet<N>, reached: u16) -> Self {
        debug_assert!(set.lines > 0, "not a set of opposite pairs");
        let s = TriSetup::new(tri);
        let start = dot(s.n, set.seg[0].0.map(T::from_i64));
        let table = unit_table(s.n.map(|c| c * T::from_i64(set.common_step)));
        let kabs = set.pair_unit.map(|u| {
            let v = table[u as usize];
            if v < T::ZERO {
                -v
            } else {
                v
            }
        });
        PairedTargets { tri, s, set, start, kabs, live: set.lines_live_of[reached as usize] as u32 }
    }

    /// Does any of voxel `ijk`'s targets meet the triangle? With `TABLE`,
    /// the crossing lines' edge sides from the sign tables (all lines at
    /// once); without, line by line, stopping at the first that hits.
    #[inline(always)]
    pub fn any<const TABLE: bool>(&self, ijk: [i64; 3]) -> bool {
        let pc = self.s.local(corner(ijk));
        let x = self.start - (self.s.bn - self.s.plane(pc));
        let y = if x >= T::ZERO { x + T::from_i64(1) } else { -x };
        let mut mask = 0u32;
        for (l, &k) in self.kabs.iter().enumerate() {
            mask |= ((k >= y) as u32) << l;
        }
        mask &= self.live;
        if mask == 0 {
            return false;
        }
        let w = self.s.centre_cross(pc);
        if TABLE {
            // Without ties, every line's three edge sides from tables.
            let (k0, t0) = sign_key(w[0]);
            let (k1, t1) = sign_key(w[1]);
            let (k2, t2) = sign_key(w[2]);
            if !(t0 | t1 | t2) {
                let p = &self.set.line_positive;
                let (p0, p1, p2) = (p[k0 & 511], p[k1 & 511], p[k2 & 511]);
                return mask & !(p0 ^ p1) as u32 & !(p0 ^ p2) as u32 != 0;
            }
        }
        while mask != 0 {
            let l = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            let l = l & 31;
            if self.s.line_hits(self.tri, &w, self.set.line_unit[l].map(T::from_i64), self.set.line_d[l]) {
                return true;
            }
        }
        false
    }
}

/// Sets the voxels of `[lo, hi]` one of whose space diagonals the (small,
/// `i64`) triangle meets, by the diagonals' lines. For each diagonal direction `u` the
/// triangle's plane is not parallel to, the lines along `u` through voxel
/// corners are the lattice points of an oblique projection along `u`
/// onto a lattice plane `z = z₀` near the triangle; each inside the
/// projected triangle's box whose (displaced) line meets the triangle
/// sets the voxel whose diagonal on that line straddles the plane
/// ([`TriSetup::straddling_step`]). Every diagonal hit is one of these,
/// so this is the definition; a triangle about a voxel wide has a handful
/// of such lines, against `cover`'s traversal of its box and four targets
/// per candidate.
///
/// With `ALTERNATING`, only each voxel's own diagonal counts (the
/// `diagonal` mode's, through its all-odd and all-even corners): those lie
/// on the lines through all-even corners, and every voxel those lines pass
/// diagonally has its diagonal along them (a step by `±1` on every axis
/// keeps which corner is odd on which side). In the projection they are
/// the points whose two indices have the parity of `z₀`'s: a quarter.
pub(crate) fn diagonal_lines<const ALTERNATING: bool>(tri: &LatticeTriangle, lo: [i64; 3], hi: [i64; 3], slab: &mut BrickSlab<'_>) {
    let s = TriSetup::<i64>::new(tri);
    let z0 = tri.bounds().0[2].div_euclid(ONE) * ONE;
    // Per edge `A × B` (relative to the first vertex): with it a line
    // direction's edge orientations `u·(A × B) − p·(e × u)` need no
    // further products per direction than `e × u` (as `DirSetup`, without
    // its tie biases, derived only on a tie).
    let ab: [[i64; 3]; 3] = std::array::from_fn(|i| crate::geom::lattice::cross(s.rel[i], s.rel[(i + 1) % 3]));
    // One instance per direction of `DIAGONALS` (a test checks the
    // list): its steps are constants, so the products with them fold
    // into additions (sep26 at 128³ on 1 thread: −18 %).
    let (box_, dirs) = ((lo, hi), (tri, &s, &ab, z0));
    diagonal_line_dir::<1, 1, 1, ALTERNATING>(dirs, box_, slab);
    diagonal_line_dir::<-1, 1, 1, ALTERNATING>(dirs, box_, slab);
    diagonal_line_dir::<1, -1, 1, ALTERNATING>(dirs, box_, slab);
    diagonal_line_dir::<1, 1, -1, ALTERNATING>(dirs, box_, slab);
}

/// The lines along `u = (UX, UY, UZ)` of [`diagonal_lines`].
#[inline(always)]
fn diagonal_line_dir<const UX: i64, const UY: i64, const UZ: i64, const ALTERNATING: bool>(
    (tri, s, ab, z0): (&LatticeTriangle, &TriSetup<i64>, &[[i64; 3]; 3], i64),
    (lo, hi): ([i64; 3], [i64; 3]),
    slab: &mut BrickSlab<'_>,
) {
    let u = [UX, UY, UZ];
    let g = s.n[0] * UX + s.n[1] * UY + s.n[2] * UZ;
    if g == 0 {
        // Parallel lines never cross the displaced plane.
        return;
    }
    // Along u to z = z0: (x − u_x·u_z·(z − z0), y − u_y·u_z·(z − z0)).
    let proj = |p: [i64; 3], c: usize| p[c] - u[c] * UZ * (p[2] - z0);
    let range = |c: usize| {
        let (mut l, mut h) = (i64::MAX, i64::MIN);
        for p in tri.v {
            (l, h) = (l.min(proj(p, c)), h.max(proj(p, c)));
        }
        (-(-l).div_euclid(ONE), h.div_euclid(ONE))
    };
    let ((x0, x1), (y0, y1)) = (range(0), range(1));
    if x0 > x1 || y0 > y1 {
        return;
    }
    let m: [[i64; 3]; 3] = std::array::from_fn(|i| crate::geom::lattice::cross(tri.edge(i), u));
    let c: [i64; 3] = std::array::from_fn(|i| dot(u, ab[i]));
    let mut visit = |kx: i64, ky: i64| {
        let k = [kx * ONE, ky * ONE, z0];
        let pk = s.local(k);
        if !all_one_side(|i| edge_side(c[i] - dot(pk, m[i]), || m[i])) {
            return;
        }
        let m = s.straddling_step(g, s.plane(pk), 0);
        let ijk: [i64; 3] = std::array::from_fn(|c| k[c].div_euclid(ONE) + if u[c] > 0 { m } else { -m - 1 });
        if (0..3).all(|c| ijk[c] >= lo[c] && ijk[c] <= hi[c]) {
            slab.set(ijk[0] as u32, ijk[1] as u32, ijk[2] as u32);
        }
    };
    if ALTERNATING {
        // Lines through all-even corners: indices of `z₀`'s parity.
        let z = z0.div_euclid(ONE);
        let (x0, y0) = (x0 + (x0 - z).rem_euclid(2), y0 + (y0 - z).rem_euclid(2));
        for ky in (y0..=y1).step_by(2) {
            for kx in (x0..=x1).step_by(2) {
                visit(kx, ky);
            }
        }
    } else {
        for ky in y0..=y1 {
            for kx in x0..=x1 {
                visit(kx, ky);
            }
        }
    }
}

/// Largest voxel box for which `sep26`, `sep6` and `ss6` take their short
/// path instead of setting up the projection: for a triangle about a
/// voxel in size, a few lines or candidates beat the projection's setup.
pub(crate) const TINY_BOX: i64 = 27;

/// Is the inclusive box `[lo, hi]` at most [`TINY_BOX`] voxels?
#[inline(always)]
pub(crate) fn is_tiny(lo: [i64; 3], hi: [i64; 3]) -> bool {
    box_volume(lo, hi) <= TINY_BOX
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::setup::fits_i64;

    fn lt(v: [[i64; 3]; 3]) -> LatticeTriangle {
        LatticeTriangle { v }
    }

    proptest::proptest! {
        /// The lazy and one-shot segment tests decide as the definition:
        /// coordinates on a coarse lattice, so segments touch the
        /// triangle's vertices, edges and plane and the tie rule decides.
        /// Each scene is moved so that the segment's line passes through
        /// the centre of voxel 0: with steps of one magnitude (half of
        /// them) it is a centred target set, with its pivot-cross path.
        #[test]
        fn segment_tests_match_the_definition_on_touching_segments(
            v in proptest::array::uniform3(proptest::array::uniform3(-4i64..=4)),
            d in proptest::array::uniform3(-12i64..=12),
            through in 0usize..5,
            back in 0i64..=3,
            scale in proptest::prop_oneof![proptest::strategy::Just(1i64), proptest::strategy::Just(H), proptest::strategy::Just(ONE << 20)],
            even in proptest::bool::ANY,
        ) {
            // Segments through a vertex, the centroid or near the
            // triangle.
            let v = v.map(|p| p.map(|c| 3 * c));
            let d = if even { d.map(|c| c.signum() * 6) } else { d };
            let target: [i64; 3] = match through {
                0..=2 => v[through],
                3 => std::array::from_fn(|c| (v[0][c] + v[1][c] + v[2][c]) / 3),
                _ => std::array::from_fn(|c| v[0][c] + 1),
            };
            // `target` goes to the centre of voxel 0.
            let shift: [i64; 3] = std::array::from_fn(|c| H - target[c] * scale);
            let t = lt(v.map(|p| std::array::from_fn(|c| p[c] * scale + shift[c])));
            let a: [i64; 3] = std::array::from_fn(|c| (target[c] - d[c] * back / 3) * scale + shift[c]);
            let d = d.map(|c| c * scale);
            // The line holds the centre unless the start was rounded off it.
            let on_line = crate::geom::lattice::cross([H - a[0], H - a[1], H - a[2]], d) == [0; 3];
            let seg = [a, add(a, d)];
            let want = segment_meets_triangle(seg, t.v, true);
            if t.normal() != [0, 0, 0] && fits_i64(&t) {
                let targets = TargetSet::<1>::new(&[(a, d)]);
                proptest::prop_assert_eq!(targets.centred, even_step(d) != 0 && on_line);
                let lazy = LazyTargets::<i64, 1>::new(&t, &targets);
                proptest::prop_assert_eq!(lazy.hits(0, [0, 0, 0]), want);
                let s = TriSetup::<i64>::new(&t);
                let p = s.local(a);
                proptest::prop_assert_eq!(s.segment_hits_once(&t, p, d, s.plane(p)), want);
            }
        }
    }

    proptest::proptest! {
        /// A triangle that meets a crosshair segment of some voxel has mid-planes
        /// in its box on two axes; one that meets a `tunnel18` target, on
        /// one; one that meets a target of a set passes its `may_meet`.
        #[test]
        fn integer_box_tests_hold_every_hit(
            cell in proptest::array::uniform3(-1i64..=1),
            target in 0usize..25,
            along in 0i64..=16,
            off in proptest::array::uniform2(proptest::array::uniform3(-ONE / 4..=ONE / 4)),
            shrink in proptest::sample::select(vec![1i64, 4, 16]),
            coarse in proptest::bool::ANY,
        ) {
            // Small and tiny triangles (the ones the tests reject), some
            // with coordinates on an eighth of a voxel: on mid-planes,
            // faces and corners.
            // Around a point of some voxel's diagonal, crosshair segment or
            // tunnel18 target, so that hits are common.
            let tunnel = crate::voxelize::tunnel::targets(crate::voxelize::tunnel::TunnelTarget::Eighteen);
            let all: Vec<(P3, P3)> = DIAGONALS.iter().chain(CROSSHAIR.iter()).chain(tunnel.iter()).copied().collect();
            let (o, d) = all[target];
            let base: P3 = std::array::from_fn(|c| cell[c] * ONE + o[c] + d[c] * along / 16);
            // Centroid on it (the third offset is minus the other two).
            let off: [[i64; 3]; 3] = [off[0], off[1], std::array::from_fn(|c| -off[0][c] - off[1][c])];
            let v = off.map(|o| std::array::from_fn(|c| base[c] + o[c] / shrink));
            let v = if coarse { v.map(|p: [i64; 3]| p.map(|c| c.div_euclid(ONE / 8) * (ONE / 8))) } else { v };
            let t = lt(v);
            let (lo, hi) = t.bounds();
            let mids = mid_planes(lo, hi).iter().filter(|&&m| m).count();
            let reached = forms_reached(lo, hi);
            // Every target of the sets the kernels use, with the forms it needs.
            let every: Vec<((P3, P3), u16)> = crate::voxelize::tunnel::targets(crate::voxelize::tunnel::TunnelTarget::TwentySix)
                .into_iter()
                .chain(DIAGONALS)
                .chain(CROSSHAIR)
                .map(|t| (t, TargetSet::<1>::needs(t.0, t.1)))
                .collect();
            for k in -2..3 {
                for j in -2..3 {
                    for i in -2..3 {
                        let ijk = [i, j, k];
                        if sep6_hit(&t, ijk) {
                            proptest::prop_assert!(mids >= 2, "{t:?} {ijk:?}");
                        }
                        if sep26_hit(&t, ijk) {
                            proptest::prop_assert!(DIAGONAL_SET.may_meet(lo, hi), "{t:?} {ijk:?}");
                        }
                        if sep6_hit(&t, ijk) {
                            proptest::prop_assert!(CROSSHAIR_SET.may_meet(lo, hi), "{t:?} {ijk:?}");
                        }
                        let c = corner(ijk);
                        if tunnel.iter().any(|(o, d)| segment_meets_triangle([add(c, *o), add(add(c, *o), *d)], t.v, true)) {
                            proptest::prop_assert!(mids >= 1, "{t:?} {ijk:?}");
                        }
                        for ((o, d), needs) in &every {
                            if segment_meets_triangle([add(c, *o), add(add(c, *o), *d)], t.v, true) {
                                proptest::prop_assert_eq!(needs & !reached, 0, "{:?} {:?} target {:?}", t, ijk, (o, d));
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn diagonal_lines_walk_the_diagonals_directions() {
        // `diagonal_lines` instantiates these four directions by hand.
        assert_eq!(DIAGONALS.map(|(_, d)| d.map(i64::signum)), [[1, 1, 1], [-1, 1, 1], [1, -1, 1], [1, 1, -1]]);
    }

    #[test]
    fn target_sets_need_their_forms() {
        // The diagonals need two pair forms, the crosshair two mid-planes,
        // a tunnel target to an edge midpoint one of each.
        assert!(DIAGONALS.iter().all(|&(o, d)| TargetSet::<4>::needs(o, d).count_ones() == 3));
        assert!(CROSSHAIR.iter().all(|&(o, d)| TargetSet::<3>::needs(o, d) & 0b111 != 0 && TargetSet::<3>::needs(o, d).count_ones() == 2));
        assert_eq!(TargetSet::<1>::needs([H, H, H], [H, H, 0]), 1 << 2 | 1 << 4);
        // Unequal steps need nothing.
        assert_eq!(TargetSet::<1>::needs([0, 0, 0], [ONE, H, 0]), 0);
    }

    /// Per target of `list` (offset from voxel `ijk`'s low corner,
    /// direction): does it meet `t`, by the definition?
    fn definition(list: &[(P3, P3)], t: &LatticeTriangle, ijk: [i64; 3]) -> Vec<bool> {
        list.iter()
            .map(|(o, d)| {
                let p = add(corner(ijk), *o);
                segment_meets_triangle([p, add(p, *d)], t.v, true)
            })
            .collect()
    }

    /// Triangles through corners, along faces, on centre planes: the
    /// degenerate touches the perturbation must decide.
    fn touching_triangles() -> [LatticeTriangle; 7] {
        [
            lt([[0, 0, 0], [2 * ONE, 0, 0], [0, 2 * ONE, 0]]),
            lt([[0, 0, H], [2 * ONE, 0, H], [0, 2 * ONE, H]]),
            lt([[0, 0, 0], [ONE, ONE, ONE], [2 * ONE, 0, ONE]]),
            lt([[H, -ONE, -ONE], [H, 3 * ONE, -ONE], [H, -ONE, 3 * ONE]]),
            lt([[0, 0, 0], [ONE, 0, ONE], [0, ONE, ONE]]),
            lt([[ONE, 0, 0], [0, ONE, 0], [0, 0, ONE]]),
            lt([[H, H, 0], [2 * ONE + H, H, ONE], [H, ONE + H, 2 * ONE]]),
        ]
    }

    #[test]
    fn sets_of_opposite_pairs_are_found_and_match_the_definition() {
        use crate::voxelize::tunnel::{targets, TunnelTarget};
        let t26 = targets(TunnelTarget::TwentySix);
        let t18 = targets(TunnelTarget::Eighteen);
        let pair = [([H, H, H], [H, 0, -H]), ([H, H, H], [-H, 0, H])];
        assert_eq!(TargetSet::<26>::new(&t26).lines, 13);
        assert_eq!(TargetSet::<26>::new(&t18).lines, 9);
        assert_eq!(TargetSet::<26>::new(&pair).lines, 1);
        // A pair need not start at the centre, only on a line through it.
        let face = [([0, H, H], [H, 0, 0]), ([0, H, H], [-H, 0, 0])];
        assert_eq!(TargetSet::<26>::new(&face).lines, 1);
        // Not pairs: one side only, off the centre, the voxel's diagonals.
        assert_eq!(TargetSet::<26>::new(&t26[..13]).lines, 0);
        assert_eq!(TargetSet::<26>::new(&[([0, 0, H], [H, 0, 0]), ([0, 0, H], [-H, 0, 0])]).lines, 0);
        assert_eq!(DIAGONAL_SET.lines, 0);
        for t in &touching_triangles() {
            for list in [&t26[..], &t18[..], &pair[..], &face[..]] {
                let set = TargetSet::<26>::new(list);
                let lazy = LazyTargets::<i64, 26>::new(t, &set);
                let (lo, hi) = t.bounds();
                let paired = PairedTargets::<i64, 26>::new(t, &set, forms_reached(lo, hi));
                let wide = PairedTargets::<i128, 26>::new(t, &set, ALL_FORMS);
                for k in -1..3 {
                    for j in -1..3 {
                        for i in -1..3 {
                            let ijk = [i, j, k];
                            let want = definition(list, t, ijk);
                            // Both ways of deciding the lines' edge sides.
                            assert_eq!(paired.any::<true>(ijk), want.contains(&true), "{t:?} {ijk:?}");
                            assert_eq!(paired.any::<false>(ijk), want.contains(&true), "{t:?} {ijk:?}");
                            assert_eq!(wide.any::<true>(ijk), want.contains(&true), "{t:?} {ijk:?}");
                            assert_eq!(wide.any::<false>(ijk), want.contains(&true), "{t:?} {ijk:?}");
                            for (n, w) in want.iter().enumerate() {
                                assert_eq!(lazy.hits(n, ijk), *w, "{t:?} {ijk:?} target {n}");
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn sign_keys_decide_every_lines_sign_or_flag_a_tie() {
        use crate::voxelize::tunnel::{targets, TunnelTarget};
        let set = TargetSet::<26>::new(&targets(TunnelTarget::TwentySix));
        let units: Vec<P3> = (0..27).map(|i| [i % 3 - 1, i / 3 % 3 - 1, i / 9 - 1]).filter(|u| *u != [0; 3]).collect();
        // Small components (ties on most vectors) and wide ones.
        let mut rng = crate::test_rng::Xorshift(0x2545_f491_4f6c_dd1d);
        let (mut ties, mut decided) = (0, 0);
        for n in 0..20_000 {
            let range = if n % 2 == 0 { 12 } else { 1 << 40 };
            let w = [rng.signed(range), rng.signed(range), rng.signed(range)];
            let (key, tie) = sign_key(w);
            let (key128, tie128) = sign_key(w.map(i128::from));
            assert_eq!((key, tie), (key128, tie128), "{w:?}");
            if units.iter().any(|u| dot(*u, w) == 0) {
                assert!(tie, "{w:?}: some u·W is 0");
            }
            if tie {
                ties += 1;
                continue;
            }
            decided += 1;
            for l in 0..set.lines {
                let u = set.line_unit[l];
                assert_eq!(set.line_positive[key] >> l & 1 == 1, dot(u, w) > 0, "{w:?} line {u:?}");
            }
        }
        assert!(ties > 1000 && decided > 10_000, "{ties} ties, {decided} decided");
    }

    #[test]
    fn fast_segment_test_matches_the_definition() {
        for t in &touching_triangles() {
            let s64 = TriSetup::<i64>::new(t);
            let s128 = TriSetup::<i128>::new(t);
            for (o, d) in DIAGONALS.iter().chain(CROSSHAIR.iter()) {
                let (d64, d128) = (s64.dir(t, *d), s128.dir(t, *d));
                for k in -1..3 {
                    for j in -1..3 {
                        for i in -1..3 {
                            let p = add(corner([i, j, k]), *o);
                            let want = segment_meets_triangle([p, add(p, *d)], t.v, true);
                            assert_eq!(s64.segment_hits(&d64, s64.local(p)), want, "{t:?} {p:?} {d:?}");
                            assert_eq!(s128.segment_hits(&d128, s128.local(p)), want);
                            let lp = s64.local(p);
                            assert_eq!(s64.segment_hits_once(t, lp, *d, s64.plane(lp)), want);
                        }
                    }
                }
            }
            // The lazy tests (plane test, then edge sides), one target at a
            // time, in either order.
            for targets in [&DIAGONALS[..], &CROSSHAIR[..]] {
                let set = TargetSet::<4>::new(targets);
                let lazy = LazyTargets::<i64, 4>::new(t, &set);
                let wide = LazyTargets::<i128, 4>::new(t, &set);
                for k in (-1..3).rev() {
                    for j in -1..3 {
                        for i in -1..3 {
                            let ijk = [i, j, k];
                            let want = definition(targets, t, ijk);
                            for (n, w) in want.iter().enumerate().rev() {
                                assert_eq!(lazy.hits(n, ijk), *w, "{t:?} {ijk:?} target {n}");
                                assert_eq!(wide.hits(n, ijk), *w);
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn triangle_on_a_grid_plane_sets_one_layer_of_sep6() {
        // z = 0 is a layer boundary. Displaced by −ε³, the z-segment of
        // layer 0 spans (−ε³, 1 − ε³) and crosses the triangle; layer −1
        // lies below.
        let t = lt([[0, 0, 0], [4 * ONE, 0, 0], [0, 4 * ONE, 0]]);
        let hit = |k| sep6_hit(&t, [0, 0, k]);
        assert!(hit(0) && !hit(-1));
    }
}
