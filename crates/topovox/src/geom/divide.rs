//! Floor and ceiling division on the lattice, exact, without a hardware
//! division where the operands allow: an `f64` estimate of the quotient
//! (a division, or a multiplication by a `Divisor`'s reciprocal)
//! corrected exactly. Every algorithm that turns a plane or edge value into
//! a voxel index divides here (the shaders of `topovox-gpu` carry the same
//! correction in WGSL); `PlaneInt::div_floor` is the plain `i64`/`i128`
//! one the estimates fall back to.

use crate::geom::fixed::{PlaneInt, ONE};

/// `(floor(n / d), n mod d)` for `d > 0`, without a hardware division: an
/// f64 estimate corrected exactly. The callers' operands satisfy
/// `|n| < 2^62` and `d >= 4096`, so the estimate is off by at most one.
#[inline(always)]
pub(crate) fn div_floor(n: i64, d: i64) -> (i64, i64) {
    debug_assert!(d > 0);
    corrected(n, d, (n as f64 / d as f64) as i64)
}

/// `(floor(n / d), n mod d)` for `d > 0` from an estimate `q` of the
/// quotient, stepped to the exact one.
#[inline(always)]
fn corrected(n: i64, d: i64, mut q: i64) -> (i64, i64) {
    let mut r = n - q * d;
    while r < 0 {
        q -= 1;
        r += d;
    }
    while r >= d {
        q += 1;
        r -= d;
    }
    (q, r)
}

/// `floor(n / d)` for `d > 0`, as an index.
#[inline(always)]
pub(crate) fn floor_div<T: PlaneInt>(n: T, d: T) -> i64 {
    let (n, d) = (n.to_i128(), d.to_i128());
    const FAST: i128 = 1 << 62;
    if n.abs() < FAST && d < FAST && d >= ONE as i128 {
        // No hardware division: the f64 estimate corrected exactly.
        return div_floor(n as i64, d as i64).0;
    }
    n.div_euclid(d).clamp(i64::MIN as i128 / 2, i64::MAX as i128 / 2) as i64
}

/// `ceil(n / d)` for `d > 0`, as an index.
#[inline(always)]
pub(crate) fn ceil_div<T: PlaneInt>(n: T, d: T) -> i64 {
    -floor_div(-n, d)
}

/// A divisor `d > 0` used many times (per row of a triangle), with its
/// reciprocal: [`Self::floor`] estimates by a multiplication instead of a
/// division (a few cycles against a dozen or more, on the row's critical
/// path) and corrects the estimate exactly, like [`div_floor`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Divisor<T> {
    d: T,
    inv: f64,
}

impl<T: PlaneInt> Divisor<T> {
    #[inline(always)]
    pub(crate) fn new(d: T) -> Divisor<T> {
        debug_assert!(d > T::ZERO);
        Divisor { d, inv: 1.0 / d.to_f64() }
    }

    /// `floor(n / d)`, as an index: exact, the same as [`floor_div`].
    #[inline(always)]
    pub(crate) fn floor(&self, n: T) -> i64 {
        let (n128, d128) = (n.to_i128(), self.d.to_i128());
        const FAST: i128 = 1 << 62;
        if n128.abs() < FAST && d128 < FAST && d128 >= ONE as i128 {
            // |n| < 2^62 and d >= 2^12: the quotient is under 2^50 and the
            // estimate's three roundings are each within 2^-53 of it, so
            // it is off by under two (each correction loop runs at most twice).
            let n = n128 as i64;
            return corrected(n, d128 as i64, (n as f64 * self.inv) as i64).0;
        }
        floor_div(n, self.d)
    }

    /// `ceil(n / d)`, as an index.
    #[inline(always)]
    pub(crate) fn ceil(&self, n: T) -> i64 {
        -self.floor(T::ZERO - n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn divisors_by_reciprocal_floor_exactly() {
        let mut rng = crate::test_rng::Xorshift(0x005e_edd1);
        let mut divisors: Vec<i64> = vec![1, 2, 3, ONE - 1, ONE, ONE + 1, 3 * ONE, (1 << 40) + 7, (1 << 62) - 1, 1 << 62, i64::MAX];
        for _ in 0..300 {
            let bits = 1 + rng.below(62);
            divisors.push(1 + rng.below(1 << bits) as i64);
        }
        // Numerators whose quotients are indices (`floor_div` clamps others).
        let (lo, hi) = (-(1i128 << 62), (1i128 << 62) - 1);
        for &d in &divisors {
            let (div, div128) = (Divisor::new(d), Divisor::new(d as i128));
            let mut nums: Vec<i128> = vec![0, 1, -1, d as i128 - 1, d as i128, -(d as i128), lo, hi, lo + 1, hi - 1];
            // Exact multiples and their neighbours, where an estimate's error shows.
            for _ in 0..20 {
                let m = rng.signed(1 << 50) as i128 * d as i128;
                nums.extend([m, m - 1, m + 1, m + d as i128 - 1]);
            }
            nums.extend((0..50).map(|_| rng.signed(1 << 62) as i128));
            for n in nums.into_iter().filter(|n| (lo..=hi).contains(n)) {
                let want = n.div_euclid(d as i128) as i64;
                let n = n as i64;
                assert_eq!(div.floor(n), want, "floor({n} / {d})");
                assert_eq!(div.floor(n), floor_div(n, d), "floor({n} / {d})");
                assert_eq!(div128.floor(n as i128), want, "i128 floor({n} / {d})");
                if n > lo as i64 {
                    assert_eq!(div.ceil(n), -((-n).div_euclid(d)), "ceil({n} / {d})");
                }
            }
        }
    }
}
