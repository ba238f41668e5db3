//! Wavefront OBJ, through the `tobj` crate.
//!
//! Polygons with more than three vertices are fan-triangulated; negative
//! (relative) indices are resolved by tobj. A missing or broken material
//! library is a warning, not an error: geometry does not need it.

use std::io::{BufReader, Cursor};
use std::path::Path;
use std::sync::Mutex;

use glam::DVec3;

use crate::error::ErrorKind;
use crate::mesh_report::{fan, finish, LoadedMesh};

/// Parses OBJ bytes; `base_dir` is where `mtllib` files are looked up.
pub fn read(bytes: &[u8], base_dir: Option<&Path>) -> Result<LoadedMesh, ErrorKind> {
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
    if let Err(e) = materials {
        if warnings.is_empty() && !matches!(e, tobj::LoadError::GenericFailure) {
            warnings.push(format!("materials ignored: {e}"));
        }
    }
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for m in &models {
        let mesh = &m.mesh;
        let base = positions.len() as i64;
        if mesh.positions.len() % 3 != 0 {
            return Err(ErrorKind::malformed("OBJ", "vertex position with fewer than 3 coordinates"));
        }
        positions.extend(mesh.positions.chunks_exact(3).map(|p| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64)));
        let idx: Vec<i64> = mesh.indices.iter().map(|&i| base + i as i64).collect();
        if mesh.face_arities.is_empty() {
            for t in idx.chunks_exact(3) {
                triangles.push([t[0], t[1], t[2]]);
            }
        } else {
            let mut at = 0usize;
            for &n in &mesh.face_arities {
                let n = n as usize;
                let Some(poly) = idx.get(at..at + n) else {
                    return Err(ErrorKind::malformed("OBJ", "face arity past the index list"));
                };
                fan(poly, &mut triangles);
                at += n;
            }
        }
    }
    finish(positions, triangles, warnings)
}
