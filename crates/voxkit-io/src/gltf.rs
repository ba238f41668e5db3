//! glTF 2.0 (`.gltf` with external or embedded buffers, and `.glb`),
//! through the `gltf` crate.
//!
//! Every triangle primitive (modes TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN)
//! of every mesh instanced by the default scene (or the first scene if none
//! is marked default) is read with its node's world transform applied.
//! Point and line primitives are skipped with a warning.

use std::path::Path;

use glam::{DMat4, DVec3, Mat4};
use gltf::mesh::Mode;

use crate::error::ErrorKind;
use crate::mesh_report::{finish, LoadedMesh};

/// Parses glTF JSON or GLB bytes; `base_dir` resolves external buffer URIs.
pub fn read(bytes: &[u8], base_dir: Option<&Path>) -> Result<LoadedMesh, ErrorKind> {
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(bytes).map_err(|e| ErrorKind::malformed("glTF", e))?;
    let buffers = gltf::import_buffers(&document, base_dir, blob).map_err(|e| ErrorKind::malformed("glTF", format!("buffer: {e}")))?;
    let mut out = Builder::default();
    let scene = document.default_scene().or_else(|| document.scenes().next());
    match scene {
        Some(scene) => {
            for node in scene.nodes() {
                out.node(&node, DMat4::IDENTITY, &buffers, 0)?;
            }
        }
        None => {
            out.warnings.push("no scene: reading every mesh untransformed".into());
            for mesh in document.meshes() {
                out.mesh(&mesh, DMat4::IDENTITY, &buffers)?;
            }
        }
    }
    finish(out.positions, out.triangles, out.warnings)
}

#[derive(Default)]
struct Builder {
    positions: Vec<DVec3>,
    triangles: Vec<[i64; 3]>,
    warnings: Vec<String>,
}

impl Builder {
    fn node(&mut self, node: &gltf::Node<'_>, parent: DMat4, buffers: &[gltf::buffer::Data], depth: usize) -> Result<(), ErrorKind> {
        if depth > 256 {
            return Err(ErrorKind::malformed("glTF", "node hierarchy deeper than 256 (cycle?)"));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix()).as_dmat4();
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            self.mesh(&mesh, world, buffers)?;
        }
        for child in node.children() {
            self.node(&child, world, buffers, depth + 1)?;
        }
        Ok(())
    }

    fn mesh(&mut self, mesh: &gltf::Mesh<'_>, world: DMat4, buffers: &[gltf::buffer::Data]) -> Result<(), ErrorKind> {
        for prim in mesh.primitives() {
            let mode = prim.mode();
            if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                self.warnings.push(format!("mesh {}: skipped a {mode:?} primitive (not triangles)", mesh.index()));
                continue;
            }
            let mi = mesh.index();
            let pos_acc = prim.get(&gltf::Semantic::Positions);
            if let Some(a) = &pos_acc {
                check_accessor(a, buffers, mi)?;
            }
            if let Some(a) = prim.indices() {
                check_accessor(&a, buffers, mi)?;
            }
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let Some(pos) = reader.read_positions() else {
                self.warnings.push(format!("mesh {}: primitive without POSITION skipped", mesh.index()));
                continue;
            };
            let base = self.positions.len() as i64;
            self.positions.extend(pos.map(|p| world.transform_point3(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))));
            let n = self.positions.len() as i64 - base;
            let idx: Vec<i64> = match reader.read_indices() {
                Some(i) => i.into_u32().map(|i| i as i64 + base).collect(),
                None => (base..base + n).collect(),
            };
            match mode {
                Mode::Triangles => {
                    for t in idx.chunks_exact(3) {
                        self.triangles.push([t[0], t[1], t[2]]);
                    }
                }
                Mode::TriangleStrip => {
                    for w in 0..idx.len().saturating_sub(2) {
                        let t = if w % 2 == 0 { [idx[w], idx[w + 1], idx[w + 2]] } else { [idx[w + 1], idx[w], idx[w + 2]] };
                        self.triangles.push(t);
                    }
                }
                _ => {
                    for w in 1..idx.len().saturating_sub(1) {
                        self.triangles.push([idx[0], idx[w], idx[w + 1]]);
                    }
                }
            }
        }
        Ok(())
    }
}

/// Checks that an accessor's elements lie inside its buffer view and the
/// view inside its buffer, so reading can neither fail silently nor panic.
fn check_accessor(a: &gltf::Accessor<'_>, buffers: &[gltf::buffer::Data], mesh: usize) -> Result<(), ErrorKind> {
    let bad = |d: String| ErrorKind::malformed("glTF", format!("mesh {mesh}, accessor {}: {d}", a.index()));
    let Some(view) = a.view() else {
        if a.sparse().is_some() {
            return Err(ErrorKind::Unsupported(format!("sparse accessor {} without a buffer view", a.index())));
        }
        return Err(bad("no buffer view".into()));
    };
    let buf_len = buffers.get(view.buffer().index()).map(|d| d.0.len()).ok_or_else(|| bad("buffer not loaded".into()))?;
    let view_end = view.offset().checked_add(view.length()).ok_or_else(|| bad("view overflows".into()))?;
    if view_end > buf_len {
        return Err(bad(format!("buffer view {} ends at byte {view_end}, past the buffer's {buf_len} bytes", view.index())));
    }
    if a.count() > 0 {
        let elem = a.size();
        let stride = view.stride().unwrap_or(elem);
        let need = (a.count() as u64 - 1) * stride as u64 + elem as u64 + a.offset() as u64;
        if need > view.length() as u64 {
            return Err(bad(format!("{} elements need {need} bytes but buffer view {} has {}", a.count(), view.index(), view.length())));
        }
    }
    Ok(())
}
