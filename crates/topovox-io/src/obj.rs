//! Wavefront OBJ geometry, parsed in parallel; material libraries through
//! the `tobj` crate.
//!
//! No crate parses OBJ in parallel, and at dataset sizes reading the file
//! took longer than voxelizing it (124 k triangles: about 100 ms through
//! tobj, which parses serially and deduplicates vertex/texcoord pairs in a
//! hash map we do not need). So the geometry records are read here:
//! the file is cut into chunks at line ends; a first parallel pass counts
//! each chunk's `v` and `vt` records and lines, so relative (negative)
//! indices and line numbers resolve in a second parallel pass that parses
//! each chunk on its own; `usemtl` state crossing chunk borders is resolved
//! in order afterwards. Results do not depend on the thread count.
//!
//! Records read: `v x y z [w]` and `v x y z r g b` (vertex colours, sRGB
//! in `[0, 1]`), `vt u [v]`, `f` (any number of corners, `v`, `v/vt`,
//! `v//vn`, `v/vt/vn`, negative indices relative to the records read so
//! far; polygons are fan-triangulated), `l` (polylines become `n − 1`
//! segments), `usemtl`, `mtllib`. Others (`vn`, `o`, `g`, `s`, `p`, curves)
//! are skipped; `#` starts a comment anywhere. Coordinates are parsed as
//! `f64`. A missing or broken material library is a warning, not an
//! error: geometry does not need it.

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;
use rayon::prelude::*;

use crate::error::{quoted, ErrorKind};
use crate::resources::Resources;
use topovox::attributes::{Appearance, Material, DEFAULT_ROUGHNESS, NO_MATERIAL};

use crate::mesh_report::{finish_with_segments, LoadedMesh};

/// Chunks are at least this long (bytes): smaller files parse in one piece.
const MIN_CHUNK: usize = 1 << 18;

/// A triangle's material before `usemtl` names are resolved: an index into
/// its chunk's names, `NONE` before any `usemtl`, or `INHERIT` for "the
/// material in force where the chunk begins".
const NONE: u32 = u32::MAX;
const INHERIT: u32 = u32::MAX - 1;

/// What one chunk of lines holds.
#[derive(Default)]
struct Chunk {
    positions: Vec<DVec3>,
    /// Per position: `Some` where the `v` record carried a colour.
    colours: Vec<Option<[u8; 3]>>,
    texcoords: Vec<[f32; 2]>,
    triangles: Vec<[i64; 3]>,
    /// Per triangle corner: the global `vt` index, or −1.
    triangle_vt: Vec<[i64; 3]>,
    triangle_material: Vec<u32>,
    segments: Vec<[i64; 2]>,
    /// `usemtl` names in this chunk, in order of first use.
    material_names: Vec<String>,
    /// The last `usemtl` of the chunk (index into `material_names`), if any.
    last_material: Option<u32>,
    mtllibs: Vec<String>,
}

/// Counts of one chunk, for the global indices of the next ones.
#[derive(Clone, Copy, Default)]
struct Counts {
    v: i64,
    vt: i64,
    /// `f` records (a lower bound on the triangles: one each).
    f: usize,
    /// `mtllib` records: without any, no triangle's texture coordinates or
    /// material is kept, so none is recorded.
    mtllib: usize,
    lines: usize,
}

/// Parses OBJ bytes; `res` resolves `mtllib` and `map_Kd` files.
pub(crate) fn read(bytes: &[u8], res: &Resources) -> Result<LoadedMesh, ErrorKind> {
    let chunks = split_at_lines(bytes, rayon::current_num_threads() * 4);
    let counts: Vec<Counts> = chunks.par_iter().map(|c| count(c)).collect();
    let mut before = Vec::with_capacity(chunks.len());
    let mut total = Counts::default();
    for c in &counts {
        before.push(total);
        total.v += c.v;
        total.vt += c.vt;
        total.lines += c.lines;
        total.mtllib += c.mtllib;
    }
    // Per-triangle texture coordinates and materials serve only materials,
    // which come from material libraries resolved next to the file.
    let appearance = total.mtllib > 0 && res.base().is_some();
    let parsed: Vec<Chunk> =
        chunks.par_iter().zip(&before).zip(&counts).map(|((c, b), own)| parse_chunk(c, *b, own, appearance)).collect::<Result<_, _>>()?;

    let mut warnings = Vec::new();
    let materials = material_libraries(&parsed, res, &mut warnings);
    let by_name: HashMap<&str, u32> = materials.iter().enumerate().rev().map(|(i, m)| (m.name.as_str(), i as u32)).collect();

    let (nv, nt) = (total.v as usize, parsed.iter().map(|c| c.triangles.len()).sum::<usize>());
    let mut positions = Vec::with_capacity(nv);
    let mut colours = Vec::new();
    let mut texcoords = Vec::with_capacity(total.vt as usize);
    let mut triangles = Vec::with_capacity(nt);
    let per_triangle = if appearance { nt } else { 0 };
    let mut tri_vt = Vec::with_capacity(per_triangle);
    let mut tri_material = Vec::with_capacity(per_triangle);
    let mut segments = Vec::new();
    let any_colour = parsed.iter().any(|c| c.colours.iter().any(Option::is_some));
    let mut current = NO_MATERIAL;
    for c in parsed {
        let resolve = |m: u32, current: u32| match m {
            NONE => NO_MATERIAL,
            INHERIT => current,
            m => by_name.get(c.material_names[m as usize].as_str()).copied().unwrap_or(NO_MATERIAL),
        };
        tri_material.extend(c.triangle_material.iter().map(|&m| resolve(m, current)));
        if let Some(m) = c.last_material {
            current = resolve(m, current);
        }
        positions.extend(c.positions);
        if any_colour {
            colours.extend(c.colours.iter().map(|c| c.unwrap_or([255; 3])));
        }
        texcoords.extend(c.texcoords);
        triangles.extend(c.triangles);
        tri_vt.extend(c.triangle_vt);
        segments.extend(c.segments);
    }

    let mut app = Appearance::default();
    if res.base().is_some() {
        add_materials(&materials, res, &mut app, &mut warnings);
    }
    if !app.materials.is_empty() {
        // OBJ puts v = 0 at the bottom of the image; topovox's textures at the top.
        let uv = |t: i64| match usize::try_from(t).ok().and_then(|t| texcoords.get(t)) {
            Some(c) => [c[0], 1.0 - c[1]],
            None => [f32::NAN; 2],
        };
        app.triangle_uv = tri_vt.iter().map(|c| c.map(uv)).collect();
        app.triangle_material = tri_material;
    }
    if any_colour {
        app.vertex_colour = colours;
    }
    let mut loaded = finish_with_segments(positions, triangles, segments, warnings)?;
    loaded.appearance = app;
    Ok(loaded)
}

/// The materials of the libraries the chunks name (`mtllib`), in order of
/// first mention; a library that cannot be read is a warning.
fn material_libraries(parsed: &[Chunk], res: &Resources, warnings: &mut Vec<String>) -> Vec<tobj::Material> {
    // Material libraries, in order of first mention.
    let mut libs: Vec<&str> = Vec::new();
    for lib in parsed.iter().flat_map(|c| &c.mtllibs) {
        if !libs.contains(&lib.as_str()) {
            libs.push(lib);
        }
    }
    let mut materials: Vec<tobj::Material> = Vec::new();
    for lib in libs {
        if res.base().is_none() {
            continue;
        }
        match res.read(Path::new(lib), None) {
            Ok(bytes) => match tobj::load_mtl_buf(&mut &bytes[..]) {
                Ok((mats, _)) => materials.extend(mats),
                Err(_) => warnings.push(format!("material library {lib} could not be read; materials ignored")),
            },
            Err(why) => warnings.push(format!("material library {why}; materials ignored")),
        }
    }
    materials
}

/// A texture a material names, read through `res` (the folder rule,
/// regular files only) and decoded.
fn read_texture(res: &Resources, reference: &Path, wrap: [topovox::attributes::Wrap; 2]) -> Result<topovox::attributes::Texture, String> {
    res.read(reference, None).and_then(|bytes| crate::texture::decode(&bytes, &reference.display().to_string(), wrap))
}

/// `materials` as topovox's (colours, textures, cut-out masks, emission,
/// roughness) into `app`; a texture that cannot be read is a warning.
fn add_materials(materials: &[tobj::Material], res: &Resources, app: &mut Appearance, warnings: &mut Vec<String>) {
    for (index, mat) in materials.iter().enumerate() {
        let factor = mat.diffuse.unwrap_or([1.0; 3]);
        let texture = mat.diffuse_texture.as_deref().filter(|t| !t.trim().is_empty()).and_then(|statement| {
            let (reference, wrap) = crate::texture::parse_map_statement(statement);
            match read_texture(res, &reference, wrap) {
                Ok(t) => {
                    app.textures.push(t);
                    Some(app.textures.len() as u32 - 1)
                }
                Err(e) => {
                    warnings.push(format!("material {:?}: {e}; its Kd colour is used instead", mat.name));
                    None
                }
            }
        });
        let name = if mat.name.is_empty() { format!("material {index}") } else { mat.name.clone() };
        // map_d: a cut-out mask (its alpha channel, or for an opaque
        // image its red channel: masks are usually grey), moved into
        // the alpha channel of its own texture.
        let alpha_texture = mat.dissolve_texture.as_deref().filter(|t| !t.trim().is_empty()).and_then(|statement| {
            let (reference, wrap) = crate::texture::parse_map_statement(statement);
            match read_texture(res, &reference, wrap) {
                Ok(mut t) => {
                    if t.rgba.chunks_exact(4).all(|p| p[3] == 255) {
                        t.rgba.chunks_exact_mut(4).for_each(|p| p[3] = p[0]);
                    }
                    app.textures.push(t);
                    Some(app.textures.len() as u32 - 1)
                }
                Err(e) => {
                    warnings.push(format!("material {name:?}: map_d {e}; the material is drawn opaque"));
                    None
                }
            }
        });
        let see_through = texture.is_some_and(|t| app.textures[t as usize].rgba.chunks_exact(4).any(|p| p[3] < 255));
        let alpha_cutoff = (alpha_texture.is_some() || see_through).then_some(0.5);
        app.materials.push(Material {
            name,
            factor,
            texture,
            emission: obj_emission(mat),
            roughness: obj_roughness(mat),
            alpha_cutoff,
            alpha_texture,
        });
    }
}

/// Cuts `bytes` into about `pieces` chunks (none shorter than
/// [`MIN_CHUNK`]), each ending just after a line end (or at the end).
fn split_at_lines(bytes: &[u8], pieces: usize) -> Vec<&[u8]> {
    let size = (bytes.len() / pieces.max(1)).max(MIN_CHUNK);
    let mut out = Vec::new();
    let mut start = 0;
    while start < bytes.len() {
        let mut end = (start + size).min(bytes.len());
        while end < bytes.len() && bytes[end - 1] != b'\n' {
            end += 1;
        }
        out.push(&bytes[start..end]);
        start = end;
    }
    out
}

/// The record keyword of a line, and the rest.
fn keyword(line: &[u8]) -> (&[u8], &[u8]) {
    let line = line.trim_ascii_start();
    let end = line.iter().position(|b| b.is_ascii_whitespace()).unwrap_or(line.len());
    (&line[..end], &line[end..])
}

fn count(chunk: &[u8]) -> Counts {
    let mut c = Counts::default();
    for line in lines(chunk) {
        c.lines += 1;
        match keyword(line).0 {
            b"v" => c.v += 1,
            b"vt" => c.vt += 1,
            b"f" => c.f += 1,
            b"mtllib" => c.mtllib += 1,
            _ => {}
        }
    }
    // `split` yields an empty piece after a final line end.
    if chunk.last() == Some(&b'\n') {
        c.lines -= 1;
    }
    c
}

/// The pieces of `chunk` between line ends, as `split(|&b| b == b'\n')`
/// gives them (an empty last piece after a final line end), found by
/// `memchr`.
fn lines(chunk: &[u8]) -> Lines<'_> {
    Lines { rest: Some(chunk) }
}

/// Iterator of [`lines`].
struct Lines<'a> {
    rest: Option<&'a [u8]>,
}

impl<'a> Iterator for Lines<'a> {
    type Item = &'a [u8];

    #[inline]
    fn next(&mut self) -> Option<&'a [u8]> {
        let r = self.rest?;
        match memchr::memchr(b'\n', r) {
            Some(i) => {
                self.rest = Some(&r[i + 1..]);
                Some(&r[..i])
            }
            None => {
                self.rest = None;
                Some(r)
            }
        }
    }
}

/// The whitespace-separated words of a line's rest, up to a `#` comment.
fn words(rest: &[u8]) -> Words<'_> {
    Words { rest }
}

/// Iterator of [`words`]: one pass over the bytes, no closure per byte.
struct Words<'a> {
    rest: &'a [u8],
}

impl<'a> Iterator for Words<'a> {
    type Item = &'a [u8];

    #[inline]
    fn next(&mut self) -> Option<&'a [u8]> {
        let s = self.rest;
        let mut i = 0;
        while i < s.len() && s[i].is_ascii_whitespace() {
            i += 1;
        }
        if i == s.len() || s[i] == b'#' {
            self.rest = &[];
            return None;
        }
        let mut j = i;
        while j < s.len() && !s[j].is_ascii_whitespace() && s[j] != b'#' {
            j += 1;
        }
        self.rest = &s[j..];
        Some(&s[i..j])
    }
}

fn number(w: &[u8]) -> Option<f64> {
    // A number is ASCII; checking that is cheaper than UTF-8 validation.
    if !w.is_ascii() {
        return None;
    }
    std::str::from_utf8(w).ok()?.parse().ok()
}

/// A decimal integer with an optional sign (as `i64::from_str` reads it),
/// parsed straight from the bytes: face indices are most of an OBJ file.
fn index(w: &[u8]) -> Option<i64> {
    let (neg, digits) = match w.first()? {
        b'-' => (true, &w[1..]),
        b'+' => (false, &w[1..]),
        _ => (false, w),
    };
    if digits.is_empty() {
        return None;
    }
    let mut x: u64 = 0;
    for &b in digits {
        let d = b.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        x = x.checked_mul(10)?.checked_add(d as u64)?;
    }
    match neg {
        true if x <= 1 << 63 => Some((x as i64).wrapping_neg()),
        true => None,
        false => i64::try_from(x).ok(),
    }
}

/// Parses one chunk; `before` counts the records of the chunks before it,
/// `own` this chunk's (its vectors are allocated once at their size).
/// Triangles' texture coordinates and materials are recorded only with
/// `appearance`.
fn parse_chunk(chunk: &[u8], before: Counts, own: &Counts, appearance: bool) -> Result<Chunk, ErrorKind> {
    let per_triangle = if appearance { own.f } else { 0 };
    let mut out = Chunk {
        positions: Vec::with_capacity(own.v as usize),
        colours: Vec::with_capacity(own.v as usize),
        texcoords: Vec::with_capacity(own.vt as usize),
        triangles: Vec::with_capacity(own.f),
        triangle_vt: Vec::with_capacity(per_triangle),
        triangle_material: Vec::with_capacity(per_triangle),
        ..Chunk::default()
    };
    let mut material = INHERIT;
    let mut poly: Vec<(i64, i64)> = Vec::new();
    let bad = |line: usize, what: String| ErrorKind::malformed("OBJ", format!("line {}: {what}", before.lines + line + 1));
    for (n, line) in lines(chunk).enumerate() {
        let (key, rest) = keyword(line);
        match key {
            b"v" => {
                let (p, colour) = vertex(rest).map_err(|w| bad(n, w))?;
                out.positions.push(p);
                out.colours.push(colour);
            }
            b"vt" => {
                let mut c = [0.0f32; 2];
                for (k, w) in words(rest).take(2).enumerate() {
                    c[k] = number(w).ok_or_else(|| bad(n, format!("bad number {} in 'vt'", quoted(&String::from_utf8_lossy(w)))))? as f32;
                }
                out.texcoords.push(c);
            }
            b"f" | b"l" => {
                let counts = (before.v + out.positions.len() as i64, before.vt + out.texcoords.len() as i64);
                polygon(rest, counts, &mut poly).map_err(|w| bad(n, w))?;
                if key == b"f" {
                    if poly.len() < 3 {
                        return Err(bad(n, "a face needs at least 3 vertices".into()));
                    }
                    for w in 1..poly.len() - 1 {
                        let c = [poly[0], poly[w], poly[w + 1]];
                        out.triangles.push(c.map(|p| p.0));
                        if appearance {
                            out.triangle_vt.push(c.map(|p| p.1));
                            out.triangle_material.push(material);
                        }
                    }
                } else {
                    if poly.len() < 2 {
                        return Err(bad(n, "'l' needs at least two vertices".into()));
                    }
                    out.segments.extend(poly.windows(2).map(|w| [w[0].0, w[1].0]));
                }
            }
            b"usemtl" => {
                let name = String::from_utf8_lossy(rest.trim_ascii()).into_owned();
                let i = match out.material_names.iter().position(|m| *m == name) {
                    Some(i) => i,
                    None => {
                        out.material_names.push(name);
                        out.material_names.len() - 1
                    }
                } as u32;
                material = i;
                out.last_material = Some(i);
            }
            b"mtllib" => {
                // Names may contain spaces only when the file is the whole rest.
                let name = String::from_utf8_lossy(rest.trim_ascii()).into_owned();
                if !name.is_empty() {
                    out.mtllibs.push(name);
                }
            }
            _ => {}
        }
    }
    // Triangles before the chunk's first `usemtl` take the material in
    // force where it begins; a chunk that starts the file has none.
    if before.lines == 0 {
        for m in &mut out.triangle_material {
            if *m == INHERIT {
                *m = NONE;
            }
        }
    }
    Ok(out)
}

/// A `v` line's rest: the position, and the colour when it has six numbers.
fn vertex(rest: &[u8]) -> Result<(DVec3, Option<[u8; 3]>), String> {
    let mut c = [0.0f64; 7];
    let mut k = 0;
    for w in words(rest) {
        if k == 7 {
            return Err("a vertex with more than 7 numbers".into());
        }
        c[k] = number(w).ok_or_else(|| format!("bad number {} in 'v'", quoted(&String::from_utf8_lossy(w))))?;
        k += 1;
    }
    if k < 3 {
        return Err("a vertex needs 3 coordinates".into());
    }
    Ok((DVec3::new(c[0], c[1], c[2]), (k == 6).then(|| [3, 4, 5].map(|a| (c[a].clamp(0.0, 1.0) * 255.0).round() as u8))))
}

/// An `f` or `l` line's rest into `poly`: 0-based vertex and texture
/// indices (texture −1 when absent); negative indices count back from the
/// `(vertices, texture coordinates)` read so far.
fn polygon(rest: &[u8], (nv, nvt): (i64, i64), poly: &mut Vec<(i64, i64)>) -> Result<(), String> {
    poly.clear();
    for w in words(rest) {
        let mut parts = w.split(|&b| b == b'/');
        let vi = parts.next().and_then(index).ok_or_else(|| format!("bad vertex index {}", quoted(&String::from_utf8_lossy(w))))?;
        let vt = match parts.next() {
            Some(t) if !t.is_empty() => index(t).ok_or_else(|| format!("bad texture index {}", quoted(&String::from_utf8_lossy(w))))?,
            _ => 0,
        };
        let resolve = |i: i64, count: i64, what: &str| match i {
            0 => Err(format!("{what} index 0 (OBJ indices start at 1)")),
            i if i > 0 => Ok(i - 1),
            i => Ok(count + i),
        };
        let v = resolve(vi, nv, "vertex")?;
        let t = if vt == 0 { -1 } else { resolve(vt, nvt, "texture")? };
        poly.push((v, t));
    }
    Ok(())
}

/// A material's `Ke` (emitted colour), non-negative; zero when absent or not finite.
fn obj_emission(mat: &tobj::Material) -> [f32; 3] {
    mat.emissive.unwrap_or([0.0; 3]).map(|e| if e.is_finite() { e.max(0.0) } else { 0.0 })
}

/// A material's roughness: `Pr` (PBR extension) if given, else from the
/// Phong exponent `Ns` by `r = sqrt(2 / (Ns + 2))`, else the default.
fn obj_roughness(mat: &tobj::Material) -> f32 {
    let pr = mat.unknown_param.get("Pr").and_then(|v| v.trim().parse::<f32>().ok()).filter(|v| v.is_finite());
    match (pr, mat.shininess.filter(|s| s.is_finite() && *s >= 0.0)) {
        (Some(r), _) => r.clamp(0.0, 1.0),
        (None, Some(ns)) => (2.0 / (ns + 2.0)).sqrt(),
        _ => DEFAULT_ROUGHNESS,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_split_at_line_ends_and_cover_everything() {
        let text: Vec<u8> = (0..100_000).flat_map(|i| format!("v {i} 0 0\n").into_bytes()).collect();
        let chunks = split_at_lines(&text, 7);
        assert!(chunks.len() > 1);
        assert_eq!(chunks.iter().map(|c| c.len()).sum::<usize>(), text.len());
        assert!(chunks.iter().all(|c| c.last() == Some(&b'\n')));
    }

    #[test]
    fn materials_and_relative_indices_cross_chunk_borders() {
        // Enough lines for several chunks; usemtl in the first chunk only.
        let mut text = String::from("usemtl red\n");
        for i in 0..60_000 {
            text += &format!("v {i} 0 0\nv {i} 1 0\nv {i} 0 1\nf -3 -2 -1\n");
        }
        text += "usemtl blue\nf 1 2 3\n";
        let chunks = split_at_lines(text.as_bytes(), 8);
        assert!(chunks.len() > 2, "{}", chunks.len());
        let m = read(text.as_bytes(), &Resources::new(None, &Default::default())).unwrap();
        assert_eq!(m.mesh.triangles.len(), 60_001);
        assert_eq!(m.mesh.triangles[59_999], [179_997, 179_998, 179_999]);
        assert_eq!(m.mesh.triangles[60_000], [0, 1, 2]);
    }

    #[test]
    fn map_d_and_transparent_textures_set_an_alpha_cutoff() {
        let dir = std::env::temp_dir().join(format!("topovox-obj-alpha-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // A grey mask (opaque PNG: its red channel becomes the alpha), a
        // colour texture with a transparent texel, and an opaque one.
        image::GrayImage::from_raw(2, 1, vec![0, 200]).unwrap().save(dir.join("mask.png")).unwrap();
        image::RgbaImage::from_raw(2, 1, vec![9, 9, 9, 255, 9, 9, 9, 0]).unwrap().save(dir.join("leaf.png")).unwrap();
        image::RgbaImage::from_raw(1, 1, vec![9, 9, 9, 255]).unwrap().save(dir.join("solid.png")).unwrap();
        std::fs::write(
            dir.join("m.mtl"),
            "newmtl masked\nKd 1 1 1\nmap_Kd solid.png\nmap_d mask.png\nnewmtl leaf\nmap_Kd leaf.png\nnewmtl solid\nmap_Kd solid.png\nnewmtl plain\n",
        )
        .unwrap();
        let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl masked\nf 1/1 2/1 3/1\nusemtl leaf\nf 1/1 2/1 3/1\nusemtl solid\nf 1/1 2/1 3/1\nusemtl plain\nf 1 2 3\n";
        let m = read(obj.as_bytes(), &Resources::new(Some(&dir), &Default::default())).unwrap();
        let (mats, tex) = (&m.appearance.materials, &m.appearance.textures);
        assert_eq!(mats[0].alpha_cutoff, Some(0.5));
        let mask = &tex[mats[0].alpha_texture.unwrap() as usize];
        assert_eq!([mask.rgba[3], mask.rgba[7]], [0, 200], "the grey mask's value is its alpha");
        assert_eq!((mats[1].alpha_cutoff, mats[1].alpha_texture), (Some(0.5), None), "transparent texels in map_Kd");
        assert_eq!((mats[2].alpha_cutoff, mats[2].alpha_texture), (None, None));
        assert_eq!((mats[3].alpha_cutoff, mats[3].alpha_texture), (None, None));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn emission_and_roughness_come_from_the_mtl() {
        let dir = std::env::temp_dir().join(format!("topovox-obj-mtl-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("m.mtl"), "newmtl lamp\nKd 1 1 1\nKe 4 2 0\nNs 48\nnewmtl pbr\nPr 0.25\nKe nan 1 -3\nnewmtl plain\n")
            .unwrap();
        let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl lamp\nf 1 2 3\nusemtl pbr\nf 1 2 3\nusemtl plain\nf 1 2 3\n";
        let m = read(obj.as_bytes(), &Resources::new(Some(&dir), &Default::default())).unwrap();
        let mats = &m.appearance.materials;
        assert_eq!(mats.len(), 3);
        assert_eq!(mats[0].emission, [4.0, 2.0, 0.0]);
        assert!((mats[0].roughness - 0.2).abs() < 1e-6, "Ns 48: sqrt(2 / 50)");
        assert_eq!(mats[1].roughness, 0.25);
        assert!(mats[1].emission.iter().all(|e| e.is_finite() && *e >= 0.0));
        assert_eq!(mats[2].emission, [0.0; 3]);
        assert_eq!(mats[2].roughness, DEFAULT_ROUGHNESS);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn lines_split_as_slice_split_does() {
        for t in ["", "\n", "a", "a\n", "a\nb", "\n\na\r\n\nb\n"] {
            let want: Vec<&[u8]> = t.as_bytes().split(|&b| b == b'\n').collect();
            assert_eq!(lines(t.as_bytes()).collect::<Vec<_>>(), want, "{t:?}");
        }
    }

    #[test]
    fn words_and_numbers_read_as_the_standard_parsers_do() {
        let w: Vec<&[u8]> = words(b"  1/2/3\t-4 +5#comment 6").collect();
        assert_eq!(w, [&b"1/2/3"[..], b"-4", b"+5"]);
        assert_eq!(words(b"# only a comment").count(), 0);
        assert_eq!(words(b"a#b c").collect::<Vec<_>>(), [&b"a"[..]]);
        assert_eq!(words(b"").count(), 0);
        let edges = ["", " 1", "١", "9223372036854775807", "9223372036854775808", "-9223372036854775808", "-9223372036854775809"];
        for t in "0 7 -12 +3 007 - + 1x x1 --1 1.5".split(' ').chain(edges) {
            assert_eq!(index(t.as_bytes()), t.parse::<i64>().ok(), "{t:?}");
        }
        for t in ["1", "-0.5", "1e3", "inf", "NaN", "1.5.2", "", "é"] {
            assert_eq!(number(t.as_bytes()).map(f64::to_bits), t.parse::<f64>().ok().map(f64::to_bits), "{t:?}");
        }
    }

    #[test]
    fn errors_name_the_line() {
        let e = read(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", &Resources::new(None, &Default::default())).unwrap_err().to_string();
        assert!(e.contains("line 4"), "{e}");
        let e = read(b"v 0 0 0\nf 0 1 2\n", &Resources::new(None, &Default::default())).unwrap_err().to_string();
        assert!(e.contains("index 0"), "{e}");
    }
}
