//! STL, ASCII and binary, through the `stl_io` crate.
//!
//! A binary file's triangle count is checked against its size before
//! parsing, so a truncated or lying header is an error, not a huge allocation.

use std::io::Cursor;

use glam::DVec3;

use crate::error::ErrorKind;
use crate::mesh_report::{finish, LoadedMesh};

/// True when `bytes` read as ASCII STL: `solid`, then `facet` or
/// `endsolid` within the first 4 KiB (a binary header may begin `solid`).
pub(crate) fn looks_ascii(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(4096)];
    bytes.trim_ascii_start().starts_with(b"solid") && (head.windows(5).any(|w| w == b"facet") || head.windows(8).any(|w| w == b"endsolid"))
}

/// Parses STL bytes (ASCII or binary).
pub fn read(bytes: &[u8]) -> Result<LoadedMesh, ErrorKind> {
    if !looks_ascii(bytes) {
        if bytes.len() < 84 {
            return Err(ErrorKind::malformed("STL", format!("binary file of {} bytes is shorter than its 84-byte header", bytes.len())));
        }
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        let need = 84 + 50 * count;
        if (bytes.len() as u64) < need {
            return Err(ErrorKind::malformed(
                "STL",
                format!("binary header promises {count} triangles ({need} bytes) but the file has {} bytes (truncated?)", bytes.len()),
            ));
        }
    }
    let mesh = stl_io::read_stl(&mut Cursor::new(bytes)).map_err(|e| ErrorKind::malformed("STL", e))?;
    let positions = mesh.vertices.iter().map(|v| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)).collect();
    let triangles = mesh.faces.iter().map(|f| f.vertices.map(|i| i as i64)).collect();
    finish(positions, triangles, Vec::new())
}
