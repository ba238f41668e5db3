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

use crate::atomic::{write_atomically_until, Spool};
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
    obj_vertices(w, p)?;
    obj_faces(w, t)
}

fn obj_vertices(w: &mut impl Write, p: &[DVec3]) -> std::io::Result<()> {
    for v in p {
        writeln!(w, "v {} {} {}", v.x, v.y, v.z)?;
    }
    Ok(())
}

fn obj_faces(w: &mut impl Write, t: &[[u32; 3]]) -> std::io::Result<()> {
    for f in t {
        writeln!(w, "f {} {} {}", f[0] as u64 + 1, f[1] as u64 + 1, f[2] as u64 + 1)?;
    }
    Ok(())
}

fn ply(w: &mut impl Write, p: &[DVec3], t: &[[u32; 3]]) -> std::io::Result<()> {
    ply_header(w, p.len() as u64, t.len() as u64)?;
    ply_vertices(w, p)?;
    ply_faces(w, t)
}

fn ply_header(w: &mut dyn Write, vertices: u64, faces: u64) -> std::io::Result<()> {
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment topovox remesh\nelement vertex {vertices}\nproperty double x\nproperty double y\nproperty double z\nelement face {faces}\nproperty list uchar uint vertex_indices\nend_header\n",
    )
}

fn ply_vertices(w: &mut impl Write, p: &[DVec3]) -> std::io::Result<()> {
    for v in p {
        for c in v.to_array() {
            w.write_all(&c.to_le_bytes())?;
        }
    }
    Ok(())
}

fn ply_faces(w: &mut impl Write, t: &[[u32; 3]]) -> std::io::Result<()> {
    for f in t {
        w.write_all(&[3])?;
        for i in f {
            w.write_all(&i.to_le_bytes())?;
        }
    }
    Ok(())
}

fn stl(w: &mut impl Write, p: &[DVec3], t: &[[u32; 3]]) -> std::io::Result<()> {
    stl_header(w, t.len() as u64)?;
    stl_facets(w, t, |i| p[i as usize])
}

fn stl_header(w: &mut dyn Write, triangles: u64) -> std::io::Result<()> {
    let count = u32::try_from(triangles).map_err(|_| std::io::Error::other("more triangles than STL can count (2^32 - 1)"))?;
    let mut header = [b' '; 80];
    header[..15].copy_from_slice(b"topovox remesh ");
    w.write_all(&header)?;
    w.write_all(&count.to_le_bytes())
}

fn stl_facets(w: &mut impl Write, t: &[[u32; 3]], at: impl Fn(u32) -> DVec3) -> std::io::Result<()> {
    for f in t {
        let [a, b, c] = f.map(&at);
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
    let mut bounds = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    let mut bin = Vec::with_capacity(t.len() * 12 + p.len() * 12);
    glb_indices(&mut bin, t)?;
    let positions_at = bin.len() as u64;
    glb_positions(&mut bin, p, &mut bounds)?;
    let doc = glb_json(t.len() as u64, p.len() as u64, positions_at, bin.len() as u64, bounds);
    write_glb(w, &doc, &bin, glb_too_large)
}

fn glb_too_large(total: u64) -> String {
    format!("a {total}-byte mesh cannot be a .glb file (the format ends at 4 GiB)")
}

fn glb_indices(w: &mut impl Write, t: &[[u32; 3]]) -> std::io::Result<()> {
    for i in t.iter().flatten() {
        w.write_all(&i.to_le_bytes())?;
    }
    Ok(())
}

fn glb_positions(w: &mut impl Write, p: &[DVec3], (lo, hi): &mut ([f32; 3], [f32; 3])) -> std::io::Result<()> {
    for v in p {
        for (a, x) in v.to_array().into_iter().enumerate() {
            let x = x as f32;
            (lo[a], hi[a]) = (lo[a].min(x), hi[a].max(x));
            w.write_all(&x.to_le_bytes())?;
        }
    }
    Ok(())
}

/// The glTF document of a mesh whose BIN chunk holds `triangles` × 3
/// indices, then `vertices` positions from byte `positions_at` to `total`.
fn glb_json(triangles: u64, vertices: u64, positions_at: u64, total: u64, (lo, hi): ([f32; 3], [f32; 3])) -> serde_json::Value {
    json!({
        "asset": {"version": "2.0", "generator": "topovox remesh"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "remesh"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 0, "mode": 4}]}],
        "buffers": [{"byteLength": total}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": positions_at, "target": 34963},
            {"buffer": 0, "byteOffset": positions_at, "byteLength": total - positions_at, "target": 34962},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5125, "count": triangles * 3, "type": "SCALAR"},
            {"bufferView": 1, "componentType": 5126, "count": vertices, "type": "VEC3", "min": lo, "max": hi},
        ],
    })
}

/// A mesh written part by part, as a surface is made slab by slab
/// (`topovox::surface::Part`), without holding it: each part's vertices
/// (numbered on from the previous part's) and triangles go to scratch
/// sections ([`Spool`]: memory, then files beside the output) as they come; [`PartWriter::finish`]
/// writes the header, now that the counts are known, and the sections, all
/// or nothing. The bytes are those [`write_mesh`] writes for the whole mesh,
/// except that an OBJ lists each part's vertices before its faces. A
/// part's triangles may use its own vertices and the previous part's.
pub struct PartWriter {
    path: std::path::PathBuf,
    format: MeshOut,
    /// Vertices so far.
    vertices: u64,
    /// Triangles so far.
    triangles: u64,
    /// Vertices (OBJ: the whole text; STL: the facets; GLB: the indices).
    first: Spool,
    /// PLY's faces and GLB's positions.
    second: Option<Spool>,
    /// The first vertex of the previous part.
    previous_first: u64,
    /// The previous and this part's positions (STL), from `window_first`.
    window: Vec<DVec3>,
    window_first: u64,
    /// GLB's position bounds.
    bounds: ([f32; 3], [f32; 3]),
    /// The first part, held until a second comes: a mesh made in one part
    /// is written as [`write_mesh`] writes it, without scratch sections.
    held: Option<(Vec<DVec3>, Vec<[u32; 3]>)>,
}

impl PartWriter {
    /// A writer for `path` as `format`; nothing is at `path` until
    /// [`PartWriter::finish`].
    pub fn new(path: &Path, format: MeshOut) -> PartWriter {
        PartWriter::spilling_past(path, format, Spool::SPILL)
    }

    /// The same, its sections going to files past `limit` bytes each.
    fn spilling_past(path: &Path, format: MeshOut, limit: usize) -> PartWriter {
        let first = Spool::spilling_past(path, limit);
        let second = match format {
            MeshOut::Ply | MeshOut::Glb => Some(Spool::spilling_past(path, limit)),
            MeshOut::Obj | MeshOut::Stl => None,
        };
        PartWriter {
            path: path.to_path_buf(),
            format,
            vertices: 0,
            triangles: 0,
            first,
            second,
            previous_first: 0,
            window: Vec::new(),
            window_first: 0,
            bounds: ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
            held: None,
        }
    }

    /// Adds a part: `positions` are vertices `vertices()..`, `triangles` use
    /// them and the previous part's.
    pub fn part(&mut self, positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Result<(), IoError> {
        let r = match self.held.take() {
            None if self.vertices == 0 && self.triangles == 0 => {
                let r = self.check_part(positions.len(), &triangles);
                self.held = Some((positions, triangles));
                r
            }
            None => self.write_part(&positions, &triangles),
            Some((p, t)) => self.write_part(&p, &t).and_then(|()| self.write_part(&positions, &triangles)),
        };
        r.map_err(|e| IoError::new(&self.path, crate::error::ErrorKind::Write(e)))
    }

    /// An error if a triangle of a part of `count` vertices uses a vertex
    /// outside it and the previous part.
    fn check_part(&self, count: usize, triangles: &[[u32; 3]]) -> std::io::Result<()> {
        let (lo, hi) = (self.previous_first, self.vertices() + count as u64);
        match triangles.iter().flatten().find(|&&v| !(lo..hi).contains(&(v as u64))) {
            Some(t) => Err(std::io::Error::other(format!("a part's triangle uses vertex {t}, outside this part and the previous one"))),
            None => Ok(()),
        }
    }

    fn write_part(&mut self, positions: &[DVec3], triangles: &[[u32; 3]]) -> std::io::Result<()> {
        self.check_part(positions.len(), triangles)?;
        let lo = self.previous_first;
        // Bytes this part adds to each section (OBJ: about).
        let (v, t) = (positions.len(), triangles.len());
        let (first, second) = match self.format {
            MeshOut::Obj => (v * 60 + t * 30, 0),
            MeshOut::Ply => (v * 24, t * 13),
            MeshOut::Stl => (t * 50, 0),
            MeshOut::Glb => (t * 12, v * 12),
        };
        self.first.reserve(first);
        if let Some(s) = &mut self.second {
            s.reserve(second);
        }
        let second = self.second.as_mut();
        match self.format {
            MeshOut::Obj => {
                in_chunks(&mut self.first, positions, obj_vertices)?;
                in_chunks(&mut self.first, triangles, obj_faces)?;
            }
            MeshOut::Ply => {
                in_chunks(&mut self.first, positions, ply_vertices)?;
                in_chunks(second.expect("PLY has two sections"), triangles, ply_faces)?;
            }
            MeshOut::Stl => {
                // The previous part's positions and this one's.
                self.window.drain(..(lo - self.window_first) as usize);
                self.window_first = lo;
                self.window.extend_from_slice(positions);
                let (window, first) = (&self.window, self.window_first);
                in_chunks(&mut self.first, triangles, |b, c| stl_facets(b, c, |v| window[(v as u64 - first) as usize]))?;
            }
            MeshOut::Glb => {
                in_chunks(&mut self.first, triangles, glb_indices)?;
                let bounds = &mut self.bounds;
                in_chunks(second.expect("GLB has two sections"), positions, |b, c| glb_positions(b, c, bounds))?;
            }
        }
        self.previous_first = self.vertices;
        self.vertices += positions.len() as u64;
        self.triangles += triangles.len() as u64;
        Ok(())
    }

    /// Vertices written so far.
    pub fn vertices(&self) -> u64 {
        self.vertices + self.held.as_ref().map_or(0, |h| h.0.len() as u64)
    }

    /// Triangles written so far.
    pub fn triangles(&self) -> u64 {
        self.triangles + self.held.as_ref().map_or(0, |h| h.1.len() as u64)
    }

    /// Writes the output: header, sections, all or nothing (nothing when
    /// `stop` is requested).
    pub fn finish(self, stop: Option<&Stop>) -> Result<(), IoError> {
        if let Some((p, t)) = &self.held {
            return write_mesh(&self.path, p, t, self.format, stop);
        }
        let PartWriter { path, format, vertices, triangles, first, second, bounds, .. } = self;
        write_atomically_until(&path, stop, move |w| {
            match format {
                MeshOut::Obj => {
                    writeln!(w, "# topovox remesh: {vertices} vertices, {triangles} triangles")?;
                    first.copy_into(w)?;
                }
                MeshOut::Ply => {
                    ply_header(w, vertices, triangles)?;
                    first.copy_into(w)?;
                    second.expect("PLY has two sections").copy_into(w)?;
                }
                MeshOut::Stl => {
                    stl_header(w, triangles)?;
                    first.copy_into(w)?;
                }
                MeshOut::Glb => {
                    let (positions_at, total) = (triangles * 12, triangles * 12 + vertices * 12);
                    let doc = glb_json(triangles, vertices, positions_at, total, bounds);
                    write_glb_head(w, &doc, total, glb_too_large)?;
                    first.copy_into(w)?;
                    second.expect("GLB has two sections").copy_into(w)?;
                }
            }
            Ok(())
        })
    }
}

/// Encodes `items` with `encode` into a buffer 65 536 at a time, each
/// chunk written to `w` at once: a spool then takes a few large writes, not
/// one per number.
fn in_chunks<T>(w: &mut Spool, items: &[T], mut encode: impl FnMut(&mut Vec<u8>, &[T]) -> std::io::Result<()>) -> std::io::Result<()> {
    let mut buf = Vec::new();
    for chunk in items.chunks(1 << 16) {
        buf.clear();
        encode(&mut buf, chunk)?;
        w.write_all(&buf)?;
    }
    Ok(())
}

/// Writes a binary glTF container: the 12-byte header, the JSON chunk
/// (padded with spaces to 4 bytes) and the BIN chunk (`bin` already
/// padded). A file past 4 GiB is refused with `too_large(total bytes)`.
pub(crate) fn write_glb(
    w: &mut dyn Write,
    doc: &serde_json::Value,
    bin: &[u8],
    too_large: impl FnOnce(u64) -> String,
) -> std::io::Result<()> {
    write_glb_head(w, doc, bin.len() as u64, too_large)?;
    w.write_all(bin)
}

/// [`write_glb`] up to the BIN chunk's bytes, which are `bin_len` long
/// (a multiple of 4) and follow.
fn write_glb_head(w: &mut dyn Write, doc: &serde_json::Value, bin_len: u64, too_large: impl FnOnce(u64) -> String) -> std::io::Result<()> {
    let mut text = doc.to_string().into_bytes();
    while text.len() % 4 != 0 {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() as u64 + 8 + bin_len;
    let total = u32::try_from(total).map_err(|_| std::io::Error::other(too_large(total)))?;
    w.write_all(b"glTF")?;
    w.write_all(&2u32.to_le_bytes())?;
    w.write_all(&total.to_le_bytes())?;
    w.write_all(&(text.len() as u32).to_le_bytes())?;
    w.write_all(b"JSON")?;
    w.write_all(&text)?;
    w.write_all(&(bin_len as u32).to_le_bytes())?;
    w.write_all(b"BIN\0")
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

    /// A mesh written in parts is the mesh written whole: the same bytes
    /// (OBJ in several parts: the same mesh read back), no scratch file
    /// left, and a part whose triangle reaches two parts back is refused.
    #[test]
    fn parts_make_the_same_file_as_the_whole() {
        use topovox::choice::Choice;
        let n = 40u32;
        let p: Vec<DVec3> = (0..n).map(|i| DVec3::new(i as f64 * 0.37, (i * i) as f64 / 7.0, 1.0 / (i as f64 + 1.0))).collect();
        let dir = std::env::temp_dir().join(format!("topovox-mesh-parts-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let listing = |dir: &Path| -> Vec<String> {
            let mut l: Vec<String> =
                std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
            l.sort();
            l
        };
        for cuts in [&[0u32, 7, 8, 19, 33, 40][..], &[0, 40]] {
            // Triangles whose vertices lie in their own part or the previous one.
            let mut parts: Vec<(std::ops::Range<u32>, Vec<[u32; 3]>)> = Vec::new();
            for w in cuts.windows(2) {
                let lo = parts.last().map_or(0, |(r, _)| r.start);
                let tris = (w[0]..w[1]).map(|v| [v, lo + (v * 3) % (v - lo + 1), lo.max(v.saturating_sub(2))]).collect();
                parts.push((w[0]..w[1], tris));
            }
            let t: Vec<[u32; 3]> = parts.iter().flat_map(|(_, t)| t.clone()).collect();
            // Sections held in memory, and spilled to scratch files at once.
            for (f, limit) in [MeshOut::Obj, MeshOut::Ply, MeshOut::Stl, MeshOut::Glb].into_iter().flat_map(|f| [(f, Spool::SPILL), (f, 0)])
            {
                let (whole, parted) = (dir.join(format!("whole.{}", f.name())), dir.join(format!("parts.{}", f.name())));
                write_mesh(&whole, &p, &t, f, None).unwrap();
                let before = listing(&dir).len();
                let mut w = PartWriter::spilling_past(&parted, f, limit);
                for (r, tris) in &parts {
                    w.part(p[r.start as usize..r.end as usize].to_vec(), tris.clone()).unwrap();
                }
                // One part is held and written whole: no scratch file.
                let sections = if matches!(f, MeshOut::Ply | MeshOut::Glb) { 2 } else { 1 };
                let scratch = if limit == 0 && parts.len() > 1 { sections } else { 0 };
                assert_eq!(listing(&dir).len(), before + scratch, "{f:?} in {} parts, spilling past {limit}", parts.len());
                assert_eq!((w.vertices(), w.triangles()), (n as u64, t.len() as u64));
                w.finish(None).unwrap();
                if f == MeshOut::Obj && parts.len() > 1 {
                    let read = |q: &Path| crate::read_mesh(q, &crate::ReadOptions::default()).unwrap().mesh;
                    let (a, b) = (read(&whole), read(&parted));
                    assert_eq!((a.positions, a.triangles), (b.positions, b.triangles));
                } else {
                    assert_eq!(std::fs::read(&whole).unwrap(), std::fs::read(&parted).unwrap(), "{f:?} in {} parts", parts.len());
                }
            }
        }
        for f in [MeshOut::Obj, MeshOut::Ply, MeshOut::Stl, MeshOut::Glb] {
            let mut w = PartWriter::new(&dir.join("bad.ply"), f);
            w.part(p[..4].to_vec(), vec![[0, 1, 2]]).unwrap();
            w.part(p[4..8].to_vec(), vec![[4, 5, 6]]).unwrap();
            let e = w.part(p[8..12].to_vec(), vec![[8, 9, 3]]).unwrap_err().to_string();
            assert!(e.contains("vertex 3") && e.contains("bad.ply"), "{e}");
            let e = PartWriter::new(&dir.join("bad.ply"), f).part(p[..4].to_vec(), vec![[0, 1, 4]]).unwrap_err().to_string();
            assert!(e.contains("vertex 4"), "{e}");
        }
        let left = listing(&dir);
        assert_eq!(left.len(), 8, "only the outputs are left: {left:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
