//! Lights from emissive triangles and the light grid of seed 002
//! (§ "gestion des lumières").
//!
//! - **Lights.** Emissive triangles are merged by material and proximity:
//!   those of one material whose centroids fall in the same cube of side
//!   [`MERGE`] (an eighth of an attenuation unit, below) become one light,
//!   at their area-weighted centroid. Its intensity is `sqrt(area)` (area in units², as the report
//!   sets it) times the largest component of the material's emission; its
//!   colour is the emission divided by that component.
//! - **Attenuation** `i / (d³ + 1)`, `d` the distance in *units*: one unit
//!   is an eighth of the scene box's largest extent, so the fall-off does
//!   not depend on the model's scale (a ceiling lamp lights its room).
//! - **Light grid.** 32×32×32 cells over the scene box; a cell lists the
//!   lights whose largest contribution to any point of the cell,
//!   `i / (d_min³ + 1)` with `d_min` the distance from the light to the
//!   cell's box, exceeds [`THRESHOLD`]. Solved for the distance, that is
//!   `d_min < cbrt(i / THRESHOLD − 1)`: each light carries the square of
//!   this reach in world units, and a cell lists it when the squared
//!   distance from the light to the cell's box is below. The fragment
//!   shader loops over its cell's list only.
//! - **Built on the GPU** (`grid.wgsl`: count per cell, one scan, fill in
//!   light order), as the report proposes; [`LightGrid::build`] is the CPU
//!   reference. Both evaluate the same `f32` expressions; a GPU may fuse a
//!   multiply and an add, so the two can differ only for a light whose
//!   reach meets a cell's box within rounding (the tests bound that
//!   margin).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::scene::Scene;

/// Cells per axis of the light grid.
pub const GRID: usize = 32;
/// Attenuation units along the scene box's largest extent.
pub const UNITS: usize = 8;
/// Side of the cubes emissive triangles are merged in, in attenuation units.
pub const MERGE: f32 = 0.125;
/// Contributions below this are left out of a cell's list.
pub const THRESHOLD: f32 = 0.02;

/// A light as the shader reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Light {
    /// World position; `w` the intensity.
    pub position_intensity: [f32; 4],
    /// Linear colour (the emission); `w` the squared reach in world
    /// units (the distance where the contribution falls to [`THRESHOLD`]).
    pub colour: [f32; 4],
}

/// The light grid: per cell a range of `indices`.
#[derive(Clone, Debug, PartialEq)]
pub struct LightGrid {
    /// Grid box lower corner.
    pub lo: Vec3,
    /// Cell size per axis (world units).
    pub cell: Vec3,
    /// World length of one attenuation unit (see [`UNITS`]).
    pub unit: f32,
    /// Per cell `(first, count)` into `indices`, cell `x + 32 (y + 32 z)`.
    pub ranges: Vec<[u32; 2]>,
    /// Light indices, cell by cell.
    pub indices: Vec<u32>,
}

/// Light count, merged from how many emissive triangles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LightReport {
    /// Lights after merging.
    pub lights: usize,
    /// Emissive triangles.
    pub emissive_triangles: usize,
}

/// The scene box and its attenuation unit.
pub fn frame(scene: &Scene) -> (Vec3, Vec3, f32) {
    let (lo, hi) = scene.bounds().unwrap_or((Vec3::ZERO, Vec3::ONE));
    let unit = ((hi - lo).max_element() / UNITS as f32).max(f32::MIN_POSITIVE.sqrt());
    (lo, hi, unit)
}

/// The light an emissive triangle joins: its material and the cube of
/// side [`MERGE`] units its centroid falls in (`lo` and `unit` from [`frame`]).
pub fn merge_key(lo: Vec3, unit: f32, material: u32, p: [Vec3; 3]) -> (u32, [i64; 3]) {
    let c = (p[0] + p[1] + p[2]) / 3.0;
    (material, ((c - lo) / (unit * MERGE)).floor().as_i64vec3().to_array())
}

/// A triangle's area in units².
pub fn area_units(p: [Vec3; 3], unit: f32) -> f32 {
    0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length() / (unit * unit)
}

/// The lights of the scene's emissive triangles.
pub fn lights(scene: &Scene) -> (Vec<Light>, LightReport) {
    let (lo, _, unit) = frame(scene);
    let mut groups: std::collections::BTreeMap<(u32, [i64; 3]), (f32, Vec3)> = Default::default();
    let mut report = LightReport::default();
    for t in scene.vertices.chunks_exact(3) {
        let m = t[0].material;
        if !scene.materials[m as usize].emissive() {
            continue;
        }
        report.emissive_triangles += 1;
        let p = [0, 1, 2].map(|c| Vec3::from(t[c].position));
        let area = area_units(p, unit);
        let c = (p[0] + p[1] + p[2]) / 3.0;
        let g = groups.entry(merge_key(lo, unit, m, p)).or_insert((0.0, Vec3::ZERO));
        g.0 += area;
        g.1 += c * area;
    }
    let out: Vec<Light> = groups
        .into_iter()
        .filter(|(_, (area, _))| *area > 0.0)
        .map(|((m, _), (area, sum))| {
            let p = sum / area;
            let e = scene.materials[m as usize].emission_shininess;
            let peak = e[0].max(e[1]).max(e[2]);
            let i = area.sqrt() * peak;
            let reach = (i / THRESHOLD - 1.0).max(0.0).cbrt() * unit;
            Light { position_intensity: [p.x, p.y, p.z, i], colour: [e[0] / peak, e[1] / peak, e[2] / peak, reach * reach] }
        })
        .collect();
    report.lights = out.len();
    (out, report)
}

/// The grid's lower corner, cell size and attenuation unit.
pub fn grid_frame(scene: &Scene) -> (Vec3, Vec3, f32) {
    let (lo, hi, unit) = frame(scene);
    (lo, ((hi - lo) / GRID as f32).max(Vec3::splat(unit * 1e-3)), unit)
}

/// Whether light `l` reaches the box `clo..chi` above the threshold.
pub fn reaches(l: &Light, clo: Vec3, chi: Vec3) -> bool {
    let p = Vec3::from_slice(&l.position_intensity[..3]);
    let d = p.clamp(clo, chi) - p;
    d.x * d.x + d.y * d.y + d.z * d.z < l.colour[3]
}

/// By how much (relative) light `l` misses or makes the box: small values
/// are decided by rounding.
pub fn reach_margin(l: &Light, clo: Vec3, chi: Vec3) -> f32 {
    let p = Vec3::from_slice(&l.position_intensity[..3]);
    let d = p.clamp(clo, chi) - p;
    ((d.x * d.x + d.y * d.y + d.z * d.z) - l.colour[3]).abs() / l.colour[3].max(f32::MIN_POSITIVE)
}

/// A light's contribution at distance `d` units.
pub fn attenuation(intensity: f32, d: f32) -> f32 {
    intensity / (d * d * d + 1.0)
}

impl LightGrid {
    /// Builds the grid over the scene box for `lights`.
    pub fn build(scene: &Scene, lights: &[Light]) -> LightGrid {
        let (lo, cell, unit) = grid_frame(scene);
        let mut ranges = Vec::with_capacity(GRID * GRID * GRID);
        let mut indices = Vec::new();
        for z in 0..GRID {
            for y in 0..GRID {
                for x in 0..GRID {
                    let clo = lo + cell * Vec3::new(x as f32, y as f32, z as f32);
                    let chi = clo + cell;
                    let first = indices.len() as u32;
                    for (n, l) in lights.iter().enumerate() {
                        if reaches(l, clo, chi) {
                            indices.push(n as u32);
                        }
                    }
                    ranges.push([first, indices.len() as u32 - first]);
                }
            }
        }
        LightGrid { lo, cell, unit, ranges, indices }
    }

    /// The cell holding point `p` (clamped to the grid), as the shader finds it.
    pub fn cell_of(&self, p: Vec3) -> usize {
        let c = ((p - self.lo) / self.cell).floor().clamp(Vec3::ZERO, Vec3::splat(GRID as f32 - 1.0));
        c.x as usize + GRID * (c.y as usize + GRID * c.z as usize)
    }

    /// The lights a fragment at `p` loops over.
    pub fn list_for_point(&self, p: Vec3) -> &[u32] {
        let [first, count] = self.ranges[self.cell_of(p)];
        &self.indices[first as usize..(first + count) as usize]
    }

    /// Total list length, mean and largest per cell.
    pub fn stats(&self) -> (usize, f64, u32) {
        let max = self.ranges.iter().map(|r| r[1]).max().unwrap_or(0);
        (self.indices.len(), self.indices.len() as f64 / self.ranges.len().max(1) as f64, max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::ShadeMaterial;

    #[test]
    fn a_point_lists_every_light_above_the_threshold() {
        let mut scene = Scene::default();
        let wall = scene.add_material(ShadeMaterial::new([0.8; 3], [0.0; 3], 0.5));
        let lamp = scene.add_material(ShadeMaterial::new([1.0; 3], [4.0, 3.0, 2.0], 0.5));
        scene.push_triangle([Vec3::ZERO, Vec3::new(32.0, 0.0, 0.0), Vec3::new(0.0, 32.0, 32.0)], wall);
        let mut state = 99u64;
        let mut rnd = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32 * 32.0
        };
        for _ in 0..60 {
            let a = Vec3::new(rnd(), rnd(), rnd());
            scene.push_triangle([a, a + Vec3::X * 0.5, a + Vec3::Y * 0.5], lamp);
        }
        let (lights, rep) = lights(&scene);
        assert_eq!(rep.emissive_triangles, 60);
        assert!(rep.lights > 10 && rep.lights <= 60);
        let grid = LightGrid::build(&scene, &lights);
        for _ in 0..2000 {
            let p = Vec3::new(rnd(), rnd(), rnd());
            let list = grid.list_for_point(p);
            for (n, l) in lights.iter().enumerate() {
                let d = (Vec3::from_slice(&l.position_intensity[..3]) - p).length() / grid.unit;
                if attenuation(l.position_intensity[3], d) > THRESHOLD {
                    assert!(list.contains(&(n as u32)), "light {n} missing at {p}");
                }
            }
        }
        let (total, mean, max) = grid.stats();
        assert!(total > 0 && mean > 0.0 && max as usize <= lights.len());
    }
}
