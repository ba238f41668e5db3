//! A mesh of the voxels — the greedy quads of [`voxkit::export::greedy`] —
//! as Wavefront OBJ or binary glTF (`.glb`).
//!
//! Colours: a quad's `class` is `1 + palette index` (0: uncoloured). OBJ
//! writes one material per palette colour (`Kd`, in a `.mtl` beside the
//! `.obj`) and groups faces with `usemtl`; GLB writes a per-vertex
//! `COLOR_0` (linear, as glTF requires) under one white material.

use std::collections::HashMap;
use std::path::Path;

use serde_json::json;
use voxkit::attributes::colour::to_linear;
use voxkit::export::greedy::Quad;
use voxkit::GridSpec;

use crate::atomic::write_atomically;
use crate::error::IoError;

/// Writes `quads` on `grid` (world coordinates) as an OBJ of quad faces,
/// counter-clockwise seen from outside, corners shared; with a `palette`,
/// also `<name>.mtl` with one material per colour. Returns the number of vertices.
pub fn write_quads_obj(path: &Path, quads: &[Quad], grid: &GridSpec, palette: Option<&[[u8; 3]]>) -> Result<usize, IoError> {
    let mut index: HashMap<[u32; 3], u32> = HashMap::with_capacity(quads.len() * 2);
    let mut order: Vec<[u32; 3]> = Vec::with_capacity(quads.len() * 2);
    let mut sorted: Vec<&Quad> = quads.iter().collect();
    sorted.sort_by_key(|q| q.class);
    let faces: Vec<(u32, [u32; 4])> = sorted
        .iter()
        .map(|q| {
            let f = q.corners().map(|c| {
                *index.entry(c).or_insert_with(|| {
                    order.push(c);
                    order.len() as u32
                })
            });
            (q.class, f)
        })
        .collect();
    let (o, s) = (grid.origin(), grid.voxel_size());
    if palette.is_some() && !matches!(crate::atomic::target(path), crate::atomic::Target::Regular(_)) {
        return Err(IoError::new(
            path,
            crate::error::ErrorKind::Write(std::io::Error::other(
                "a coloured .obj needs its .mtl file beside it; write it to a regular file (or use .glb, which holds its colours)",
            )),
        ));
    }
    let mtl = palette.map(|p| (path.with_extension("mtl"), p));
    if let Some((mtl_path, p)) = &mtl {
        write_atomically(mtl_path, |w| {
            writeln!(w, "# voxkit: one material per voxel colour")?;
            for (i, c) in p.iter().enumerate() {
                let [r, g, b] = c.map(|v| v as f64 / 255.0);
                writeln!(w, "newmtl c{i}\nKd {r:.6} {g:.6} {b:.6}\nKa 0 0 0\nKs 0 0 0\nillum 1\n")?;
            }
            Ok(())
        })?;
    }
    write_atomically(path, |w| {
        writeln!(w, "# voxkit: {} greedy quads of the voxels' boundary faces", quads.len())?;
        if let Some((m, _)) = &mtl {
            writeln!(w, "mtllib {}", m.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default())?;
        }
        for c in &order {
            writeln!(w, "v {} {} {}", o.x + c[0] as f64 * s, o.y + c[1] as f64 * s, o.z + c[2] as f64 * s)?;
        }
        let mut current = u32::MAX;
        for (class, f) in &faces {
            if mtl.is_some() && *class != current && *class > 0 {
                writeln!(w, "usemtl c{}", class - 1)?;
                current = *class;
            }
            writeln!(w, "f {} {} {} {}", f[0], f[1], f[2], f[3])?;
        }
        Ok(())
    })?;
    Ok(order.len())
}

/// Writes `quads` as a binary glTF 2.0 file: two triangles per quad, four
/// vertices per quad (flat normals), `COLOR_0` from `palette` when given.
/// Returns the number of vertices.
pub fn write_quads_glb(path: &Path, quads: &[Quad], grid: &GridSpec, palette: Option<&[[u8; 3]]>) -> Result<usize, IoError> {
    let (o, s) = (grid.origin(), grid.voxel_size());
    let nv = quads.len() * 4;
    let mut pos = Vec::with_capacity(nv * 12);
    let mut nrm = Vec::with_capacity(nv * 12);
    let mut col = Vec::with_capacity(if palette.is_some() { nv * 12 } else { 0 });
    let mut idx = Vec::with_capacity(quads.len() * 24);
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for (qi, q) in quads.iter().enumerate() {
        let mut n = [0f32; 3];
        n[q.axis] = if q.positive { 1.0 } else { -1.0 };
        let colour = palette.map(|p| p.get(q.class.wrapping_sub(1) as usize).copied().unwrap_or([255; 3]).map(|c| to_linear(c) as f32));
        for c in q.corners() {
            let p = [o.x + c[0] as f64 * s, o.y + c[1] as f64 * s, o.z + c[2] as f64 * s].map(|v| v as f32);
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
            pos.extend(p.iter().flat_map(|v| v.to_le_bytes()));
            nrm.extend(n.iter().flat_map(|v| v.to_le_bytes()));
            if let Some(c) = colour {
                col.extend(c.iter().flat_map(|v| v.to_le_bytes()));
            }
        }
        let b = (qi * 4) as u32;
        idx.extend([b, b + 1, b + 2, b, b + 2, b + 3].iter().flat_map(|v| v.to_le_bytes()));
    }
    let mut bin = Vec::new();
    let mut views = Vec::new();
    for (data, target) in [(&idx, 34963), (&pos, 34962), (&nrm, 34962), (&col, 34962)] {
        if data.is_empty() && target == 34962 {
            continue;
        }
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": data.len(), "target": target}));
        bin.extend_from_slice(data);
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
    }
    let mut accessors = vec![
        json!({"bufferView": 0, "componentType": 5125, "count": quads.len() * 6, "type": "SCALAR"}),
        json!({"bufferView": 1, "componentType": 5126, "count": nv, "type": "VEC3", "min": lo, "max": hi}),
        json!({"bufferView": 2, "componentType": 5126, "count": nv, "type": "VEC3"}),
    ];
    let mut attributes = json!({"POSITION": 1, "NORMAL": 2});
    if palette.is_some() {
        accessors.push(json!({"bufferView": 3, "componentType": 5126, "count": nv, "type": "VEC3"}));
        attributes["COLOR_0"] = json!(3);
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "voxkit"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "voxels"}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 0, "material": 0, "mode": 4}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    let mut text = doc.to_string().into_bytes();
    while text.len() % 4 != 0 {
        text.push(b' ');
    }
    write_atomically(path, |w| {
        let total = 12 + 8 + text.len() + 8 + bin.len();
        if total > u32::MAX as usize {
            return Err(std::io::Error::other(format!(
                "{} quads make a {total}-byte GLB; the format ends at 4 GiB (write .obj instead)",
                quads.len()
            )));
        }
        w.write_all(b"glTF")?;
        w.write_all(&2u32.to_le_bytes())?;
        w.write_all(&(total as u32).to_le_bytes())?;
        w.write_all(&(text.len() as u32).to_le_bytes())?;
        w.write_all(b"JSON")?;
        w.write_all(&text)?;
        w.write_all(&(bin.len() as u32).to_le_bytes())?;
        w.write_all(b"BIN\0")?;
        w.write_all(&bin)
    })?;
    Ok(nv)
}
