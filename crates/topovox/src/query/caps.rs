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

pub use crate::geom::solid_angle::solid_angle;
use crate::topology::cycles::triangulate;

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
