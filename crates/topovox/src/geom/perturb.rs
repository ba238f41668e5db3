//! The tie rule of every target-based mode: Laine's fixed infinitesimal
//! perturbation.
//!
//! This work is based on: S. Laine, "A Topological Approach to
//! Voxelization", Computer Graphics Forum 32(4), 2013, §3.2.
//!
//! **Rule.** Every intersection target (space diagonals, crosshairs, the
//! bisecting squares and the faces of a voxel) is displaced by the
//! infinitesimal vector `δ = −(ε, ε², ε³)`, `0 < ε` smaller than anything
//! else. The input is not moved. (Laine's example vector points the other
//! way; any fixed generic vector works. Pointing it towards the grid's low
//! corner keeps geometry lying exactly on a fitted grid's low faces — where
//! `origin = bbox min` puts it — inside the grid; geometry exactly on the
//! plane of a grid's *high* face belongs to the voxels beyond it.) A primitive then never passes exactly
//! through a target's end point or along it: every predicate is the sign of
//! a polynomial `c₀ + c₁ε + c₂ε² + c₃ε³` whose coefficients are exact
//! integers, and its sign is the sign of the first non-zero coefficient.
//! Concretely, a triangle passing exactly through the end point shared by
//! two targets hits exactly one of them, and a triangle containing a target
//! segment hits it not at all (the segment is parallel to it and displaced
//! off its plane).
//!
//! For orientation predicates the polynomial is affine in `δ` (terms with
//! `δ` twice are triple products with a repeated vector, hence zero), so its
//! coefficients are found exactly by evaluating the determinant at
//! `δ = 0, x̂, ŷ, ẑ` on the integer lattice. Everything here is `i128` and
//! serves as the definition the references use; fast paths use the same
//! rule through [`bias`].

/// A lattice point.
pub type P3 = [i64; 3];

/// Sign of the displacement: `δ = DELTA_SIGN · (ε, ε², ε³)`.
pub const DELTA_SIGN: i64 = -1;

/// Sign (−1, 0, 1) of `c[0] + c[1]ε + c[2]ε² + c[3]ε³` for infinitesimal `ε > 0`.
#[inline]
pub fn lex_sign(c: [i128; 4]) -> i32 {
    c.iter().find(|&&x| x != 0).map_or(0, |&x| if x > 0 { 1 } else { -1 })
}

/// Sign of `f(p + δ)` for an affine `f` with integer value `f(p)` and gradient `g`.
#[inline]
pub fn displaced_sign(value: i128, g: [i128; 3]) -> i32 {
    let s = DELTA_SIGN as i128;
    lex_sign([value, s * g[0], s * g[1], s * g[2]])
}

/// For an affine function `f(p) = g·p + c` evaluated at a displaced target
/// point `p + δ` with integer value `f(p)`: `f(p + δ) > 0` iff
/// `f(p) >= bias(g)`. (`g = 0` gives bias 0: the value itself decides, and
/// zero counts as non-negative.)
#[inline]
pub fn bias(g: [i64; 3]) -> i64 {
    match g.iter().find(|&&x| x != 0) {
        Some(&x) if x * DELTA_SIGN < 0 => 1,
        _ => 0,
    }
}

fn det(p: [[i128; 3]; 4]) -> i128 {
    let d = |k: usize| [p[k][0] - p[0][0], p[k][1] - p[0][1], p[k][2] - p[0][2]];
    let (a, b, c) = (d(1), d(2), d(3));
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// Sign of the orientation determinant `det[p1−p0, p2−p0, p3−p0]` where the
/// points flagged in `shifted` are displaced by `δ`.
pub fn orient(p: [P3; 4], shifted: [bool; 4]) -> i32 {
    let at = |dx: [i128; 3]| det(std::array::from_fn(|k| std::array::from_fn(|a| p[k][a] as i128 + if shifted[k] { dx[a] } else { 0 })));
    let d0 = at([0, 0, 0]);
    let s = DELTA_SIGN as i128;
    lex_sign([d0, at([s, 0, 0]) - d0, at([0, s, 0]) - d0, at([0, 0, s]) - d0])
}

/// Does the closed segment `s` meet the closed triangle `t`, with the
/// target (the segment if `segment_is_target`, else the triangle) displaced
/// by `δ`? Degenerate primitives (zero length, zero area) meet nothing.
pub fn segment_meets_triangle(s: [P3; 2], t: [P3; 3], segment_is_target: bool) -> bool {
    let (ss, ts) = (segment_is_target, !segment_is_target);
    let sp = orient([t[0], t[1], t[2], s[0]], [ts, ts, ts, ss]);
    let sq = orient([t[0], t[1], t[2], s[1]], [ts, ts, ts, ss]);
    if sp == 0 || sp == sq {
        return false;
    }
    let e0 = orient([s[0], s[1], t[0], t[1]], [ss, ss, ts, ts]);
    let e1 = orient([s[0], s[1], t[1], t[2]], [ss, ss, ts, ts]);
    let e2 = orient([s[0], s[1], t[2], t[0]], [ss, ss, ts, ts]);
    e0 != 0 && e0 == e1 && e1 == e2
}

/// Does the input segment `s` meet the target square (axis-aligned, given
/// by its four corners in order), displaced by `δ`?
pub fn segment_meets_square(s: [P3; 2], q: [P3; 4]) -> bool {
    // The two halves share a diagonal; under the perturbation a segment
    // crossing the square crosses exactly one half.
    segment_meets_triangle(s, [q[0], q[1], q[2]], false) || segment_meets_triangle(s, [q[0], q[2], q[3]], false)
}

/// Does the input triangle `t` meet the target square `q` (displaced by
/// `δ`)? Two convex polygons in general position meet iff an edge of one
/// crosses the other.
pub fn triangle_meets_square(t: [P3; 3], q: [P3; 4]) -> bool {
    (0..3).any(|i| segment_meets_square([t[i], t[(i + 1) % 3]], q))
        || (0..4).any(|i| segment_meets_triangle([q[i], q[(i + 1) % 4]], t, true))
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: i64 = 4096;

    #[test]
    fn lex_sign_takes_first_non_zero() {
        assert_eq!(lex_sign([0, 0, -3, 5]), -1);
        assert_eq!(lex_sign([2, -9, 0, 0]), 1);
        assert_eq!(lex_sign([0; 4]), 0);
    }

    #[test]
    fn triangle_through_a_shared_end_point_hits_exactly_one_segment() {
        // Two collinear target segments meeting at the origin; a triangle in
        // the plane z = 0 contains that end point.
        let t = [[-S, -S, 0], [S, -S, 0], [0, S, 0]];
        let below = segment_meets_triangle([[0, 0, -S], [0, 0, 0]], t, true);
        let above = segment_meets_triangle([[0, 0, 0], [0, 0, S]], t, true);
        assert!(below ^ above);
    }

    #[test]
    fn segment_along_a_triangle_is_not_hit() {
        let t = [[-S, -S, 0], [S, -S, 0], [0, S, 0]];
        assert!(!segment_meets_triangle([[-S / 2, 0, 0], [S / 2, 0, 0]], t, true));
    }

    #[test]
    fn segment_through_a_shared_edge_hits_exactly_one_triangle() {
        // A target segment crossing z = 0 exactly on the edge shared by two
        // triangles of a fan.
        let (a, b, c, d) = ([0, -S, 0], [0, S, 0], [S, 0, 0], [-S, 0, 0]);
        for x in [0, S / 3] {
            let s = [[0, x / 2, -S], [0, x / 2, S]];
            let one = segment_meets_triangle(s, [a, b, c], true);
            let two = segment_meets_triangle(s, [b, a, d], true);
            assert!(one ^ two, "x = {x}");
        }
    }

    #[test]
    fn bias_matches_the_perturbed_sign() {
        for g in [[1, 0, 0], [-1, 5, 0], [0, -2, 1], [0, 0, 3], [0, 0, -3]] {
            for v in -2..=2i64 {
                let perturbed = displaced_sign(v as i128, g.map(|c| c as i128)) > 0;
                assert_eq!(perturbed, v >= bias(g), "g = {g:?}, v = {v}");
            }
        }
    }

    #[test]
    fn triangle_and_square_in_general_position() {
        let q = [[0, 0, 0], [S, 0, 0], [S, S, 0], [0, S, 0]];
        // Pierces the square's interior.
        assert!(triangle_meets_square([[S / 2, S / 2, -S], [S / 2 + 10, S / 2, S], [S / 2, S / 2 + 10, S]], q));
        // Beside it.
        assert!(!triangle_meets_square([[2 * S, 0, -S], [2 * S + 10, 0, S], [2 * S, 10, S]], q));
        // In the square's own plane: the displaced square lies below it.
        assert!(!triangle_meets_square([[0, 0, 0], [S, 0, 0], [0, S, 0]], q));
    }
}
