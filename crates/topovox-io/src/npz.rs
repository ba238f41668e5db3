//! NumPy `.npz` of sparse coordinates: the set voxels as a `(k, 3)` array
//! of indices and the grid beside them, for grids of any size.
//!
//! The archive is what `numpy.savez` writes (a ZIP of uncompressed `.npy`
//! members), so `numpy.load("out.npz")` reads it:
//!
//! | member | dtype | shape | holds |
//! |---|---|---|---|
//! | `indices` | `int32` | `(k, 3)` | row `n` is the `(i, j, k)` of the `n`-th set voxel, ordered by `k`, then `j`, then `i` |
//! | `dims` | `int64` | `(3,)` | the grid's `(nx, ny, nz)` |
//! | `origin` | `float64` | `(3,)` | the world position of voxel `(0, 0, 0)`'s low corner |
//! | `voxel_size` | `float64` | `()` or `(3,)` | the voxel's edge length; `(sx, sy, sz)` for boxes |
//!
//! A dense grid comes back with `grid = np.zeros(dims, bool);
//! grid[tuple(indices.T)] = True`. The writer streams: it holds one buffer
//! of coordinates, never the grid or the whole list, and writes through
//! the `zip` crate's streaming writer (sizes and checksums in data
//! descriptors, ZIP64 past 4 GiB), so it needs no seeking and also writes
//! to standard output. The `.npy` headers are [`crate::npy`]'s.

use std::io::{Read, Seek, Write};

use glam::DVec3;
use std::collections::HashMap;

use topovox::grid::bricks::{set_in_brick, Brick};
use topovox::grid::sparse::SparseBricks;
use topovox::{GridSpec, VoxelSource};

use crate::error::ErrorKind;
use crate::npy::{header, header_field};
use crate::{LoadedVoxels, SparseVoxels};

const FORMAT: &str = "npz";

/// Writes the set voxels of `bits` on `grid` as an `.npz` archive.
pub fn write(w: &mut dyn Write, bits: &dyn VoxelSource, grid: &GridSpec) -> std::io::Result<()> {
    let dims = bits.dims();
    let count = bits.count();
    let index_bytes = count.checked_mul(12).ok_or_else(|| std::io::Error::other("too many voxels for an .npz index array"))?;
    let mut zip = zip::ZipWriter::new_stream(w);
    let small = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    // ZIP64 fields for the index member when it may pass 4 GiB.
    let large = small.large_file(index_bytes > u32::MAX as u64 / 2);
    let member = |zip: &mut zip::ZipWriter<_>, name: &str, header: Vec<u8>, data: &[u8]| -> std::io::Result<()> {
        zip.start_file(name, small).map_err(std::io::Error::other)?;
        zip.write_all(&header)?;
        zip.write_all(data)
    };
    let o = grid.origin();
    let dims_le: Vec<u8> = dims.iter().flat_map(|&d| (d as i64).to_le_bytes()).collect();
    member(&mut zip, "dims.npy", header("<i8", "(3,)"), &dims_le)?;
    let origin_le: Vec<u8> = [o.x, o.y, o.z].iter().flat_map(|c| c.to_le_bytes()).collect();
    member(&mut zip, "origin.npy", header("<f8", "(3,)"), &origin_le)?;
    let size = grid.voxel_size().recorded();
    let size_le: Vec<u8> = size.iter().flat_map(|v| v.to_le_bytes()).collect();
    member(&mut zip, "voxel_size.npy", header("<f8", if size.len() == 1 { "()" } else { "(3,)" }), &size_le)?;

    zip.start_file("indices.npy", large).map_err(std::io::Error::other)?;
    zip.write_all(&header("<i4", &format!("({count}, 3)")))?;
    let mut buf: Vec<u8> = Vec::with_capacity(1 << 16);
    let mut result = Ok(());
    bits.for_each_set(&mut |i, j, k| {
        if result.is_err() {
            return;
        }
        for c in [i, j, k] {
            buf.extend_from_slice(&(c as i32).to_le_bytes());
        }
        if buf.len() >= 1 << 16 {
            result = zip.write_all(&buf);
            buf.clear();
        }
    });
    result?;
    zip.write_all(&buf)?;
    zip.finish().map_err(std::io::Error::other)?;
    Ok(())
}

/// A member's `.npy` header: dtype and shape.
struct Header {
    descr: String,
    shape: Vec<u64>,
}

/// Reads a member's `.npy` header (version 1, 2 or 3, C order).
fn read_header(r: &mut impl Read, name: &str) -> Result<Header, ErrorKind> {
    let bad = |d: String| ErrorKind::malformed("npz", format!("member {name}: {d}"));
    let mut magic = [0u8; 8];
    r.read_exact(&mut magic).map_err(|_| bad("shorter than an .npy header".into()))?;
    if &magic[..6] != b"\x93NUMPY" {
        return Err(bad("not an .npy array".into()));
    }
    let len = match magic[6] {
        1 => {
            let mut l = [0u8; 2];
            r.read_exact(&mut l).map_err(|_| bad("header cut short".into()))?;
            u16::from_le_bytes(l) as usize
        }
        2 | 3 => {
            let mut l = [0u8; 4];
            r.read_exact(&mut l).map_err(|_| bad("header cut short".into()))?;
            u32::from_le_bytes(l) as usize
        }
        v => return Err(bad(format!("unknown .npy version {v}"))),
    };
    if len > 1 << 16 {
        return Err(bad(format!("header of {len} bytes")));
    }
    let mut text = vec![0u8; len];
    r.read_exact(&mut text).map_err(|_| bad("header cut short".into()))?;
    let text = String::from_utf8(text).map_err(|_| bad("header is not text".into()))?;
    let field = |key: &str| header_field(&text, key);
    let descr =
        field("descr").and_then(|v| v.strip_prefix('\'')).and_then(|v| v.split('\'').next()).ok_or_else(|| bad("no dtype".into()))?;
    if !field("fortran_order").is_some_and(|v| v.starts_with("False")) {
        return Err(bad("only C-ordered arrays are read".into()));
    }
    let shape_text =
        field("shape").and_then(|v| v.strip_prefix('(')).and_then(|v| v.split(')').next()).ok_or_else(|| bad("no shape".into()))?;
    let shape = shape_text
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.trim_end_matches('L').parse::<u64>())
        .collect::<Result<Vec<_>, _>>()
        .map_err(|_| bad(format!("shape ({shape_text}) is not a tuple of sizes")))?;
    Ok(Header { descr: descr.to_string(), shape })
}

/// Reads `n` numbers of `descr` (little- or big-endian integers of 1, 2, 4
/// or 8 bytes, or 8-byte floats) as `f64`.
fn read_numbers(r: &mut impl Read, descr: &str, n: usize, name: &str) -> Result<Vec<f64>, ErrorKind> {
    let bad = |d: String| ErrorKind::malformed("npz", format!("member {name}: {d}"));
    if !descr.is_ascii() {
        return Err(bad(format!("dtype {descr:?} (expected integers or float64)")));
    }
    let (order, kind) = descr.split_at(1.min(descr.len()));
    let big = order == ">";
    let size: usize = kind.get(1..).and_then(|s| s.parse().ok()).ok_or_else(|| bad(format!("dtype {descr:?}")))?;
    if !matches!((kind.as_bytes().first(), size), (Some(b'i' | b'u'), 1 | 2 | 4 | 8) | (Some(b'f'), 8))
        || !matches!(order, "<" | ">" | "|" | "=")
    {
        return Err(bad(format!("dtype {descr:?} (expected integers or float64)")));
    }
    // One read for the block (element by element, the decompressor's
    // per-call cost dominated: 100 M rows took 26 s).
    let total = n.checked_mul(size).filter(|&t| t <= 1 << 30).ok_or_else(|| bad(format!("{n} values in one block")))?;
    let mut block = vec![0u8; total];
    r.read_exact(&mut block).map_err(|_| bad("data cut short".into()))?;
    // One tight loop per element type, chosen once.
    fn each<const N: usize>(block: &[u8], big: bool, f: impl Fn([u8; N]) -> f64) -> Vec<f64> {
        block
            .chunks_exact(N)
            .map(|c| {
                let mut b: [u8; N] = c.try_into().expect("N bytes");
                if big {
                    b.reverse();
                }
                f(b)
            })
            .collect()
    }
    let out = match (kind.as_bytes()[0], size) {
        (b'f', _) => each::<8>(&block, big, f64::from_le_bytes),
        (b'u', 1) => each::<1>(&block, big, |b| b[0] as f64),
        (b'u', 2) => each::<2>(&block, big, |b| u16::from_le_bytes(b) as f64),
        (b'u', 4) => each::<4>(&block, big, |b| u32::from_le_bytes(b) as f64),
        (b'u', _) => each::<8>(&block, big, |b| u64::from_le_bytes(b) as f64),
        (_, 1) => each::<1>(&block, big, |b| b[0] as i8 as f64),
        (_, 2) => each::<2>(&block, big, |b| i16::from_le_bytes(b) as f64),
        (_, 4) => each::<4>(&block, big, |b| i32::from_le_bytes(b) as f64),
        _ => each::<8>(&block, big, |b| i64::from_le_bytes(b) as f64),
    };
    Ok(out)
}

/// Reads an `.npz` of sparse coordinates (as [`write()`] makes, or any
/// `numpy.savez` with an `indices` array of shape `(k, 3)`, integer
/// dtype); `dims` is read when present, else the smallest grid holding
/// every voxel; `origin` and `voxel_size`, when present, place the grid.
pub fn read(bytes: &[u8]) -> Result<LoadedVoxels, ErrorKind> {
    read_from(std::io::Cursor::new(bytes), bytes.len() as u64)
}

/// [`read()`] from a seekable reader of `total` bytes (a file: the index
/// array is streamed into the grid, never held whole).
pub fn read_from<R: Read + Seek>(r: R, total: u64) -> Result<LoadedVoxels, ErrorKind> {
    let (grid, placement) = read_into(r, total, false)?;
    match grid {
        Read3::Dense(bits) => Ok(LoadedVoxels { bits, placement, attributes: None }),
        Read3::Sparse(_) => unreachable!("asked for a dense grid"),
    }
}

/// [`read_from`] without a dense grid: the indices gathered into bricks,
/// for grids past memory.
pub fn read_sparse_from<R: Read + Seek>(r: R, total: u64) -> Result<SparseVoxels, ErrorKind> {
    let (grid, placement) = read_into(r, total, true)?;
    match grid {
        Read3::Sparse(bits) => Ok(SparseVoxels { bits, placement, attributes_left: false, attributes: None }),
        Read3::Dense(_) => unreachable!("asked for sparse bricks"),
    }
}

/// The voxels read: a dense grid, or sparse bricks.
enum Read3 {
    Dense(topovox::DenseBits),
    Sparse(SparseBricks),
}

/// Where indices go while they are read.
enum Sink {
    Dense(topovox::DenseBits),
    Bricks(Bricks),
    /// Without recorded dims, the grid is sized after reading them all:
    /// bricks meanwhile, so memory follows the distinct voxels, not the
    /// rows (a file may repeat one voxel a hundred million times).
    Unsized(Bricks, [u32; 3]),
}

/// Voxels gathered into 8³ bricks; the brick of the last voxel is kept
/// aside, so runs of indices in one brick (the common order) cost no
/// lookup.
#[derive(Default)]
struct Bricks {
    map: HashMap<[u32; 3], Brick>,
    current: Option<([u32; 3], Brick)>,
}

impl Bricks {
    fn set(&mut self, q: [u32; 3]) {
        let key = q.map(|c| c / 8);
        match &mut self.current {
            Some((k, b)) if *k == key => set_in_brick(b, q[0], q[1], q[2]),
            current => {
                if let Some((k, b)) = current.take() {
                    self.map.insert(k, b);
                }
                let mut b = self.map.remove(&key).unwrap_or([0; 8]);
                set_in_brick(&mut b, q[0], q[1], q[2]);
                self.current = Some((key, b));
            }
        }
    }

    fn into_parts(mut self) -> Vec<([u32; 3], Brick)> {
        if let Some((k, b)) = self.current.take() {
            self.map.insert(k, b);
        }
        self.map.into_iter().collect()
    }
}

fn read_into<R: Read + Seek>(r: R, total: u64, sparse: bool) -> Result<(Read3, Option<(DVec3, DVec3)>), ErrorKind> {
    let mut zip = zip::ZipArchive::new(r).map_err(|e| ErrorKind::malformed(FORMAT, format!("not a ZIP archive ({e})")))?;
    // A small member of `ns[0]` values (or of any other count in `ns`).
    let small = |zip: &mut zip::ZipArchive<R>, name: &str, ns: &[usize]| -> Result<Option<Vec<f64>>, ErrorKind> {
        let Ok(mut f) = zip.by_name(name) else { return Ok(None) };
        let h = read_header(&mut f, name)?;
        let Some(&n) = ns.iter().find(|&&n| h.shape.iter().product::<u64>() == n as u64) else {
            return Err(ErrorKind::malformed(FORMAT, format!("member {name}: shape {:?}, expected {} values", h.shape, ns[0])));
        };
        read_numbers(&mut f, &h.descr, n, name).map(Some)
    };
    let dims = small(&mut zip, "dims.npy", &[3])?;
    let origin = small(&mut zip, "origin.npy", &[3])?;
    let size = small(&mut zip, "voxel_size.npy", &[1, 3])?;
    let name = "indices.npy";
    let mut f = zip.by_name(name).map_err(|_| ErrorKind::malformed(FORMAT, "no 'indices' array"))?;
    let h = read_header(&mut f, name)?;
    let [k, 3] = h.shape[..] else {
        return Err(ErrorKind::malformed(FORMAT, format!("'indices' has shape {:?}, expected (k, 3)", h.shape)));
    };
    if h.descr.contains('f') {
        return Err(ErrorKind::malformed(FORMAT, format!("'indices' has dtype {:?}, expected integers", h.descr)));
    }
    // A hostile header can claim more rows than the archive holds.
    let elem: u64 = h.descr.get(2..).and_then(|s| s.parse().ok()).unwrap_or(8);
    if k.saturating_mul(3 * elem) > f.size() {
        return Err(ErrorKind::malformed(FORMAT, format!("'indices' claims {k} rows, more than its {} bytes hold", f.size())));
    }
    if f.size() > total.saturating_mul(1 << 10) {
        return Err(ErrorKind::malformed(
            FORMAT,
            format!("'indices' inflates to {} bytes, over 1024 times the archive's {total}", f.size()),
        ));
    }
    let max = topovox::grid::spec::MAX_DIM as f64;
    let check = |v: f64| v >= 0.0 && v < max && v.fract() == 0.0;
    let dims = match dims {
        Some(d) => {
            if !d.iter().all(|&c| (1.0..=max).contains(&c) && c.fract() == 0.0) {
                return Err(ErrorKind::malformed(FORMAT, format!("grid dims {d:?} out of range")));
            }
            Some([d[0] as u32, d[1] as u32, d[2] as u32])
        }
        None => None,
    };
    // Indices come in chunks; without dims the grid is sized after reading them all.
    let mut sink = sink_for(dims, sparse)?;
    let mut left = k as usize;
    while left > 0 {
        let n = left.min(1 << 16);
        let v = read_numbers(&mut f, &h.descr, 3 * n, name)?;
        for p in v.chunks_exact(3) {
            if !p.iter().all(|&c| check(c)) {
                return Err(ErrorKind::malformed(FORMAT, format!("index {p:?} is not a voxel of a grid")));
            }
            let q = [p[0] as u32, p[1] as u32, p[2] as u32];
            if let Some(d) = dims {
                if (0..3).any(|a| q[a] >= d[a]) {
                    return Err(ErrorKind::malformed(FORMAT, format!("index {q:?} lies outside the {d:?} grid")));
                }
            }
            match &mut sink {
                Sink::Dense(b) => b.set(q[0], q[1], q[2]),
                Sink::Bricks(b) => b.set(q),
                Sink::Unsized(b, d) => {
                    b.set(q);
                    for a in 0..3 {
                        d[a] = d[a].max(q[a] + 1);
                    }
                }
            }
        }
        left -= n;
    }
    Ok((finish(sink, dims, sparse)?, placement_of(origin, size)?))
}

/// Where the indices go: a dense grid, bricks of known dims, or bricks
/// whose dims grow with the indices.
fn sink_for(dims: Option<[u32; 3]>, sparse: bool) -> Result<Sink, ErrorKind> {
    Ok(match dims {
        Some(d) if sparse => {
            if d.iter().any(|&x| x > SparseBricks::MAX_DIM) {
                return Err(ErrorKind::malformed(FORMAT, format!("grid dims {d:?} beyond {} voxels per axis", SparseBricks::MAX_DIM)));
            }
            Sink::Bricks(Bricks::default())
        }
        Some(d) => Sink::Dense(crate::dense_grid(d)?),
        None => Sink::Unsized(Bricks::default(), [1; 3]),
    })
}

/// The grid the indices made.
fn finish(sink: Sink, dims: Option<[u32; 3]>, sparse: bool) -> Result<Read3, ErrorKind> {
    Ok(match sink {
        Sink::Dense(b) => Read3::Dense(b),
        Sink::Bricks(b) => Read3::Sparse(SparseBricks::from_parts(dims.expect("bricks need dims"), b.into_parts(), Vec::new())),
        Sink::Unsized(bricks, d) => {
            let sparse_bits = SparseBricks::from_parts(d, bricks.into_parts(), Vec::new());
            if sparse {
                Read3::Sparse(sparse_bits)
            } else {
                let mut b = crate::dense_grid(d)?;
                sparse_bits.for_each_set(&mut |i, j, k| b.set(i, j, k));
                Read3::Dense(b)
            }
        }
    })
}

/// The recorded origin and voxel size, both or neither.
fn placement_of(origin: Option<Vec<f64>>, size: Option<Vec<f64>>) -> Result<Option<(DVec3, DVec3)>, ErrorKind> {
    Ok(match (origin, size) {
        (Some(o), Some(s)) if o.iter().all(|c| c.is_finite()) && s.iter().all(|&v| v.is_finite() && v > 0.0) => {
            let s = if s.len() == 3 { DVec3::new(s[0], s[1], s[2]) } else { DVec3::splat(s[0]) };
            Some((DVec3::new(o[0], o[1], o[2]), s))
        }
        (None, None) => None,
        _ => return Err(ErrorKind::malformed(FORMAT, "origin and voxel_size must both be finite, the size positive")),
    })
}

/// One array of a [`write_arrays`] archive: its dtype (`<f4`, `<f8`,
/// `|u1`, …), shape, and little-endian bytes.
pub struct Member<'a> {
    /// The member's name without `.npy`.
    pub name: &'a str,
    /// NumPy's dtype string.
    pub descr: &'a str,
    /// The shape.
    pub shape: Vec<u64>,
    /// The data, C order, little endian.
    pub bytes: Vec<u8>,
}

/// Writes named arrays as an `.npz` archive (stored, no compression), as
/// `numpy.savez` does: `numpy.load(path)["name"]` reads each.
pub fn write_arrays(w: &mut dyn Write, members: &[Member<'_>]) -> std::io::Result<()> {
    let mut zip = zip::ZipWriter::new_stream(w);
    for m in members {
        let large = m.bytes.len() as u64 >= u32::MAX as u64 / 2;
        let opts = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored).large_file(large);
        zip.start_file(format!("{}.npy", m.name), opts).map_err(std::io::Error::other)?;
        let shape = match m.shape.as_slice() {
            [n] => format!("({n},)"),
            s => format!("({})", s.iter().map(u64::to_string).collect::<Vec<_>>().join(", ")),
        };
        zip.write_all(&header(m.descr, &shape))?;
        zip.write_all(&m.bytes)?;
    }
    zip.finish().map_err(std::io::Error::other)?;
    Ok(())
}
