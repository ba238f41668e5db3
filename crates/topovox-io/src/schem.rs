//! Minecraft Sponge schematic `.schem`, version 2 (read: versions 2 and 3),
//! written as gzip-compressed NBT through the `fastnbt` and `flate2` crates.
//!
//! Axes: Minecraft is y-up; the grid is rotated so the data's up axis
//! (`--up`, default y) points up there ([`crate::orient`]: with up = y,
//! voxel `(i, j, k)` is block `(i, j, k)`; with up = z, block
//! `(i, k, ny − 1 − j)`) — a rotation, not a mirror — and the up axis is
//! recorded in the metadata (`TopovoxUp`, beside WorldEdit's `WEOffsetX/Y/Z`)
//! so topovox reads it back unrotated. Every set voxel becomes the solid block whose
//! average colour is nearest to the voxel's colour in Oklab: from a
//! built-in table of 67 blocks (concrete, wool, terracotta and a few
//! common solids; average colours of their textures, approximate) or from a
//! user palette file of `namespace:block R G B` lines (`#` comments).
//! Voxels without colour become light grey concrete.

use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::path::Path;

use fastnbt::{ByteArray, IntArray};
use serde::{Deserialize, Serialize};
use topovox::attributes::colour::{oklab, pack};
use topovox::attributes::{quantize, VoxelAttributes};
use topovox::VoxelSource;

use crate::error::{ErrorKind, IoError};
use crate::orient::{Orientation, Up};
use crate::LoadedVoxels;

/// Minecraft data version written (Java Edition 1.20.4).
const DATA_VERSION: i32 = 3700;

/// The block of uncoloured voxels.
const PLAIN: &str = "minecraft:light_gray_concrete";

/// Built-in solid blocks and the average sRGB colour of their textures.
pub const BLOCKS: &[(&str, [u8; 3])] = &[
    ("white_concrete", [207, 213, 214]),
    ("orange_concrete", [224, 97, 0]),
    ("magenta_concrete", [169, 48, 159]),
    ("light_blue_concrete", [35, 137, 198]),
    ("yellow_concrete", [241, 175, 21]),
    ("lime_concrete", [94, 168, 24]),
    ("pink_concrete", [213, 101, 142]),
    ("gray_concrete", [54, 57, 61]),
    ("light_gray_concrete", [125, 125, 115]),
    ("cyan_concrete", [21, 119, 136]),
    ("purple_concrete", [100, 31, 156]),
    ("blue_concrete", [44, 46, 143]),
    ("brown_concrete", [96, 59, 31]),
    ("green_concrete", [73, 91, 36]),
    ("red_concrete", [142, 32, 32]),
    ("black_concrete", [8, 10, 15]),
    ("white_wool", [233, 236, 236]),
    ("orange_wool", [240, 118, 19]),
    ("magenta_wool", [189, 68, 179]),
    ("light_blue_wool", [58, 175, 217]),
    ("yellow_wool", [248, 197, 39]),
    ("lime_wool", [112, 185, 25]),
    ("pink_wool", [237, 141, 172]),
    ("gray_wool", [62, 68, 71]),
    ("light_gray_wool", [142, 142, 134]),
    ("cyan_wool", [21, 137, 145]),
    ("purple_wool", [121, 42, 172]),
    ("blue_wool", [53, 57, 157]),
    ("brown_wool", [114, 71, 40]),
    ("green_wool", [84, 109, 27]),
    ("red_wool", [160, 39, 34]),
    ("black_wool", [20, 21, 25]),
    ("terracotta", [152, 94, 67]),
    ("white_terracotta", [209, 178, 161]),
    ("orange_terracotta", [161, 83, 37]),
    ("magenta_terracotta", [149, 88, 108]),
    ("light_blue_terracotta", [113, 108, 137]),
    ("yellow_terracotta", [186, 133, 35]),
    ("lime_terracotta", [103, 117, 52]),
    ("pink_terracotta", [161, 78, 78]),
    ("gray_terracotta", [57, 42, 35]),
    ("light_gray_terracotta", [135, 106, 97]),
    ("cyan_terracotta", [86, 91, 91]),
    ("purple_terracotta", [118, 70, 86]),
    ("blue_terracotta", [74, 59, 91]),
    ("brown_terracotta", [77, 51, 35]),
    ("green_terracotta", [76, 83, 42]),
    ("red_terracotta", [143, 61, 46]),
    ("black_terracotta", [37, 22, 16]),
    ("stone", [125, 125, 125]),
    ("smooth_stone", [158, 158, 158]),
    ("oak_planks", [162, 130, 78]),
    ("spruce_planks", [114, 84, 48]),
    ("birch_planks", [192, 175, 121]),
    ("dark_oak_planks", [66, 43, 20]),
    ("sandstone", [216, 203, 155]),
    ("quartz_block", [235, 229, 222]),
    ("snow_block", [249, 254, 254]),
    ("coal_block", [16, 15, 15]),
    ("gold_block", [246, 208, 61]),
    ("iron_block", [220, 220, 220]),
    ("diamond_block", [98, 237, 228]),
    ("emerald_block", [42, 203, 87]),
    ("lapis_block", [30, 67, 140]),
    ("redstone_block", [175, 24, 5]),
    ("netherrack", [97, 38, 38]),
    ("bricks", [150, 97, 83]),
];

/// A colour → block table.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockPalette {
    /// Block ids (`namespace:name`) and their colours.
    pub blocks: Vec<(String, [u8; 3])>,
}

impl Default for BlockPalette {
    fn default() -> BlockPalette {
        BlockPalette { blocks: BLOCKS.iter().map(|(n, c)| (format!("minecraft:{n}"), *c)).collect() }
    }
}

impl BlockPalette {
    /// Reads a palette file: `namespace:block R G B` per line, `#` comments.
    pub fn read(path: &Path) -> Result<BlockPalette, IoError> {
        let bytes = crate::read_regular(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
        let text = String::from_utf8(bytes).map_err(|_| IoError::new(path, ErrorKind::malformed("palette", "not UTF-8 text")))?;
        let mut blocks = Vec::new();
        for (n, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let w: Vec<&str> = line.split_whitespace().collect();
            let rgb: Option<Vec<u8>> = w.get(1..4).map(|c| c.iter().filter_map(|v| v.parse().ok()).collect());
            match (w.len(), rgb) {
                (4, Some(c)) if c.len() == 3 => {
                    let id = if w[0].contains(':') { w[0].to_string() } else { format!("minecraft:{}", w[0]) };
                    blocks.push((id, [c[0], c[1], c[2]]));
                }
                _ => {
                    let msg = format!("line {}: expected 'namespace:block R G B' with R, G, B in 0..=255, got {line:?}", n + 1);
                    return Err(IoError::new(path, ErrorKind::malformed("block palette", msg)));
                }
            }
        }
        if blocks.is_empty() {
            return Err(IoError::new(path, ErrorKind::malformed("block palette", "no blocks")));
        }
        Ok(BlockPalette { blocks })
    }
}

#[derive(Serialize, Deserialize)]
#[serde(rename_all = "PascalCase")]
struct V2 {
    version: i32,
    data_version: i32,
    width: i16,
    height: i16,
    length: i16,
    offset: IntArray,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    metadata: Option<Metadata>,
    palette_max: i32,
    palette: BTreeMap<String, i32>,
    block_data: ByteArray,
}

/// The schematic's metadata: WorldEdit's paste offset (which tools such as
/// mcschematic expect), and the data's up axis, so reading needs no `--up`.
#[derive(Serialize, Deserialize, Default)]
struct Metadata {
    #[serde(rename = "WEOffsetX", default)]
    we_offset_x: i32,
    #[serde(rename = "WEOffsetY", default)]
    we_offset_y: i32,
    #[serde(rename = "WEOffsetZ", default)]
    we_offset_z: i32,
    #[serde(rename = "TopovoxUp", alias = "VoxkitUp", default, skip_serializing_if = "Option::is_none")]
    topovox_up: Option<String>,
}

#[derive(Deserialize)]
#[serde(rename_all = "PascalCase")]
struct V3Root {
    schematic: V3,
}

#[derive(Deserialize)]
#[serde(rename_all = "PascalCase")]
struct V3 {
    width: i16,
    height: i16,
    length: i16,
    blocks: V3Blocks,
}

#[derive(Deserialize)]
#[serde(rename_all = "PascalCase")]
struct V3Blocks {
    palette: BTreeMap<String, i32>,
    data: ByteArray,
}

/// Why a schematic cannot hold a grid of `dims`: at most 65535 blocks a
/// side (NBT shorts), and at most 2³¹ − 1 blocks, the longest NBT byte
/// array (one byte per block while the palette has fewer than 128
/// entries). `None` when it can.
pub fn too_large(dims: [u32; 3]) -> Option<String> {
    let [nx, ny, nz] = dims;
    if dims.iter().any(|&d| d > u16::MAX as u32) {
        return Some(format!("a schematic holds at most {} blocks on a side; the grid is {nx}x{ny}x{nz}", u16::MAX));
    }
    let blocks = nx as u64 * ny as u64 * nz as u64;
    (blocks > i32::MAX as u64).then(|| {
        format!(
            "a schematic holds at most {} blocks (an NBT array); the grid {nx}x{ny}x{nz} has {blocks}; write .vdb, .zarr or .npz",
            i32::MAX
        )
    })
}

/// Writes `bits` as a Sponge schematic (version 2), blocks chosen by
/// colour, rotated so `up` points up (Minecraft is y-up).
pub fn write(
    w: &mut dyn Write,
    bits: &dyn VoxelSource,
    attrs: Option<&VoxelAttributes>,
    blocks: &BlockPalette,
    up: Up,
) -> std::io::Result<()> {
    let [nx, ny, nz] = bits.dims();
    if let Some(why) = too_large([nx, ny, nz]) {
        return Err(std::io::Error::other(why));
    }
    let orient = Orientation::minecraft(up);
    let src_dims = [nx, ny, nz];
    let [width, height, length] = orient.dims(src_dims).map(|d| d as usize);
    let labs: Vec<[f32; 3]> = blocks.blocks.iter().map(|b| oklab(b.1)).collect();
    let mut palette: BTreeMap<String, i32> = BTreeMap::from([("minecraft:air".to_string(), 0)]);
    let mut ids: BTreeMap<u32, u16> = BTreeMap::new();
    if blocks.blocks.len() >= u16::MAX as usize {
        return Err(std::io::Error::other("a block palette holds fewer than 65535 blocks"));
    }
    let mut cells = vec![0u16; width * height * length];
    let id_of = |name: &str, palette: &mut BTreeMap<String, i32>| -> u16 {
        let next = palette.len() as i32;
        *palette.entry(name.to_string()).or_insert(next) as u16
    };
    let plain = id_of(PLAIN, &mut palette);
    bits.for_each_set(&mut |i, j, k| {
        let id = match attrs.and_then(|a| a.colour_of(i, j, k)) {
            Some(c) => *ids.entry(pack(c)).or_insert_with(|| id_of(&blocks.blocks[quantize::nearest(&labs, oklab(c))].0, &mut palette)),
            None => plain,
        };
        let [x, y, z] = orient.apply([i, j, k], src_dims).map(|c| c as usize);
        cells[x + z * width + y * width * length] = id;
    });
    let mut data = Vec::with_capacity(cells.len());
    for &c in &cells {
        let mut v = c as u32;
        loop {
            let b = (v & 0x7f) as u8;
            v >>= 7;
            if v == 0 {
                data.push(b as i8);
                break;
            }
            data.push((b | 0x80) as i8);
        }
    }
    if data.len() > i32::MAX as usize {
        return Err(std::io::Error::other(format!(
            "the block data takes {} bytes (block ids past 127 take two), more than an NBT array holds",
            data.len()
        )));
    }
    let s = V2 {
        version: 2,
        data_version: DATA_VERSION,
        width: width as u16 as i16,
        height: height as u16 as i16,
        length: length as u16 as i16,
        offset: IntArray::new(vec![0, 0, 0]),
        metadata: Some(Metadata { we_offset_x: 0, we_offset_y: 0, we_offset_z: 0, topovox_up: Some(up.to_string()) }),
        palette_max: palette.len() as i32,
        palette,
        block_data: ByteArray::new(data),
    };
    let nbt = fastnbt::to_bytes_with_opts(&s, fastnbt::SerOpts::new().root_name("Schematic")).map_err(std::io::Error::other)?;
    let mut gz = flate2::write::GzEncoder::new(w, flate2::Compression::default());
    gz.write_all(&nbt)?;
    gz.finish()?;
    Ok(())
}

/// How deeply NBT compounds and lists may nest: fastnbt's deserializer
/// recurses once per level (skipping unknown tags too), and 467 bytes of
/// gzip can nest 85,000 compounds (a stack overflow). Schematics nest a
/// handful deep.
const MAX_NBT_DEPTH: usize = 512;

/// One open NBT container while [`nbt_depth`] walks the tags.
enum Open {
    /// Named tags until TAG_End.
    Compound,
    /// `left` more payloads of tag type `of`.
    List { of: u8, left: u32 },
}

/// Refuses NBT nesting compounds and lists deeper than `limit`, walked
/// with an explicit stack (the point is not to recurse). Each step reads
/// at least one byte, so the walk ends; a truncated or malformed stream
/// is left for fastnbt to report.
fn nbt_depth(b: &[u8], limit: usize) -> Result<(), String> {
    nbt_walk(b, limit, false).map(|_| ())
}

/// [`nbt_depth`]'s walk, which also returns the schematic's `Width`,
/// `Height` and `Length` once all three have been read (in the root, or
/// in version 3's `Schematic` compound) — from a prefix of the stream too;
/// `early`: stop there.
fn nbt_walk(b: &[u8], limit: usize, early: bool) -> Result<Option<[u16; 3]>, String> {
    let mut dims: [Option<u16>; 3] = [None; 3];
    let mut at = 0usize;
    let take = |at: &mut usize, n: usize| -> Option<usize> {
        let start = *at;
        *at = at.checked_add(n).filter(|&e| e <= b.len())?;
        Some(start)
    };
    let int = |at: usize, n: usize| b[at..at + n].iter().fold(0u64, |v, &x| v << 8 | x as u64);
    // Skips a payload of `tag`, or opens it; None: the stream ended.
    let mut stack: Vec<Open> = Vec::new();
    let payload = |tag: u8, at: &mut usize, stack: &mut Vec<Open>| -> Option<()> {
        let fixed = [0usize, 1, 2, 4, 8, 4, 8];
        match tag {
            0..=6 => {
                take(at, fixed[tag as usize])?;
            }
            7 | 11 | 12 => {
                let n = int(take(at, 4)?, 4) as u32 as i32;
                take(at, n.max(0) as usize * [1, 4, 8][(tag != 7) as usize + (tag == 12) as usize])?;
            }
            8 => {
                let n = int(take(at, 2)?, 2) as usize;
                take(at, n)?;
            }
            9 => {
                let of = b[take(at, 1)?];
                let n = int(take(at, 4)?, 4) as u32 as i32;
                match of {
                    0..=6 => {
                        take(at, n.max(0) as usize * fixed[of as usize])?;
                    }
                    _ => stack.push(Open::List { of, left: n.max(0) as u32 }),
                }
            }
            10 => stack.push(Open::Compound),
            _ => return None,
        }
        Some(())
    };
    // The root: a named tag.
    let Some(t) = take(&mut at, 1).map(|i| b[i]) else { return Ok(None) };
    let named = |at: &mut usize| take(at, 2).and_then(|i| Some(&b[take(at, int(i, 2) as usize)?..*at]));
    if named(&mut at).and_then(|_| payload(t, &mut at, &mut stack)).is_none() {
        return Ok(None);
    }
    let found = |dims: &[Option<u16>; 3]| -> Option<[u16; 3]> { Some([dims[0]?, dims[1]?, dims[2]?]) };
    while !stack.is_empty() {
        if let (true, Some(d)) = (early, found(&dims)) {
            return Ok(Some(d));
        }
        if stack.len() > limit {
            return Err(format!("NBT nested more than {limit} deep"));
        }
        // The next payload's tag: a list's element type, or a compound's next tag.
        let list_item = match stack.last_mut() {
            Some(Open::List { left: 0, .. }) => {
                stack.pop();
                continue;
            }
            Some(Open::List { of, left }) => {
                *left -= 1;
                Some(*of)
            }
            _ => None,
        };
        let step = match list_item {
            Some(of) => payload(of, &mut at, &mut stack),
            None => match take(&mut at, 1).map(|i| b[i]) {
                Some(0) => stack.pop().map(|_| ()),
                Some(2) if stack.len() <= 2 => named(&mut at).and_then(|name| {
                    let v = int(take(&mut at, 2)?, 2) as u16;
                    if let Some(d) = ["Width", "Height", "Length"].iter().position(|n| n.as_bytes() == name) {
                        dims[d] = Some(v);
                    }
                    Some(())
                }),
                Some(t) => named(&mut at).and_then(|_| payload(t, &mut at, &mut stack)),
                None => None,
            },
        };
        if step.is_none() {
            return Ok(found(&dims));
        }
    }
    Ok(found(&dims))
}

/// Bytes of NBT a schematic may hold besides its block data (palette,
/// metadata, block entities), once its size is known.
const NBT_BESIDES_BLOCKS: u64 = 64 << 20;

/// Decompresses a schematic, bounded by what its header allows: once
/// `Width`, `Height` and `Length` have been read, at most five bytes per
/// block (a varint's longest) plus [`NBT_BESIDES_BLOCKS`]; before that,
/// and in all, what a read may take (and never past 2 GiB, NBT's array
/// limit). A 3 MB gzip bomb stops at its bound, not at 2 GB.
fn inflate(bytes: &[u8]) -> Result<Vec<u8>, String> {
    let mut gz = flate2::read::GzDecoder::new(bytes);
    let mut nbt = Vec::new();
    let mut bound = crate::read_limit().min(1 << 31);
    let mut dims = None;
    let mut next_look = 1 << 16;
    loop {
        let before = nbt.len();
        let step = (bound + 1).saturating_sub(before as u64).min(1 << 20);
        let read = (&mut gz).take(step).read_to_end(&mut nbt).map_err(|e| format!("not gzip-compressed NBT ({e})"))?;
        if read == 0 {
            return Ok(nbt);
        }
        if dims.is_none() && (nbt.len() >= next_look || read < step as usize) {
            // Looked for again each time the stream doubles: linear in all.
            next_look = nbt.len() * 2;
            if let Some([w, h, l]) = nbt_walk(&nbt, MAX_NBT_DEPTH, true)? {
                dims = Some([w, h, l]);
                let blocks = w as u64 * h as u64 * l as u64;
                bound = bound.min(blocks.saturating_mul(5).saturating_add(NBT_BESIDES_BLOCKS).saturating_add(nbt.len() as u64));
            }
        }
        if nbt.len() as u64 > bound {
            let why = match dims {
                Some([w, h, l]) => format!("{w}x{h}x{l} blocks"),
                None => "a read".into(),
            };
            return Err(format!("decompresses to more than the {} that {why} may take (a gzip bomb?)", crate::bytes(bound)));
        }
    }
}

/// Reads a Sponge schematic (version 2 or 3): every non-air block is a
/// voxel, coloured from the built-in table where the block is in it,
/// rotated back from Minecraft's y-up by the up axis the file records
/// (topovox's), else by `up`.
pub fn read(bytes: &[u8], up: Up) -> Result<LoadedVoxels, ErrorKind> {
    let bad = |m: String| ErrorKind::malformed("schem", m);
    let nbt = inflate(bytes).map_err(bad)?;
    nbt_depth(&nbt, MAX_NBT_DEPTH).map_err(bad)?;
    // fastnbt refuses sequences past 10⁸ elements by default; a 512³
    // schematic has 1.3·10⁸ blocks. No sequence is longer than the stream.
    let opts = || fastnbt::DeOpts::new().max_seq_len(nbt.len());
    let (w, h, l, palette, data, recorded) = match fastnbt::from_bytes_with_opts::<V2>(&nbt, opts()) {
        Ok(v) => (v.width, v.height, v.length, v.palette, v.block_data, v.metadata.and_then(|m| m.topovox_up)),
        Err(e2) => match fastnbt::from_bytes_with_opts::<V3Root>(&nbt, opts()) {
            Ok(r) => (r.schematic.width, r.schematic.height, r.schematic.length, r.schematic.blocks.palette, r.schematic.blocks.data, None),
            Err(e3) => return Err(bad(format!("neither a version 2 ({e2}) nor a version 3 ({e3}) schematic"))),
        },
    };
    let [width, height, length] = [w, h, l].map(|d| d as u16 as usize);
    let n = width.checked_mul(height).and_then(|v| v.checked_mul(length)).ok_or_else(|| bad("size overflows".into()))?;
    if n == 0 {
        return Err(bad(format!("the schematic is {width}x{height}x{length} blocks")));
    }
    if n > data.len() {
        return Err(bad(format!("{width}x{height}x{length} blocks but only {} bytes of block data", data.len())));
    }
    let table = BlockPalette::default();
    let mut by_id: BTreeMap<i32, Option<[u8; 3]>> = BTreeMap::new();
    for (name, id) in &palette {
        let base = name.split('[').next().unwrap_or(name);
        let colour = if base == "minecraft:air" || base == "minecraft:cave_air" || base == "minecraft:void_air" {
            None
        } else {
            Some(table.blocks.iter().find(|b| b.0 == base).map(|b| b.1).unwrap_or([160, 160, 160]))
        };
        by_id.insert(*id, colour);
    }
    let orient = Orientation::minecraft(recorded.as_deref().and_then(Up::from_name).unwrap_or(up));
    let tdims = [width as u32, height as u32, length as u32];
    let dims = orient.source_dims(tdims);
    let mut bits = crate::dense_grid(dims)?;
    let mut coloured = Vec::new();
    let (mut at, mut cell) = (0usize, 0usize);
    while cell < n {
        let (mut v, mut shift) = (0u32, 0u32);
        loop {
            let b = *data.get(at).ok_or_else(|| bad(format!("block data ends after {cell} of {n} blocks")))? as u8;
            at += 1;
            if shift > 28 {
                return Err(bad("a block id's varint is longer than 5 bytes".into()));
            }
            v |= ((b & 0x7f) as u32) << shift;
            shift += 7;
            if b & 0x80 == 0 {
                break;
            }
        }
        let colour = by_id.get(&(v as i32)).ok_or_else(|| bad(format!("block {cell} uses id {v}, not in the palette")))?;
        if let Some(c) = colour {
            let (x, z, y) = (cell % width, cell / width % length, cell / (width * length));
            let p = orient.invert([x as u32, y as u32, z as u32], tdims);
            bits.set(p[0], p[1], p[2]);
            coloured.push((p, *c));
        }
        cell += 1;
    }
    Ok(LoadedVoxels { bits, placement: None, attributes: Some(VoxelAttributes::from_coloured(dims, coloured)) })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gzip(bytes: &[u8]) -> Vec<u8> {
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        std::io::Write::write_all(&mut e, bytes).unwrap();
        e.finish().unwrap()
    }

    /// A root compound holding `n` nested compounds, then a list of lists.
    fn nested(n: usize) -> Vec<u8> {
        let mut b = vec![10, 0, 9];
        b.extend_from_slice(b"Schematic");
        for _ in 0..n {
            b.extend_from_slice(&[10, 0, 1, b'a']);
        }
        b.extend(std::iter::repeat_n(0u8, n + 1));
        b
    }

    #[test]
    fn deep_nesting_is_refused_not_a_stack_overflow() {
        // Issue 54: 85,000 nested compounds in 467 bytes overflowed the stack.
        let e = read(&gzip(&nested(85_000)), Up::Y).unwrap_err().to_string();
        assert!(e.contains("NBT nested more than 512 deep"), "{e}");
        assert!(gzip(&nested(85_000)).len() < 1000);
        // Lists nest too: a list of lists of ... compounds.
        let mut b = vec![10, 0, 1, b's', 9, 0, 1, b'l'];
        for _ in 0..1000 {
            b.extend_from_slice(&[9, 0, 0, 0, 1]);
        }
        let e = read(&gzip(&b), Up::Y).unwrap_err().to_string();
        assert!(e.contains("NBT nested more than 512 deep"), "{e}");
        // Shallow but not a schematic: fastnbt says what is wrong.
        let e = read(&gzip(&nested(20)), Up::Y).unwrap_err().to_string();
        assert!(!e.contains("nested") && e.contains("schematic"), "{e}");
    }

    #[test]
    fn gzip_bombs_stop_at_the_bound_their_header_allows() {
        // Issue 54: a 2.9 MB file cost 2.1 GB before its refusal. A 2x2x2
        // schematic's header, then 400 MB of zeros in an unknown byte array.
        let mut b = vec![10, 0, 9];
        b.extend_from_slice(b"Schematic");
        for name in ["Width", "Height", "Length"] {
            b.extend_from_slice(&[2, 0, name.len() as u8]);
            b.extend_from_slice(name.as_bytes());
            b.extend_from_slice(&[0, 2]);
        }
        let zeros = 400usize << 20;
        b.extend_from_slice(&[7, 0, 1, b'z']);
        b.extend_from_slice(&(zeros as i32).to_be_bytes());
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        std::io::Write::write_all(&mut e, &b).unwrap();
        let chunk = vec![0u8; 1 << 20];
        for _ in 0..zeros >> 20 {
            std::io::Write::write_all(&mut e, &chunk).unwrap();
        }
        let bomb = e.finish().unwrap();
        assert!(bomb.len() < 1 << 20, "{}", bomb.len());
        let e = inflate(&bomb).unwrap_err();
        assert!(e.contains("MiB that 2x2x2 blocks may take"), "{e}");
        // The header alone, read in full: its dims are found.
        assert_eq!(nbt_walk(&b[..b.len() - 8], 8, true), Ok(Some([2, 2, 2])));
    }

    #[test]
    fn the_depth_walk_reads_every_tag_kind() {
        // byte, short, int, long, float, double, byte array, string, list of
        // ints, int array, long array, then End: depth 1, nothing refused.
        let mut b = vec![10, 0, 0];
        for (tag, payload) in [
            (1u8, vec![7u8]),
            (2, vec![0, 7]),
            (3, vec![0, 0, 0, 7]),
            (4, vec![0; 8]),
            (5, vec![0; 4]),
            (6, vec![0; 8]),
            (7, vec![0, 0, 0, 2, 1, 2]),
            (8, vec![0, 2, b'h', b'i']),
            (9, vec![3, 0, 0, 0, 2, 0, 0, 0, 1, 0, 0, 0, 2]),
            (11, vec![0, 0, 0, 1, 0, 0, 0, 9]),
            (12, vec![0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 9]),
        ] {
            b.extend_from_slice(&[tag, 0, 1, b'x']);
            b.extend(payload);
        }
        b.push(0);
        assert_eq!(nbt_depth(&b, 1), Ok(()));
        // The root compound is a level: `nested(n)` is n + 1 deep.
        assert_eq!(nbt_depth(&nested(2), 3), Ok(()));
        assert!(nbt_depth(&nested(3), 3).is_err());
    }
}
