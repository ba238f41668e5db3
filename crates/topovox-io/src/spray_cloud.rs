//! The point clouds of `topovox spray` as PLY: each ray's hit with its
//! normal and the stored light terms (albedo, light, emission), so that
//! `render --gpu --points` and `view --points` draw them lit as they were,
//! and `red green blue` so that other tools (MeshLab, CloudCompare, Open3D)
//! show a lit cloud. Read through `ply-rs-bw` (any encoding and property
//! order); the spray itself is `topovox_view::spray`.

use std::io::Write;

use bytemuck::{Pod, Zeroable};

/// One point of the cloud, as the GPU reads it (64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct SprayPoint {
    /// Where the ray hit.
    pub position: [f32; 3],
    /// Unit normal of the hit triangle, on the side the ray came from.
    pub normal: [f32; 3],
    /// Linear albedo (the material's base colour).
    pub albedo: [f32; 3],
    /// The light term (linear RGB, see the module documentation).
    pub light: [f32; 3],
    /// Linear emitted radiance.
    pub emission: [f32; 3],
    /// Padding to 64 bytes.
    pub _pad: f32,
}

impl SprayPoint {
    /// The colour a viewer straight along the normal at one view unit sees
    /// (albedo × light term + emission), in sRGB bytes: the colour the PLY
    /// file's `red green blue` carry for other tools.
    pub fn preview_rgb(&self) -> [u8; 3] {
        std::array::from_fn(|c| {
            let x = (self.albedo[c] * self.light[c] + self.emission[c]).clamp(0.0, 1.0);
            let s = if x <= 0.003_130_8 { 12.92 * x } else { 1.055 * x.powf(1.0 / 2.4) - 0.055 };
            (s * 255.0).round() as u8
        })
    }
}

const PLY_COMMENT: &str = "comment topovox spray";
const FLOATS: [&str; 15] = [
    "x",
    "y",
    "z",
    "nx",
    "ny",
    "nz",
    "albedo_r",
    "albedo_g",
    "albedo_b",
    "light_r",
    "light_g",
    "light_b",
    "emission_r",
    "emission_g",
    "emission_b",
];

/// Writes a cloud as binary little-endian PLY: a `vertex` element with
/// `x y z nx ny nz` and the stored terms as floats (`albedo_*`, `light_*`,
/// `emission_*`), then `red green blue` (uchar, [`SprayPoint::preview_rgb`])
/// so that other tools show a lit cloud.
pub fn write_ply(w: &mut dyn Write, points: &[SprayPoint]) -> std::io::Result<()> {
    let mut head = format!(
        "ply\nformat binary_little_endian 1.0\n{PLY_COMMENT}: ray hits with their light term (see topovox-io's spray_cloud.rs)\nelement vertex {}\n",
        points.len()
    );
    for f in FLOATS {
        head.push_str(&format!("property float {f}\n"));
    }
    head.push_str("property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n");
    w.write_all(head.as_bytes())?;
    let mut buf = Vec::with_capacity(1 << 16);
    for p in points {
        for v in p.position.iter().chain(&p.normal).chain(&p.albedo).chain(&p.light).chain(&p.emission) {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        buf.extend_from_slice(&p.preview_rgb());
        if buf.len() >= 1 << 16 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)
}

/// Reads a cloud written by [`write_ply`] (through `ply-rs-bw`, so any
/// encoding and property order); a PLY without the stored terms is
/// refused with the name of the first one missing.
pub fn read_ply(bytes: &[u8]) -> Result<Vec<SprayPoint>, String> {
    use ply_rs_bw::ply::Property;
    let parser = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new();
    if !bytes.starts_with(b"ply") {
        return Err("not a PLY file (it does not start with 'ply')".into());
    }
    let ply = parser
        .read_ply(&mut std::io::Cursor::new(bytes))
        .map_err(|e| format!("not a readable PLY file: {}", e.to_string().lines().next().unwrap_or("unknown error")))?;
    let verts = ply.payload.get("vertex").ok_or("no 'vertex' element")?;
    let mut out = Vec::with_capacity(verts.len());
    for (n, v) in verts.iter().enumerate() {
        let mut f = [0.0f32; 15];
        for (slot, name) in f.iter_mut().zip(FLOATS) {
            *slot = match v.get(name) {
                Some(Property::Float(x)) => *x,
                Some(Property::Double(x)) => *x as f32,
                Some(_) => return Err(format!("property {name} is not a float")),
                None => return Err(format!("no property {name}: not a topovox spray cloud (written by topovox spray)")),
            };
        }
        if !f.iter().all(|x| x.is_finite()) {
            return Err(format!("point {n} has a non-finite value"));
        }
        let g = |i: usize| [f[i], f[i + 1], f[i + 2]];
        out.push(SprayPoint { position: g(0), normal: g(3), albedo: g(6), light: g(9), emission: g(12), _pad: 0.0 });
    }
    Ok(out)
}
