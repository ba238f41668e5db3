//! Ray spray into a point cloud (seed 002, first part, "Ray-tracing").
//!
//! Rays are cast into the scene (from a camera, or in a cone around the
//! viewer's cursor); each hit becomes a point that stores what does not
//! depend on the viewer, and the GPU computes the rest every frame
//! (`shaders/points.wgsl`):
//!
//! - **stored**: the position, the normal facing the ray, the material's
//!   albedo and emission, and the *light term* — the Lambert term and the
//!   attenuation `i / (d³ + 1)` towards light samples drawn uniformly over
//!   the emissive triangles, each sample's visibility tested by a shadow
//!   ray;
//! - **per frame**: the Lambert term and the attenuation towards the viewer
//!   (see `points.wgsl`).
//!
//! **Light samples.** A triangle is chosen with probability proportional
//! to its area, and a point on it by the square-root parametrisation
//! (P. Dutré, *Global Illumination Compendium*, formula 18):
//! `p = (1 − √u) a + √u (1 − v) b + √u v c`, uniform over the triangle.
//! Emissive triangles form the renderer's lights ([`crate::lights`]:
//! merged by material and proximity, intensity `√a` times the emission for
//! a light of area `a` in attenuation units²), each light spread over its
//! triangles; the light term estimates the sum over lights of their mean
//! `√a · e · max(0, n·l) · V / (d³ + 1)` over their area (`V` the
//! sample's visibility, `d` in attenuation units). With samples drawn by
//! area over all `A` units² of emissive surface, a sample on a light of
//! area `a` is weighted `A / √a`, and the light term is the mean of the
//! `K` weighted samples: on average what the rasterizer's lights give,
//! with shadows and the lights' true extent. A scene without
//! emissive triangles gets a light term of zero (points show emission
//! only); the viewer's head-light still shows their albedo.
//!
//! **Acceleration structure**: a compressed wide BVH (`obvhs`: PLOC build,
//! Ylitie et al.'s CWBVH8 traversal); triangles are hit by Möller–Trumbore.
//!
//! **Deterministic**: rays are drawn in blocks of [`BLOCK`], each block
//! from its own ChaCha8 stream of the seed, and the blocks are joined in
//! order, so a cloud depends only on the scene, the camera, the seed and
//! the counts, not on the thread count.

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::cwbvh::{builder::build_cwbvh_from_tris, CwBvh};
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::camera::Camera;
use crate::lights::{area_units, frame, merge_key};
use crate::scene::{Scene, ShadeMaterial};
use crate::ViewError;
use topovox::attributes::colour::to_linear;
use topovox::attributes::Texture;
pub use topovox_io::spray_cloud::SprayPoint;

/// Rays per random stream.
pub const BLOCK: usize = 4096;

/// How many rays and light samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SprayOptions {
    /// Rays cast.
    pub rays: usize,
    /// Light samples per hit point.
    pub light_samples: u32,
    /// Seed of the random streams.
    pub seed: u64,
    /// Shadow rays towards the light samples (off: every sample is seen).
    pub shadows: bool,
}

impl Default for SprayOptions {
    fn default() -> Self {
        SprayOptions { rays: 100_000, light_samples: 16, seed: 1, shadows: true }
    }
}

/// Emissive triangles for sampling: cumulative areas, and per triangle
/// the weight `A / √a` of its light (see the module documentation).
struct Emitters {
    triangles: Vec<u32>,
    cumulative: Vec<f64>,
    weight: Vec<f32>,
}

/// A scene ready for rays.
pub struct Tracer {
    bvh: CwBvh,
    triangles: Vec<Triangle>,
    /// Per triangle: its material, and the UV of its corners.
    material: Vec<u32>,
    uv: Vec<[[f32; 2]; 3]>,
    materials: Vec<ShadeMaterial>,
    textures: Vec<Texture>,
    normals: Vec<Vec3>,
    emitters: Emitters,
    unit: f32,
    /// Offset of shadow-ray origins off the surface (world units).
    epsilon: f32,
}

impl Tracer {
    /// Builds the BVH over the scene's triangles.
    pub fn new(scene: &Scene) -> Result<Tracer, ViewError> {
        if scene.triangles() == 0 {
            return Err(ViewError::EmptyScene);
        }
        let (lo, hi, unit) = frame(scene);
        let triangles: Vec<Triangle> = scene
            .vertices
            .chunks_exact(3)
            .map(|t| Triangle { v0: Vec3A::from(t[0].position), v1: Vec3A::from(t[1].position), v2: Vec3A::from(t[2].position) })
            .collect();
        let normals = scene.vertices.chunks_exact(3).map(|t| Vec3::from(t[0].normal)).collect();
        let material = |t: &[crate::scene::Vertex]| scene.materials[t[0].material as usize];
        // The lights as crate::lights merges them: total area per light.
        let mut emitters = Emitters { triangles: Vec::new(), cumulative: Vec::new(), weight: Vec::new() };
        let mut lights: std::collections::HashMap<(u32, [i64; 3]), f32> = Default::default();
        let mut keys = Vec::new();
        let mut total = 0.0f64;
        for (i, t) in scene.vertices.chunks_exact(3).enumerate() {
            if !material(t).emissive() {
                continue;
            }
            let p = [0, 1, 2].map(|c| Vec3::from(t[c].position));
            let a = area_units(p, unit);
            if a.is_nan() || a <= 0.0 {
                continue;
            }
            let key = merge_key(lo, unit, t[0].material, p);
            *lights.entry(key).or_default() += a;
            keys.push(key);
            total += f64::from(a);
            emitters.triangles.push(i as u32);
            emitters.cumulative.push(total);
        }
        emitters.weight = keys.iter().map(|k| (total / f64::from(lights[k]).sqrt()) as f32).collect();
        let bvh = build_cwbvh_from_tris(&triangles, BvhBuildParams::medium_build(), &mut Duration::default());
        let epsilon = (hi - lo).max_element().max(f32::MIN_POSITIVE) * 1e-5;
        let material = scene.vertices.chunks_exact(3).map(|t| t[0].material).collect();
        let uv = scene.vertices.chunks_exact(3).map(|t| [t[0].uv, t[1].uv, t[2].uv]).collect();
        Ok(Tracer {
            bvh,
            triangles,
            material,
            uv,
            materials: scene.materials.clone(),
            textures: scene.textures.clone(),
            normals,
            emitters,
            unit,
            epsilon,
        })
    }

    /// Triangle `t`'s emitted radiance (its material's).
    fn emission(&self, t: usize) -> [f32; 3] {
        let e = self.materials[self.material[t] as usize].emission_shininess;
        [e[0], e[1], e[2]]
    }

    /// The texture coordinate of point `p` on triangle `t`.
    fn uv_at(&self, t: usize, p: Vec3) -> [f64; 2] {
        let tri = &self.triangles[t];
        let [a, b, c] = [tri.v0, tri.v1, tri.v2].map(|v| Vec3::from(v).as_dvec3());
        let (e1, e2, q) = (b - a, c - a, p.as_dvec3() - a);
        let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (d20, d21) = (q.dot(e1), q.dot(e2));
        let den = d00 * d11 - d01 * d01;
        let (v, w) = if den > 0.0 { ((d11 * d20 - d01 * d21) / den, (d00 * d21 - d01 * d20) / den) } else { (0.0, 0.0) };
        let uv = self.uv[t];
        std::array::from_fn(|k| (1.0 - v - w) * f64::from(uv[0][k]) + v * f64::from(uv[1][k]) + w * f64::from(uv[2][k]))
    }

    /// The base texture's texel at `p` on triangle `t` (white without one).
    fn texel(&self, t: usize, p: Vec3) -> [u8; 4] {
        let m = &self.materials[self.material[t] as usize];
        match usize::try_from(m.layers[0]).ok().and_then(|l| self.textures.get(l)) {
            Some(tex) => {
                let [u, v] = self.uv_at(t, p);
                tex.texel_rgba(u, v)
            }
            None => [255; 4],
        }
    }

    /// Whether the alpha test cuts triangle `t` out at `p` (as `shade.wgsl`
    /// does, with the nearest texel instead of a filtered one).
    fn cut_out(&self, t: usize, p: Vec3) -> bool {
        let m = &self.materials[self.material[t] as usize];
        if !m.cut_out() {
            return false;
        }
        let alpha = match usize::try_from(m.layers[1]).ok().and_then(|l| self.textures.get(l)) {
            Some(tex) => {
                let [u, v] = self.uv_at(t, p);
                tex.texel_rgba(u, v)[3]
            }
            None => self.texel(t, p)[3],
        };
        f32::from(alpha) / 255.0 < m.colour[3]
    }

    /// The ray's distance to triangle `t`, infinite on a miss or where the
    /// surface is cut out (rays and shadow rays pass through cut-outs).
    fn intersect(&self, r: &Ray, t: usize) -> f32 {
        let d = self.triangles[t].intersect(r);
        if d.is_finite() && self.cut_out(t, Vec3::from(r.origin + r.direction * d)) {
            f32::INFINITY
        } else {
            d
        }
    }

    /// Emissive triangles the light samples are drawn from.
    pub fn emissive_triangles(&self) -> usize {
        self.emitters.triangles.len()
    }

    /// The nearest hit along the ray: distance and triangle.
    pub fn hit(&self, origin: Vec3, dir: Vec3) -> Option<(f32, usize)> {
        let ray = Ray::new_inf(origin.into(), positive_zeros(dir).into());
        let mut hit = RayHit::none();
        self.bvh
            .ray_traverse(ray, &mut hit, |r, id| self.intersect(r, self.bvh.primitive_indices[id] as usize))
            .then(|| (hit.t, self.bvh.primitive_indices[hit.primitive_id as usize] as usize))
    }

    /// Whether nothing lies between `from` and `to` (both excluded).
    fn clear(&self, from: Vec3, to: Vec3) -> bool {
        let d = to - from;
        let len = d.length();
        if len <= 2.0 * self.epsilon {
            return true;
        }
        let ray = Ray::new(from.into(), positive_zeros(d / len).into(), self.epsilon, len - self.epsilon);
        self.bvh.ray_traverse_miss(ray, |r, id| self.intersect(r, self.bvh.primitive_indices[id] as usize))
    }

    /// A uniform point on the emissive surface.
    fn light_sample(&self, rng: &mut ChaCha8Rng) -> Option<(Vec3, Vec3)> {
        let total = *self.emitters.cumulative.last()?;
        let x = rng.random::<f64>() * total;
        let k = self.emitters.cumulative.partition_point(|&c| c <= x).min(self.emitters.triangles.len() - 1);
        let t = self.emitters.triangles[k] as usize;
        let tri = &self.triangles[t];
        let (u, v) = (rng.random::<f32>(), rng.random::<f32>());
        let s = u.sqrt();
        let p = tri.v0 * (1.0 - s) + tri.v1 * (s * (1.0 - v)) + tri.v2 * (s * v);
        Some((p.into(), Vec3::from(self.emission(t)) * self.emitters.weight[k]))
    }

    /// The point where a ray hits, with its light term, or `None` on a miss.
    pub fn point(&self, origin: Vec3, dir: Vec3, o: &SprayOptions, rng: &mut ChaCha8Rng) -> Option<SprayPoint> {
        let dir = dir.normalize_or_zero();
        let (t, tri) = self.hit(origin, dir)?;
        let p = origin + dir * t;
        let mut n = self.normals[tri];
        if n.dot(dir) > 0.0 {
            n = -n;
        }
        let mut light = Vec3::ZERO;
        if !self.emitters.triangles.is_empty() && o.light_samples > 0 {
            let from = p + n * self.epsilon;
            for _ in 0..o.light_samples {
                let Some((q, e)) = self.light_sample(rng) else { break };
                let to = q - p;
                let dist = to.length();
                let cos = if dist > 0.0 { n.dot(to) / dist } else { 0.0 };
                if cos <= 0.0 || (o.shadows && !self.clear(from, q)) {
                    continue;
                }
                let d = dist / self.unit;
                light += e * (cos / (d * d * d + 1.0));
            }
            light /= o.light_samples as f32;
        }
        Some(SprayPoint {
            position: p.to_array(),
            normal: n.to_array(),
            albedo: {
                // The base colour times the texture's (sRGB) texel.
                let texel = self.texel(tri, p);
                let base = self.materials[self.material[tri] as usize].colour;
                std::array::from_fn(|c| base[c] * to_linear(texel[c]) as f32)
            },
            light: light.to_array(),
            emission: self.emission(tri),
            _pad: 0.0,
        })
    }

    /// Casts `o.rays` rays, each `ray(rng)` (origin and direction), block
    /// by block in parallel (see the module documentation); the hits, in
    /// ray order.
    fn cast(&self, o: &SprayOptions, ray: impl Fn(&mut ChaCha8Rng) -> (Vec3, Vec3) + Sync) -> Vec<SprayPoint> {
        let blocks = o.rays.div_ceil(BLOCK);
        let per_block: Vec<Vec<SprayPoint>> = (0..blocks)
            .into_par_iter()
            .map(|b| {
                let mut rng = ChaCha8Rng::seed_from_u64(o.seed);
                rng.set_stream(b as u64);
                let n = BLOCK.min(o.rays - b * BLOCK);
                (0..n)
                    .filter_map(|_| {
                        let (origin, dir) = ray(&mut rng);
                        self.point(origin, dir, o, &mut rng)
                    })
                    .collect()
            })
            .collect();
        // Joined block by block, each freed once copied: the memory peak
        // stays near one copy of the cloud.
        let mut out = Vec::with_capacity(per_block.iter().map(Vec::len).sum());
        for block in per_block {
            out.extend_from_slice(&block);
        }
        out
    }

    /// Rays from the camera's eye through points drawn uniformly over its
    /// picture (of `aspect` width / height).
    pub fn spray_camera(&self, camera: &Camera, aspect: f32, o: &SprayOptions) -> Vec<SprayPoint> {
        self.cast(o, |rng| {
            let (x, y) = (rng.random::<f32>() * 2.0 - 1.0, rng.random::<f32>() * 2.0 - 1.0);
            (camera.eye, camera.ray(aspect, x, y))
        })
    }

    /// Rays from `origin` in a cone of half-angle `half_angle` (radians)
    /// around `dir`, uniform over the cone's solid angle: the viewer's
    /// spray at the cursor.
    pub fn spray_cone(&self, origin: Vec3, dir: Vec3, half_angle: f32, o: &SprayOptions) -> Vec<SprayPoint> {
        let w = dir.normalize_or_zero();
        let (u, v) = w.any_orthonormal_pair();
        let cos_max = half_angle.clamp(0.0, std::f32::consts::PI).cos();
        self.cast(o, |rng| {
            let c = 1.0 - rng.random::<f32>() * (1.0 - cos_max);
            let s = (1.0 - c * c).max(0.0).sqrt();
            let phi = rng.random::<f32>() * std::f32::consts::TAU;
            (origin, w * c + (u * phi.cos() + v * phi.sin()) * s)
        })
    }
}

/// `dir` with every `−0.0` made `+0.0`: obvhs's wide-node traversal
/// misses everything along a direction with a negative zero component
/// (`−Y` exactly, say), which the tests caught; adding `+0.0` is the IEEE
/// way to clear the sign of a zero and leaves every other value as is.
fn positive_zeros(dir: Vec3) -> Vec3 {
    dir + Vec3::ZERO
}
