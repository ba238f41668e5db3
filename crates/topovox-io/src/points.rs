//! A PLY point cloud of voxel centres (binary little-endian): `x y z` as
//! float, plus `red green blue` (uchar, sRGB) when the voxels have colours.
//! A header comment records the grid (`comment topovox grid origin X Y Z
//! voxel_size S dims NX NY NZ`, or `voxel_size SX SY SZ` for a grid of
//! boxes), which lets topovox read the file back as
//! voxels; other readers (MeshLab, CloudCompare, Open3D, `plyfile`) see an
//! ordinary point cloud.

use std::io::Write;

use glam::DVec3;
use topovox::attributes::VoxelAttributes;
use topovox::{GridSpec, VoxelSource};

use crate::error::ErrorKind;
use crate::LoadedVoxels;

const GRID_COMMENT: &str = "comment topovox grid";

/// Writes the centres of the set voxels of `bits` on `grid`.
pub fn write(w: &mut dyn Write, bits: &dyn VoxelSource, grid: &GridSpec, attrs: Option<&VoxelAttributes>) -> std::io::Result<()> {
    let colours = attrs.and_then(|a| a.colour.as_ref().map(|c| (a, c)));
    let o = grid.origin();
    let size = grid.voxel_size().recorded().iter().map(|v| format!("{v:?}")).collect::<Vec<_>>().join(" ");
    let d = grid.dims();
    let mut head = format!(
        "ply\nformat binary_little_endian 1.0\ncomment voxel centres written by topovox\n{GRID_COMMENT} origin {:?} {:?} {:?} voxel_size {size} dims {} {} {}\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        o.x,
        o.y,
        o.z,
        d[0],
        d[1],
        d[2],
        bits.count()
    );
    if colours.is_some() {
        head.push_str("property uchar red\nproperty uchar green\nproperty uchar blue\n");
    }
    head.push_str("end_header\n");
    w.write_all(head.as_bytes())?;
    let mut buf = Vec::with_capacity(1 << 16);
    let mut result = Ok(());
    bits.for_each_set(&mut |i, j, k| {
        let c = grid.voxel_center([i, j, k]);
        for v in [c.x, c.y, c.z] {
            buf.extend_from_slice(&(v as f32).to_le_bytes());
        }
        if let Some((a, cs)) = colours {
            buf.extend_from_slice(&a.slot(i, j, k).map(|t| cs[t]).unwrap_or([255; 3]));
        }
        if buf.len() >= 1 << 16 && result.is_ok() {
            result = w.write_all(&buf);
            buf.clear();
        }
    });
    result?;
    w.write_all(&buf)
}

/// The header line recording the grid, under either name (the two are
/// one word each, so the numbers sit at the same places).
fn is_grid_line(line: &str) -> bool {
    line.starts_with(GRID_COMMENT) || line.starts_with(crate::former_name::PLY_GRID_COMMENT)
}

/// True when PLY bytes start with a topovox voxel point cloud header.
pub fn is_voxel_cloud(head: &[u8]) -> bool {
    let end = head.windows(10).position(|w| w == b"end_header").unwrap_or(head.len());
    String::from_utf8_lossy(&head[..end]).lines().any(is_grid_line)
}

/// Reads a topovox point cloud back (through `ply-rs-bw`): each point marks
/// the voxel containing it, on the grid its header comment records.
pub fn read(bytes: &[u8]) -> Result<LoadedVoxels, ErrorKind> {
    let bad = |m: String| ErrorKind::malformed("PLY point cloud", m);
    let end = bytes.windows(10).position(|w| w == b"end_header").ok_or_else(|| bad("no end_header".into()))?;
    let head = String::from_utf8_lossy(&bytes[..end]);
    let line = head
        .lines()
        .find(|l| is_grid_line(l))
        .ok_or_else(|| bad(format!("no '{GRID_COMMENT} …' line: not a topovox voxel point cloud (meshes are read by voxelize)")))?;
    let w: Vec<&str> = line.split_whitespace().collect();
    let num = |i: usize| w.get(i).and_then(|v| v.parse::<f64>().ok()).filter(|v| v.is_finite());
    // `voxel_size` holds one number (cubes) or three (boxes); `dims` follows.
    let d = w.iter().position(|&v| v == "dims").unwrap_or(9);
    let size = match d {
        11 => (num(8), num(9), num(10)),
        _ => (num(8), num(8), num(8)),
    };
    let (Some(ox), Some(oy), Some(oz), (Some(sx), Some(sy), Some(sz)), Some(nx), Some(ny), Some(nz)) =
        (num(4), num(5), num(6), size, num(d + 1), num(d + 2), num(d + 3))
    else {
        return Err(bad(format!("unreadable grid line {line:?}")));
    };
    let grid =
        GridSpec::new(DVec3::new(ox, oy, oz), [sx, sy, sz], [nx as u64, ny as u64, nz as u64]).map_err(|e| bad(format!("grid: {e}")))?;
    let parser = ply_rs_bw::parser::Parser::<ply_rs_bw::ply::DefaultElement>::new();
    let ply = parser.read_ply(&mut std::io::Cursor::new(bytes)).map_err(|e| bad(e.to_string()))?;
    let verts = ply.payload.get("vertex").ok_or_else(|| bad("no 'vertex' element".into()))?;
    let dims = grid.dims();
    if dims.iter().map(|&d| d as u64).product::<u64>() > 1 << 35 {
        return Err(bad(format!("the recorded grid {dims:?} is too large to read back densely")));
    }
    let mut bits = crate::dense_grid(dims)?;
    let mut coloured = Vec::new();
    let mut has_colour = false;
    use ply_rs_bw::ply::Property;
    let f = |p: Option<&Property>| match p {
        Some(Property::Float(v)) => Some(*v as f64),
        Some(Property::Double(v)) => Some(*v),
        _ => None,
    };
    for (n, v) in verts.iter().enumerate() {
        let (Some(x), Some(y), Some(z)) = (f(v.get("x")), f(v.get("y")), f(v.get("z"))) else {
            return Err(bad(format!("point {n} has no float x, y, z")));
        };
        let g = grid.to_grid_units(DVec3::new(x, y, z));
        let ijk = [g.x, g.y, g.z].map(|c| c.floor());
        if (0..3).any(|a| !(ijk[a] >= 0.0 && ijk[a] < dims[a] as f64)) {
            return Err(bad(format!("point {n} ({x}, {y}, {z}) lies outside the recorded grid")));
        }
        let p = ijk.map(|c| c as u32);
        bits.set(p[0], p[1], p[2]);
        let c = [v.get("red"), v.get("green"), v.get("blue")].map(|p| match p {
            Some(Property::UChar(c)) => Some(*c),
            _ => None,
        });
        if let [Some(r), Some(g), Some(b)] = c {
            has_colour = true;
            coloured.push((p, [r, g, b]));
        }
    }
    let attributes = has_colour.then(|| VoxelAttributes::from_coloured(dims, coloured));
    Ok(LoadedVoxels { bits, placement: Some((grid.origin(), grid.voxel_size().0)), attributes })
}
