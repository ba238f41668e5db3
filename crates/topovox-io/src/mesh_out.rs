//! Triangle meshes out (what `topovox remesh` writes): OBJ, PLY, STL, GLB,
//! each replaced all or nothing.
//!
//! Precision: OBJ writes each f64 coordinate in its shortest text that
//! reads back to the same f64 (Rust's `Display`), PLY writes `double`s, so
//! both read back bit for bit. STL and GLB hold `float`s: a caller that
//! certifies what it writes rounds to f32 first ([`MeshOut::single`]).
//! Triangles are counter-clockwise seen from outside in every format; STL
//! facets carry their normal; GLB has positions and indices only (glTF
//! viewers then compute flat normals, as the specification requires).

use std::io::Write;
use std::path::Path;

use glam::DVec3;
use serde_json::json;
use topovox::stop::Stop;

use crate::atomic::write_atomically_until;
use crate::error::IoError;

topovox::choice! {
    /// Triangle mesh files topovox writes.
    pub enum MeshOut: "format" {
        /// Wavefront OBJ: text, coordinates exact (f64).
        Obj = "obj",
        /// PLY, binary little endian, double coordinates.
        Ply = "ply",
        /// STL, binary, float coordinates.
        Stl = "stl",
        /// glTF 2.0 binary: float positions and 32-bit indices.
        Glb = "glb",
    }
}

impl MeshOut {
    /// Whether the format stores coordinates as f32.
    pub fn single(self) -> bool {
        matches!(self, MeshOut::Stl | MeshOut::Glb)
    }

    /// The format of `path`'s extension, if it is one of these.
    pub fn of_path(path: &Path) -> Option<MeshOut> {
        use topovox::choice::Choice;
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        MeshOut::parse(&ext).ok()
    }
}

/// Writes the mesh to `path` as `format` (to a temporary file renamed into
/// place; nothing is left when `stop` is requested).
pub fn write_mesh(path: &Path, positions: &[DVec3], triangles: &[[u32; 3]], format: MeshOut, stop: Option<&Stop>) -> Result<(), IoError> {
    write_atomically_until(path, stop, |w| {
        let mut w = std::io::BufWriter::with_capacity(1 << 20, w);
        match format {
            MeshOut::Obj => obj(&mut w, positions, triangles)?,
            MeshOut::Ply => ply(&mut w, positions, triangles)?,
            MeshOut::Stl => stl(&mut w, positions, triangles)?,
            MeshOut::Glb => glb(&mut w, positions, triangles)?,
        }
        w.flush()
    })
}

fn obj(w: &mut impl Write, p: &[DVec3], t: &[[u32; 3]]) -> std::io::Result<()> {
    writeln!(w, "# topovox remesh: {} vertices, {} triangles", p.len(), t.len())?;
    for v in p {
        writeln!(w, "v {} {} {}", v.x, v.y, v.z)?;
    }
    for f in t {
        writeln!(w, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1)?;
    }
    Ok(())
}

fn ply(w: &mut impl Write, p: &[DVec3], t: &[[u32; 3]]) -> std::io::Result<()> {
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment topovox remesh\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nelement face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        p.len(),
        t.len()
    )?;
    for v in p {
        for c in v.to_array() {
            w.write_all(&c.to_le_bytes())?;
        }
    }
    for f in t {
        w.write_all(&[3])?;
        for i in f {
            w.write_all(&i.to_le_bytes())?;
        }
    }
    Ok(())
}

fn stl(w: &mut impl Write, p: &[DVec3], t: &[[u32; 3]]) -> std::io::Result<()> {
    let count = u32::try_from(t.len()).map_err(|_| std::io::Error::other("more triangles than STL can count (2^32 - 1)"))?;
    let mut header = [b' '; 80];
    header[..15].copy_from_slice(b"topovox remesh ");
    w.write_all(&header)?;
    w.write_all(&count.to_le_bytes())?;
    for f in t {
        let [a, b, c] = f.map(|i| p[i as usize]);
        let n = (b - a).cross(c - a).normalize_or_zero();
        for v in [n, a, b, c] {
            for x in v.to_array() {
                w.write_all(&(x as f32).to_le_bytes())?;
            }
        }
        w.write_all(&[0, 0])?;
    }
    Ok(())
}

fn glb(w: &mut dyn Write, p: &[DVec3], t: &[[u32; 3]]) -> std::io::Result<()> {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    let mut bin = Vec::with_capacity(t.len() * 12 + p.len() * 12);
    for f in t {
        for i in f {
            bin.extend_from_slice(&i.to_le_bytes());
        }
    }
    let positions_at = bin.len();
    for v in p {
        for (a, x) in v.to_array().into_iter().enumerate() {
            let x = x as f32;
            (lo[a], hi[a]) = (lo[a].min(x), hi[a].max(x));
            bin.extend_from_slice(&x.to_le_bytes());
        }
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "topovox remesh"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "remesh"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0, "mode": 4}]}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": positions_at, "target": 34963},
            {"buffer": 0, "byteOffset": positions_at, "byteLength": bin.len() - positions_at, "target": 34962},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5125, "count": t.len() * 3, "type": "SCALAR"},
            {"bufferView": 1, "componentType": 5126, "count": p.len(), "type": "VEC3", "min": lo, "max": hi},
        ],
    });
    write_glb(w, &doc, &bin, |total| format!("a {total}-byte mesh cannot be a .glb file (the format ends at 4 GiB)"))
}

/// Writes a binary glTF container: the 12-byte header, the JSON chunk
/// (padded with spaces to 4 bytes) and the BIN chunk (`bin` already
/// padded). A file past 4 GiB is refused with `too_large(total bytes)`.
pub(crate) fn write_glb(
    w: &mut dyn Write,
    doc: &serde_json::Value,
    bin: &[u8],
    too_large: impl FnOnce(usize) -> String,
) -> std::io::Result<()> {
    let mut text = doc.to_string().into_bytes();
    while text.len() % 4 != 0 {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let total = u32::try_from(total).map_err(|_| std::io::Error::other(too_large(total)))?;
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&total.to_le_bytes())?;
    w.write_all(&(text.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&text)?;
    w.write_all(&(bin.len() as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")?;
    w.write_all(bin)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every format reads back through topovox's own readers: the same
    /// triangles, positions exact (OBJ, PLY) or as f32 (STL, GLB).
    #[test]
    fn every_format_reads_back() {
        let p = vec![
            DVec3::new(0.1, 0.2, 0.3),
            DVec3::new(1.0 / 3.0, -2.5e-7, 4.0),
            DVec3::new(7.0, 8.0, -9.125),
            DVec3::new(1e5 + 0.1, 0.0, 1.0),
        ];
        let t = vec![[0, 1, 2], [0, 2, 3], [3, 2, 1], [0, 3, 1]];
        let dir = std::env::temp_dir().join(format!("topovox-mesh-out-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for f in [MeshOut::Obj, MeshOut::Ply, MeshOut::Stl, MeshOut::Glb] {
            use topovox::choice::Choice;
            let path = dir.join(format!("m.{}", f.name()));
            write_mesh(&path, &p, &t, f, None).unwrap();
            let back = crate::read_mesh(&path, &crate::ReadOptions::default()).unwrap();
            let m = back.mesh;
            assert_eq!(m.triangles.len(), t.len(), "{f:?}");
            for (n, tri) in t.iter().enumerate() {
                for c in 0..3 {
                    let (want, got) = (p[tri[c] as usize], m.positions[m.triangles[n][c] as usize]);
                    let want = if f.single() { want.as_vec3().as_dvec3() } else { want };
                    assert_eq!(want, got, "{f:?} triangle {n} corner {c}");
                }
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
