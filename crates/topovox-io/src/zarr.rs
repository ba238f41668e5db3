//! Zarr v3 arrays (`OUT.zarr/`, a directory), written and read by hand.
//!
//! **Why by hand.** The `zarrs` crate, even without default features,
//! builds zlib from C and pulls async runtimes and caches; the part of the
//! format topovox needs — one array, regular chunks, the `bytes`, `gzip` and
//! `sharding_indexed` codecs — is a JSON document and, per shard, gzip
//! streams (`flate2`, already a dependency) followed by an index.
//!
//! **Layout.** `zarr.json`: `zarr_format` 3, `node_type` `array`, `shape`
//! `[nx, ny, nz]`, `data_type` `bool`, `chunk_grid` regular whose
//! `chunk_shape` is the shard (512 voxels a side, less on an axis shorter
//! than that, rounded up to 64), `chunk_key_encoding` `default` with `/`
//! (shard `(a, b, c)` at `c/a/b/c`), `fill_value` `false`, one codec,
//! `sharding_indexed`: inner chunks of 64³ encoded by `bytes` then `gzip`
//! (level 1), the index (`bytes`, little-endian) at the end of the shard,
//! without a checksum. `dimension_names` are `["i", "j", "k"]`, and
//! `attributes.topovox` holds the grid's `origin` and `voxel_size` (one
//! number for cubes, `[sx, sy, sz]` for boxes). Element
//! `[i, j, k]` is voxel `(i, j, k)` (C order, `k` fastest, as `.npy`).
//! Chunks holding no set voxel are not written (the index marks them empty
//! and the fill value stands for them), nor are shards without any, so a
//! sparse surface on a huge grid stays small: a 16384³ grid has at most
//! 32³ shard files instead of 256³ chunk files. Edge chunks are whole
//! chunks, padded with `false`. The Python `zarr` package (and Dask,
//! `dask.array.from_zarr`) opens it as one array; CI checks every voxel.
//!
//! **Attributes** (`--attributes`): the directory is a Zarr group
//! (`node_type` `group`, `attributes.topovox` with the grid and the array
//! names) holding the array above as `voxels/` and, with the same shards
//! and chunks, `colour/` (`uint8`, sRGB, shape `[nx, ny, nz, 3]`, chunks
//! `[64, 64, 64, 3]`, keys `c/a/b/c/0`), `normal/` (`float32`, 3
//! components likewise), `coverage/` (`float32`) and `material/`
//! (`int32`, fill -1: none), little-endian; elements off the voxels hold
//! the fill value.
//!
//! Distance fields (`topovox sdf`: one `float32` array, fill value the
//! background, `attributes.topovox.distance`) are read as their inside:
//! the negative elements, or for an unsigned field those within half a
//! voxel diagonal of the surface.
//!
//! The reader takes topovox's arrays and groups, and plain (unsharded) ones with the
//! `bytes` and `gzip` codecs, as the `zarr` package writes them; a shard
//! index's `crc32c` checksum, where present, is skipped, not verified
//! (every offset is still bounds-checked).
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
use topovox::attributes::{VoxelAttributes, NO_MATERIAL};
use topovox::distance::field::Field;
use topovox::grid::bricks::{set_in_brick, Brick};
use topovox::grid::sparse::SparseBricks;
use topovox::voxelize::Stop;
use topovox::{GridSpec, VoxelSource};

use crate::atomic::Temporary;
use crate::error::{ErrorKind, IoError};
use crate::resources::ReadOptions;
use crate::{LoadedVoxels, SparseVoxels};

/// Chunk edge in voxels (8 bricks).
pub const CHUNK: u32 = 64;

/// Largest shard edge in voxels (8 chunks, the tiled driver's default tile).
pub const SHARD: u32 = 512;

/// The shard shape of a grid: [`SHARD`], or the axis rounded up to
/// [`CHUNK`] where it is shorter.
fn shard_shape(dims: [u32; 3]) -> [u32; 3] {
    dims.map(|d| d.next_multiple_of(CHUNK).clamp(CHUNK, SHARD))
}

/// An empty inner chunk's index entry (offset and size both all ones).
const EMPTY: u64 = u64::MAX;

/// The grid placement topovox records in `attributes.topovox`.
fn placement(grid: &GridSpec) -> Value {
    let o = grid.origin();
    json!({"topovox": {"origin": [o.x, o.y, o.z], "voxel_size": crate::size_json(grid.voxel_size())}})
}

/// An array's metadata document: occupancy (`bool`), or an attribute with
/// `comps` components per voxel as a trailing axis `c` of that length.
fn metadata(grid: &GridSpec, kind: &Kind<'_>) -> Value {
    // Multi-byte values say their byte order; one-byte ones need none.
    let bytes = if kind.bytes as u32 > kind.comps {
        json!({"name": "bytes", "configuration": {"endian": "little"}})
    } else {
        json!({"name": "bytes"})
    };
    let (mut shape, mut shard, mut inner, mut names) =
        (grid.dims().to_vec(), shard_shape(grid.dims()).to_vec(), vec![CHUNK; 3], vec!["i", "j", "k"]);
    if kind.comps > 1 {
        shape.push(kind.comps);
        shard.push(kind.comps);
        inner.push(kind.comps);
        names.push("c");
    }
    json!({
        "zarr_format": 3,
        "node_type": "array",
        "shape": shape,
        "data_type": kind.data_type,
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": shard}},
        "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
        "fill_value": kind.fill_value,
        "codecs": [{"name": "sharding_indexed", "configuration": {
            "chunk_shape": inner,
            "codecs": [bytes, {"name": "gzip", "configuration": {"level": 1}}],
            "index_codecs": [{"name": "bytes", "configuration": {"endian": "little"}}],
            "index_location": "end",
        }}],
        "dimension_names": names,
        "attributes": placement(grid),
    })
}

/// Appends the value of the voxel in an attribute slot, little-endian.
type PutValue<'a> = Box<dyn Fn(usize, &mut Vec<u8>) + Sync + 'a>;

/// What one array holds: the occupancy (`put` is `None`: one byte, 1 where
/// set) or an attribute, `comps` values of `data_type` per voxel.
struct Kind<'a> {
    name: &'static str,
    data_type: &'static str,
    comps: u32,
    /// Bytes per voxel (all components).
    bytes: usize,
    fill_value: Value,
    /// One voxel's fill bytes.
    fill: Vec<u8>,
    put: Option<(&'a VoxelAttributes, PutValue<'a>)>,
}

/// The occupancy array.
fn occupancy<'a>() -> Kind<'a> {
    Kind { name: "voxels", data_type: "bool", comps: 1, bytes: 1, fill_value: json!(false), fill: vec![0], put: None }
}

/// The attribute arrays of `attrs`: `colour` (uint8 × 3, sRGB), `normal`
/// (float32 × 3), `coverage` (float32), `material` (int32, -1 for none).
/// An attribute array of `comps` values per voxel (`bytes` in all) and
/// `fill` elsewhere, when the attribute is present (`put`).
fn attribute_kind<'a>(
    attrs: &'a VoxelAttributes,
    (name, data_type, comps, bytes, fill): (&'static str, &'static str, u32, usize, i32),
    put: Option<PutValue<'a>>,
) -> Option<Kind<'a>> {
    let fill_value = if data_type == "float32" { json!(fill as f64) } else { json!(fill) };
    let fill = if data_type == "int32" { fill.to_le_bytes().to_vec() } else { vec![0; bytes] };
    put.map(|put| Kind { name, data_type, comps, bytes, fill_value, fill, put: Some((attrs, put)) })
}

fn attribute_arrays(attrs: &VoxelAttributes) -> Vec<Kind<'_>> {
    let f32s = |b: &mut Vec<u8>, v: &[f32]| v.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
    let kind = |name, data_type, comps, bytes, fill, put| attribute_kind(attrs, (name, data_type, comps, bytes, fill), put);
    let material = |m: u32| if m == NO_MATERIAL { -1 } else { m as i32 };
    [
        kind(
            "colour",
            "uint8",
            3,
            3,
            0,
            attrs.colour.as_ref().map(|c| -> PutValue<'_> { Box::new(move |s, b| b.extend_from_slice(&c[s])) }),
        ),
        kind("normal", "float32", 3, 12, 0, attrs.normal.as_ref().map(|n| -> PutValue<'_> { Box::new(move |s, b| f32s(b, &n[s])) })),
        kind("coverage", "float32", 1, 4, 0, attrs.coverage.as_ref().map(|c| -> PutValue<'_> { Box::new(move |s, b| f32s(b, &[c[s]])) })),
        kind(
            "material",
            "int32",
            1,
            4,
            -1,
            attrs.material.as_ref().map(|m| -> PutValue<'_> { Box::new(move |s, b| b.extend_from_slice(&material(m[s]).to_le_bytes())) }),
        ),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// One chunk's bytes (C order, `k` fastest, then the components) from its
/// bricks: 1 per set voxel for the occupancy, else each set voxel's value
/// and the fill value elsewhere.
fn chunk_bytes(bricks: &[([u32; 3], Brick)], kind: &Kind<'_>) -> std::io::Result<Vec<u8>> {
    let c = CHUNK as usize;
    let mut out = kind.fill.repeat(c * c * c);
    let mut value = Vec::with_capacity(kind.bytes);
    for (b, bits) in bricks {
        let base = b.map(|v| (v % (CHUNK / 8)) as usize * 8);
        for (z, &w) in bits.iter().enumerate() {
            let mut w = w;
            while w != 0 {
                let bit = w.trailing_zeros() as usize;
                w &= w - 1;
                let (i, j, k) = (base[0] + (bit & 7), base[1] + (bit >> 3), base[2] + z);
                let at = ((i * c + j) * c + k) * kind.bytes;
                match &kind.put {
                    None => out[at] = 1,
                    Some((attrs, put)) => {
                        let v = [b[0] * 8 + (bit & 7) as u32, b[1] * 8 + (bit >> 3) as u32, b[2] * 8 + z as u32];
                        let slot = attrs.slot(v[0], v[1], v[2]).ok_or_else(|| {
                            std::io::Error::other(format!("voxel {v:?} is set but has no attributes (voxels and attributes differ)"))
                        })?;
                        value.clear();
                        put(slot, &mut value);
                        out[at..at + kind.bytes].copy_from_slice(&value);
                    }
                }
            }
        }
    }
    Ok(out)
}

fn io(path: &Path, e: std::io::Error) -> IoError {
    IoError::new(path, ErrorKind::Write(e))
}

/// Writes `bits` on `grid` as a Zarr v3 array directory at `path`; with
/// `attrs` that have any array, a group holding the `voxels` array and one
/// array per attribute. An existing `path` is replaced only if it is an
/// empty folder or an array or group topovox wrote, holding nothing else
/// ([`check_replaceable`]); the new one is written to a temporary folder
/// beside it first. Once `stop` is requested the shards left are not
/// written and the temporary folder is removed ([`crate::atomic::stopped`]).
pub fn write(
    path: &Path,
    bits: &dyn VoxelSource,
    grid: &GridSpec,
    attrs: Option<&VoxelAttributes>,
    stop: Option<&Stop>,
) -> Result<(), IoError> {
    crate::atomic::recover_replaced(path);
    check_replaceable(path)?;
    crate::atomic::remove_stale_temporaries(path);
    let tmp = Temporary::create_dir(path).map_err(|e| io(path, e))?;
    let extra = attrs.map(attribute_arrays).unwrap_or_default();
    fill_all(tmp.path(), bits, grid, extra, stop).map_err(|e| io(path, e))?;
    crate::atomic::check_stop(stop).map_err(|e| io(path, e))?;
    crate::atomic::replace_dir(tmp, path).map_err(|e| io(path, e))
}

/// Writes a distance field on `grid` as a Zarr v3 `float32` array at
/// `path`, sharded and chunked as the occupancy ([`write`](fn@write), whose
/// replacement and stop rules apply), fill value `+background`: chunks
/// holding no band voxel and nothing inside are not written.
/// `attributes.topovox.distance` records the background and `signed`.
pub fn write_distance(path: &Path, field: &Field, grid: &GridSpec, signed: bool, stop: Option<&Stop>) -> Result<(), IoError> {
    crate::atomic::recover_replaced(path);
    check_replaceable(path)?;
    crate::atomic::remove_stale_temporaries(path);
    let tmp = Temporary::create_dir(path).map_err(|e| io(path, e))?;
    fill_distance(tmp.path(), field, grid, signed, stop).map_err(|e| io(path, e))?;
    crate::atomic::check_stop(stop).map_err(|e| io(path, e))?;
    crate::atomic::replace_dir(tmp, path).map_err(|e| io(path, e))
}

fn fill_distance(dir: &Path, field: &Field, grid: &GridSpec, signed: bool, stop: Option<&Stop>) -> std::io::Result<()> {
    let bg = field.background;
    let kind = Kind {
        name: "distance",
        data_type: "float32",
        comps: 1,
        bytes: 4,
        fill_value: json!(bg as f64),
        fill: bg.to_le_bytes().to_vec(),
        put: None,
    };
    let mut meta = metadata(grid, &kind);
    meta["attributes"]["topovox"]["distance"] = json!({"background": bg as f64, "signed": signed});
    std::fs::create_dir_all(dir)?;
    std::fs::write(dir.join("zarr.json"), serde_json::to_vec_pretty(&meta).map_err(std::io::Error::other)?)?;
    // The chunks holding a band voxel or an inside one, by shard.
    let per = CHUNK / 8;
    let shard = shard_shape(grid.dims());
    let inner = shard.map(|s| s / CHUNK);
    let mut chunks: Vec<[u32; 3]> = field.band.bricks.iter().map(|b| b.at.map(|v| v / per)).collect();
    if let Some(inside) = &field.inside {
        topovox::VoxelSource::for_each_brick_run(inside, &mut |b, _, n| {
            for x in (b[0] / per)..=((b[0] + n - 1) / per) {
                chunks.push([x, b[1] / per, b[2] / per]);
            }
        });
    }
    let shard_of = |c: &[u32; 3]| std::array::from_fn::<u32, 3, _>(|a| c[a] / inner[a]);
    chunks.par_sort_unstable_by_key(|c| (shard_of(c), *c));
    chunks.dedup();
    let shards = crate::runs(&chunks, shard_of);
    shards.par_iter().try_for_each(|r| -> std::io::Result<()> {
        crate::atomic::check_stop(stop)?;
        let s = shard_of(&chunks[r.start]);
        let mut body = Vec::new();
        let mut index = vec![EMPTY; 2 * (inner[0] * inner[1] * inner[2]) as usize];
        for c in &chunks[r.clone()] {
            let n = (((c[0] % inner[0]) * inner[1] + c[1] % inner[1]) * inner[2] + c[2] % inner[2]) as usize;
            let mut enc = GzEncoder::new(Vec::new(), flate2::Compression::new(1));
            enc.write_all(&distance_chunk(field, *c))?;
            let z = enc.finish()?;
            index[2 * n] = body.len() as u64;
            index[2 * n + 1] = z.len() as u64;
            body.extend_from_slice(&z);
        }
        body.extend(index.iter().flat_map(|v| v.to_le_bytes()));
        let d = dir.join("c").join(s[0].to_string()).join(s[1].to_string());
        std::fs::create_dir_all(&d)?;
        std::fs::write(d.join(s[2].to_string()), body)
    })
}

/// One chunk of a distance field, C order, little-endian float32.
fn distance_chunk(field: &Field, c: [u32; 3]) -> Vec<u8> {
    let n = CHUNK as usize;
    let mut values = vec![field.background; n * n * n];
    let per = CHUNK / 8;
    for bk in 0..per {
        for bj in 0..per {
            for bi in 0..per {
                let at = [c[0] * per + bi, c[1] * per + bj, c[2] * per + bk];
                let (v, _) = field.brick_values(at);
                for (slot, &x) in v.iter().enumerate() {
                    let (i, j, k) = (bi as usize * 8 + (slot & 7), bj as usize * 8 + (slot >> 3 & 7), bk as usize * 8 + (slot >> 6));
                    values[(i * n + j) * n + k] = x;
                }
            }
        }
    }
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// Refuses to write over `path` unless it does not exist, is an empty
/// folder, or is a Zarr array or group that topovox wrote (its
/// attributes say so) holding only what topovox writes there: replacing
/// a folder deletes it, so anything else of the user's is never touched.
pub fn check_replaceable(path: &Path) -> Result<(), IoError> {
    let refuse = |why: String| {
        Err(io(path, std::io::Error::other(format!("{why}; refusing to replace it (topovox replaces only its own Zarr arrays)"))))
    };
    let meta = match std::fs::symlink_metadata(path) {
        Err(_) => return Ok(()),
        Ok(m) => m,
    };
    if !meta.is_dir() {
        return refuse("exists and is not a folder".into());
    }
    let entries: Vec<String> =
        std::fs::read_dir(path).map_err(|e| io(path, e))?.flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect();
    if entries.is_empty() {
        return Ok(());
    }
    let node: Option<Value> = std::fs::symlink_metadata(path.join("zarr.json"))
        .ok()
        .filter(|m| m.is_file() && m.len() <= MAX_JSON_BYTES)
        .and_then(|_| std::fs::read(path.join("zarr.json")).ok())
        .and_then(|b| serde_json::from_slice(&b).ok());
    let Some(node) = node else {
        return refuse("exists and is not a Zarr array (no readable zarr.json)".into());
    };
    let ours = match &node["attributes"]["topovox"] {
        Value::Null => &node["attributes"][crate::former_name::ZARR_ATTRIBUTES],
        v => v,
    };
    let allowed: Vec<String> = match (node["node_type"].as_str(), ours) {
        (_, Value::Null) => return refuse("is a Zarr node topovox did not write".into()),
        (Some("array"), _) => vec!["zarr.json".into(), "c".into()],
        (Some("group"), v) => {
            let arrays = v["arrays"].as_array().map(|a| a.iter().filter_map(|x| x.as_str().map(String::from)).collect::<Vec<_>>());
            let Some(arrays) = arrays else { return refuse("is a Zarr group topovox did not write".into()) };
            std::iter::once("zarr.json".to_string()).chain(arrays).collect()
        }
        _ => return refuse("is not a Zarr array or group".into()),
    };
    let mut others: Vec<&String> = entries.iter().filter(|e| !allowed.contains(e)).collect();
    if !others.is_empty() {
        others.sort();
        return refuse(format!(
            "holds files topovox did not write ({})",
            others.iter().take(3).map(|s| s.as_str()).collect::<Vec<_>>().join(", ")
        ));
    }
    Ok(())
}

/// The occupancy array at `dir`, or with `extra` arrays a group there
/// holding `voxels` and them.
fn fill_all(dir: &Path, bits: &dyn VoxelSource, grid: &GridSpec, extra: Vec<Kind<'_>>, stop: Option<&Stop>) -> std::io::Result<()> {
    if extra.is_empty() {
        return fill(dir, bits, grid, &[occupancy()], stop);
    }
    std::fs::create_dir_all(dir)?;
    let names: Vec<&str> = std::iter::once("voxels").chain(extra.iter().map(|k| k.name)).collect();
    let mut attributes = placement(grid);
    attributes["topovox"]["arrays"] = json!(names);
    let group = json!({"zarr_format": 3, "node_type": "group", "attributes": attributes});
    std::fs::write(dir.join("zarr.json"), serde_json::to_vec_pretty(&group).map_err(std::io::Error::other)?)?;
    let mut kinds = vec![occupancy()];
    kinds.extend(extra);
    fill(dir, bits, grid, &kinds, stop)
}

/// Writes each of `kinds` as an array: at `dir` itself for the occupancy
/// alone, else at `dir/NAME`. The bricks are gathered and sorted once.
fn fill(dir: &Path, bits: &dyn VoxelSource, grid: &GridSpec, kinds: &[Kind<'_>], stop: Option<&Stop>) -> std::io::Result<()> {
    let alone = kinds.len() == 1;
    let dir_of = |k: &Kind<'_>| if alone { dir.to_path_buf() } else { dir.join(k.name) };
    for k in kinds {
        std::fs::create_dir_all(dir_of(k))?;
        std::fs::write(dir_of(k).join("zarr.json"), serde_json::to_vec_pretty(&metadata(grid, k)).map_err(std::io::Error::other)?)?;
    }
    // Bricks grouped by shard, then by chunk within it (C order of chunks).
    let shard = shard_shape(grid.dims());
    let inner = shard.map(|s| s / CHUNK);
    let per = CHUNK / 8;
    let mut bricks: Vec<([u32; 3], Brick)> = Vec::new();
    bits.for_each_brick(&mut |b, bits| bricks.push((b, *bits)));
    let chunk_of = |b: &[u32; 3]| b.map(|v| v / per);
    let shard_of = |c: [u32; 3]| std::array::from_fn::<u32, 3, _>(|a| c[a] / inner[a]);
    bricks.par_sort_unstable_by_key(|(b, _)| {
        let c = chunk_of(b);
        (shard_of(c), c)
    });
    let shards = crate::runs(&bricks, |(b, _)| shard_of(chunk_of(b)));
    let work: Vec<(&Kind<'_>, &std::ops::Range<usize>)> = kinds.iter().flat_map(|k| shards.iter().map(move |r| (k, r))).collect();
    work.par_iter().try_for_each(|&(kind, r)| -> std::io::Result<()> {
        crate::atomic::check_stop(stop)?;
        let s = shard_of(chunk_of(&bricks[r.start].0));
        let mut body = Vec::new();
        let mut index = vec![EMPTY; 2 * (inner[0] * inner[1] * inner[2]) as usize];
        for g in crate::runs(&bricks[r.clone()], |(b, _)| chunk_of(b)) {
            let g = r.start + g.start..r.start + g.end;
            let c = chunk_of(&bricks[g.start].0);
            let n = (((c[0] % inner[0]) * inner[1] + c[1] % inner[1]) * inner[2] + c[2] % inner[2]) as usize;
            let mut enc = GzEncoder::new(Vec::new(), flate2::Compression::new(1));
            enc.write_all(&chunk_bytes(&bricks[g], kind)?)?;
            let z = enc.finish()?;
            index[2 * n] = body.len() as u64;
            index[2 * n + 1] = z.len() as u64;
            body.extend_from_slice(&z);
        }
        body.extend(index.iter().flat_map(|v| v.to_le_bytes()));
        // Shard (a, b, c) at `c/a/b/c`; with a component axis (one chunk
        // along it) at `c/a/b/c/0`.
        let mut d = dir_of(kind).join("c").join(s[0].to_string()).join(s[1].to_string());
        let mut file = s[2].to_string();
        if kind.comps > 1 {
            d = d.join(file);
            file = "0".to_string();
        }
        std::fs::create_dir_all(&d)?;
        std::fs::write(d.join(file), body)
    })
}

fn bad(what: impl Into<String>) -> ErrorKind {
    ErrorKind::malformed("Zarr", what.into())
}

/// Largest chunk topovox reads (elements): a hostile `zarr.json` can claim
/// any chunk shape.
const MAX_CHUNK_ELEMENTS: u64 = 1 << 30;

/// Most chunk entries topovox lists in an array's folders (the chunks are
/// found by listing, so this bounds the work a folder of junk can cause,
/// not the size a `zarr.json` may claim).
const MAX_CHUNKS: u64 = 1 << 24;

/// How an array's chunk files are encoded.
#[derive(Clone, Copy)]
enum Layout {
    /// One chunk per file: `bytes`, then `gzip` or not.
    Plain { gzip: bool },
    /// One shard per file: inner chunks of `inner` (`bytes`, `gzip` or
    /// not) and an index of (offset, size) pairs, with a 4-byte checksum or
    /// not, at the end or the start.
    Sharded { inner: [u64; 3], gzip: bool, checksum: bool, at_end: bool },
}

/// Whether chunk codecs `bytes` (and optionally `gzip`) ask for gzip.
fn chunk_codecs(codecs: &[Value]) -> Result<bool, ErrorKind> {
    let mut gzip = false;
    for c in codecs {
        match c["name"].as_str() {
            Some("bytes") => {}
            Some("gzip") => gzip = true,
            other => return Err(bad(format!("codec {other:?} (topovox reads bytes, gzip and sharding_indexed)"))),
        }
    }
    Ok(gzip)
}

/// Decodes one chunk of `len` bytes into `buf`.
fn decode(raw: &[u8], gzip: bool, len: u64, buf: &mut Vec<u8>) -> Result<(), ErrorKind> {
    buf.clear();
    if gzip {
        GzDecoder::new(raw).take(len + 1).read_to_end(buf).map_err(|x| bad(x.to_string()))?;
    } else {
        buf.extend_from_slice(raw);
    }
    if buf.len() as u64 != len {
        return Err(bad(format!("{} bytes, a chunk holds {len}", buf.len())));
    }
    Ok(())
}

/// Sets the voxels of a decoded chunk of `shape` at `origin` (elements
/// past the array's `dims` are padding).
fn place(bits: &mut topovox::DenseBits, buf: &[u8], origin: [u64; 3], shape: [u64; 3], dims: [u64; 3]) {
    for (idx, &v) in buf.iter().enumerate() {
        if v == 0 {
            continue;
        }
        let idx = idx as u64;
        let q = [idx / (shape[1] * shape[2]), (idx / shape[2]) % shape[1], idx % shape[2]];
        let g: [u64; 3] = std::array::from_fn(|x| origin[x] + q[x]);
        if g[0] < dims[0] && g[1] < dims[1] && g[2] < dims[2] {
            bits.set(g[0] as u32, g[1] as u32, g[2] as u32);
        }
    }
}

/// A Zarr v3 array's metadata, as topovox reads it.
struct ArrayMeta {
    /// Voxels per axis.
    shape: [u64; 3],
    /// The chunk (or shard) shape over the voxel axes.
    chunk: [u64; 3],
    /// Components per voxel: the length of a fourth axis, or 1 without one.
    comps: u64,
    /// The array has that fourth axis (its chunk keys have four indices).
    four_axes: bool,
    data_type: String,
    sep: String,
    layout: Layout,
    attributes: Value,
}

/// The folder a Zarr hierarchy is read from: every file read below it is
/// a regular file (not a device or a FIFO), read with a bound, and lies
/// inside the folder once links are resolved, unless external paths are
/// allowed.
struct Store {
    /// The folder the user named, canonical.
    root: PathBuf,
    allow_external: bool,
}

/// Largest `zarr.json` read (attributes included).
const MAX_JSON_BYTES: u64 = 16 << 20;

impl Store {
    fn open(path: &Path, opts: &ReadOptions) -> Result<Store, IoError> {
        let root = std::fs::canonicalize(path).map_err(|x| IoError::new(path, ErrorKind::Read(x)))?;
        Ok(Store { root, allow_external: opts.allow_external_paths })
    }

    /// `path` (below the store), checked: inside the store once links are
    /// resolved (unless allowed), and a regular file. `Ok(None)` when it
    /// does not exist.
    fn file(&self, path: &Path) -> Result<Option<PathBuf>, IoError> {
        let real = match std::fs::canonicalize(path) {
            Ok(r) => r,
            Err(x) if x.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(x) => return Err(IoError::new(path, ErrorKind::Read(x))),
        };
        if !self.allow_external && !real.starts_with(&self.root) {
            return Err(IoError::new(
                path,
                bad(format!(
                    "a link leads outside the Zarr folder {} (to {}); not read (--allow-external-paths reads it)",
                    self.root.display(),
                    real.display()
                )),
            ));
        }
        let meta = std::fs::metadata(&real).map_err(|x| IoError::new(path, ErrorKind::Read(x)))?;
        if !meta.is_file() {
            return Err(IoError::new(path, bad("not a regular file (a device, a FIFO or a folder); not read")));
        }
        Ok(Some(real))
    }

    /// The bytes of the regular file `path` (see [`Store::file`]), at most
    /// `max`; `Ok(None)` when it does not exist.
    fn read(&self, path: &Path, max: u64) -> Result<Option<Vec<u8>>, IoError> {
        let Some(real) = self.file(path)? else { return Ok(None) };
        let e = |x| IoError::new(path, ErrorKind::Read(x));
        let mut out = Vec::new();
        std::fs::File::open(&real).map_err(e)?.take(max + 1).read_to_end(&mut out).map_err(e)?;
        if out.len() as u64 > max {
            return Err(IoError::new(path, bad(format!("larger than the {max} bytes it may hold"))));
        }
        Ok(Some(out))
    }

    /// Whether `dir` holds a `zarr.json` (checked like every file).
    fn has_node(&self, dir: &Path) -> Result<bool, IoError> {
        Ok(self.file(&dir.join("zarr.json"))?.is_some())
    }
}

/// Reads `path/zarr.json`, which must be a Zarr v3 node.
fn node(store: &Store, path: &Path) -> Result<Value, IoError> {
    let e = |k| IoError::new(path, k);
    let json = path.join("zarr.json");
    let text = store.read(&json, MAX_JSON_BYTES)?.ok_or_else(|| e(ErrorKind::Read(std::io::ErrorKind::NotFound.into())))?;
    let m: Value = serde_json::from_slice(&text).map_err(|x| e(bad(format!("zarr.json: {x}"))))?;
    if m["zarr_format"] != 3 || !matches!(m["node_type"].as_str(), Some("array" | "group")) {
        return Err(e(bad("zarr.json is not a Zarr v3 array or group")));
    }
    Ok(m)
}

/// The metadata of the array `m` at `path`: three voxel axes, and with
/// `max_comps` above 1 optionally a fourth of at most that many components
/// (whole in every chunk).
fn array_meta(path: &Path, m: &Value, max_comps: u64) -> Result<ArrayMeta, IoError> {
    let e = |k| IoError::new(path, k);
    if m["node_type"] != "array" {
        return Err(e(bad("zarr.json is not a Zarr v3 array")));
    }
    // The voxel axes, and the component axis (1 when absent).
    let axes = |v: &Value, what: &str| -> Result<([u64; 3], u64), IoError> {
        let a = v.as_array().filter(|a| a.len() == 3 || (max_comps > 1 && a.len() == 4)).ok_or_else(|| {
            e(bad(if max_comps > 1 { format!("{what} must have three or four axes") } else { format!("{what} must have three axes") }))
        })?;
        let mut out = [0u64; 3];
        for (o, x) in out.iter_mut().zip(a) {
            *o = x
                .as_u64()
                .filter(|&x| x > 0 && x <= topovox::grid::spec::MAX_DIM as u64)
                .ok_or_else(|| e(bad(format!("{what}: {x} is not a size from 1 to {}", topovox::grid::spec::MAX_DIM))))?;
        }
        let comps = match a.get(3) {
            None => 1,
            Some(x) => x
                .as_u64()
                .filter(|&c| (1..=max_comps).contains(&c))
                .ok_or_else(|| e(bad(format!("{what}: {x} components (topovox reads 1 to {max_comps})"))))?,
        };
        Ok((out, comps))
    };
    let (shape, comps) = axes(&m["shape"], "shape")?;
    let four_axes = m["shape"].as_array().is_some_and(|a| a.len() == 4);
    if m["chunk_grid"]["name"] != "regular" {
        return Err(e(bad("only regular chunk grids are read")));
    }
    let whole =
        |c: u64, what: &str| if c == comps { Ok(()) } else { Err(e(bad(format!("{what} splits the {comps} components of a voxel")))) };
    let (chunk, c) = axes(&m["chunk_grid"]["configuration"]["chunk_shape"], "chunk_shape")?;
    whole(c, "chunk_shape")?;
    if chunk.iter().product::<u64>() * comps > MAX_CHUNK_ELEMENTS {
        return Err(e(bad(format!("chunk shape {chunk:?} is larger than topovox reads"))));
    }
    let sep = match m["chunk_key_encoding"]["name"].as_str() {
        Some("default") => match m["chunk_key_encoding"]["configuration"]["separator"].as_str().unwrap_or("/") {
            // The only two the Zarr v3 specification allows: anything else
            // would let a key name a path outside the array.
            sep @ ("/" | ".") => sep.to_string(),
            other => return Err(e(bad(format!("chunk key separator {other:?} (the specification allows \"/\" and \".\")")))),
        },
        other => return Err(e(bad(format!("chunk_key_encoding {other:?} (topovox reads default)")))),
    };
    let codecs = m["codecs"].as_array().ok_or_else(|| e(bad("no codecs")))?;
    let layout = match &codecs[..] {
        [c] if c["name"] == "sharding_indexed" => {
            let conf = &c["configuration"];
            let (inner, c) = axes(&conf["chunk_shape"], "sharding chunk_shape")?;
            whole(c, "sharding chunk_shape")?;
            if (0..3).any(|a| chunk[a] % inner[a] != 0) {
                return Err(e(bad(format!("shard shape {chunk:?} is not a multiple of its chunk shape {inner:?}"))));
            }
            let gzip = chunk_codecs(conf["codecs"].as_array().ok_or_else(|| e(bad("sharding without codecs")))?).map_err(e)?;
            let mut checksum = false;
            for c in conf["index_codecs"].as_array().ok_or_else(|| e(bad("sharding without index_codecs")))? {
                match c["name"].as_str() {
                    Some("bytes") if c["configuration"]["endian"].as_str().unwrap_or("little") == "little" => {}
                    Some("crc32c") => checksum = true,
                    other => return Err(e(bad(format!("index codec {other:?} (topovox reads little-endian bytes and crc32c)")))),
                }
            }
            let at_end = match conf["index_location"].as_str().unwrap_or("end") {
                "end" => true,
                "start" => false,
                other => return Err(e(bad(format!("index_location {other:?}")))),
            };
            Layout::Sharded { inner, gzip, checksum, at_end }
        }
        _ => Layout::Plain { gzip: chunk_codecs(codecs).map_err(e)? },
    };
    let data_type = m["data_type"].as_str().unwrap_or("").to_string();
    Ok(ArrayMeta { shape, chunk, comps, four_axes, data_type, sep, layout, attributes: m["attributes"].clone() })
}

/// The grid indices of the chunks the array at `path` stores, in C order,
/// found by listing its folders (never by probing every index a shape
/// allows: a hostile `zarr.json` can claim billions). Names that are not
/// chunk keys of this array are ignored.
fn stored_chunks(path: &Path, a: &ArrayMeta) -> Result<Vec<[u64; 3]>, IoError> {
    let n = [0, 1, 2].map(|x| a.shape[x].div_ceil(a.chunk[x]));
    let depth = if a.four_axes { 4 } else { 3 };
    let index = |s: &str, axis: usize| -> Option<u64> {
        let v = s.parse::<u64>().ok().filter(|v| v.to_string() == s)?;
        if axis < 3 {
            (v < n[axis]).then_some(v)
        } else {
            (v == 0).then_some(v)
        }
    };
    let names = |dir: &Path| -> Result<Vec<String>, IoError> {
        match std::fs::read_dir(dir) {
            Ok(entries) => Ok(entries.flatten().filter_map(|e| e.file_name().into_string().ok()).collect()),
            Err(x) if x.kind() == std::io::ErrorKind::NotFound || x.kind() == std::io::ErrorKind::NotADirectory => Ok(Vec::new()),
            Err(x) => Err(IoError::new(dir, ErrorKind::Read(x))),
        }
    };
    let mut found = Vec::new();
    if a.sep == "." {
        for name in names(path)? {
            let parts: Vec<&str> = name.split('.').collect();
            if parts.len() == depth + 1 && parts[0] == "c" {
                let idx: Option<Vec<u64>> = parts[1..].iter().enumerate().map(|(x, p)| index(p, x)).collect();
                if let Some(idx) = idx {
                    found.push([idx[0], idx[1], idx[2]]);
                }
            }
        }
    } else {
        // c/i/j/k (and /0): walk the folders level by level.
        let mut level: Vec<(PathBuf, Vec<u64>)> = vec![(path.join("c"), Vec::new())];
        for axis in 0..depth {
            let mut next = Vec::new();
            for (dir, idx) in &level {
                for name in names(dir)? {
                    if let Some(v) = index(&name, axis) {
                        let mut idx = idx.clone();
                        idx.push(v);
                        next.push((dir.join(&name), idx));
                    }
                }
            }
            level = next;
            if level.len() as u64 > MAX_CHUNKS {
                return Err(IoError::new(path, bad(format!("more than {MAX_CHUNKS} chunk entries"))));
            }
        }
        found.extend(level.into_iter().map(|(_, idx)| [idx[0], idx[1], idx[2]]));
    }
    found.sort_unstable();
    found.dedup();
    Ok(found)
}

/// The path of chunk `c` of the array at `path`, from validated parts only.
fn chunk_path(path: &Path, a: &ArrayMeta, c: [u64; 3]) -> PathBuf {
    let mut parts = vec!["c".to_string(), c[0].to_string(), c[1].to_string(), c[2].to_string()];
    if a.four_axes {
        parts.push("0".to_string()); // the one chunk along the component axis
    }
    if a.sep == "." {
        path.join(parts.join("."))
    } else {
        parts.iter().fold(path.to_path_buf(), |p, x| p.join(x))
    }
}

/// Largest file a chunk (or shard) of `a` can be: its elements' bytes,
/// per inner chunk when sharded, with room for gzip's framing and for
/// incompressible data, plus the shard index.
fn max_chunk_file(a: &ArrayMeta, elem: u64) -> u64 {
    let framed = |elements: u64| {
        let raw = elements * a.comps * elem;
        raw + raw / 64 + 1024
    };
    match a.layout {
        Layout::Plain { .. } => framed(a.chunk.iter().product()),
        Layout::Sharded { inner, .. } => {
            let count = (0..3).map(|x| a.chunk[x] / inner[x]).product::<u64>();
            count * (framed(inner.iter().product()) + 16) + 4
        }
    }
}

/// Calls `f(origin, shape, bytes)` for every chunk the array at `path`
/// stores, decoded (C order, components last; `elem` bytes per component).
fn for_each_chunk(
    store: &Store,
    path: &Path,
    a: &ArrayMeta,
    elem: u64,
    mut f: impl FnMut([u64; 3], [u64; 3], &[u8]),
) -> Result<(), IoError> {
    let max_file = max_chunk_file(a, elem);
    let mut buf = Vec::new();
    for c in stored_chunks(path, a)? {
        let file = chunk_path(path, a, c);
        let Some(raw) = store.read(&file, max_file)? else { continue };
        let key = file.strip_prefix(path).unwrap_or(&file).display().to_string();
        let at = |x: ErrorKind| match x {
            ErrorKind::Malformed { format, detail } => {
                IoError::new(path, ErrorKind::Malformed { format, detail: format!("{key}: {detail}") })
            }
            x => IoError::new(path, x),
        };
        let origin = [0, 1, 2].map(|x| c[x] * a.chunk[x]);
        decode_chunk_file(&raw, a, elem, origin, &mut buf, &mut f).map_err(at)?;
    }
    Ok(())
}

/// Decodes one chunk file of `a` at `origin` (a plain chunk, or a shard of
/// inner chunks) and hands each chunk to `f`.
fn decode_chunk_file(
    raw: &[u8],
    a: &ArrayMeta,
    elem: u64,
    origin: [u64; 3],
    buf: &mut Vec<u8>,
    f: &mut impl FnMut([u64; 3], [u64; 3], &[u8]),
) -> Result<(), ErrorKind> {
    let bytes = |shape: [u64; 3]| shape.iter().product::<u64>() * a.comps * elem;
    match a.layout {
        Layout::Plain { gzip } => {
            decode(raw, gzip, bytes(a.chunk), buf)?;
            f(origin, a.chunk, buf);
        }
        Layout::Sharded { inner, gzip, checksum, at_end } => {
            let per = [0, 1, 2].map(|x| a.chunk[x] / inner[x]);
            let count = per.iter().product::<u64>() as usize;
            let index_len = 16 * count + if checksum { 4 } else { 0 };
            if index_len > raw.len() {
                return Err(bad(format!("{} bytes, less than its shard index ({index_len})", raw.len())));
            }
            let index = if at_end { &raw[raw.len() - index_len..] } else { &raw[..index_len] };
            let word = |x: usize| u64::from_le_bytes(index[8 * x..8 * x + 8].try_into().expect("8 bytes"));
            for q in 0..count {
                let (off, len) = (word(2 * q), word(2 * q + 1));
                if off == EMPTY && len == EMPTY {
                    continue;
                }
                let Some(bytes_at) =
                    off.checked_add(len).filter(|&end| end <= raw.len() as u64).map(|end| &raw[off as usize..end as usize])
                else {
                    return Err(bad(format!("inner chunk {q} at bytes {off}+{len}, outside the shard")));
                };
                decode(bytes_at, gzip, bytes(inner), buf)?;
                let qi = [q as u64 / (per[1] * per[2]), (q as u64 / per[2]) % per[1], q as u64 % per[2]];
                f(std::array::from_fn(|x| origin[x] + qi[x] * inner[x]), inner, buf);
            }
        }
    }
    Ok(())
}

/// The grid placement in `attributes.topovox`, when recorded.
fn read_placement(attributes: &Value) -> Option<(glam::DVec3, glam::DVec3)> {
    let vk = match &attributes["topovox"] {
        Value::Null => &attributes[crate::former_name::ZARR_ATTRIBUTES],
        v => v,
    };
    match (vk["origin"].as_array(), crate::size_from_json(&vk["voxel_size"])) {
        (Some(o), Some(s)) if o.len() == 3 && o.iter().all(|x| x.is_f64() || x.is_i64()) => {
            Some((glam::DVec3::new(o[0].as_f64().unwrap_or(0.0), o[1].as_f64().unwrap_or(0.0), o[2].as_f64().unwrap_or(0.0)), s))
        }
        _ => None,
    }
}

/// Reads a Zarr v3 array of `bool` or `uint8` (non-zero = set) with
/// regular chunks, the `bytes` codec and optionally `gzip`, sharded
/// (`sharding_indexed`) or not: topovox's own arrays and those written the
/// same way by the `zarr` package. A group (topovox's layout with
/// attributes) is read as its `voxels` array and the attribute arrays
/// beside it (`colour`, `normal`, `coverage`, `material`).
///
/// Every file read lies inside `path` once links are resolved (unless
/// `opts` allows external paths) and is a regular file, read with the
/// bound its format allows; chunks are found by listing the folders, so
/// the work follows what is stored, not what `zarr.json` claims.
pub fn read(path: &Path, opts: &ReadOptions) -> Result<LoadedVoxels, IoError> {
    let store = Store::open(path, opts)?;
    let m = node(&store, path)?;
    if m["node_type"] == "array" {
        return read_occupancy(&store, path, &m);
    }
    let voxels = path.join("voxels");
    if !store.has_node(&voxels)? {
        return Err(IoError::new(path, bad("a Zarr group without a `voxels` array (topovox reads its own groups, or an array)")));
    }
    let mut loaded = read_occupancy(&store, &voxels, &node(&store, &voxels)?)?;
    if loaded.placement.is_none() {
        loaded.placement = read_placement(&m["attributes"]);
    }
    loaded.attributes = read_attributes(&store, path, &loaded.bits)?;
    Ok(loaded)
}

/// The attribute arrays of a topovox group (`colour`, `normal`, `coverage`,
/// `material`) at the set voxels of `voxels` (any storage), or `None`
/// when the group has none. Each stored chunk is visited row by row
/// through the voxels' sorted keys, so the work follows the set voxels
/// and the chunks' rows, not the chunks' volume.
fn read_attributes(store: &Store, path: &Path, voxels: &dyn VoxelSource) -> Result<Option<VoxelAttributes>, IoError> {
    let dims = voxels.dims();
    let mut attrs = VoxelAttributes { dims, keys: Vec::new(), ..Default::default() };
    let mut any = false;
    for (name, data_type, comps) in [("colour", "uint8", 3), ("normal", "float32", 3), ("coverage", "float32", 1), ("material", "int32", 1)]
    {
        let dir = path.join(name);
        if !store.has_node(&dir)? {
            continue;
        }
        if !any {
            attrs.keys = VoxelAttributes::keys_of(voxels);
        }
        let a = array_meta(&dir, &node(store, &dir)?, 3)?;
        if a.data_type != data_type || a.comps != comps || a.shape != dims.map(u64::from) {
            return Err(IoError::new(
                &dir,
                bad(format!(
                    "{} × {} over {:?}; topovox reads {name} as {data_type} × {comps} over the voxels' {dims:?}",
                    a.data_type, a.comps, a.shape
                )),
            ));
        }
        // Each set voxel's value bytes, by slot (the fill value where no chunk is stored).
        let elem = if data_type == "uint8" { 1 } else { 4 };
        let size = elem * comps as usize;
        let fill: Vec<u8> = if name == "material" { (-1i32).to_le_bytes().to_vec() } else { vec![0; size] };
        let mut vals = fill.repeat(attrs.keys.len());
        let keys = &attrs.keys;
        for_each_chunk(store, &dir, &a, elem as u64, |o, shape, buf| {
            // The chunk's rows along i (its elements are laid out i, j, k
            // with k fastest); each row's set voxels are a range of keys.
            let end = [0, 1, 2].map(|x| (o[x] + shape[x]).min(dims[x] as u64));
            if (0..3).any(|x| o[x] >= end[x]) {
                return;
            }
            let key = |i: u64, j: u64, k: u64| VoxelAttributes::key(dims, i as u32, j as u32, k as u32);
            for k in o[2]..end[2] {
                // The keys of this plane's part of the chunk, then row by row
                // within them (rows ascend with j).
                let (mut lo, ph) =
                    (keys.partition_point(|&x| x < key(o[0], o[1], k)), keys.partition_point(|&x| x <= key(end[0] - 1, end[1] - 1, k)));
                if lo >= ph {
                    continue;
                }
                for j in o[1]..end[1] {
                    lo += keys[lo..ph].partition_point(|&x| x < key(o[0], j, k));
                    let hi = lo + keys[lo..ph].partition_point(|&x| x <= key(end[0] - 1, j, k));
                    let row0 = key(0, j, k);
                    for (s, &kk) in keys[lo..hi].iter().enumerate() {
                        let i = kk - row0;
                        let n = (((i - o[0]) * shape[1] + (j - o[1])) * shape[2] + (k - o[2])) as usize;
                        let slot = lo + s;
                        vals[slot * size..(slot + 1) * size].copy_from_slice(&buf[n * size..(n + 1) * size]);
                    }
                }
            }
        })?;
        let f = |b: &[u8]| f32::from_le_bytes(b.try_into().expect("4 bytes"));
        match name {
            "colour" => attrs.colour = Some(vals.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()),
            "normal" => attrs.normal = Some(vals.chunks_exact(12).map(|c| [f(&c[0..4]), f(&c[4..8]), f(&c[8..12])]).collect()),
            "coverage" => attrs.coverage = Some(vals.chunks_exact(4).map(f).collect()),
            _ => {
                let id = |c: &[u8]| u32::try_from(i32::from_le_bytes(c.try_into().expect("4 bytes"))).unwrap_or(NO_MATERIAL);
                attrs.material = Some(vals.chunks_exact(4).map(id).collect());
            }
        }
        any = true;
    }
    Ok(any.then_some(attrs))
}

/// A Zarr array's voxels (or those of a topovox group's `voxels` array)
/// as sparse bricks, without a dense grid: memory follows the set voxels.
/// Also the placement and, with `attributes`, a group's attribute arrays
/// at the set voxels (about 32 bytes per voxel); otherwise whether any
/// were left unread.
pub fn read_sparse(path: &Path, attributes: bool, opts: &ReadOptions) -> Result<SparseVoxels, IoError> {
    let store = Store::open(path, opts)?;
    let m = node(&store, path)?;
    let (dir, m, placement, attributes_left) = if m["node_type"] == "group" {
        let voxels = path.join("voxels");
        if !store.has_node(&voxels)? {
            return Err(IoError::new(path, bad("a Zarr group without a `voxels` array (topovox reads its own groups, or an array)")));
        }
        let mut attributes = false;
        for n in ["colour", "normal", "coverage", "material"] {
            attributes |= store.has_node(&path.join(n))?;
        }
        (voxels.clone(), node(&store, &voxels)?, read_placement(&m["attributes"]), attributes)
    } else {
        (path.to_path_buf(), m, None, false)
    };
    let a = array_meta(&dir, &m, 1)?;
    let elements = Elements::of(&a).map_err(|k| IoError::new(&dir, k))?;
    if a.shape.iter().any(|&d| d > SparseBricks::MAX_DIM as u64) {
        return Err(IoError::new(&dir, bad(format!("shape {:?} beyond {} voxels per axis", a.shape, SparseBricks::MAX_DIM))));
    }
    let mut bricks = Vec::new();
    for_each_chunk(&store, &dir, &a, elements.size(), |o, shape, buf| place_bricks(&mut bricks, &elements.set(buf), o, shape, a.shape))?;
    let placement = read_placement(&a.attributes).or(placement);
    let bits = SparseBricks::from_parts(a.shape.map(|d| d as u32), bricks, Vec::new());
    let attrs = if attributes && attributes_left { read_attributes(&store, path, &bits)? } else { None };
    Ok(SparseVoxels { bits, placement, attributes_left: attributes_left && attrs.is_none(), attributes: attrs })
}

/// Appends the non-empty bricks of a decoded chunk of `shape` at `origin`
/// (any alignment; elements past `dims` are padding).
fn place_bricks(out: &mut Vec<([u32; 3], Brick)>, buf: &[u8], origin: [u64; 3], shape: [u64; 3], dims: [u64; 3]) {
    if (0..3).any(|x| origin[x] >= dims[x]) {
        return;
    }
    let lo = origin.map(|c| c / 8);
    let hi: [u64; 3] = std::array::from_fn(|x| ((origin[x] + shape[x]).min(dims[x]) - 1) / 8);
    let n: [usize; 3] = std::array::from_fn(|x| (hi[x] - lo[x] + 1) as usize);
    let mut local = vec![[0u64; 8]; n[0] * n[1] * n[2]];
    for (g, group) in buf.chunks(8).enumerate() {
        if group.iter().all(|&v| v == 0) {
            continue;
        }
        for (e, &v) in group.iter().enumerate() {
            if v == 0 {
                continue;
            }
            let idx = (8 * g + e) as u64;
            let q = [idx / (shape[1] * shape[2]), (idx / shape[2]) % shape[1], idx % shape[2]];
            let p: [u64; 3] = std::array::from_fn(|x| origin[x] + q[x]);
            if (0..3).any(|x| p[x] >= dims[x]) {
                continue;
            }
            let b: [usize; 3] = std::array::from_fn(|x| (p[x] / 8 - lo[x]) as usize);
            set_in_brick(&mut local[(b[2] * n[1] + b[1]) * n[0] + b[0]], p[0] as u32, p[1] as u32, p[2] as u32);
        }
    }
    for (at, brick) in local.into_iter().enumerate() {
        if brick != [0; 8] {
            let b = [at % n[0], at / n[0] % n[1], at / (n[0] * n[1])];
            out.push((std::array::from_fn(|x| (lo[x] + b[x] as u64) as u32), brick));
        }
    }
}

/// What an array's elements are and which make a voxel set.
enum Elements {
    /// bool or uint8: nonzero.
    Bytes,
    /// A float32 distance field (`topovox sdf`): negative (signed), or
    /// within this distance (unsigned: half a voxel diagonal).
    Distance(Option<f32>),
}

impl Elements {
    fn of(a: &ArrayMeta) -> Result<Elements, ErrorKind> {
        match a.data_type.as_str() {
            "bool" | "uint8" => Ok(Elements::Bytes),
            "float32" => {
                let ours = &a.attributes["topovox"];
                let unsigned = ours["distance"]["signed"] == json!(false);
                let near = crate::size_from_json(&ours["voxel_size"]).map(|s| crate::half_diagonal(s) as f32);
                match (unsigned, near) {
                    (false, _) => Ok(Elements::Distance(None)),
                    (true, Some(n)) => Ok(Elements::Distance(Some(n))),
                    (true, None) => Err(bad("an unsigned distance field without its voxel size")),
                }
            }
            t => Err(bad(format!("data_type {t:?} (topovox reads bool and uint8, and float32 distance fields)"))),
        }
    }

    /// Bytes per element.
    fn size(&self) -> u64 {
        match self {
            Elements::Bytes => 1,
            Elements::Distance(_) => 4,
        }
    }

    /// One byte per element of a decoded chunk: nonzero where set.
    fn set<'b>(&self, buf: &'b [u8]) -> std::borrow::Cow<'b, [u8]> {
        match self {
            Elements::Bytes => std::borrow::Cow::Borrowed(buf),
            Elements::Distance(near) => {
                let test = |v: f32| near.map_or(v < 0.0, |n| v <= n);
                buf.chunks_exact(4).map(|x| test(f32::from_le_bytes(x.try_into().expect("4 bytes"))) as u8).collect()
            }
        }
    }
}

/// The occupancy array `m` at `path`.
fn read_occupancy(store: &Store, path: &Path, m: &Value) -> Result<LoadedVoxels, IoError> {
    let e = |k| IoError::new(path, k);
    let a = array_meta(path, m, 1)?;
    let elements = Elements::of(&a).map_err(e)?;
    let dims = a.shape.map(|d| d as u32);
    let mut bits = crate::dense_grid(dims).map_err(e)?;
    for_each_chunk(store, path, &a, elements.size(), |o, shape, buf| place(&mut bits, &elements.set(buf), o, shape, a.shape))?;
    Ok(LoadedVoxels { bits, placement: read_placement(&a.attributes), attributes: None })
}

#[cfg(test)]
mod tests {
    use super::*;
    use topovox::DenseBits;

    #[test]
    fn round_trip_with_partial_chunks_and_replacement() {
        let dims = [130, 70, 9];
        let mut d = DenseBits::new(dims);
        for (i, j, k) in [(0, 0, 0), (63, 63, 8), (64, 0, 0), (129, 69, 8), (100, 7, 3)] {
            d.set(i, j, k);
        }
        let grid = GridSpec::new(glam::DVec3::new(-1.0, 2.0, 0.5), 0.25, dims.map(|x| x as u64)).unwrap();
        let dir = std::env::temp_dir().join(format!("topovox-zarr-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("v.zarr");
        write(&out, &d, &grid, None, None).unwrap();
        let back = read(&out, &ReadOptions::default()).unwrap();
        assert_eq!(back.bits, d);
        assert_eq!(back.placement, Some((grid.origin(), glam::DVec3::splat(0.25))));
        // One shard (192 × 128 × 64 voxels) holds the whole grid.
        assert!(out.join("c/0/0/0").is_file() && !out.join("c/1").exists());
        // Writing again replaces the array; a non-Zarr directory is refused.
        let mut e = DenseBits::new(dims);
        e.set(5, 5, 5);
        write(&out, &e, &grid, None, None).unwrap();
        assert_eq!(read(&out, &ReadOptions::default()).unwrap().bits, e);
        let other = dir.join("other.zarr");
        std::fs::create_dir_all(&other).unwrap();
        std::fs::write(other.join("keep.txt"), "mine").unwrap();
        assert!(write(&other, &e, &grid, None, None).is_err());
        assert_eq!(std::fs::read_to_string(other.join("keep.txt")).unwrap(), "mine");
        let _ = std::fs::remove_dir_all(&dir);
    }

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("topovox-zarr-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Shards of 512 along a long axis; shards and chunks without voxels
    /// are not written, and the index marks the empty chunks.
    #[test]
    fn shards_split_long_axes_and_skip_empty_ones() {
        let dims = [1100, 70, 8];
        let mut d = DenseBits::new(dims);
        for (i, j, k) in [(0, 0, 0), (511, 69, 7), (1099, 3, 4)] {
            d.set(i, j, k);
        }
        let grid = GridSpec::new(glam::DVec3::ZERO, 1.0, dims.map(|x| x as u64)).unwrap();
        let dir = scratch("shards");
        let out = dir.join("v.zarr");
        write(&out, &d, &grid, None, None).unwrap();
        assert_eq!(read(&out, &ReadOptions::default()).unwrap().bits, d);
        assert_eq!(read_sparse(&out, false, &ReadOptions::default()).unwrap().bits.to_dense(), d);
        assert!(out.join("c/0/0/0").is_file() && !out.join("c/1/0/0").exists() && out.join("c/2/0/0").is_file());
        // Shard (0, 0, 0): 8 × 2 × 1 chunks, of which (0, 0, 0) and (7, 1, 0) hold voxels.
        let shard = std::fs::read(out.join("c/0/0/0")).unwrap();
        let index: Vec<u64> = shard[shard.len() - 16 * 16..].chunks_exact(8).map(|c| u64::from_le_bytes(c.try_into().unwrap())).collect();
        let used: Vec<usize> = (0..16).filter(|&q| index[2 * q] != EMPTY).collect();
        assert_eq!(used, [0, 15]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// Arrays without sharding (as `zarr` writes by default) are read; a
    /// shard index pointing outside its shard is an error, not a panic.
    #[test]
    fn plain_chunks_and_broken_shard_indexes() {
        let dir = scratch("plain");
        let out = dir.join("p.zarr");
        std::fs::create_dir_all(out.join("c/1/0")).unwrap();
        let meta = json!({"zarr_format": 3, "node_type": "array", "shape": [5, 2, 2], "data_type": "uint8",
            "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [3, 2, 2]}},
            "chunk_key_encoding": {"name": "default"}, "fill_value": 0,
            "codecs": [{"name": "bytes"}, {"name": "gzip", "configuration": {"level": 5}}]});
        std::fs::write(out.join("zarr.json"), meta.to_string()).unwrap();
        let mut enc = GzEncoder::new(Vec::new(), flate2::Compression::new(5));
        enc.write_all(&[0, 0, 0, 7, 1, 0, 0, 0, 0, 0, 0, 0]).unwrap();
        std::fs::write(out.join("c/1/0/0"), enc.finish().unwrap()).unwrap();
        let back = read(&out, &ReadOptions::default()).unwrap().bits;
        let mut set = Vec::new();
        back.for_each_set(|i, j, k| set.push([i, j, k]));
        assert_eq!(set, [[4, 0, 0], [3, 1, 1]]);
        assert_eq!(read_sparse(&out, false, &ReadOptions::default()).unwrap().bits.to_dense(), back, "chunks off the bricks (3 × 2 × 2)");

        let mut d = DenseBits::new([8, 8, 8]);
        d.set(1, 1, 1);
        let grid = GridSpec::new(glam::DVec3::ZERO, 1.0, [8, 8, 8]).unwrap();
        let sharded = dir.join("s.zarr");
        write(&sharded, &d, &grid, None, None).unwrap();
        let f = sharded.join("c/0/0/0");
        let mut shard = std::fs::read(&f).unwrap();
        let n = shard.len();
        shard[n - 16..n - 8].copy_from_slice(&(u64::MAX - 3).to_le_bytes());
        std::fs::write(&f, &shard).unwrap();
        let e = read(&sharded, &ReadOptions::default()).unwrap_err().to_string();
        assert!(e.contains("c/0/0/0") && e.contains("outside the shard"), "{e}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// With attributes, a group: `voxels` and one array per attribute over
    /// the same grid (components as a last axis), read back exactly; the
    /// `zarr.json` of a plain array is unchanged without them.
    #[test]
    fn attributes_make_a_group_read_back_exactly() {
        let dims = [70, 9, 66];
        let mut d = DenseBits::new(dims);
        d.fill_box([8, 0, 56], [15, 7, 65]);
        for (i, j, k) in [(0, 0, 0), (69, 8, 65), (64, 3, 1)] {
            d.set(i, j, k);
        }
        let keys = VoxelAttributes::keys_of(&d);
        let n = keys.len();
        let attrs = VoxelAttributes {
            dims,
            colour: Some((0..n).map(|s| [(s % 256) as u8, 7, (s * 3 % 256) as u8]).collect()),
            material: Some((0..n).map(|s| if s % 4 == 0 { NO_MATERIAL } else { s as u32 }).collect()),
            normal: Some((0..n).map(|s| [s as f32, -1.5, 0.25]).collect()),
            coverage: Some((0..n).map(|s| s as f32 / 3.0).collect()),
            keys,
        };
        let grid = GridSpec::new(glam::DVec3::new(0.5, 1.0, -2.0), 0.125, dims.map(|x| x as u64)).unwrap();
        let dir = scratch("attrs");
        let out = dir.join("a.zarr");
        write(&out, &d, &grid, Some(&attrs), None).unwrap();
        let m: Value = serde_json::from_slice(&std::fs::read(out.join("zarr.json")).unwrap()).unwrap();
        assert_eq!(m["node_type"], "group");
        let c: Value = serde_json::from_slice(&std::fs::read(out.join("colour/zarr.json")).unwrap()).unwrap();
        assert_eq!(c["shape"], json!([70, 9, 66, 3]));
        assert!(out.join("colour/c/0/0/0/0").is_file() && out.join("coverage/c/0/0/0").is_file());
        let back = read(&out, &ReadOptions::default()).unwrap();
        assert_eq!(back.bits, d);
        assert_eq!(back.placement, Some((grid.origin(), glam::DVec3::splat(0.125))));
        assert_eq!(back.attributes.as_ref(), Some(&attrs));
        let sparse = read_sparse(&out, false, &ReadOptions::default()).unwrap();
        assert_eq!((sparse.bits.to_dense(), sparse.placement, sparse.attributes_left), (d.clone(), back.placement, true));
        let with = read_sparse(&out, true, &ReadOptions::default()).unwrap();
        assert_eq!((with.attributes.as_ref(), with.attributes_left), (Some(&attrs), false), "the sparse reader reads the same attributes");
        assert_eq!(sparse.bits.full_bricks(), 1, "the full brick is read as a run");
        // Without attributes: the plain array, as before.
        write(&out, &d, &grid, None, None).unwrap();
        let m: Value = serde_json::from_slice(&std::fs::read(out.join("zarr.json")).unwrap()).unwrap();
        assert_eq!(m["node_type"], "array");
        assert_eq!(m["codecs"][0]["configuration"]["codecs"][0], json!({"name": "bytes"}));
        assert!(read(&out, &ReadOptions::default()).unwrap().attributes.is_none() && !out.join("colour").exists());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
