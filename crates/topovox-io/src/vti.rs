//! VTK ImageData `.vti` (VTK XML format, binary appended data, zlib
//! compressed), written by hand (the format is XML plus zlib blocks from
//! `flate2`); opens in ParaView and PyVista.
//!
//! Voxels are **cells**: `WholeExtent="0 nx 0 ny 0 nz"` (points), `Origin`
//! = the grid origin, `Spacing` = the voxel size per axis, cell `(i, j, k)` at index
//! `i + nx·(j + ny·k)`. Cell arrays: `occupancy` (UInt8, 0/1), and when
//! present `colour` (UInt8 × 3, sRGB), `material` (Int32, −1 for none and
//! for empty cells),
//! `coverage` (Float32, the surface area inside the voxel in index space:
//! / s² for cubes) and `normal`
//! (Float32 × 3); a distance field is one Float32 cell array
//! `distance`, read back as its inside (negative cells). Each array is one appended block stream with a UInt64
//! compression header (VTK's `vtkZLibDataCompressor` layout). Arrays are
//! built block by block from the set voxels in key order, so memory stays
//! at one block plus the compressed output.

use std::io::{Read, Write};

use flate2::write::ZlibEncoder;
use glam::DVec3;
use rayon::prelude::*;
use topovox::attributes::{VoxelAttributes, NO_MATERIAL};
use topovox::{GridSpec, VoxelSource};

use crate::error::ErrorKind;
use crate::LoadedVoxels;

/// Uncompressed bytes per compressed block.
const BLOCK: usize = 1 << 16;

/// One array being compressed block by block.
struct Stream {
    size: usize,
    filled: usize,
    buf: Vec<u8>,
    blocks: Vec<Vec<u8>>,
    /// Compressed full blocks of one repeated byte (most blocks of a sparse grid).
    uniform: std::collections::HashMap<u8, Vec<u8>>,
}

impl Stream {
    fn new(cells: u64, width: usize) -> Stream {
        Stream { size: cells as usize * width, filled: 0, buf: Vec::with_capacity(BLOCK), blocks: Vec::new(), uniform: Default::default() }
    }

    /// Appends `bytes`, compressing every full block.
    fn push(&mut self, mut bytes: &[u8]) -> std::io::Result<()> {
        while !bytes.is_empty() {
            let take = (BLOCK - self.buf.len()).min(bytes.len());
            self.buf.extend_from_slice(&bytes[..take]);
            bytes = &bytes[take..];
            self.filled += take;
            if self.buf.len() == BLOCK {
                self.flush()?;
            }
        }
        Ok(())
    }

    /// Appends `cells` copies of the empty-cell value `fill` (one repeated
    /// byte: 0, or 0xFF for material −1). Whole blocks of it reuse one
    /// compressed block instead of being copied and compressed again.
    fn fill(&mut self, cells: usize, fill: &[u8]) -> std::io::Result<()> {
        let b = fill[0];
        debug_assert!(fill.iter().all(|&x| x == b));
        let mut n = cells * fill.len();
        while n > 0 {
            if self.buf.is_empty() && n >= BLOCK {
                let z = match self.uniform.get(&b) {
                    Some(z) => z.clone(),
                    None => {
                        let z = compress(&vec![b; BLOCK])?;
                        self.uniform.insert(b, z.clone());
                        z
                    }
                };
                self.blocks.push(z);
                self.filled += BLOCK;
                n -= BLOCK;
                continue;
            }
            let take = (BLOCK - self.buf.len()).min(n);
            self.buf.resize(self.buf.len() + take, b);
            self.filled += take;
            n -= take;
            if self.buf.len() == BLOCK {
                self.flush()?;
            }
        }
        Ok(())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        if !self.buf.is_empty() {
            self.blocks.push(compress(&self.buf)?);
            self.buf.clear();
        }
        Ok(())
    }

    /// The header and blocks as they go into the appended section.
    fn finish(mut self, fill: &[u8]) -> std::io::Result<Vec<u8>> {
        self.fill((self.size - self.filled) / fill.len(), fill)?;
        self.flush()?;
        let last = (self.size % BLOCK) as u64;
        let mut out = Vec::new();
        for v in [self.blocks.len() as u64, BLOCK as u64, last] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for b in &self.blocks {
            out.extend_from_slice(&(b.len() as u64).to_le_bytes());
        }
        for b in &self.blocks {
            out.extend_from_slice(b);
        }
        Ok(out)
    }
}

fn compress(bytes: &[u8]) -> std::io::Result<Vec<u8>> {
    let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    z.write_all(bytes)?;
    z.finish()
}

/// Writes `bits` on `grid` as `.vti`, with the arrays `attrs` has.
pub fn write(w: &mut dyn Write, bits: &dyn VoxelSource, grid: &GridSpec, attrs: Option<&VoxelAttributes>) -> std::io::Result<()> {
    let dims = bits.dims();
    let cells: u64 = dims.iter().map(|&d| d as u64).product();
    // (name, VTK type, components, bytes per cell, value of slot s; empty cells hold `fill`)
    type Value<'a> = Box<dyn Fn(usize) -> Vec<u8> + Sync + 'a>;
    let mut arrays: Vec<(&str, &str, usize, usize, Option<Value<'_>>)> = vec![("occupancy", "UInt8", 1, 1, None)];
    let fill_of = |name: &str, width: usize| if name == "material" { (-1i32).to_le_bytes().to_vec() } else { vec![0u8; width] };
    if let Some(a) = attrs {
        if let Some(c) = &a.colour {
            arrays.push(("colour", "UInt8", 3, 3, Some(Box::new(move |s| c[s].to_vec()))));
        }
        if let Some(m) = &a.material {
            arrays.push((
                "material",
                "Int32",
                1,
                4,
                Some(Box::new(move |s| (if m[s] == NO_MATERIAL { -1 } else { m[s] as i32 }).to_le_bytes().to_vec())),
            ));
        }
        if let Some(c) = &a.coverage {
            arrays.push(("coverage", "Float32", 1, 4, Some(Box::new(move |s| c[s].to_le_bytes().to_vec()))));
        }
        if let Some(n) = &a.normal {
            arrays.push(("normal", "Float32", 3, 12, Some(Box::new(move |s| n[s].iter().flat_map(|v| v.to_le_bytes()).collect()))));
        }
    }
    // The set voxels' keys, ascending; `aligned` when they are the attributes' slots.
    let keys = VoxelAttributes::keys_of(bits);
    let aligned = attrs.is_some_and(|a| a.keys == keys);
    // One array per task: each is an independent block stream.
    let encode = |(name, _, _, width, value): &(&str, &str, usize, usize, Option<Value<'_>>)| -> std::io::Result<Vec<u8>> {
        let fill = fill_of(name, *width);
        let mut st = Stream::new(cells, *width);
        let mut next: u64 = 0;
        for (at, &key) in keys.iter().enumerate() {
            st.fill((key - next) as usize, &fill)?;
            match value {
                None => st.push(&[1])?,
                Some(f) => {
                    let slot = if aligned { Some(at) } else { attrs.and_then(|a| a.keys.binary_search(&key).ok()) };
                    match slot {
                        Some(s) => st.push(&f(s))?,
                        None => st.fill(1, &fill)?,
                    }
                }
            }
            next = key + 1;
        }
        st.finish(&fill)
    };
    let encoded: Vec<Vec<u8>> = arrays.par_iter().map(encode).collect::<std::io::Result<_>>()?;
    let mut xml = head(grid, "occupancy");
    let mut offset = 0usize;
    for ((name, ty, comps, _, _), e) in arrays.iter().zip(&encoded) {
        xml.push_str(&format!(
            "        <DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{comps}\" format=\"appended\" offset=\"{offset}\"/>\n"
        ));
        offset += e.len();
    }
    xml.push_str(TAIL);
    w.write_all(xml.as_bytes())?;
    for e in &encoded {
        w.write_all(e)?;
    }
    w.write_all(b"\n  </AppendedData>\n</VTKFile>\n")
}

/// Writes a distance field (`values` in C order, `[i][j][k]`) on `grid`
/// as `.vti`: one Float32 cell array `distance`.
pub fn write_distance(w: &mut dyn Write, values: &[f32], grid: &GridSpec) -> std::io::Result<()> {
    let dims = grid.dims();
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let mut st = Stream::new((nx * ny * nz) as u64, 4);
    let mut row = Vec::with_capacity(4 * nx);
    for k in 0..nz {
        for j in 0..ny {
            row.clear();
            (0..nx).for_each(|i| row.extend_from_slice(&values[(i * ny + j) * nz + k].to_le_bytes()));
            st.push(&row)?;
        }
    }
    let encoded = st.finish(&[0; 4])?;
    w.write_all(head(grid, "distance").as_bytes())?;
    w.write_all(b"        <DataArray type=\"Float32\" Name=\"distance\" NumberOfComponents=\"1\" format=\"appended\" offset=\"0\"/>\n")?;
    w.write_all(TAIL.as_bytes())?;
    w.write_all(&encoded)?;
    w.write_all(b"\n  </AppendedData>\n</VTKFile>\n")
}

/// The document up to the first cell array, with `scalars` the active one.
fn head(grid: &GridSpec, scalars: &str) -> String {
    let (dims, o, s) = (grid.dims(), grid.origin(), grid.voxel_size().0);
    let mut xml = String::new();
    xml.push_str("<?xml version=\"1.0\"?>\n");
    xml.push_str("<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\">\n");
    let extent = format!("0 {} 0 {} 0 {}", dims[0], dims[1], dims[2]);
    xml.push_str(&format!(
        "  <ImageData WholeExtent=\"{extent}\" Origin=\"{:?} {:?} {:?}\" Spacing=\"{:?} {:?} {:?}\">\n",
        o.x, o.y, o.z, s.x, s.y, s.z
    ));
    xml.push_str(&format!(
        "    <Piece Extent=\"{extent}\">\n      <PointData>\n      </PointData>\n      <CellData Scalars=\"{scalars}\">\n"
    ));
    xml
}

/// The document after the cell arrays, up to the appended data.
const TAIL: &str = "      </CellData>\n    </Piece>\n  </ImageData>\n  <AppendedData encoding=\"raw\">\n   _";

/// An attribute's value in an XML tag.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let at = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    let end = tag[at..].find('"')?;
    Some(&tag[at..at + end])
}

/// Reads a `.vti` with raw appended data, zlib-compressed or not (UInt32 or
/// UInt64 headers): `occupancy` (or the first cell array) gives the voxels,
/// `colour`, `material`, `coverage` and `normal` are read when present.
pub fn read(bytes: &[u8]) -> Result<LoadedVoxels, ErrorKind> {
    let bad = |m: String| ErrorKind::malformed("vti", m);
    let marker = bytes
        .windows(13)
        .position(|w| w == b"<AppendedData")
        .ok_or_else(|| bad("no <AppendedData> section (only appended raw data is read)".into()))?;
    let head = std::str::from_utf8(&bytes[..marker]).map_err(|_| bad("the XML header is not UTF-8".into()))?;
    let start = marker + bytes[marker..].iter().position(|&b| b == b'_').ok_or_else(|| bad("appended data has no '_' mark".into()))? + 1;
    let data = &bytes[start..];
    if !head.contains("type=\"ImageData\"") {
        return Err(bad("not ImageData".into()));
    }
    if head.contains("encoding=\"base64\"") {
        return Err(ErrorKind::Unsupported("base64-encoded .vti (topovox reads raw appended data)".into()));
    }
    let big = head.contains("byte_order=\"BigEndian\"");
    if big {
        return Err(ErrorKind::Unsupported("big-endian .vti".into()));
    }
    let u64_header = head.contains("header_type=\"UInt64\"");
    let compressed = head.contains("vtkZLibDataCompressor");
    if !compressed && head.contains("compressor=") {
        return Err(ErrorKind::Unsupported("a .vti compressor other than zlib".into()));
    }
    let image_tag =
        head.split("<ImageData").nth(1).and_then(|t| t.split('>').next()).ok_or_else(|| bad("no <ImageData> element".into()))?;
    let nums = |name: &str, n: usize| -> Result<Vec<f64>, ErrorKind> {
        let v: Vec<f64> = attr(image_tag, name).unwrap_or("").split_whitespace().filter_map(|x| x.parse().ok()).collect();
        if v.len() == n {
            Ok(v)
        } else {
            Err(bad(format!("ImageData {name} needs {n} numbers")))
        }
    };
    let e = nums("WholeExtent", 6)?;
    let dims_u: Vec<i64> = (0..3).map(|a| e[2 * a + 1] as i64 - e[2 * a] as i64).collect();
    if dims_u.iter().any(|&d| d < 1 || d > topovox::grid::spec::MAX_DIM as i64) {
        return Err(bad(format!("extent {e:?} does not describe 1..={} cells per axis", topovox::grid::spec::MAX_DIM)));
    }
    let dims = [dims_u[0] as u32, dims_u[1] as u32, dims_u[2] as u32];
    let cells = dims.iter().map(|&d| d as u64).product::<u64>();
    // Absent: the defaults; present, they must be what they say (a bad
    // Spacing used to be dropped without a word).
    let given = |name: &str, default: f64| if attr(image_tag, name).is_some() { nums(name, 3) } else { Ok(vec![default; 3]) };
    let origin = given("Origin", 0.0)?;
    let spacing = given("Spacing", 1.0)?;
    if origin.iter().any(|v| !v.is_finite()) || spacing.iter().any(|&v| !(v.is_finite() && v > 0.0)) {
        return Err(bad(format!("ImageData Origin {origin:?} and Spacing {spacing:?}: finite numbers, spacings above 0")));
    }
    let arrays = cell_arrays(head, data, cells, compressed, u64_header)?;
    let occ = arrays.iter().find(|a| a.0 == "occupancy").or(arrays.first()).ok_or_else(|| bad("no cell arrays".into()))?;
    let mut bits = crate::dense_grid(dims)?;
    let (ow, ot) = (occ.3.len() / cells as usize / occ.2, occ.1.clone());
    // A distance field (`topovox sdf`): its inside, the negative cells; an
    // unsigned one (no negative cell) the cells within half a voxel
    // diagonal of the surface.
    let distance = (occ.0 == "distance" && ot == "Float32" && occ.2 == 1).then(|| {
        let values: Vec<f32> = occ.3.chunks_exact(4).map(|b| f32::from_le_bytes(b.try_into().expect("4 bytes"))).collect();
        let signed = values.iter().any(|&v| v < 0.0);
        let near = crate::half_diagonal(DVec3::new(spacing[0], spacing[1], spacing[2])) as f32;
        move |b: &[u8]| {
            let v = f32::from_le_bytes(b.try_into().expect("4 bytes"));
            if signed {
                v < 0.0
            } else {
                v <= near
            }
        }
    });
    let nonzero = |b: &[u8]| match &distance {
        Some(inside) => inside(b),
        None if ot.starts_with("Float") => b.iter().any(|&x| x != 0 && x != 0x80),
        None => b.iter().any(|&x| x != 0),
    };
    let mut keys = Vec::new();
    for c in 0..cells as usize {
        if nonzero(&occ.3[c * ow * occ.2..c * ow * occ.2 + ow]) {
            let key = c as u64;
            keys.push(key);
        }
    }
    let mut attrs = VoxelAttributes { dims, keys, ..VoxelAttributes::default() };
    for k in &attrs.keys {
        let [i, j, kk] = attrs.voxel(*k);
        bits.set(i, j, kk);
    }
    carried(&arrays, &mut attrs);
    let placement = Some((DVec3::new(origin[0], origin[1], origin[2]), DVec3::new(spacing[0], spacing[1], spacing[2])));
    Ok(LoadedVoxels { bits, placement, attributes: Some(attrs) })
}

/// One cell array: its name, type, components and raw bytes.
type CellArray = (String, String, usize, Vec<u8>);

/// The `<CellData>` arrays of the XML header `head`, each decoded from
/// the appended `data` (`cells` values of its components).
fn cell_arrays(head: &str, data: &[u8], cells: u64, compressed: bool, u64_header: bool) -> Result<Vec<CellArray>, ErrorKind> {
    let bad = |m: String| ErrorKind::malformed("vti", m);
    let cell_data = head.split("<CellData").nth(1).ok_or_else(|| bad("no <CellData> (voxels are cells)".into()))?;
    let cell_data = cell_data.split("</CellData>").next().unwrap_or(cell_data);
    let mut arrays: Vec<CellArray> = Vec::new();
    for tag in cell_data.split("<DataArray").skip(1) {
        let tag = tag.split('>').next().unwrap_or(tag);
        let name = attr(tag, "Name").unwrap_or("").to_string();
        let ty = attr(tag, "type").unwrap_or("").to_string();
        let comps: u64 = attr(tag, "NumberOfComponents").and_then(|c| c.parse().ok()).unwrap_or(1);
        let offset: usize =
            attr(tag, "offset").and_then(|c| c.parse().ok()).ok_or_else(|| bad(format!("array {name:?} has no appended offset")))?;
        let width = match ty.as_str() {
            "UInt8" | "Int8" => 1,
            "Int32" | "UInt32" | "Float32" => 4,
            "Float64" | "Int64" | "UInt64" => 8,
            t => return Err(ErrorKind::Unsupported(format!("{t} arrays in .vti"))),
        };
        let want = cells.checked_mul(comps * width).ok_or_else(|| bad("array size overflows".into()))?;
        let raw =
            decode(data.get(offset..).ok_or_else(|| bad(format!("array {name:?} starts past the end")))?, want, compressed, u64_header)
                .map_err(bad)?;
        arrays.push((name, ty, comps as usize, raw));
    }
    Ok(arrays)
}

/// The attribute arrays topovox writes (`colour`, `material`, `coverage`,
/// `normal`), at `attrs`' voxels.
fn carried(arrays: &[CellArray], attrs: &mut VoxelAttributes) {
    let at = |name: &str, ty: &str, comps: usize| arrays.iter().find(|a| a.0 == name && a.1 == ty && a.2 == comps).map(|a| &a.3);
    if let Some(c) = at("colour", "UInt8", 3) {
        attrs.colour = Some(attrs.keys.iter().map(|&k| [0, 1, 2].map(|a| c[3 * k as usize + a])).collect());
    }
    let f32_at = |buf: &[u8], i: usize| f32::from_le_bytes([buf[4 * i], buf[4 * i + 1], buf[4 * i + 2], buf[4 * i + 3]]);
    if let Some(m) = at("material", "Int32", 1) {
        attrs.material = Some(
            attrs
                .keys
                .iter()
                .map(|&k| i32::from_le_bytes([0, 1, 2, 3].map(|b| m[4 * k as usize + b])))
                .map(|v| if v < 0 { NO_MATERIAL } else { v as u32 })
                .collect(),
        );
    }
    if let Some(c) = at("coverage", "Float32", 1) {
        attrs.coverage = Some(attrs.keys.iter().map(|&k| f32_at(c, k as usize)).collect());
    }
    if let Some(n) = at("normal", "Float32", 3) {
        attrs.normal = Some(attrs.keys.iter().map(|&k| [0, 1, 2].map(|a| f32_at(n, 3 * k as usize + a))).collect());
    }
}

/// One appended array: `want` bytes after its header.
fn decode(data: &[u8], want: u64, compressed: bool, u64_header: bool) -> Result<Vec<u8>, String> {
    let hw = if u64_header { 8 } else { 4 };
    let word = |i: usize| -> Result<u64, String> {
        let b = data.get(i * hw..(i + 1) * hw).ok_or("the data ends inside an array header")?;
        Ok(if u64_header {
            u64::from_le_bytes(b.try_into().map_err(|_| "header")?)
        } else {
            u32::from_le_bytes(b.try_into().map_err(|_| "header")?) as u64
        })
    };
    if !compressed {
        let n = word(0)?;
        if n != want || n > data.len() as u64 {
            return Err(format!("an array holds {n} bytes, {want} expected"));
        }
        return data.get(hw..hw + n as usize).map(|d| d.to_vec()).ok_or_else(|| "an array runs past the end".to_string());
    }
    let (nb, bs, last) = (word(0)?, word(1)?, word(2)?);
    let total = if nb == 0 { 0 } else { (nb - 1) * bs + if last == 0 { bs } else { last } };
    if total != want || nb > want + 1 {
        return Err(format!("a compressed array holds {total} bytes, {want} expected"));
    }
    // zlib inflates at most about 1032:1; a header claiming more is lying.
    if want > 1100 * data.len() as u64 + BLOCK as u64 {
        return Err(format!("an array claims {want} bytes from {} bytes of data", data.len()));
    }
    let mut at = (3 + nb as usize) * hw;
    let mut out = Vec::with_capacity(want.min(1 << 26) as usize);
    for b in 0..nb as usize {
        let len = word(3 + b)? as usize;
        let chunk = data.get(at..at + len).ok_or("a compressed block runs past the end")?;
        at += len;
        let limit = if b + 1 == nb as usize && last != 0 { last } else { bs };
        let before = out.len();
        flate2::read::ZlibDecoder::new(chunk).take(limit).read_to_end(&mut out).map_err(|e| format!("a block does not inflate ({e})"))?;
        if (out.len() - before) as u64 != limit {
            return Err("a compressed block inflates to the wrong size".into());
        }
    }
    Ok(out)
}
