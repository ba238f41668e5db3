//! Attributes carried from a mesh's surface into its voxels: colour,
//! material id, average normal and coverage (surface area inside a voxel).
//!
//! - [`Appearance`] is what a reader found besides geometry: materials
//!   (colour factors, textures), per-triangle UVs and material ids, and
//!   per-vertex colours.
//! - [`carry::carry`] computes [`VoxelAttributes`] for a voxel set from the
//!   part of each triangle inside each voxel.
//! - [`quantize`] builds a palette of at most N colours (median cut in
//!   Oklab, refined by k-means) for formats with palettes.

pub mod carry;
pub mod colour;
pub mod quantize;

/// Texture coordinate wrapping (glTF sampler `wrapS`/`wrapT`; OBJ `-clamp`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// Repeat (the default of both OBJ and glTF).
    #[default]
    Repeat,
    /// Repeat, mirrored every other time.
    MirroredRepeat,
    /// Clamp to the edge texels.
    ClampToEdge,
}

impl Wrap {
    /// The texel index for coordinate `t` (in texture widths) on a side of `n` texels.
    pub fn texel(self, t: f64, n: u32) -> u32 {
        let n_f = n as f64;
        let x = if t.is_finite() { t * n_f } else { 0.0 };
        let i = x.floor();
        let idx = match self {
            // (`rem_euclid` is a library call; inside the range it is the identity.)
            Wrap::Repeat if i >= 0.0 && i < n_f => i,
            Wrap::Repeat => i.rem_euclid(n_f),
            Wrap::ClampToEdge => i.clamp(0.0, n_f - 1.0),
            Wrap::MirroredRepeat => {
                let m = i.rem_euclid(2.0 * n_f);
                if m < n_f {
                    m
                } else {
                    2.0 * n_f - 1.0 - m
                }
            }
        };
        (idx as u32).min(n - 1)
    }
}

/// A decoded texture: sRGB bytes, RGBA, rows top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Where it came from (for messages).
    pub name: String,
    /// Texels across.
    pub width: u32,
    /// Texels down.
    pub height: u32,
    /// `width × height × 4` bytes, row-major from the top row.
    pub rgba: Vec<u8>,
    /// Wrapping along u and v.
    pub wrap: [Wrap; 2],
}

impl Texture {
    /// The texel nearest to `(u, v)`, with `v = 0` at the **top** row
    /// (glTF's convention; readers flip OBJ's `v` on loading). Nearest-texel
    /// lookup never invents a colour.
    pub fn texel(&self, u: f64, v: f64) -> [u8; 3] {
        let [r, g, b, _] = self.texel_rgba(u, v);
        [r, g, b]
    }

    /// The nearest texel with its alpha (see [`Texture::texel`]).
    pub fn texel_rgba(&self, u: f64, v: f64) -> [u8; 4] {
        let x = self.wrap[0].texel(u, self.width);
        let y = self.wrap[1].texel(v, self.height);
        let at = 4 * (y as usize * self.width as usize + x as usize);
        [self.rgba[at], self.rgba[at + 1], self.rgba[at + 2], self.rgba[at + 3]]
    }
}

/// A material: a colour factor in linear RGB (OBJ `Kd`, glTF
/// `baseColorFactor`) that multiplies its texture, if it has one.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name (OBJ `newmtl`, glTF material name or index).
    pub name: String,
    /// Linear RGB multiplier (the colour itself when there is no texture).
    pub factor: [f32; 3],
    /// Index into [`Appearance::textures`].
    pub texture: Option<u32>,
    /// Emitted linear RGB (OBJ `Ke`, glTF `emissiveFactor`); zero for most.
    pub emission: [f32; 3],
    /// Roughness in 0..=1 (glTF `roughnessFactor`; OBJ `Pr`, or `Ns`
    /// converted by `r = sqrt(2 / (Ns + 2))`, the inverse of the viewer's
    /// Blinn–Phong exponent `2 / r² − 2`). Default 0.6 when unset.
    pub roughness: f32,
    /// Alpha test of the GPU renderer: where the alpha is below this the
    /// surface is cut out (glTF `alphaMode: MASK` with its `alphaCutoff`;
    /// OBJ `map_d`, or a `map_Kd` image with transparent texels: 0.5, as
    /// seed 002 uses). `None`: opaque. Voxelization ignores it.
    pub alpha_cutoff: Option<f32>,
    /// Where the alpha comes from when it is not the base texture's alpha
    /// channel: a texture whose alpha channel holds it (OBJ `map_d`).
    pub alpha_texture: Option<u32>,
}

/// Roughness of a material that does not say.
pub const DEFAULT_ROUGHNESS: f32 = 0.6;

/// Marks a triangle without a material.
pub const NO_MATERIAL: u32 = u32::MAX;

/// What a mesh looks like, aligned with its triangles and vertices. Every
/// list may be empty (the mesh does not have it).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Appearance {
    /// Materials.
    pub materials: Vec<Material>,
    /// Textures, referenced by materials.
    pub textures: Vec<Texture>,
    /// Per triangle: index into `materials`, or [`NO_MATERIAL`].
    pub triangle_material: Vec<u32>,
    /// Per triangle: the UV of each corner, `v = 0` at the top of the
    /// texture; NaN where the triangle has none.
    pub triangle_uv: Vec<[[f32; 2]; 3]>,
    /// Per vertex: an sRGB colour (PLY `red green blue`, glTF `COLOR_0`).
    pub vertex_colour: Vec<[u8; 3]>,
}

impl Appearance {
    /// True when the mesh carries any colour (materials or vertex colours).
    pub fn has_colour(&self) -> bool {
        !self.materials.is_empty() || !self.vertex_colour.is_empty()
    }

    /// True when triangles carry material ids.
    pub fn has_materials(&self) -> bool {
        self.triangle_material.iter().any(|&m| m != NO_MATERIAL)
    }
}

crate::choice! {
    /// How a voxel's colour is made from the colours of the surface inside it.
    pub enum ColourRule: "colour rule" default Dominant {
        /// The colour covering the most area inside the voxel: always a
        /// colour of the texture (or material, or vertex), never a new one.
        Dominant = "dominant",
        /// The area-weighted mean in linear light.
        Blend = "blend",
    }
}

/// Per-voxel attributes of a voxel set, aligned with its set voxels in
/// key order (`i + nx·(j + ny·k)`, ascending: the order of
/// [`crate::VoxelSource::for_each_set`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VoxelAttributes {
    /// Grid dims.
    pub dims: [u32; 3],
    /// Keys of the set voxels, ascending.
    pub keys: Vec<u64>,
    /// sRGB colour per voxel.
    pub colour: Option<Vec<[u8; 3]>>,
    /// Material id per voxel ([`NO_MATERIAL`] for none).
    pub material: Option<Vec<u32>>,
    /// Area-weighted mean unit normal per voxel (zero where the surface inside cancels).
    pub normal: Option<Vec<[f32; 3]>>,
    /// Surface area inside the voxel, measured in index space: a piece
    /// spanning the voxel parallel to any face has 1 (for cubes, area / s²).
    pub coverage: Option<Vec<f32>>,
}

impl VoxelAttributes {
    /// The key of voxel `(i, j, k)` on a grid of `dims`.
    pub fn key(dims: [u32; 3], i: u32, j: u32, k: u32) -> u64 {
        i as u64 + dims[0] as u64 * (j as u64 + dims[1] as u64 * k as u64)
    }

    /// The keys of the set voxels of `voxels`, ascending: the slots
    /// attributes of exactly those voxels take.
    pub fn keys_of(voxels: &dyn crate::VoxelSource) -> Vec<u64> {
        let dims = voxels.dims();
        let mut keys = Vec::with_capacity(voxels.count() as usize);
        // `for_each_set` goes by k, then j, then i: ascending keys.
        voxels.for_each_set(&mut |i, j, k| keys.push(Self::key(dims, i, j, k)));
        keys
    }

    /// The voxel of a key.
    pub fn voxel(&self, key: u64) -> [u32; 3] {
        let (nx, ny) = (self.dims[0] as u64, self.dims[1] as u64);
        [(key % nx) as u32, (key / nx % ny) as u32, (key / (nx * ny)) as u32]
    }

    /// The slot of voxel `(i, j, k)`, if it is set.
    pub fn slot(&self, i: u32, j: u32, k: u32) -> Option<usize> {
        self.keys.binary_search(&Self::key(self.dims, i, j, k)).ok()
    }

    /// The colour of voxel `(i, j, k)`, if colours are present and it is set.
    pub fn colour_of(&self, i: u32, j: u32, k: u32) -> Option<[u8; 3]> {
        let c = self.colour.as_ref()?;
        self.slot(i, j, k).map(|s| c[s])
    }

    /// Attributes with only colours, for `voxels` given as `(i, j, k, colour)`
    /// in any order (readers of coloured formats use it).
    pub fn from_coloured(dims: [u32; 3], mut voxels: Vec<([u32; 3], [u8; 3])>) -> VoxelAttributes {
        voxels.sort_unstable_by_key(|(v, _)| Self::key(dims, v[0], v[1], v[2]));
        voxels.dedup_by_key(|(v, _)| *v);
        VoxelAttributes {
            dims,
            keys: voxels.iter().map(|(v, _)| Self::key(dims, v[0], v[1], v[2])).collect(),
            colour: Some(voxels.into_iter().map(|(_, c)| c).collect()),
            ..VoxelAttributes::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_modes() {
        assert_eq!(Wrap::Repeat.texel(1.25, 4), 1);
        assert_eq!(Wrap::Repeat.texel(-0.1, 4), 3);
        assert_eq!(Wrap::ClampToEdge.texel(1.25, 4), 3);
        assert_eq!(Wrap::ClampToEdge.texel(-3.0, 4), 0);
        assert_eq!(Wrap::MirroredRepeat.texel(1.1, 4), 3);
        assert_eq!(Wrap::MirroredRepeat.texel(-0.1, 4), 0);
        assert_eq!(Wrap::Repeat.texel(f64::NAN, 4), 0);
        assert_eq!(Wrap::Repeat.texel(1.0, 4), 0);
    }

    #[test]
    fn keys_round_trip() {
        let a = VoxelAttributes { dims: [3, 4, 5], ..VoxelAttributes::default() };
        let k = VoxelAttributes::key(a.dims, 2, 3, 4);
        assert_eq!(a.voxel(k), [2, 3, 4]);
    }
}
