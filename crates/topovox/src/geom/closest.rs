//! The point of a triangle, segment or point nearest to a query point, in
//! f64: C. Ericson, *Real-Time Collision Detection*, Morgan Kaufmann 2005,
//! §5.1.2 (segment) and §5.1.5 (triangle, by Voronoi regions).
//!
//! Used by the attribute carrier (where a voxel touches a triangle the
//! clip missed). The distance fields measure with their own code
//! (`distance/mod.rs`, and an independent brute force in
//! `distance/reference.rs`): on sliver triangles the Voronoi-region
//! method here is off, tried and measured on the distance tests' soups.

use glam::DVec3;

/// The point of triangle `p` nearest to `q` (Ericson §5.1.5). For a
/// triangle of (nearly) zero area the answer can be far off: the distance
/// fields measure such triangles to their edges instead.
pub fn closest_point(p: &[DVec3; 3], q: DVec3) -> DVec3 {
    let (a, b, c) = (p[0], p[1], p[2]);
    let (ab, ac, ap) = (b - a, c - a, q - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = q - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = q - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom == 0.0 {
        return a;
    }
    a + ab * (vb / denom) + ac * (vc / denom)
}

/// The point of segment `[a, b]` nearest to `q` (Ericson §5.1.2); a
/// segment of zero length is its point.
pub fn closest_on_segment(a: DVec3, b: DVec3, q: DVec3) -> DVec3 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 == 0.0 {
        return a;
    }
    a + ab * ((q - a).dot(ab) / len2).clamp(0.0, 1.0)
}
