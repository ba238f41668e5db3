//! The fixed-point lattice every predicate is evaluated on.
//!
//! A world point `p` is first expressed in *grid units*,
//! `u = (p - origin) / voxel_size` (f64), then snapped to the lattice
//! `2^-FRAC_BITS` voxel: `round(u * 4096)` (round half away from zero) as an
//! `i64`. Voxel corners are lattice points (`index * ONE`), so after snapping
//! every test — triangle/box overlap, plane side, edge functions — is an
//! integer computation with no rounding, and the CPU reference, the CPU fast
//! paths and any GPU path classify every voxel identically.
//!
//! # Guarantees
//! - Snapping moves a vertex by at most `2^-13` voxel on each axis; the
//!   guarantee of each mode holds exactly for the snapped triangles.
//! - Lattice coordinates satisfy `|c| <= MAX_ABS` (`2^29 - 1`, i.e. about
//!   131 000 voxels from the grid origin). Triangles reaching further are
//!   clipped to the grid's neighbourhood in f64 before snapping (see
//!   [`crate::geom::clip`]). With that bound, edge vectors fit in 31 bits,
//!   normals in 62 bits and plane values in `i128`, so no product overflows.

/// Fractional bits of the lattice: one voxel is `2^12 = 4096` lattice units.
pub const FRAC_BITS: u32 = 12;
/// One voxel in lattice units.
pub const ONE: i64 = 1 << FRAC_BITS;
/// Largest allowed absolute lattice coordinate.
pub const MAX_ABS: i64 = (1 << 29) - 1;
/// Largest grid-unit magnitude snapped directly; beyond it triangles are clipped first.
pub const DIRECT_LIMIT_VOXELS: f64 = 65_536.0 * 1.5;

/// Snaps a grid-unit coordinate to the lattice. `u` must be finite and
/// `|u| <= DIRECT_LIMIT_VOXELS`; callers ensure it.
#[inline]
pub fn snap(u: f64) -> i64 {
    debug_assert!(u.is_finite() && u.abs() <= DIRECT_LIMIT_VOXELS + 2.0);
    // `f64::round` (half away from zero) without the libm call baseline
    // x86-64 makes for it: truncate, then correct by the exact remainder
    // (`x - trunc(x)` is exact for |x| < 2^52).
    let x = u * ONE as f64;
    let t = x as i64;
    let f = x - t as f64;
    t + (f >= 0.5) as i64 - (f <= -0.5) as i64
}

/// The voxel indices `i` whose closed extent `[i*ONE, (i+1)*ONE]` meets the
/// closed interval `[lo, hi]` of lattice coordinates, as `(first, last)`.
#[inline]
pub fn voxel_span(lo: i64, hi: i64) -> (i64, i64) {
    ((lo - 1).div_euclid(ONE), hi.div_euclid(ONE))
}

/// Integer types the exact predicates run in: `i64` for triangles small enough
/// that every plane value fits (the common case), `i128` otherwise.
pub(crate) trait PlaneInt:
    Copy
    + PartialOrd
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Neg<Output = Self>
{
    const ZERO: Self;
    fn from_i64(x: i64) -> Self;
    fn to_f64(self) -> f64;
    fn to_i128(self) -> i128;
    /// Floor division (`d != 0`).
    fn div_floor(self, d: Self) -> Self;
}

impl PlaneInt for i64 {
    const ZERO: Self = 0;
    #[inline(always)]
    fn from_i64(x: i64) -> Self {
        x
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn to_i128(self) -> i128 {
        self as i128
    }
    #[inline(always)]
    fn div_floor(self, d: Self) -> Self {
        self.div_euclid(d) - if d < 0 && self.rem_euclid(d) != 0 { 1 } else { 0 }
    }
}

impl PlaneInt for i128 {
    const ZERO: Self = 0;
    #[inline(always)]
    fn from_i64(x: i64) -> Self {
        x as i128
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn to_i128(self) -> i128 {
        self
    }
    #[inline(always)]
    fn div_floor(self, d: Self) -> Self {
        self.div_euclid(d) - if d < 0 && self.rem_euclid(d) != 0 { 1 } else { 0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voxel_span_counts_touching_voxels() {
        // A point exactly on the plane between voxels 0 and 1 touches both.
        assert_eq!(voxel_span(ONE, ONE), (0, 1));
        // A point strictly inside voxel 0 touches only voxel 0.
        assert_eq!(voxel_span(1, ONE - 1), (0, 0));
        // The origin touches voxel -1 and 0.
        assert_eq!(voxel_span(0, 0), (-1, 0));
        assert_eq!(voxel_span(-1, -1), (-1, -1));
    }

    #[test]
    fn snap_rounds_to_nearest() {
        assert_eq!(snap(1.0), ONE);
        assert_eq!(snap(-0.5), -ONE / 2);
        assert_eq!(snap(1.0 + 1e-9), ONE);
        assert_eq!(snap(0.3 / 4096.0), 0);
    }

    #[test]
    fn snap_is_f64_round() {
        let mut rng = crate::test_rng::Xorshift(0x9e37_79b9_7f4a_7c15);
        let mut cases = vec![0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 0.49999999999999994, -0.49999999999999994, 1e5, -1e5];
        for _ in 0..100_000 {
            let u = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * 2.0e5 - 1.0e5;
            cases.push(u);
            // Exact halves of the lattice.
            cases.push(((u * 8192.0).round() + 1.0) / 8192.0);
        }
        for u in cases {
            assert_eq!(snap(u), (u * ONE as f64).round() as i64, "{u}");
        }
    }
}
