//! Wavefront OBJ, through the `tobj` crate.
//!
//! Polygons with more than three vertices are fan-triangulated; negative
//! (relative) indices are resolved by tobj. A missing or broken material
//! library is a warning, not an error: geometry does not need it.
//!
//! Polylines (`l v1 v2 … vn`) become `n − 1` segments. tobj reads an `l`
//! record with three vertices as a triangle, so `l` records are read here
//! (vertex indices only; `v/vt` forms accepted, negative indices relative
//! to the vertices read so far) and blanked out before tobj sees the file.

use std::io::{BufReader, Cursor};
use std::path::Path;
use std::sync::Mutex;

use glam::DVec3;

use crate::error::ErrorKind;
use voxkit::attributes::{Appearance, Material, NO_MATERIAL};

use crate::mesh_report::{finish_with_segments, LoadedMesh};

/// Parses OBJ bytes; `base_dir` is where `mtllib` files are looked up.
pub fn read(bytes: &[u8], base_dir: Option<&Path>) -> Result<LoadedMesh, ErrorKind> {
    let (blanked, line_positions, line_segments) = split_polylines(bytes)?;
    let bytes: &[u8] = blanked.as_deref().unwrap_or(bytes);
    let warnings = Mutex::new(Vec::<String>::new());
    let opts = tobj::LoadOptions { triangulate: false, single_index: false, ignore_points: true, ignore_lines: true };
    let mut reader = BufReader::new(Cursor::new(bytes));
    let loaded = tobj::load_obj_buf(&mut reader, &opts, |mtl: &Path| {
        let Some(dir) = base_dir else {
            return Err(tobj::LoadError::OpenFileFailed);
        };
        let full = dir.join(mtl);
        let r = tobj::load_mtl(&full);
        if r.is_err() {
            if let Ok(mut w) = warnings.lock() {
                w.push(format!("material library {} could not be read; materials ignored", full.display()));
            }
        }
        r
    });
    let (models, materials) = loaded.map_err(|e| ErrorKind::malformed("OBJ", e))?;
    let mut warnings = warnings.into_inner().unwrap_or_default();
    if let Err(e) = &materials {
        if warnings.is_empty() && !matches!(e, tobj::LoadError::GenericFailure) {
            warnings.push(format!("materials ignored: {e}"));
        }
    }
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut app = Appearance::default();
    let mut tri_material = Vec::new();
    let mut tri_uv = Vec::new();
    let mut vertex_colour = Vec::new();
    for m in &models {
        let mesh = &m.mesh;
        let base = positions.len() as i64;
        if mesh.positions.len() % 3 != 0 {
            return Err(ErrorKind::malformed("OBJ", "vertex position with fewer than 3 coordinates"));
        }
        positions.extend(mesh.positions.chunks_exact(3).map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)));
        // `v x y z r g b`: tobj keeps colours per position (sRGB in [0, 1]).
        if mesh.vertex_color.len() == mesh.positions.len() {
            vertex_colour.resize(base as usize, [255u8; 3]);
            vertex_colour
                .extend(mesh.vertex_color.chunks_exact(3).map(|c| [0, 1, 2].map(|a| (c[a].clamp(0.0, 1.0) * 255.0).round() as u8)));
        }
        let material = m.mesh.material_id.map(|i| i as u32).unwrap_or(NO_MATERIAL);
        let has_uv = mesh.texcoord_indices.len() == mesh.indices.len() && !mesh.texcoords.is_empty();
        // OBJ puts v = 0 at the bottom of the image; voxkit's textures at the top.
        let uv_of = |corner: usize| -> [f32; 2] {
            if !has_uv {
                return [f32::NAN; 2];
            }
            let t = mesh.texcoord_indices[corner] as usize;
            match mesh.texcoords.get(2 * t..2 * t + 2) {
                Some(c) => [c[0], 1.0 - c[1]],
                None => [f32::NAN; 2],
            }
        };
        let arities: Vec<usize> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.iter().map(|&n| n as usize).collect()
        };
        let mut at = 0usize;
        for n in arities {
            if at + n > mesh.indices.len() {
                return Err(ErrorKind::malformed("OBJ", "face arity past the index list"));
            }
            for w in 1..n.saturating_sub(1) {
                let corners = [at, at + w, at + w + 1];
                triangles.push(corners.map(|c| base + mesh.indices[c] as i64));
                tri_material.push(material);
                tri_uv.push(corners.map(uv_of));
            }
            at += n;
        }
    }
    if let (Ok(mats), Some(dir)) = (&materials, base_dir) {
        for (index, mat) in mats.iter().enumerate() {
            let factor = mat.diffuse.unwrap_or([1.0; 3]);
            let texture = mat.diffuse_texture.as_deref().filter(|t| !t.trim().is_empty()).and_then(|statement| {
                let (path, wrap) = crate::texture::parse_map_statement(statement, dir);
                match crate::texture::load(&path, wrap) {
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
            app.materials.push(Material { name, factor, texture });
        }
    }
    if !app.materials.is_empty() {
        app.triangle_material = tri_material;
        app.triangle_uv = tri_uv;
    }
    if !vertex_colour.is_empty() {
        vertex_colour.resize(positions.len(), [255; 3]);
        app.vertex_colour = vertex_colour;
    }
    let base = positions.len() as i64;
    positions.extend(line_positions);
    if !app.vertex_colour.is_empty() {
        app.vertex_colour.resize(positions.len(), [255; 3]);
    }
    let segments = line_segments.into_iter().map(|[a, b]| [base + a, base + b]).collect();
    let mut loaded = finish_with_segments(positions, triangles, segments, warnings)?;
    loaded.appearance = app;
    Ok(loaded)
}

/// Reads the `v` and `l` records. Returns the bytes with `l` records
/// blanked (None if there are none), the vertex positions, and the segments
/// as 0-based indices into them.
#[allow(clippy::type_complexity)]
fn split_polylines(bytes: &[u8]) -> Result<(Option<Vec<u8>>, Vec<DVec3>, Vec<[i64; 2]>), ErrorKind> {
    let is_l = |line: &[u8]| line.first() == Some(&b'l') && line.get(1).is_some_and(|c| c.is_ascii_whitespace());
    if !bytes.split(|&b| b == b'\n').any(|l| is_l(l.trim_ascii_start())) {
        return Ok((None, Vec::new(), Vec::new()));
    }
    let mut out = bytes.to_vec();
    let mut positions = Vec::new();
    let mut segments = Vec::new();
    let mut at = 0usize;
    for (number, raw) in bytes.split(|&b| b == b'\n').enumerate() {
        let start = at;
        at += raw.len() + 1;
        let line = raw.trim_ascii_start();
        let text = String::from_utf8_lossy(line);
        let mut words = text.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f64> = words.take(3).map_while(|w| w.parse().ok()).collect();
                // Malformed vertices are tobj's to report; keep numbering aligned.
                positions.push(if c.len() == 3 { DVec3::new(c[0], c[1], c[2]) } else { DVec3::NAN });
            }
            Some("l") => {
                let mut poly = Vec::new();
                for w in words {
                    let first = w.split('/').next().unwrap_or("");
                    let i: i64 = first
                        .parse()
                        .map_err(|_| ErrorKind::malformed("OBJ", format!("line {}: bad vertex index {w:?} in 'l'", number + 1)))?;
                    let resolved = match i {
                        0 => return Err(ErrorKind::malformed("OBJ", format!("line {}: vertex index 0 in 'l'", number + 1))),
                        i if i > 0 => i - 1,
                        i => positions.len() as i64 + i,
                    };
                    poly.push(resolved);
                }
                if poly.len() < 2 {
                    return Err(ErrorKind::malformed("OBJ", format!("line {}: 'l' needs at least two vertices", number + 1)));
                }
                segments.extend(poly.windows(2).map(|w| [w[0], w[1]]));
                out[start..start + raw.len()].iter_mut().for_each(|b| *b = b' ');
            }
            _ => {}
        }
    }
    Ok((Some(out), positions, segments))
}
