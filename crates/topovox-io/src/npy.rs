//! NumPy `.npy` (format version 1.0), written by hand.
//!
//! Shape `(nx, ny, nz)`, C order, element `[i, j, k]` = voxel `(i, j, k)`,
//! dtype `uint8` (`|u1`, 0 or 1) or `bool` (`|b1`); distance fields
//! as `float32` (`<f4`), read back (with `<f8`) as their inside, the
//! negative elements. Written directly rather
//! than through `npyz`: its per-element writer is far slower for the 10⁹
//! elements of a 1024³ grid, and the header is a dozen lines. Tests read
//! the files back with NumPy itself.

use std::io::Write;

use topovox::{DenseBits, VoxelSource};

use crate::error::ErrorKind;
use crate::LoadedVoxels;

/// Element type of the array.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dtype {
    /// `uint8`, values 0 and 1.
    U8,
    /// `bool`.
    Bool,
}

/// Writes `bits` as an `.npy` array of shape `(nx, ny, nz)`.
pub fn write(w: &mut dyn Write, bits: &dyn VoxelSource, dtype: Dtype) -> std::io::Result<()> {
    let [nx, ny, nz] = bits.dims();
    let descr = match dtype {
        Dtype::U8 => "|u1",
        Dtype::Bool => "|b1",
    };
    w.write_all(&header(descr, &format!("({nx}, {ny}, {nz})")))?;
    let plane = ny as usize * nz as usize;
    let block = plane_block(plane);
    let mut buf = vec![0u8; plane * block as usize];
    let mut i0 = 0;
    while i0 < nx {
        let count = block.min(nx - i0);
        bits.fill_i_planes(i0, count, true, &mut buf);
        w.write_all(&buf[..plane * count as usize])?;
        i0 += count;
    }
    Ok(())
}

/// Writes `values` (C order, `[i][j][k]`) as a float32 `.npy` array
/// (`<f4`) of shape `dims`: a distance field.
pub fn write_f32(w: &mut dyn Write, dims: [u32; 3], values: &[f32]) -> std::io::Result<()> {
    let [nx, ny, nz] = dims;
    debug_assert_eq!(values.len() as u64, nx as u64 * ny as u64 * nz as u64);
    w.write_all(&header("<f4", &format!("({nx}, {ny}, {nz})")))?;
    let mut buf = Vec::with_capacity(1 << 20);
    for chunk in values.chunks(1 << 18) {
        buf.clear();
        chunk.iter().for_each(|v| buf.extend_from_slice(&v.to_le_bytes()));
        w.write_all(&buf)?;
    }
    Ok(())
}

/// How many `i`-planes of `plane` bytes to extract at once: a power of two
/// up to 64 (so blocks never straddle a storage word) using at most 64 MiB.
pub(crate) fn plane_block(plane: usize) -> u32 {
    let mut b = 64u32;
    while b > 1 && plane * b as usize > 64 << 20 {
        b /= 2;
    }
    b
}

/// What an element is and which elements are set.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Element {
    /// uint8, int8 or bool: nonzero is set.
    Byte,
    /// float32 or float64, a distance field (`topovox sdf`): negative is set (inside).
    Float(usize),
}

impl Element {
    fn size(self) -> usize {
        match self {
            Element::Byte => 1,
            Element::Float(s) => s,
        }
    }
}

/// Reads a 3-D `.npy` array in C order: uint8/int8/bool (nonzero = set),
/// or float32/float64, a distance field (negative = set: the inside).
pub fn read(bytes: &[u8]) -> Result<LoadedVoxels, ErrorKind> {
    let (dims, data_at, elem) = parse_header(bytes)?;
    let data = &bytes[data_at..];
    let n = (dims[0] * dims[1] * dims[2]) as usize * elem.size();
    if data.len() < n {
        return Err(truncated(data.len(), n));
    }
    let mut bits = crate::dense_grid(dims.map(|d| d as u32))?;
    fill(&mut bits, &data[..n], 0, elem);
    Ok(LoadedVoxels { bits, placement: None, attributes: None })
}

/// [`read`] from a stream of `total` bytes, a few megabytes at a time: a
/// 1024³ grid is a gigabyte of bytes that need not all be in memory at
/// once. A header promising more data than `total` is rejected before
/// anything is allocated.
pub fn read_stream(r: &mut impl std::io::Read, total: u64) -> Result<LoadedVoxels, ErrorKind> {
    let io = |e: std::io::Error| {
        if e.kind() == std::io::ErrorKind::UnexpectedEof {
            ErrorKind::malformed("npy", "truncated header")
        } else {
            ErrorKind::Read(e)
        }
    };
    let mut head = vec![0u8; 12];
    r.read_exact(&mut head[..10]).map_err(io)?;
    let hlen = match head[6] {
        1 => u16::from_le_bytes([head[8], head[9]]) as usize,
        2 | 3 => {
            r.read_exact(&mut head[10..12]).map_err(io)?;
            u32::from_le_bytes([head[8], head[9], head[10], head[11]]) as usize
        }
        _ => 0,
    };
    if head[6] == 1 {
        head.truncate(10);
    }
    if hlen > 1 << 20 {
        return Err(ErrorKind::malformed("npy", format!("header of {hlen} bytes")));
    }
    let start = head.len();
    head.resize(start + hlen, 0);
    r.read_exact(&mut head[start..]).map_err(io)?;
    let (dims, _, elem) = parse_header(&head)?;
    let n = (dims[0] * dims[1] * dims[2]) as usize * elem.size();
    let have = total.saturating_sub(head.len() as u64);
    if have < n as u64 {
        return Err(truncated(have as usize, n));
    }
    let mut bits = crate::dense_grid(dims.map(|d| d as u32))?;
    let mut buf = vec![0u8; 1 << 22];
    let mut at = 0usize;
    while at < n {
        // Whole elements at a time (the buffer is a multiple of 8 bytes).
        let want = buf.len().min(n - at);
        r.read_exact(&mut buf[..want]).map_err(|e| match e.kind() {
            std::io::ErrorKind::UnexpectedEof => truncated(at, n),
            _ => ErrorKind::Read(e),
        })?;
        fill(&mut bits, &buf[..want], at, elem);
        at += want;
    }
    Ok(LoadedVoxels { bits, placement: None, attributes: None })
}

fn truncated(have: usize, need: usize) -> ErrorKind {
    ErrorKind::malformed("npy", format!("data holds {have} bytes, shape needs {need} (truncated?)"))
}

/// The version 1.0 `.npy` header of a C-ordered array of dtype `descr` and
/// `shape` (a Python tuple), padded so the data starts on 64 bytes.
pub(crate) fn header(descr: &str, shape: &str) -> Vec<u8> {
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat(total.div_ceil(64) * 64 - total));
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out
}

/// The value text after `'key':` in a header's dictionary, if present.
pub(crate) fn header_field<'h>(header: &'h str, key: &str) -> Option<&'h str> {
    let at = header.find(&format!("'{key}'"))? + key.len() + 2;
    header[at..].trim_start().strip_prefix(':').map(str::trim_start)
}

/// Validates the header; returns the shape, where the data starts and
/// what an element is.
fn parse_header(bytes: &[u8]) -> Result<([u64; 3], usize, Element), ErrorKind> {
    let bad = |d: &str| ErrorKind::malformed("npy", d);
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(bad("missing \\x93NUMPY magic"));
    }
    let (hlen, hstart) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize, 12),
        v => return Err(bad(&format!("unsupported format version {v}"))),
    };
    let header = bytes.get(hstart..hstart + hlen).ok_or_else(|| bad("truncated header"))?;
    let header = std::str::from_utf8(header).map_err(|_| bad("header is not text"))?;
    let field = |key: &str| header_field(header, key);
    let descr = field("descr").and_then(|r| r.strip_prefix('\'')).and_then(|r| r.split('\'').next()).ok_or_else(|| bad("no descr"))?;
    let elem = match descr {
        "|u1" | "|b1" | "|i1" | "<u1" | "<i1" => Element::Byte,
        "<f4" => Element::Float(4),
        "<f8" => Element::Float(8),
        _ => {
            return Err(ErrorKind::Unsupported(format!("npy dtype {descr} (expected uint8 or bool, or a float32/float64 distance field)")))
        }
    };
    if field("fortran_order").is_some_and(|r| r.starts_with("True")) {
        return Err(ErrorKind::Unsupported("Fortran-ordered npy arrays".into()));
    }
    let shape = field("shape").and_then(|r| r.strip_prefix('(')).and_then(|r| r.split(')').next()).ok_or_else(|| bad("no shape"))?;
    let dims: Vec<u64> = shape
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<u64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad("shape is not a tuple of integers"))?;
    let [nx, ny, nz] = dims[..] else {
        return Err(ErrorKind::Unsupported(format!("npy array of {} dimensions (expected 3)", dims.len())));
    };
    if [nx, ny, nz].iter().any(|&d| d == 0 || d > topovox::grid::spec::MAX_DIM as u64) {
        return Err(bad(&format!("shape ({nx}, {ny}, {nz}) out of range")));
    }
    Ok(([nx, ny, nz], hstart + hlen, elem))
}

/// Sets the voxels of the set elements of `data` (whole elements), whose
/// first byte is byte `start` of the C-ordered array.
fn fill(bits: &mut DenseBits, data: &[u8], start: usize, elem: Element) {
    let [_, ny, nz] = bits.dims().map(|d| d as usize);
    if let Element::Float(size) = elem {
        for (e, x) in data.chunks_exact(size).enumerate() {
            let v = if size == 4 {
                f32::from_le_bytes(x.try_into().expect("4 bytes")) as f64
            } else {
                f64::from_le_bytes(x.try_into().expect("8 bytes"))
            };
            if v < 0.0 {
                let idx = start / size + e;
                let (k, j, i) = (idx % nz, (idx / nz) % ny, idx / (nz * ny));
                bits.set(i as u32, j as u32, k as u32);
            }
        }
        return;
    }
    // Surfaces are sparse: skip zero bytes eight at a time.
    for (c, chunk) in data.chunks(8).enumerate() {
        if chunk.len() == 8 && u64::from_ne_bytes(chunk.try_into().unwrap_or([0; 8])) == 0 {
            continue;
        }
        for (o, &b) in chunk.iter().enumerate() {
            if b != 0 {
                let idx = start + c * 8 + o;
                let (k, j, i) = (idx % nz, (idx / nz) % ny, idx / (nz * ny));
                bits.set(i as u32, j as u32, k as u32);
            }
        }
    }
}
