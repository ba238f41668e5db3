//! A plain text polyline format (`.lines`): one segment or polyline per
//! line, as whitespace- or comma-separated coordinates
//! `x1 y1 z1 x2 y2 z2 [x3 y3 z3 …]`. Blank lines and lines starting with
//! `#` are ignored. A polyline of `n` points gives `n − 1` segments.

use glam::DVec3;

use crate::error::ErrorKind;
use crate::mesh_report::{finish_with_segments, LoadedMesh};

/// Parses `.lines` text.
pub fn read(bytes: &[u8]) -> Result<LoadedMesh, ErrorKind> {
    let text = std::str::from_utf8(bytes).map_err(|e| ErrorKind::malformed("polyline", format!("not UTF-8 text ({e})")))?;
    let mut positions = Vec::new();
    let mut segments = Vec::new();
    for (number, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let bad = |what: String| ErrorKind::malformed("polyline", format!("line {}: {what}", number + 1));
        let values: Vec<f64> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|w| !w.is_empty())
            .map(|w| w.parse::<f64>().map_err(|_| bad(format!("{} is not a number", crate::error::quoted(w)))))
            .collect::<Result<_, _>>()?;
        if values.len() % 3 != 0 || values.len() < 6 {
            return Err(bad(format!("expected x y z for at least two points, found {} numbers", values.len())));
        }
        let first = positions.len() as i64;
        positions.extend(values.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])));
        let n = (values.len() / 3) as i64;
        segments.extend((0..n - 1).map(|k| [first + k, first + k + 1]));
    }
    finish_with_segments(positions, Vec::new(), segments, Vec::new())
}
