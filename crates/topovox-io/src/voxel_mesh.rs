//! A mesh of the voxels — the greedy quads of [`topovox::export::greedy`] —
//! as Wavefront OBJ or binary glTF (`.glb`).
//!
//! Colours: a quad's `class` is `1 + palette index` (0: uncoloured). OBJ
//! writes one material per palette colour (`Kd`, in a `.mtl` beside the
//! `.obj`) and groups faces with `usemtl`; GLB writes a per-vertex
//! `COLOR_0` (linear, as glTF requires) under one white material.

use std::collections::HashMap;
use std::path::Path;

use serde_json::json;
use topovox::attributes::carry::DEFAULT_COLOUR;
use topovox::attributes::colour::to_linear;
use topovox::export::greedy::Quad;
use topovox::GridSpec;

use crate::atomic::{stage, write_atomically};
use crate::error::IoError;

/// How a mesh of the voxels is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshOptions {
    /// Split every T-junction of the greedy quads, so each edge is shared by
    /// the faces on both sides ([`topovox::export::watertight`]): what 3D
    /// printing and booleans need. Default: on.
    pub watertight: bool,
    /// Write triangles only (OBJ: quads become two triangles; some readers,
    /// Open3D among them, read only triangles). Default: off (GLB is
    /// always triangles).
    pub triangulate: bool,
}

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions { watertight: true, triangulate: false }
    }
}

/// The faces to write: quads and triangles in doubled voxel-corner
/// coordinates, with their class and the axis/side of their quad.
fn faces(quads: &[Quad], opts: &MeshOptions) -> Vec<(u32, usize, Vec<[u32; 3]>)> {
    let faces: Vec<(u32, usize, Vec<[u32; 3]>)> = if opts.watertight {
        topovox::export::watertight::conform(quads).into_iter().map(|f| (f.class, f.quad, f.vertices)).collect()
    } else {
        quads.iter().enumerate().map(|(i, q)| (q.class, i, q.corners().map(|c| c.map(|x| 2 * x)).to_vec())).collect()
    };
    if !opts.triangulate {
        return faces;
    }
    faces
        .into_iter()
        .flat_map(
            |(c, q, v)| if v.len() == 4 { vec![(c, q, vec![v[0], v[1], v[2]]), (c, q, vec![v[0], v[2], v[3]])] } else { vec![(c, q, v)] },
        )
        .collect()
}

/// Writes `quads` on `grid` (world coordinates) as an OBJ: quads and
/// triangles (see [`MeshOptions`]), counter-clockwise seen from outside,
/// vertices shared; with a `palette`, also `<output stem>.mtl` with one
/// material per colour. Returns the number of vertices.
pub fn write_quads_obj(
    path: &Path,
    quads: &[Quad],
    grid: &GridSpec,
    palette: Option<&[[u8; 3]]>,
    opts: &MeshOptions,
) -> Result<usize, IoError> {
    let mut index: HashMap<[u32; 3], u32> = HashMap::with_capacity(quads.len() * 2);
    let mut order: Vec<[u32; 3]> = Vec::with_capacity(quads.len() * 2);
    let mut all = faces(quads, opts);
    all.sort_by_key(|f| f.0);
    let faces: Vec<(u32, Vec<u32>)> = all
        .iter()
        .map(|(class, _, vs)| {
            let f = vs
                .iter()
                .map(|&c| {
                    *index.entry(c).or_insert_with(|| {
                        order.push(c);
                        order.len() as u32
                    })
                })
                .collect();
            (*class, f)
        })
        .collect();
    let (o, s) = (grid.origin(), grid.voxel_size().0 / 2.0);
    if palette.is_some() && !matches!(crate::atomic::target(path), crate::atomic::Target::Regular(_)) {
        return Err(IoError::new(
            path,
            crate::error::ErrorKind::Write(std::io::Error::other(
                "a coloured .obj needs its .mtl file beside it; write it to a regular file (or use .glb, which holds its colours)",
            )),
        ));
    }
    let mtl = palette.map(|p| (path.with_extension("mtl"), p));
    // Both files are complete before either is renamed into place, the
    // `.mtl` first: a failure (a full disk) leaves the old pair intact.
    let staged_mtl = match &mtl {
        None => None,
        Some((mtl_path, p)) => Some(stage(mtl_path, |w| {
            writeln!(w, "# topovox: one material per voxel colour")?;
            for (i, c) in p.iter().enumerate() {
                let [r, g, b] = c.map(|v| v as f64 / 255.0);
                writeln!(w, "newmtl c{i}\nKd {r:.6} {g:.6} {b:.6}\nKa 0 0 0\nKs 0 0 0\nillum 1\n")?;
            }
            Ok(())
        })?),
    };
    let staged_obj = stage(path, |w| {
        writeln!(
            w,
            "# topovox: {} faces from {} greedy quads of the voxels' boundary faces{}",
            faces.len(),
            quads.len(),
            if opts.watertight { ", T-junctions split (watertight)" } else { "" }
        )?;
        if let Some((m, _)) = &mtl {
            writeln!(w, "mtllib {}", m.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default())?;
        }
        for c in &order {
            writeln!(w, "v {} {} {}", o.x + c[0] as f64 * s.x, o.y + c[1] as f64 * s.y, o.z + c[2] as f64 * s.z)?;
        }
        let mut current = u32::MAX;
        for (class, f) in &faces {
            if mtl.is_some() && *class != current && *class > 0 {
                writeln!(w, "usemtl c{}", class - 1)?;
                current = *class;
            }
            write!(w, "f")?;
            for v in f {
                write!(w, " {v}")?;
            }
            writeln!(w)?;
        }
        Ok(())
    })?;
    if let Some(m) = staged_mtl {
        m.commit()?;
    }
    staged_obj.commit()?;
    Ok(order.len())
}

/// Vertices (world coordinates, shared), triangles and, with a palette,
/// one colour per triangle.
pub type Triangles = (Vec<[f64; 3]>, Vec<[u32; 3]>, Option<Vec<[u8; 3]>>);

/// `quads` on `grid` as an indexed triangle mesh: T-junctions split (so it
/// is watertight), each face fan-triangulated, its colour from `palette`
/// (class `c` is `palette[c - 1]`). What Python's `VoxelGrid.to_mesh` returns.
pub fn triangles(quads: &[Quad], grid: &GridSpec, palette: Option<&[[u8; 3]]>) -> Triangles {
    let (o, s) = (grid.origin(), grid.voxel_size().0 / 2.0);
    let mut index: HashMap<[u32; 3], u32> = HashMap::with_capacity(quads.len() * 2);
    let mut verts = Vec::with_capacity(quads.len() * 2);
    let mut faces = Vec::with_capacity(quads.len() * 3);
    let mut colours = palette.map(|_| Vec::with_capacity(quads.len() * 3));
    for f in topovox::export::watertight::conform(quads) {
        let ids: Vec<u32> = f
            .vertices
            .iter()
            .map(|&c| {
                *index.entry(c).or_insert_with(|| {
                    verts.push([o.x + c[0] as f64 * s.x, o.y + c[1] as f64 * s.y, o.z + c[2] as f64 * s.z]);
                    verts.len() as u32 - 1
                })
            })
            .collect();
        let colour = palette.map(|p| f.class.checked_sub(1).and_then(|i| p.get(i as usize)).copied().unwrap_or(DEFAULT_COLOUR));
        for t in 1..ids.len() - 1 {
            faces.push([ids[0], ids[t], ids[t + 1]]);
            if let (Some(out), Some(c)) = (colours.as_mut(), colour) {
                out.push(c);
            }
        }
    }
    (verts, faces, colours)
}

/// Writes `quads` as a binary glTF 2.0 file: triangles (T-junctions split
/// when [`MeshOptions::watertight`]), vertices per face (flat normals),
/// `COLOR_0` from `palette` when given. Returns the number of vertices.
pub fn write_quads_glb(
    path: &Path,
    quads: &[Quad],
    grid: &GridSpec,
    palette: Option<&[[u8; 3]]>,
    opts: &MeshOptions,
) -> Result<usize, IoError> {
    let (o, s) = (grid.origin(), grid.voxel_size().0 / 2.0);
    let faces = faces(quads, &MeshOptions { triangulate: false, ..*opts });
    let nv: usize = faces.iter().map(|f| f.2.len()).sum();
    let ni: usize = faces.iter().map(|f| 3 * (f.2.len() - 2)).sum();
    let mut pos = Vec::with_capacity(nv * 12);
    let mut nrm = Vec::with_capacity(nv * 12);
    let mut col = Vec::with_capacity(if palette.is_some() { nv * 12 } else { 0 });
    let mut idx = Vec::with_capacity(ni * 4);
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    let mut base = 0u32;
    for (class, qi, vs) in &faces {
        let q = &quads[*qi];
        let mut n = [0f32; 3];
        n[q.axis] = if q.positive { 1.0 } else { -1.0 };
        let colour = palette.map(|p| p.get(class.wrapping_sub(1) as usize).copied().unwrap_or([255; 3]).map(|c| to_linear(c) as f32));
        for c in vs {
            let p = [o.x + c[0] as f64 * s.x, o.y + c[1] as f64 * s.y, o.z + c[2] as f64 * s.z].map(|v| v as f32);
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
        for t in 1..vs.len() as u32 - 1 {
            idx.extend([base, base + t, base + t + 1].iter().flat_map(|v| v.to_le_bytes()));
        }
        base += vs.len() as u32;
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
        json!({"bufferView": 0, "componentType": 5125, "count": ni, "type": "SCALAR"}),
        json!({"bufferView": 1, "componentType": 5126, "count": nv, "type": "VEC3", "min": lo, "max": hi}),
        json!({"bufferView": 2, "componentType": 5126, "count": nv, "type": "VEC3"}),
    ];
    let mut attributes = json!({"POSITION": 1, "NORMAL": 2});
    if palette.is_some() {
        accessors.push(json!({"bufferView": 3, "componentType": 5126, "count": nv, "type": "VEC3"}));
        attributes["COLOR_0"] = json!(3);
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "topovox"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "voxels"}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 0, "material": 0, "mode": 4}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    write_atomically(path, |w| {
        crate::mesh_out::write_glb(w, &doc, &bin, |total| {
            format!("{} quads make a {total}-byte GLB; the format ends at 4 GiB (write .obj instead)", quads.len())
        })
    })?;
    Ok(nv)
}
