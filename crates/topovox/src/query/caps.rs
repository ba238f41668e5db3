//! The generalized winding number at any point, exactly where it is an
//! integer: caps close the mesh's boundary, the closed whole is counted by
//! exact ray crossings, and only the caps' solid angles are summed.
//!
//! This work is based on: A. Jacobson, L. Kavan, O. Sorkine-Hornung,
//! "Robust Inside-Outside Segmentation using Generalized Winding Numbers",
//! ACM TOG 32(4), 2013 (`w(q) = Σ_T Ω_T(q) / 4π`, Van Oosterom–Strackee
//! solid angles).
//!
//! **Definition.** The mesh's oriented boundary (edges not cancelled by an
//! opposite use, vertices identified by equal coordinates) is split into
//! cycles and each cycle closed by a cap of triangles, reversed against it,
//! so mesh + caps has no boundary. Then `w = J − w_caps`, `J` the exact
//! integer winding number of mesh + caps ([`super::ray`]) and `w_caps` the
//! caps' solid angles summed in f64 over every cap triangle (none is left
//! out: the value is the generalized winding number to within rounding). A
//! point in a cap triangle's plane takes its displaced side, as `J` does.
//! This is how [`crate::voxelize::winding`] decides on the lattice; it
//! leaves out caps whose bound is below 10⁻³ at a voxel, so the two can
//! differ where `|w − ½|` is that small.

use glam::DVec3;

use robust::{orient2d, Coord};

use super::ray::{normal_signs, plane_side};
use crate::voxelize::winding::triangulate;

/// The caps of a mesh's boundary cycles (world coordinates).
#[derive(Clone, Debug, Default)]
pub struct Caps {
    /// Every cap triangle.
    pub tris: Vec<[DVec3; 3]>,
    /// Boundary cycles closed.
    pub cycles: usize,
    /// Per cap: a bounding sphere (centre, radius) and its area.
    spheres: Vec<(DVec3, f64, f64)>,
}

impl Caps {
    /// Caps over `cycles`, each a closed list of points (the boundary's
    /// direction), as [`crate::voxelize::winding`] builds them.
    pub fn new(cycles: &[Vec<DVec3>]) -> Caps {
        let mut out = Caps::default();
        for c in cycles.iter().filter(|c| c.len() >= 3) {
            let verts: Vec<DVec3> = c.iter().rev().copied().collect();
            let order: Vec<u32> = (0..verts.len() as u32).collect();
            let mut index = Vec::with_capacity(verts.len() - 2);
            triangulate(&order, &mut index);
            let tris: Vec<[DVec3; 3]> = index.iter().map(|ix| ix.map(|i| verts[i as usize])).collect();
            let centre = verts.iter().sum::<DVec3>() / verts.len() as f64;
            let radius = verts.iter().map(|p| p.distance(centre)).fold(0.0, f64::max);
            let area = tris.iter().map(|t| (t[1] - t[0]).cross(t[2] - t[0]).length() * 0.5).sum::<f64>();
            out.spheres.push((centre, radius, area));
            out.tris.extend(tris);
            out.cycles += 1;
        }
        out
    }

    /// An upper bound of `|w_caps(q)|`: each cap's area over `4π d²`, `d`
    /// the distance from `q` to its bounding sphere (infinite within it).
    /// Each triangle's solid angle is at most its area over its squared
    /// distance, which is no less than `d`.
    pub fn bound(&self, q: DVec3) -> f64 {
        self.spheres
            .iter()
            .map(|&(c, r, area)| {
                let d = q.distance(c) - r;
                if d > 0.0 {
                    area / (4.0 * std::f64::consts::PI * d * d)
                } else {
                    f64::INFINITY
                }
            })
            .sum()
    }

    /// `w_caps(q)`: the caps' solid angles at `q` over 4π.
    pub fn winding(&self, q: DVec3) -> f64 {
        self.tris.iter().map(|t| solid_angle(t, q)).sum::<f64>() / (4.0 * std::f64::consts::PI)
    }
}

/// The signed solid angle of triangle `t` seen from `q`
/// (`2·atan2(det, denom)`, Van Oosterom–Strackee). A point in (or
/// numerically at) the triangle's plane is displaced by the tie rule's
/// `δ = −(ε, ε², ε³)`, and the angle is the limit from there: ±2π inside
/// the triangle, 0 outside, and on an edge or a corner the angle of that
/// edge's half-plane or that corner's wedge seen from the direction `δ`
/// leaves in (see [`on_the_boundary`]), so the triangles of a flat fan sum
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
