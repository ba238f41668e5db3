//! What the renderer draws: triangles with flat normals and a material
//! each, built from a mesh and its appearance or from a voxel grid's greedy
//! quads (`topovox::export::greedy`), in one coordinate frame.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use topovox::attributes::{Appearance, NO_MATERIAL};
use topovox::export::greedy::Quad;
use topovox::MeshRef;

/// One vertex as the GPU reads it (triangles are not welded: a flat normal
/// and a material per triangle).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct Vertex {
    /// World position.
    pub position: [f32; 3],
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Unit face normal.
    pub normal: [f32; 3],
    /// Texture coordinate (`v = 0` at the top row; zero without a texture).
    pub uv: [f32; 2],
}

/// A material as the shader reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct ShadeMaterial {
    /// Linear base colour (multiplies the base texture); `w` the alpha
    /// cutoff (0: opaque).
    pub colour: [f32; 4],
    /// Linear emitted radiance; `w` is the Blinn–Phong exponent.
    pub emission_shininess: [f32; 4],
    /// Layers of [`Scene::textures`]: the base colour's and the alpha's
    /// (−1: none; the alpha is then the base texture's, or 1), and padding.
    pub layers: [i32; 4],
}

impl ShadeMaterial {
    /// A material of `colour` with `roughness` in 0..=1 (glTF's), converted
    /// to a Blinn–Phong exponent by `n = 2 / r² − 2` (Walter et al. 2007's
    /// Beckmann–Phong correspondence `α_p = 2 α_b⁻² − 2`), clamped to
    /// 1..=1024.
    pub fn new(colour: [f32; 3], emission: [f32; 3], roughness: f32) -> ShadeMaterial {
        ShadeMaterial {
            colour: [colour[0], colour[1], colour[2], 0.0],
            emission_shininess: [emission[0], emission[1], emission[2], shininess(roughness)],
            layers: [-1, -1, 0, 0],
        }
    }

    /// This material with a base-colour texture layer, an alpha layer and
    /// an alpha cutoff (fragments whose alpha is below it are cut out).
    pub fn with_textures(mut self, base: Option<u32>, alpha: Option<u32>, cutoff: Option<f32>) -> ShadeMaterial {
        let layer = |t: Option<u32>| t.map_or(-1, |t| t as i32);
        self.layers = [layer(base), layer(alpha), 0, 0];
        self.colour[3] = cutoff.filter(|c| c.is_finite()).map_or(0.0, |c| c.clamp(0.0, 1.0));
        self
    }

    /// True when some of the surface may be cut out.
    pub fn cut_out(&self) -> bool {
        self.colour[3] > 0.0
    }

    /// True when the material emits light.
    pub fn emissive(&self) -> bool {
        self.emission_shininess[..3].iter().any(|&e| e > 0.0)
    }
}

/// Blinn–Phong exponent of a roughness (see [`ShadeMaterial::new`]).
pub fn shininess(roughness: f32) -> f32 {
    let r = roughness.clamp(0.03, 1.0);
    (2.0 / (r * r) - 2.0).clamp(1.0, 1024.0)
}

/// Triangles ready to draw, three vertices each.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Three per triangle.
    pub vertices: Vec<Vertex>,
    /// Materials the vertices name.
    pub materials: Vec<ShadeMaterial>,
    /// Textures the materials name (RGBA8, `v = 0` at the top row).
    pub textures: Vec<topovox::attributes::Texture>,
}

/// The material of triangles that name none: light grey, rough.
const DEFAULT_COLOUR: [f32; 3] = [0.7, 0.7, 0.7];
const DEFAULT_ROUGHNESS: f32 = 0.6;

impl Scene {
    /// Triangles drawn.
    pub fn triangles(&self) -> usize {
        self.vertices.len() / 3
    }

    /// The bounding box of every vertex (`None` for an empty scene).
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.vertices.iter().map(|v| Vec3::from(v.position));
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
    }

    /// Adds a material; returns its index.
    pub fn add_material(&mut self, m: ShadeMaterial) -> u32 {
        self.materials.push(m);
        self.materials.len() as u32 - 1
    }

    /// Adds a mesh's triangles with its materials (base colour factor,
    /// emission, roughness). Triangles with a non-finite corner or no area
    /// are skipped; returns how many were.
    pub fn add_mesh(&mut self, mesh: MeshRef<'_>, app: &Appearance) -> usize {
        let base = self.materials.len() as u32;
        let first_texture = self.textures.len() as u32;
        self.textures.extend(app.textures.iter().cloned());
        let layer = |t: Option<u32>| t.filter(|&t| (t as usize) < app.textures.len()).map(|t| first_texture + t);
        for m in &app.materials {
            let (texture, alpha) = (layer(m.texture), layer(m.alpha_texture));
            // A cutoff needs an alpha to test: the alpha texture's or the base texture's.
            let cutoff = m.alpha_cutoff.filter(|_| texture.is_some() || alpha.is_some());
            self.materials.push(ShadeMaterial::new(m.factor, m.emission, m.roughness).with_textures(texture, alpha, cutoff));
        }
        let default = self.add_material(ShadeMaterial::new(DEFAULT_COLOUR, [0.0; 3], DEFAULT_ROUGHNESS));
        let mut skipped = 0;
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let material = match app.triangle_material.get(t) {
                Some(&m) if m != NO_MATERIAL && (m as usize) < app.materials.len() => base + m,
                _ => default,
            };
            let p: Option<Vec<Vec3>> = tri.iter().map(|&v| mesh.positions.get(v as usize).map(|p| p.as_vec3())).collect();
            let uv = app.triangle_uv.get(t).copied().filter(|uv| uv.iter().flatten().all(|x| x.is_finite())).unwrap_or([[0.0; 2]; 3]);
            if !p.as_ref().is_some_and(|p| self.push_triangle_uv([p[0], p[1], p[2]], uv, material)) {
                skipped += 1;
            }
        }
        skipped
    }

    /// Adds a triangle; false (and nothing added) when it has a
    /// non-finite corner or no area in `f32`.
    pub fn push_triangle(&mut self, p: [Vec3; 3], material: u32) -> bool {
        self.push_triangle_uv(p, [[0.0; 2]; 3], material)
    }

    /// Adds a triangle with texture coordinates; as [`Scene::push_triangle`].
    pub fn push_triangle_uv(&mut self, p: [Vec3; 3], uv: [[f32; 2]; 3], material: u32) -> bool {
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        if !p.iter().all(|c| c.is_finite()) || !n.is_finite() || n.length_squared() <= 0.0 {
            return false;
        }
        let normal = n.normalize().to_array();
        for (c, uv) in p.into_iter().zip(uv) {
            self.vertices.push(Vertex { position: c.to_array(), material, normal, uv });
        }
        true
    }

    /// Adds a voxel grid's greedy quads, two triangles each, mapping grid
    /// corner `c` to `origin + c ∘ voxel_size` (a size per axis), all of `material`.
    pub fn add_quads(&mut self, quads: &[Quad], origin: Vec3, voxel_size: Vec3, material: u32) {
        for q in quads {
            let c = q.corners().map(|c| origin + Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32) * voxel_size);
            // Wound so the normal points out of the solid side.
            let (a, b) = if q.positive { ([c[0], c[1], c[2]], [c[0], c[2], c[3]]) } else { ([c[0], c[2], c[1]], [c[0], c[3], c[2]]) };
            let out = {
                let mut n = [0.0f32; 3];
                n[q.axis] = if q.positive { 1.0 } else { -1.0 };
                Vec3::from(n)
            };
            for t in [a, b] {
                let n = (t[1] - t[0]).cross(t[2] - t[0]);
                let t = if n.dot(out) < 0.0 { [t[0], t[2], t[1]] } else { t };
                self.push_triangle(t, material);
            }
        }
    }
}
