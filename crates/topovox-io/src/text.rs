//! Plain text: a header comment with the grid, then one `i j k` line per set
//! voxel, ordered by `k`, then `j`, then `i`.
//!
//! ```text
//! # topovox voxels dims 4 4 2 origin 0 0 0 voxel_size 0.25
//! 0 0 0
//! 3 1 0
//! ```
//!
//! A grid of boxes gives three sizes: `voxel_size 0.7 0.7 2.5`.

use std::io::Write;

use glam::DVec3;
use topovox::{GridSpec, VoxelSource};

use crate::error::ErrorKind;
use crate::LoadedVoxels;

/// Writes the header and one line per set voxel.
pub fn write(w: &mut dyn Write, bits: &dyn VoxelSource, grid: &GridSpec) -> std::io::Result<()> {
    let [nx, ny, nz] = bits.dims();
    let o = grid.origin();
    let size = grid.voxel_size().recorded().iter().map(f64::to_string).collect::<Vec<_>>().join(" ");
    writeln!(w, "# topovox voxels dims {nx} {ny} {nz} origin {} {} {} voxel_size {size}", o.x, o.y, o.z)?;
    let mut result = Ok(());
    bits.for_each_set(&mut |i, j, k| {
        if result.is_ok() {
            result = writeln!(w, "{i} {j} {k}");
        }
    });
    result
}

/// Reads a voxel list; without a header the grid is the smallest holding every voxel.
pub fn read(bytes: &[u8]) -> Result<LoadedVoxels, ErrorKind> {
    let text = std::str::from_utf8(bytes).map_err(|_| ErrorKind::malformed("text", "not UTF-8"))?;
    let mut dims: Option<[u32; 3]> = None;
    let mut placement = None;
    let mut voxels = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if let Some(h) = line.strip_prefix("# topovox voxels").or_else(|| line.strip_prefix(crate::former_name::TEXT_HEADER)) {
            let f: Vec<&str> = h.split_whitespace().collect();
            let num = |i: usize| f.get(i).and_then(|s| s.parse::<f64>().ok());
            if let (Some(&"dims"), Some(x), Some(y), Some(z)) = (f.first(), num(1), num(2), num(3)) {
                dims = Some([x as u32, y as u32, z as u32]);
            }
            if let (Some(x), Some(y), Some(z), Some(s)) = (num(5), num(6), num(7), num(9)) {
                let size = match (num(10), num(11)) {
                    (Some(sy), Some(sz)) => DVec3::new(s, sy, sz),
                    _ => DVec3::splat(s),
                };
                placement = Some((DVec3::new(x, y, z), size));
            }
            continue;
        }
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let v: Vec<u32> =
            line.split_whitespace().map(|s| s.parse()).collect::<Result<_, _>>().map_err(|_| {
                ErrorKind::malformed("text", format!("line {}: expected 'i j k', got {}", n + 1, crate::error::quoted(line)))
            })?;
        let [i, j, k] = v[..] else {
            return Err(ErrorKind::malformed("text", format!("line {}: expected 3 integers", n + 1)));
        };
        voxels.push([i, j, k]);
    }
    let dims = match dims {
        Some(d) => d,
        None => {
            let mut d = [1u32; 3];
            for v in &voxels {
                for a in 0..3 {
                    d[a] = d[a].max(v[a].saturating_add(1));
                }
            }
            d
        }
    };
    if dims.iter().any(|&d| d == 0 || d > topovox::grid::spec::MAX_DIM) {
        return Err(ErrorKind::malformed("text", format!("grid dims {dims:?} out of range")));
    }
    let mut bits = crate::dense_grid(dims)?;
    for v in voxels {
        if (0..3).any(|a| v[a] >= dims[a]) {
            return Err(ErrorKind::malformed("text", format!("voxel {v:?} outside dims {dims:?}")));
        }
        bits.set(v[0], v[1], v[2]);
    }
    Ok(LoadedVoxels { bits, placement, attributes: None })
}
