//! Zarr v3 arrays (`OUT.zarr/`, a directory), written and read by hand.
//!
//! **Why by hand.** The `zarrs` crate, even without default features,
//! builds zlib from C and pulls async runtimes and caches; the part of the
//! format voxkit needs — one array, regular chunks, the `bytes` and `gzip`
//! codecs — is a JSON document and one gzip stream per chunk (`flate2`,
//! already a dependency). Sharding is not written yet.
//!
//! **Layout.** `zarr.json`: `zarr_format` 3, `node_type` `array`, `shape`
//! `[nx, ny, nz]`, `data_type` `bool`, `chunk_grid` regular with
//! `chunk_shape` `[64, 64, 64]`, `chunk_key_encoding` `default` with `/`
//! (chunk `(a, b, c)` at `c/a/b/c`), `fill_value` `false`, codecs
//! `bytes` then `gzip` (level 1), `dimension_names` `["i", "j", "k"]`, and
//! `attributes.voxkit` with the grid's `origin` and `voxel_size`. Element
//! `[i, j, k]` is voxel `(i, j, k)` (C order, `k` fastest, as `.npy`).
//! Chunks holding no set voxel are not written (the fill value stands for
//! them), so a sparse surface on a huge grid stays small; edge chunks are
//! whole chunks, padded with `false`. The Python `zarr` package (and Dask,
//! `dask.array.from_zarr`) opens it as one array; CI checks every voxel.
//!
//! The directory is built beside the output under a temporary name and
//! renamed into place; an existing Zarr array at the output is replaced
//! only after the new one is complete, anything else there is refused.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use flate2::read::GzDecoder;
use flate2::write::GzEncoder;
use rayon::prelude::*;
use serde_json::{json, Value};
use voxkit::grid::bricks::Brick;
use voxkit::{GridSpec, VoxelSource};

use crate::error::{ErrorKind, IoError};
use crate::LoadedVoxels;

/// Chunk edge in voxels (8 bricks).
pub const CHUNK: u32 = 64;

/// The array's metadata document.
fn metadata(grid: &GridSpec) -> Value {
    let o = grid.origin();
    json!({
        "zarr_format": 3,
        "node_type": "array",
        "shape": grid.dims(),
        "data_type": "bool",
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [CHUNK, CHUNK, CHUNK]}},
        "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
        "fill_value": false,
        "codecs": [{"name": "bytes"}, {"name": "gzip", "configuration": {"level": 1}}],
        "dimension_names": ["i", "j", "k"],
        "attributes": {"voxkit": {"origin": [o.x, o.y, o.z], "voxel_size": grid.voxel_size()}},
    })
}

/// One chunk's bytes (C order, `k` fastest) from its bricks.
fn chunk_bytes(bricks: &[([u32; 3], Brick)]) -> Vec<u8> {
    let c = CHUNK as usize;
    let mut out = vec![0u8; c * c * c];
    for (b, bits) in bricks {
        let base = b.map(|v| (v % (CHUNK / 8)) as usize * 8);
        for (z, &w) in bits.iter().enumerate() {
            let mut w = w;
            while w != 0 {
                let bit = w.trailing_zeros() as usize;
                w &= w - 1;
                let (i, j, k) = (base[0] + (bit & 7), base[1] + (bit >> 3), base[2] + z);
                out[(i * c + j) * c + k] = 1;
            }
        }
    }
    out
}

fn io(path: &Path, e: std::io::Error) -> IoError {
    IoError::new(path, ErrorKind::Write(e))
}

/// Writes `bits` on `grid` as a Zarr v3 array directory at `path`.
pub fn write(path: &Path, bits: &dyn VoxelSource, grid: &GridSpec) -> Result<(), IoError> {
    if path.exists() && !path.join("zarr.json").is_file() {
        return Err(io(path, std::io::Error::other("exists and is not a Zarr array; voxkit replaces only Zarr arrays")));
    }
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.voxkit-tmp-{}", std::process::id()));
    let result = fill(&tmp, bits, grid).and_then(|_| replace(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    result.map_err(|e| io(path, e))
}

fn fill(dir: &Path, bits: &dyn VoxelSource, grid: &GridSpec) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    std::fs::write(dir.join("zarr.json"), serde_json::to_vec_pretty(&metadata(grid)).map_err(std::io::Error::other)?)?;
    // Bricks grouped by chunk (8³ bricks per chunk).
    let per = CHUNK / 8;
    let mut bricks: Vec<([u32; 3], Brick)> = Vec::new();
    bits.for_each_brick(&mut |b, bits| bricks.push((b, *bits)));
    let chunk_of = |b: &[u32; 3]| b.map(|v| v / per);
    bricks.par_sort_unstable_by_key(|(b, _)| chunk_of(b));
    let mut groups: Vec<std::ops::Range<usize>> = Vec::new();
    let mut s = 0;
    while s < bricks.len() {
        let c = chunk_of(&bricks[s].0);
        let e = s + bricks[s..].iter().take_while(|(b, _)| chunk_of(b) == c).count();
        groups.push(s..e);
        s = e;
    }
    groups.par_iter().try_for_each(|g| -> std::io::Result<()> {
        let c = chunk_of(&bricks[g.start].0);
        let d = dir.join("c").join(c[0].to_string()).join(c[1].to_string());
        std::fs::create_dir_all(&d)?;
        let mut enc = GzEncoder::new(Vec::new(), flate2::Compression::new(1));
        enc.write_all(&chunk_bytes(&bricks[g.clone()]))?;
        std::fs::write(d.join(c[2].to_string()), enc.finish()?)
    })
}

/// Renames `tmp` to `path`, moving an existing array aside first and
/// removing it only once the new one is in place.
fn replace(tmp: &Path, path: &Path) -> std::io::Result<()> {
    if !path.exists() {
        return std::fs::rename(tmp, path);
    }
    let old: PathBuf =
        path.with_file_name(format!(".{}.voxkit-old-{}", path.file_name().unwrap_or_default().to_string_lossy(), std::process::id()));
    std::fs::rename(path, &old)?;
    if let Err(e) = std::fs::rename(tmp, path) {
        let _ = std::fs::rename(&old, path);
        return Err(e);
    }
    std::fs::remove_dir_all(&old)
}

fn bad(what: impl Into<String>) -> ErrorKind {
    ErrorKind::malformed("Zarr", what.into())
}

/// Largest chunk voxkit reads (elements): a hostile `zarr.json` can claim
/// any chunk shape.
const MAX_CHUNK_ELEMENTS: u64 = 1 << 30;

/// Most chunks voxkit looks for (each is a file lookup).
const MAX_CHUNKS: u64 = 1 << 24;

/// Reads a Zarr v3 array of `bool` or `uint8` (non-zero = set) with
/// regular chunks, the `bytes` codec and optionally `gzip`: voxkit's own
/// arrays and those written the same way by the `zarr` package.
pub fn read(path: &Path) -> Result<LoadedVoxels, IoError> {
    let e = |k| IoError::new(path, k);
    let meta_path = path.join("zarr.json");
    let text = std::fs::read(&meta_path).map_err(|x| e(ErrorKind::Read(x)))?;
    let m: Value = serde_json::from_slice(&text).map_err(|x| e(bad(format!("zarr.json: {x}"))))?;
    if m["zarr_format"] != 3 || m["node_type"] != "array" {
        return Err(e(bad("zarr.json is not a Zarr v3 array")));
    }
    let dims3 = |v: &Value, what: &str| -> Result<[u64; 3], IoError> {
        let a = v.as_array().filter(|a| a.len() == 3).ok_or_else(|| e(bad(format!("{what} must have three axes"))))?;
        let mut out = [0u64; 3];
        for (o, x) in out.iter_mut().zip(a) {
            *o = x
                .as_u64()
                .filter(|&x| x > 0 && x <= voxkit::grid::spec::MAX_DIM as u64)
                .ok_or_else(|| e(bad(format!("{what}: {x} is not a size from 1 to {}", voxkit::grid::spec::MAX_DIM))))?;
        }
        Ok(out)
    };
    let shape = dims3(&m["shape"], "shape")?;
    if m["chunk_grid"]["name"] != "regular" {
        return Err(e(bad("only regular chunk grids are read")));
    }
    let chunk = dims3(&m["chunk_grid"]["configuration"]["chunk_shape"], "chunk_shape")?;
    if chunk.iter().product::<u64>() > MAX_CHUNK_ELEMENTS {
        return Err(e(bad(format!("chunk shape {chunk:?} is larger than voxkit reads"))));
    }
    let dtype = m["data_type"].as_str().unwrap_or("");
    if !matches!(dtype, "bool" | "uint8") {
        return Err(e(bad(format!("data_type {dtype:?} (voxkit reads bool and uint8)"))));
    }
    let sep = match m["chunk_key_encoding"]["name"].as_str() {
        Some("default") => m["chunk_key_encoding"]["configuration"]["separator"].as_str().unwrap_or("/").to_string(),
        other => return Err(e(bad(format!("chunk_key_encoding {other:?} (voxkit reads default)")))),
    };
    let mut gzip = false;
    for c in m["codecs"].as_array().ok_or_else(|| e(bad("no codecs")))? {
        match c["name"].as_str() {
            Some("bytes") => {}
            Some("gzip") => gzip = true,
            other => return Err(e(bad(format!("codec {other:?} (voxkit reads bytes and gzip)")))),
        }
    }
    let n = [0, 1, 2].map(|a| shape[a].div_ceil(chunk[a]));
    if n.iter().product::<u64>() > MAX_CHUNKS {
        return Err(e(bad(format!("{n:?} chunks, more than voxkit looks for ({MAX_CHUNKS})"))));
    }
    let dims = shape.map(|d| d as u32);
    let mut bits = crate::dense_grid(dims).map_err(e)?;
    let len = chunk.iter().product::<u64>() as usize;
    let mut buf = Vec::with_capacity(len);
    for a in 0..n[0] {
        for b in 0..n[1] {
            for c in 0..n[2] {
                let key = format!("c{sep}{a}{sep}{b}{sep}{c}");
                let p = path.join(&key);
                let Ok(raw) = std::fs::read(&p) else { continue };
                buf.clear();
                if gzip {
                    GzDecoder::new(&raw[..]).take(len as u64 + 1).read_to_end(&mut buf).map_err(|x| e(bad(format!("{key}: {x}"))))?;
                } else {
                    buf.extend_from_slice(&raw);
                }
                if buf.len() != len {
                    return Err(e(bad(format!("{key}: {} bytes, a chunk holds {len}", buf.len()))));
                }
                let o = [a * chunk[0], b * chunk[1], c * chunk[2]];
                for (idx, &v) in buf.iter().enumerate() {
                    if v == 0 {
                        continue;
                    }
                    let idx = idx as u64;
                    let q = [idx / (chunk[1] * chunk[2]), (idx / chunk[2]) % chunk[1], idx % chunk[2]];
                    let g: [u64; 3] = std::array::from_fn(|x| o[x] + q[x]);
                    if g[0] < shape[0] && g[1] < shape[1] && g[2] < shape[2] {
                        bits.set(g[0] as u32, g[1] as u32, g[2] as u32);
                    }
                }
            }
        }
    }
    let vk = &m["attributes"]["voxkit"];
    let placement = match (vk["origin"].as_array(), vk["voxel_size"].as_f64()) {
        (Some(o), Some(s)) if o.len() == 3 && o.iter().all(|x| x.is_f64() || x.is_i64()) => {
            Some((glam::DVec3::new(o[0].as_f64().unwrap_or(0.0), o[1].as_f64().unwrap_or(0.0), o[2].as_f64().unwrap_or(0.0)), s))
        }
        _ => None,
    };
    Ok(LoadedVoxels { bits, placement, attributes: None })
}

#[cfg(test)]
mod tests {
    use super::*;
    use voxkit::DenseBits;

    #[test]
    fn round_trip_with_partial_chunks_and_replacement() {
        let dims = [130, 70, 9];
        let mut d = DenseBits::new(dims);
        for (i, j, k) in [(0, 0, 0), (63, 63, 8), (64, 0, 0), (129, 69, 8), (100, 7, 3)] {
            d.set(i, j, k);
        }
        let grid = GridSpec::new(glam::DVec3::new(-1.0, 2.0, 0.5), 0.25, dims.map(|x| x as u64)).unwrap();
        let dir = std::env::temp_dir().join(format!("voxkit-zarr-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("v.zarr");
        write(&out, &d, &grid).unwrap();
        let back = read(&out).unwrap();
        assert_eq!(back.bits, d);
        assert_eq!(back.placement, Some((grid.origin(), 0.25)));
        // Chunk (1, 0, 0) exists, chunk (1, 1, 0) (no voxel) does not.
        assert!(out.join("c/1/0/0").is_file() && !out.join("c/1/1/0").exists());
        // Writing again replaces the array; a non-Zarr directory is refused.
        let mut e = DenseBits::new(dims);
        e.set(5, 5, 5);
        write(&out, &e, &grid).unwrap();
        assert_eq!(read(&out).unwrap().bits, e);
        let other = dir.join("other.zarr");
        std::fs::create_dir_all(&other).unwrap();
        std::fs::write(other.join("keep.txt"), "mine").unwrap();
        assert!(write(&other, &e, &grid).is_err());
        assert_eq!(std::fs::read_to_string(other.join("keep.txt")).unwrap(), "mine");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
