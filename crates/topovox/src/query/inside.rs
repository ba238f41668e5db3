//! Inside at any point, by the grids' rules, on the vertices as given:
//! ray parity or the integer winding number by exact crossings
//! ([`super::ray`]), the generalized winding number with caps
//! ([`super::caps`]). The winding rules decide on the mesh as
//! [`super::orient`] turns it (each part consistently, closed parts
//! outward or inward by nesting), so face
//! orientation does not matter; `Sign::Auto` is the nonzero winding number
//! on a mesh that is then closed (the union of overlapping shells), the
//! generalized winding number `|w| ≥ ½` otherwise.

use glam::DVec3;
use rustc_hash::FxHashMap;

use super::caps::Caps;
use super::orient::{orient, OrientReport};
use super::ray::RayIndex;
use super::Sign;
use crate::MeshRef;

/// A mesh prepared for inside tests (no distances).
#[derive(Clone, Debug)]
pub struct Inside {
    /// The mesh's triangles, for crossings.
    mesh: RayIndex,
    /// The caps' triangles, for crossings, and their solid angles.
    cap_rays: RayIndex,
    caps: Caps,
    watertight: bool,
    /// The rule, `Auto` resolved.
    sign: Sign,
    /// What orienting the mesh did (`None` under parity, which ignores
    /// orientation, and for triangles prepared as given).
    orientation: Option<OrientReport>,
}

impl Inside {
    /// Prepares the triangles of `mesh` whose indices are valid and whose
    /// corners are finite (others are left out, as the grids leave them),
    /// oriented by [`orient`] unless `sign` is parity.
    pub fn new(mesh: MeshRef<'_>, sign: Sign) -> Inside {
        if sign == Sign::Parity {
            return Inside::of_triangles(triangles(mesh), sign);
        }
        let oriented = orient(mesh);
        let mut inside = Inside::of_triangles(triangles(oriented.mesh(mesh)), sign);
        inside.orientation = Some(oriented.report);
        inside
    }

    /// Prepares `tris` (world coordinates).
    pub fn of_triangles(tris: Vec<[DVec3; 3]>, sign: Sign) -> Inside {
        let (watertight, cycles) = boundary(&tris);
        Inside::with_cycles(tris, watertight, &cycles, sign)
    }

    /// Prepares `tris` that [`watertight`] found closed (no boundary to
    /// find again, no caps): what the solids use after testing it.
    pub fn closed(tris: Vec<[DVec3; 3]>, sign: Sign) -> Inside {
        debug_assert!(watertight(&tris));
        Inside::with_cycles(tris, true, &[], sign)
    }

    fn with_cycles(tris: Vec<[DVec3; 3]>, watertight: bool, cycles: &[Vec<DVec3>], sign: Sign) -> Inside {
        let caps = Caps::new(cycles);
        let sign = match sign {
            Sign::Auto => Sign::Winding,
            s => s,
        };
        let mesh = RayIndex::new(tris.into_iter());
        let cap_rays = RayIndex::new(caps.tris.iter().copied());
        Inside { mesh, cap_rays, caps, watertight, sign, orientation: None }
    }

    /// What orienting the mesh found and did (`None` under parity).
    pub fn orientation(&self) -> Option<OrientReport> {
        self.orientation
    }

    /// Closed and consistently oriented.
    pub fn watertight(&self) -> bool {
        self.watertight
    }

    /// Boundary cycles closed by caps.
    pub fn cycles(&self) -> u64 {
        self.caps.cycles as u64
    }

    /// The rule (`Auto` resolved).
    pub fn sign(&self) -> Sign {
        self.sign
    }

    /// The winding number at `q`: an exact integer for a closed mesh, the
    /// generalized winding number otherwise (NaN for a point not finite).
    pub fn winding_number(&self, q: DVec3) -> f64 {
        if !crate::in_range(q) {
            return f64::NAN;
        }
        let j = self.mesh.crossings(q).winding + self.cap_rays.crossings(q).winding;
        if self.caps.tris.is_empty() {
            return j as f64;
        }
        j as f64 - self.caps.winding(q)
    }

    /// Whether `q` is inside, by the rule (false when not finite).
    pub fn contains(&self, q: DVec3) -> bool {
        if !crate::in_range(q) {
            return false;
        }
        match self.sign {
            Sign::Parity => self.mesh.crossings(q).count % 2 == 1,
            _ if self.caps.tris.is_empty() => self.mesh.crossings(q).winding != 0,
            _ => {
                // |w − J| = |w_caps| is below the caps' bound: where that is
                // below ½, J alone decides (no solid angle needed).
                let j = self.mesh.crossings(q).winding + self.cap_rays.crossings(q).winding;
                if self.caps.bound(q) < 0.5 {
                    return j != 0;
                }
                (j as f64 - self.caps.winding(q)).abs() >= 0.5
            }
        }
    }
}

/// Whether `tris` close up consistently (every edge used equally often in
/// both directions, vertices identified by equal coordinates): the test
/// `Sign::Auto` resolves by, without preparing anything.
pub fn watertight(tris: &[[DVec3; 3]]) -> bool {
    boundary(tris).0
}

/// The triangles of `mesh` whose indices are valid and whose corners are
/// finite, in mesh order (world coordinates).
pub fn triangles(mesh: MeshRef<'_>) -> Vec<[DVec3; 3]> {
    mesh.triangles
        .iter()
        .filter_map(|t| {
            let p = |i: u32| mesh.positions.get(i as usize).copied().filter(|p| p.is_finite());
            Some([p(t[0])?, p(t[1])?, p(t[2])?])
        })
        .collect()
}

/// A total-order key of a point's coordinates (`−0` as `+0`), so points
/// are identified by equal coordinates and ordered as the lattice orders
/// its points.
fn key(p: DVec3) -> [i64; 3] {
    p.to_array().map(|v| {
        let b = (v + 0.0).to_bits() as i64;
        b ^ (((b >> 63) as u64) >> 1) as i64
    })
}

fn unkey(k: [i64; 3]) -> DVec3 {
    let f = |b: i64| f64::from_bits((b ^ (((b >> 63) as u64) >> 1) as i64) as u64);
    DVec3::new(f(k[0]), f(k[1]), f(k[2]))
}

/// Whether triangles `tris` close up consistently, and the boundary
/// cycles (points in the boundary's direction) when not.
fn boundary(tris: &[[DVec3; 3]]) -> (bool, Vec<Vec<DVec3>>) {
    let mut numbers: FxHashMap<[i64; 3], u32> = FxHashMap::default();
    let mut points = Vec::new();
    let ends: Vec<[u32; 3]> = tris
        .iter()
        .map(|t| {
            t.map(|p| {
                let k = key(p);
                *numbers.entry(k).or_insert_with(|| {
                    points.push(k);
                    (points.len() - 1) as u32
                })
            })
        })
        .collect();
    let (odd, net) = crate::topology::inside::count_edges(&ends, points.len());
    let watertight = odd == 0 && net.is_empty() && !tris.is_empty();
    let mut net: Vec<([i64; 3], [i64; 3], i64)> = net
        .into_iter()
        .map(|(lo, hi, balance)| {
            let (a, b) = (points[lo as usize], points[hi as usize]);
            if a < b {
                (a, b, balance)
            } else {
                (b, a, -balance)
            }
        })
        .collect();
    net.sort_unstable();
    let cycles = crate::topology::cycles::boundary_cycles(&net);
    (watertight, cycles.into_iter().map(|c| c.into_iter().map(unkey).collect()).collect())
}
