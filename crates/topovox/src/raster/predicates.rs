//! The 2D tie rule: targets (and pixel centres) displaced by
//! `δ = −(ε, ε²)`, as in 3D ([`crate::geom::perturb`]).
//!
//! An orientation `orient(a, b, c)` with some of its points displaced is
//! affine in `δ`, so it is the polynomial `c₀ + c₁ε + c₂ε²` whose
//! coefficients are found exactly by evaluating it at `δ = 0, x̂, ŷ`; its
//! sign is that of the first non-zero coefficient. Non-degenerate inputs
//! then never pass exactly through a target's end point or along it.

use super::P2;
use crate::geom::perturb::{lex_sign, DELTA_SIGN};

/// `(b − a) × (c − a)`, exact.
#[inline]
fn cross(a: [i128; 2], b: [i128; 2], c: [i128; 2]) -> i128 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Sign of `orient(p₀, p₁, p₂)` with the points flagged in `shifted`
/// displaced by `δ`.
pub fn orient(p: [P2; 3], shifted: [bool; 3]) -> i32 {
    let at = |d: [i128; 2]| {
        let q: [[i128; 2]; 3] = std::array::from_fn(|k| std::array::from_fn(|a| p[k][a] as i128 + if shifted[k] { d[a] } else { 0 }));
        cross(q[0], q[1], q[2])
    };
    let d0 = at([0, 0]);
    let s = DELTA_SIGN as i128;
    lex_sign([d0, at([s, 0]) - d0, at([0, s]) - d0, 0])
}

/// Does the input segment `s` meet the target segment `t` (displaced)?
pub fn segment_meets_target(s: [P2; 2], t: [P2; 2]) -> bool {
    let s1 = orient([s[0], s[1], t[0]], [false, false, true]);
    let s2 = orient([s[0], s[1], t[1]], [false, false, true]);
    if s1 == 0 || s1 == s2 {
        return false;
    }
    let s3 = orient([t[0], t[1], s[0]], [true, true, false]);
    let s4 = orient([t[0], t[1], s[1]], [true, true, false]);
    s3 != s4
}

/// Is the input point `a` inside the convex target polygon `poly`
/// (counter-clockwise, displaced)?
pub fn point_in_target(a: P2, poly: &[P2]) -> bool {
    (0..poly.len()).all(|k| orient([poly[k], poly[(k + 1) % poly.len()], a], [true, true, false]) > 0)
}

/// The winding contribution of input edge `u → v` at the displaced point
/// `c + δ`: the signed crossing of the ray towards `+x`.
#[inline]
pub fn winding_crossing(u: P2, v: P2, c: P2) -> i32 {
    // c.y + δ.y = c.y − ε²: an integer y is above it iff y >= c.y.
    let (up_u, up_v) = (u[1] >= c[1], v[1] >= c[1]);
    if up_u == up_v {
        return 0;
    }
    let o = orient([u, v, c], [false, false, true]);
    match (up_v, o > 0) {
        // Upward edge with the point on its left: crosses to the right.
        (true, true) => 1,
        // Downward edge with the point on its right.
        (false, false) => -1,
        _ => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_segment_through_a_target_end_hits_exactly_one_of_two_targets() {
        // Two targets sharing the end (10, 10); a segment through it.
        let (a, b) = ([[0, 10], [10, 10]], [[10, 10], [20, 10]]);
        for s in [[[10, 0], [10, 20]], [[0, 0], [20, 20]], [[5, 15], [15, 5]]] {
            assert_eq!(segment_meets_target(s, a) as u8 + segment_meets_target(s, b) as u8, 1, "{s:?}");
        }
        // Along a target: misses it.
        assert!(!segment_meets_target([[0, 10], [20, 10]], a));
    }

    #[test]
    fn a_fan_covers_every_point_exactly_once() {
        // The square (0,0)-(8,8) as four triangles fanned from (4,4), and
        // points on every edge and vertex of the fan.
        let sq: [P2; 4] = [[0, 0], [8, 0], [8, 8], [0, 8]];
        for x in 0..=8 {
            for y in 0..=8 {
                let c = [x, y];
                let hits: i32 = (0..4)
                    .map(|k| {
                        let t = [[4, 4], sq[k], sq[(k + 1) % 4]];
                        (0..3).map(|e| winding_crossing(t[e], t[(e + 1) % 3], c)).sum::<i32>()
                    })
                    .filter(|&w| w != 0)
                    .count() as i32;
                let inside_square: i32 = (0..4).map(|e| winding_crossing(sq[e], sq[(e + 1) % 4], c)).sum();
                assert_eq!(hits, inside_square.abs(), "{c:?}");
            }
        }
    }
}
