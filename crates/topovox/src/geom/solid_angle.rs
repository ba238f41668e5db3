//! Signed solid angles of triangles, exact where a point lies in a
//! triangle's plane, and the exact orientation predicates they and the
//! ray crossings share.
//!
//! This work is based on: A. Van Oosterom, J. Strackee, "The Solid Angle
//! of a Plane Triangle", IEEE Trans. Biomed. Eng. 30(2), 1983 (the angle as
//! `2·atan2(det, denom)`), with J. R. Shewchuk's exact predicates
//! ("Adaptive Precision Floating-Point Arithmetic and Fast Robust Geometric
//! Predicates", 1997; the `robust` crate) and the tie rule of
//! [`super::perturb`]: a point in a triangle's plane is displaced by
//! `δ = −(ε, ε², ε³)` and takes the limit from there.

use glam::DVec3;
use robust::{orient2d, orient3d, Coord, Coord3D};

/// Sign (−1, 0, 1) of a float.
#[inline]
pub(crate) fn sign(v: f64) -> i32 {
    (v > 0.0) as i32 - (v < 0.0) as i32
}

/// Exact sign of each component of the normal `(b − a) × (c − a)`.
pub(crate) fn normal_signs(t: &[DVec3; 3]) -> [i32; 3] {
    let o = |x: usize, y: usize| {
        let c = |p: DVec3| Coord { x: p[x], y: p[y] };
        sign(orient2d(c(t[0]), c(t[1]), c(t[2])))
    };
    [o(1, 2), o(2, 0), o(0, 1)]
}

/// Exact sign of `n · (q + δ − a)`, `n = (b − a) × (c − a)`: which side of
/// the triangle's plane the displaced point lies on (0 only when the
/// triangle has no normal at all).
pub(crate) fn plane_side(t: &[DVec3; 3], q: DVec3) -> i32 {
    let c = |p: DVec3| Coord3D { x: p.x, y: p.y, z: p.z };
    // orient3d(a, b, c, q) = −n · (q − a).
    let s = -sign(orient3d(c(t[0]), c(t[1]), c(t[2]), c(q)));
    if s != 0 {
        return s;
    }
    // n · δ = −ε n_x − ε² n_y − ε³ n_z.
    normal_signs(t).into_iter().find(|&n| n != 0).map_or(0, |n| -n)
}

/// The signed solid angle of triangle `t` seen from `q`
/// (`2·atan2(det, denom)`, Van Oosterom–Strackee). A point in (or
/// numerically at) the triangle's plane is displaced by the tie rule's
/// `δ = −(ε, ε², ε³)`, and the angle is the limit from there: ±2π inside
/// the triangle, 0 outside, and on an edge or a corner the angle of that
/// edge's half-plane or that corner's wedge seen from the direction `δ`
/// leaves in (see `on_the_boundary`), so the triangles of a flat fan sum
/// to ±2π at any point of it.
pub fn solid_angle(t: &[DVec3; 3], q: DVec3) -> f64 {
    solid_angle_in(t, q, DVec3::ONE)
}

/// [`solid_angle`] with exact coordinates `t`, `q` (for the predicates)
/// measured in a metric stretched by `scale` per axis (a grid of boxes'
/// index space in the world's shape).
pub fn solid_angle_in(t: &[DVec3; 3], q: DVec3, scale: DVec3) -> f64 {
    let (a, b, c) = ((t[0] - q) * scale, (t[1] - q) * scale, (t[2] - q) * scale);
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let det = a.dot(b.cross(c));
    let denom = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    if det.abs() > 1e-12 * la * lb * lc {
        return 2.0 * det.atan2(denom);
    }
    // det = −n · (q − a): the displaced side.
    let side = plane_side(t, q);
    if side == 0 {
        return 0.0;
    }
    // In the plane, or off it by less than rounding: each triangle's angle
    // is then ill-conditioned near its edges (the sum over a flat fan is
    // not), so it is taken as the limit at the projection of q, whose
    // place in the triangle is decided exactly.
    in_plane(t, q, scale, side)
}

/// The limit of the solid angle at `q + δ` for `q` in the plane of `t`
/// (within rounding; its projection along the normal's largest axis is
/// placed exactly), `side` the exact side `q + δ` lies on.
fn in_plane(t: &[DVec3; 3], q: DVec3, scale: DVec3, side: i32) -> f64 {
    // Exactly where q lies: each edge's orientation in the projection
    // along the normal's largest axis, made positive inwards.
    let n = (t[1] - t[0]).cross(t[2] - t[0]);
    let signs = normal_signs(t);
    let k = (0..3).filter(|&k| signs[k] != 0).max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs())).expect("a normal");
    let (u, v) = ((k + 1) % 3, (k + 2) % 3);
    let c2 = |p: DVec3| Coord { x: p[u], y: p[v] };
    let s: [i32; 3] = std::array::from_fn(|e| {
        let o = orient2d(c2(t[e]), c2(t[(e + 1) % 3]), c2(q));
        ((o > 0.0) as i32 - (o < 0.0) as i32) * signs[k]
    });
    let full = -(side as f64) * std::f64::consts::TAU;
    if s.iter().all(|&x| x > 0) {
        return full;
    }
    if s.iter().any(|&x| x < 0) {
        return 0.0;
    }
    on_the_boundary(t, scale, s, full, (u, v))
}

/// `q` on an edge or a corner of `t` (the edges through it have `s = 0`).
/// `δ = −(ε, ε², ε³)` moves `q` along `−x̂`, then `−ŷ`, then `−ẑ`, each
/// infinitely less than the one before. Order by order: a move with a
/// component across an edge through `q` (in the plane) puts `q` strictly
/// inside or outside that edge; the first move with a component off the
/// plane lifts it. Outside any edge: 0; inside every edge before lifting:
/// `full`; lifted while on one edge (or a corner): the angle of that
/// edge's half-plane (two wedges) or that corner's wedge seen from the
/// lifting move's direction (Van Oosterom–Strackee with unit vectors: the
/// limit of the triangle stretched to infinity).
fn on_the_boundary(t: &[DVec3; 3], scale: DVec3, s: [i32; 3], full: f64, (u, v): (usize, usize)) -> f64 {
    let normal = normal_signs(t);
    let k = (u + 2) % 3;
    let mut open: Vec<usize> = (0..3).filter(|&e| s[e] == 0).collect();
    for m in 0..3 {
        // How the move −ê_m turns each open edge's orientation (inward > 0).
        let turn = |e: usize| {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            let c = if m == u {
                b[v] - a[v]
            } else if m == v {
                a[u] - b[u]
            } else {
                0.0
            };
            (c > 0.0) as i32 - (c < 0.0) as i32
        };
        if normal[m] != 0 {
            // Lifted: edges the same move crosses count too (their limit
            // is the wedge's); earlier ones were settled inside.
            let mut n = ((t[1] - t[0]) * scale).cross((t[2] - t[0]) * scale).normalize();
            if (n[m] > 0.0) != (normal[m] > 0) || n[m] == 0.0 {
                // The lift's side is the exact one, however small.
                n[m] = f64::from(normal[m]) * f64::MIN_POSITIVE;
            }
            let mut d = DVec3::ZERO;
            d[m] = -scale[m];
            return wedges(t, scale, &open, n, d.normalize());
        }
        let mut still = Vec::new();
        for &e in &open {
            match turn(e) * normal[k] {
                x if x < 0 => return 0.0,
                0 => still.push(e),
                _ => {}
            }
        }
        if still.is_empty() {
            return full;
        }
        open = still;
    }
    0.0
}

/// The angle, seen from direction `d` off the plane, of the half-plane of
/// the one edge in `open` or of the wedge at the corner of the two.
fn wedges(t: &[DVec3; 3], scale: DVec3, open: &[usize], n: DVec3, d: DVec3) -> f64 {
    let wedge = |e1: DVec3, e2: DVec3| {
        let a = -d;
        2.0 * a.dot(e1.cross(e2)).atan2(1.0 + a.dot(e1) + e1.dot(e2) + e2.dot(a))
    };
    match *open {
        [e] => {
            let along = ((t[(e + 1) % 3] - t[e]) * scale).normalize();
            let inward = n.cross(along);
            wedge(along, inward) + wedge(inward, -along)
        }
        [e, f] => {
            // The corner both edges share.
            let i = if (e, f) == (0, 2) { 0 } else { f };
            wedge(((t[(i + 1) % 3] - t[i]) * scale).normalize(), ((t[(i + 2) % 3] - t[i]) * scale).normalize())
        }
        _ => 0.0,
    }
}
