//! OpenVDB `.vdb` (file format 224, as written by OpenVDB 10–12), written
//! and read by hand: no maintained Rust crate writes VDB files.
//!
//! **What is written.** One `BoolGrid` named `voxels` (tree
//! `Tree_bool_5_4_3`: root → 32³ internal nodes → 16³ internal nodes → 8³
//! leaves). Every set voxel is an active voxel with value `true`; index
//! coordinate `(i, j, k)` is topovox's voxel `(i, j, k)`. The transform is a
//! `UniformScaleTranslateMap` taking index `(i, j, k)` to that voxel's
//! centre: scale = voxel size, translation = grid origin + half a voxel; a
//! grid of boxes gets a `ScaleTranslateMap` with the size per axis (the same
//! six vectors, which OpenVDB's `voxelSize()` gives back per axis).
//! Grid metadata: `file_bbox_min`/`file_bbox_max`/`file_voxel_count` (as
//! OpenVDB writes them), and `topovox_dims`, `topovox_origin`,
//! `topovox_voxel_size` (a `double`, a `vec3d` for boxes), which the reader
//! uses to restore the exact grid.
//! Full 8³ bricks are active tiles of their 16³ node (value `true`), and
//! 16³ nodes whose 4096 bricks are all full are active tiles of 128³ in
//! their 32³ node: a solid's interior costs bits per brick, not voxels.
//!
//! **Attributes** (`voxelize --attributes`, or `convert` from a file that
//! has them) follow as one grid each, over the same active voxels (every
//! brick a leaf: each voxel holds its own value), background zero: `Cd`
//! (`Tree_vec3s_5_4_3`, colour in linear RGB, the name Houdini gives
//! colour), `normal` (`Tree_vec3s_5_4_3`), `coverage` (`Tree_float_5_4_3`)
//! and `material` (`Tree_float_5_4_3`, the id, -1 for none: pyopenvdb
//! reads no integer grids; ids below 2^24 are exact). Leaf values use
//! OpenVDB's active-mask compression with metadata 0 (only the active
//! values, in index order), the layout of `LeafNode<T>::writeBuffers` and
//! `io::writeCompressedValues`.
//! Internal-node values use OpenVDB's active-mask compression (only the
//! active tiles' values are stored), leaves are uncompressed bit masks, so
//! the file needs no compression library. The byte layout
//! follows OpenVDB's `Archive::writeGrid`, `RootNode`/`InternalNode::
//! writeTopology` and `LeafNode<bool>::writeBuffers`; CI reads every file
//! back with OpenVDB's own reader (`pyopenvdb`) and compares every active
//! voxel.
//!
//! **What is read.** The first bool grid, or without one the first float
//! level set (or topovox's unsigned `surface` field) as the voxels inside
//! it (negative values, active or not; unsigned: within half a voxel
//! diagonal of the surface), written uncompressed or with
//! active-mask compression (topovox's own files, and OpenVDB files saved
//! without zip/blosc), active voxels and active tiles, and beside it the
//! attribute grids named and typed as above (a set voxel a grid holds no
//! active value for gets zero, the background). Every node-compression
//! metadata case of `io::readCompressedValues` is read; zip/blosc and
//! half-float values are refused by name.
//!
//! Sizes are computed before anything is written, so the file streams
//! through one pass (the grid offsets OpenVDB puts before each grid are
//! known in advance) and memory is the sorted leaf list, 72 bytes per
//! partial brick, and 512 bytes per 16³ node holding tiles.

use std::io::Write;

use glam::DVec3;
use topovox::attributes::colour::{from_linear, to_linear};
use topovox::attributes::{VoxelAttributes, NO_MATERIAL};
use topovox::grid::bricks::{set_in_brick, Brick};
use topovox::grid::sparse::{SparseBricks, FULL};
use topovox::{GridSpec, VoxelSource};

use crate::error::ErrorKind;
use crate::{LoadedVoxels, SparseVoxels};

mod level_set;
pub use level_set::{write_level_set, LEVEL_SET_NAME};
use topovox::distance::field::Field;

const MAGIC: i64 = 0x5644_4220;
const FILE_VERSION: u32 = 224;
/// Oldest format read: 222 introduced node-mask compression and the
/// per-grid compression flags this reader expects.
const MIN_VERSION: u32 = 222;
const COMPRESS_ZIP: u32 = 1;
const COMPRESS_ACTIVE_MASK: u32 = 2;
const COMPRESS_BLOSC: u32 = 4;
const GRID_TYPE: &str = "Tree_bool_5_4_3";
const FLOAT_TYPE: &str = "Tree_float_5_4_3";
const VEC3_TYPE: &str = "Tree_vec3s_5_4_3";
/// The occupancy grid's name.
const GRID_NAME: &str = "voxels";
/// The attribute grids' names (`Cd` as Houdini names colour).
const ATTR_COLOUR: &str = "Cd";
const ATTR_NORMAL: &str = "normal";
const ATTR_COVERAGE: &str = "coverage";
const ATTR_MATERIAL: &str = "material";

/// Log2 of the node sizes in voxels: leaf 8, lower internal 128, upper 4096.
const LEAF: u32 = 3;
const LOWER: u32 = 7;
const UPPER: u32 = 12;

/// A leaf: origin and OpenVDB's bit layout (bit `x·64 + y·8 + z`, so word
/// `x`, bit `y·8 + z`).
struct Leaf {
    origin: [u32; 3],
    mask: [u64; 8],
}

impl Leaf {
    /// Order of OpenVDB's traversal: root children by origin `(x, y, z)`,
    /// then children of internal nodes by their index (x slowest).
    fn order(&self) -> (u32, u32, u32, u32, u32) {
        let [x, y, z] = self.origin;
        let up = |c: u32| c >> UPPER;
        let lower = ((x >> LOWER) & 31) << 10 | ((y >> LOWER) & 31) << 5 | ((z >> LOWER) & 31);
        let leaf = ((x >> LEAF) & 15) << 8 | ((y >> LEAF) & 15) << 4 | ((z >> LEAF) & 15);
        (up(x), up(y), up(z), lower, leaf)
    }
}

/// topovox's brick layout (word `z`, bit `y·8 + x`) to OpenVDB's.
fn to_vdb(b: &Brick) -> [u64; 8] {
    let mut m = [0u64; 8];
    for (z, &w) in b.iter().enumerate() {
        let mut w = w;
        while w != 0 {
            let bit = w.trailing_zeros();
            w &= w - 1;
            let (x, y) = (bit & 7, bit >> 3);
            m[x as usize] |= 1 << (y * 8 + z as u32);
        }
    }
    m
}

/// A byte sink: a writer, or a counter of the bytes a writer would get.
trait Out {
    fn put(&mut self, b: &[u8]) -> std::io::Result<()>;
    /// Puts the `len` bytes `fill` appends to a buffer; a counter adds
    /// `len` without calling it.
    fn put_with(&mut self, len: usize, fill: &mut dyn FnMut(&mut Vec<u8>) -> std::io::Result<()>) -> std::io::Result<()> {
        let mut buf = Vec::with_capacity(len);
        fill(&mut buf)?;
        // The counting pass took `len`: a mismatch would misplace every
        // later offset, so it is an error, never a corrupt file.
        if buf.len() != len {
            return Err(std::io::Error::other(format!("vdb writer: {} bytes where {len} were counted", buf.len())));
        }
        self.put(&buf)
    }
}

struct Count(u64);

impl Out for Count {
    fn put(&mut self, b: &[u8]) -> std::io::Result<()> {
        self.0 += b.len() as u64;
        Ok(())
    }
    fn put_with(&mut self, len: usize, _: &mut dyn FnMut(&mut Vec<u8>) -> std::io::Result<()>) -> std::io::Result<()> {
        self.0 += len as u64;
        Ok(())
    }
}

struct Stream<'a>(&'a mut dyn Write);

impl Out for Stream<'_> {
    fn put(&mut self, b: &[u8]) -> std::io::Result<()> {
        self.0.write_all(b)
    }
}

fn put_str(o: &mut dyn Out, s: &str) -> std::io::Result<()> {
    o.put(&(s.len() as u32).to_le_bytes())?;
    o.put(s.as_bytes())
}

fn put_words(o: &mut dyn Out, words: &[u64]) -> std::io::Result<()> {
    let mut buf = [0u8; 512];
    for chunk in words.chunks(64) {
        for (n, w) in chunk.iter().enumerate() {
            buf[8 * n..8 * n + 8].copy_from_slice(&w.to_le_bytes());
        }
        o.put(&buf[..8 * chunk.len()])?;
    }
    Ok(())
}

/// One metadata entry: name, type name, byte size, value.
fn put_meta(o: &mut dyn Out, name: &str, ty: &str, value: &[u8]) -> std::io::Result<()> {
    put_str(o, name)?;
    put_str(o, ty)?;
    o.put(&(value.len() as u32).to_le_bytes())?;
    o.put(value)
}

fn vec3i(v: [i32; 3]) -> Vec<u8> {
    v.iter().flat_map(|c| c.to_le_bytes()).collect()
}

fn vec3d(v: [f64; 3]) -> Vec<u8> {
    v.iter().flat_map(|c| c.to_le_bytes()).collect()
}

/// The grid's metadata and transform.
fn put_grid_head(o: &mut dyn Out, g: &GridOut<'_>, grid: &GridSpec) -> std::io::Result<()> {
    let (name, tree, count) = (g.name, g.tree, g.count);
    o.put(&COMPRESS_ACTIVE_MASK.to_le_bytes())?;
    // Bounds of the active voxels: the tiles' boxes, then leaf by leaf: x
    // from the non-zero words, y and z from the bytes and bits of their union.
    let mut bbox: Option<([i32; 3], [i32; 3])> = tree.tile_box;
    for l in &tree.leaves {
        let Some(x0) = l.mask.iter().position(|&w| w != 0) else { continue };
        let x1 = l.mask.iter().rposition(|&w| w != 0).unwrap_or(x0);
        let all = l.mask.iter().fold(0u64, |a, &w| a | w);
        let ys = (0..8u32).filter(|y| (all >> (y * 8)) & 0xff != 0);
        let (y0, y1) = (ys.clone().min().unwrap_or(0), ys.max().unwrap_or(0));
        let zs = (0..8u32).fold(0u64, |a, y| a | ((all >> (y * 8)) & 0xff));
        let (z0, z1) = (zs.trailing_zeros(), 63 - zs.leading_zeros());
        let lo = [l.origin[0] + x0 as u32, l.origin[1] + y0, l.origin[2] + z0].map(|c| c as i32);
        let hi = [l.origin[0] + x1 as u32, l.origin[1] + y1, l.origin[2] + z1].map(|c| c as i32);
        let b = bbox.get_or_insert((lo, hi));
        for a in 0..3 {
            b.0[a] = b.0[a].min(lo[a]);
            b.1[a] = b.1[a].max(hi[a]);
        }
    }
    let o_ = grid.origin();
    let s = grid.voxel_size();
    let dims = grid.dims().map(|d| d as i32);
    let mut entries: Vec<(&str, &str, Vec<u8>)> = Vec::new();
    if let Some(class) = g.class {
        entries.push(("class", "string", class.as_bytes().to_vec()));
    }
    if let Some((lo, hi)) = bbox {
        entries.push(("file_bbox_max", "vec3i", vec3i(hi)));
        entries.push(("file_bbox_min", "vec3i", vec3i(lo)));
    }
    entries.push(("file_voxel_count", "int64", (count as i64).to_le_bytes().to_vec()));
    entries.push(("name", "string", name.as_bytes().to_vec()));
    entries.push(("topovox_dims", "vec3i", vec3i(dims)));
    entries.push(("topovox_origin", "vec3d", vec3d(o_.to_array())));
    entries.push(match grid.cube_size() {
        Some(c) => ("topovox_voxel_size", "double", c.to_le_bytes().to_vec()),
        None => ("topovox_voxel_size", "vec3d", vec3d(s.to_array())),
    });
    o.put(&(entries.len() as u32).to_le_bytes())?;
    for (n, t, v) in &entries {
        put_meta(o, n, t, v)?;
    }
    // OpenVDB's `ScaleTranslateMap::write` order: translation, scale, voxel
    // size, 1/scale, 1/scale², 1/(2·scale); the uniform map is the same.
    put_str(o, if grid.cube_size().is_some() { "UniformScaleTranslateMap" } else { "ScaleTranslateMap" })?;
    let t = o_ + 0.5 * s;
    for v in [t, s, s, 1.0 / s, 1.0 / (s * s), 0.5 / s] {
        o.put(&vec3d(v.to_array()))?;
    }
    Ok(())
}

/// Full bricks by lower node: key → mask of its 16³ bricks.
type FullBricks = std::collections::HashMap<(u32, u32, u32, u32), Box<[u64; 64]>>;

/// Marks the run of `n` full bricks from brick `b` along x in `full`,
/// cut where it crosses lower nodes (16 bricks each).
fn mark_full(full: &mut FullBricks, b: [u32; 3], n: u32) {
    let mut x = b[0];
    while x < b[0] + n {
        let end = (b[0] + n).min((x / 16 + 1) * 16);
        let first = Leaf { origin: [x << LEAF, b[1] << LEAF, b[2] << LEAF], mask: [0; 8] }.order();
        let mask = full.entry((first.0, first.1, first.2, first.3)).or_insert_with(|| Box::new([0; 64]));
        for xx in x..end {
            let idx = (((xx & 15) << 8) | (first.4 & 0xff)) as usize;
            mask[idx / 64] |= 1 << (idx % 64);
        }
        x = end;
    }
}

/// A lower internal node (128³ voxels): its leaves, and its active tiles
/// (full 8³ bricks) as a mask over its 16³ children.
struct Lower {
    /// `(upper x, y, z, index in the upper node)`: OpenVDB's order.
    key: (u32, u32, u32, u32),
    leaves: std::ops::Range<usize>,
    tiles: Box<[u64; 64]>,
}

/// The tree to write: leaves (partial bricks) in OpenVDB's order, lower
/// nodes holding leaves or tiles, and the lower nodes wholly full, which
/// become active tiles of their upper node.
struct Tree {
    leaves: Vec<Leaf>,
    lowers: Vec<Lower>,
    /// Full lower nodes as `(upper x, y, z, index)`, sorted.
    full_lowers: Vec<(u32, u32, u32, u32)>,
    /// Bounds of the tiles' voxels.
    tile_box: Option<([i32; 3], [i32; 3])>,
}

fn upper_of(k: &(u32, u32, u32, u32)) -> (u32, u32, u32) {
    (k.0, k.1, k.2)
}

impl Tree {
    /// Gathers the bricks of `bits`: partial ones as leaves, runs of full
    /// ones as tiles (never one by one: a solid's interior is a few runs
    /// per brick row), lower nodes all of whose 4096 bricks are full as
    /// tiles of 128³. Without `tiles` (attribute grids, whose voxels each
    /// hold their own value) every brick is a leaf.
    fn of(bits: &dyn VoxelSource, tiles: bool) -> Tree {
        let mut leaves = Vec::new();
        let mut full = FullBricks::new();
        let mut tile_box: Option<([i32; 3], [i32; 3])> = None;
        bits.for_each_brick_run(&mut |b, brick, n| {
            if *brick != FULL {
                leaves.push(Leaf { origin: b.map(|c| c << LEAF), mask: to_vdb(brick) });
                return;
            }
            if !tiles {
                for x in b[0]..b[0] + n {
                    leaves.push(Leaf { origin: [x << LEAF, b[1] << LEAF, b[2] << LEAF], mask: [u64::MAX; 8] });
                }
                return;
            }
            let lo = b.map(|c| (c << LEAF) as i32);
            let hi = [((b[0] + n) << LEAF) as i32 - 1, lo[1] + 7, lo[2] + 7];
            let bb = tile_box.get_or_insert((lo, hi));
            for a in 0..3 {
                bb.0[a] = bb.0[a].min(lo[a]);
                bb.1[a] = bb.1[a].max(hi[a]);
            }
            mark_full(&mut full, b, n);
        });
        Tree::assemble(leaves, full, tile_box)
    }

    /// The tree of `leaves` (any order) and the full bricks of lower nodes
    /// (`full`: lower-node key → mask of its 16³ bricks).
    fn assemble(mut leaves: Vec<Leaf>, mut full: FullBricks, tile_box: Option<([i32; 3], [i32; 3])>) -> Tree {
        use rayon::slice::ParallelSliceMut;
        leaves.par_sort_unstable_by_key(Leaf::order);
        // Lower nodes: those of leaves, with their tiles, then tile-only ones.
        let lower_key = |l: &Leaf| {
            let o = l.order();
            (o.0, o.1, o.2, o.3)
        };
        let mut lowers: Vec<Lower> = Vec::new();
        for range in crate::runs(&leaves, lower_key) {
            let key = lower_key(&leaves[range.start]);
            let tiles = full.remove(&key).unwrap_or_else(|| Box::new([0; 64]));
            lowers.push(Lower { key, leaves: range, tiles });
        }
        let mut full_lowers = Vec::new();
        for (key, tiles) in full {
            if tiles.iter().all(|&w| w == u64::MAX) {
                full_lowers.push(key);
            } else {
                lowers.push(Lower { key, leaves: 0..0, tiles });
            }
        }
        lowers.sort_unstable_by_key(|l| l.key);
        full_lowers.sort_unstable();
        Tree { leaves, lowers, full_lowers, tile_box }
    }
}

/// An internal node's values after its masks: the metadata byte saying no
/// inactive value differs from the background, then one `true` byte per
/// active tile (mask compression stores only active values).
fn put_tile_values(o: &mut dyn Out, tiles: &[u64]) -> std::io::Result<()> {
    o.put(&[0])?;
    let n: u32 = tiles.iter().map(|w| w.count_ones()).sum();
    let ones = [1u8; 512];
    let mut left = n as usize;
    while left > 0 {
        let k = left.min(ones.len());
        o.put(&ones[..k])?;
        left -= k;
    }
    Ok(())
}

/// What a tree's nodes hold beyond their topology.
#[derive(Clone, Copy)]
enum Buffers<'a> {
    /// A bool grid: tiles are active `true`, leaves' masks are the values.
    Occupancy,
    /// An attribute grid: no tiles, zero background, each leaf's active
    /// values after its mask.
    Attribute(&'a Values<'a>),
    /// A distance field: tiles are inactive `−background` (inside), every
    /// other inactive value `±background` by its sign ([`level_set`]).
    LevelSet(&'a Field),
}

/// An internal node's value mask and values after its child mask: active
/// tiles (`Occupancy`), or for a level set no active tile and a selection
/// mask (metadata 3: a set bit is `+background`, a clear one
/// `−background`), clear where `tiles` are inside.
fn put_node_values(o: &mut dyn Out, tiles: &[u64], buffers: Buffers<'_>) -> std::io::Result<()> {
    if let Buffers::LevelSet(_) = buffers {
        put_words(o, &vec![0; tiles.len()])?;
        o.put(&[3])?;
        let outside: Vec<u64> = tiles.iter().map(|w| !w).collect();
        return put_words(o, &outside);
    }
    put_words(o, tiles)?;
    put_tile_values(o, tiles)
}

/// The tree: topology, then buffers.
fn put_tree(o: &mut dyn Out, tree: &Tree, buffers: Buffers<'_>) -> std::io::Result<()> {
    o.put(&1i32.to_le_bytes())?; // buffer count
    match buffers {
        Buffers::Occupancy => o.put(&[0])?, // background: false
        Buffers::Attribute(v) => o.put(&[0; 12][..v.size])?,
        Buffers::LevelSet(f) => o.put(&f.background.to_le_bytes())?,
    }
    // Upper nodes: those of lower nodes and of full lower nodes, in order.
    let mut uppers: Vec<(u32, u32, u32)> =
        tree.lowers.iter().map(|l| upper_of(&l.key)).chain(tree.full_lowers.iter().map(upper_of)).collect();
    uppers.sort_unstable();
    uppers.dedup();
    o.put(&0u32.to_le_bytes())?; // tiles
    o.put(&(uppers.len() as u32).to_le_bytes())?;
    let (mut l, mut f) = (0, 0);
    for up in &uppers {
        o.put(&vec3i([up.0, up.1, up.2].map(|c| (c << UPPER) as i32)))?;
        let l_end = l + tree.lowers[l..].iter().take_while(|x| upper_of(&x.key) == *up).count();
        let f_end = f + tree.full_lowers[f..].iter().take_while(|x| upper_of(x) == *up).count();
        let mut child = vec![0u64; 32 * 32 * 32 / 64];
        for x in &tree.lowers[l..l_end] {
            child[x.key.3 as usize / 64] |= 1 << (x.key.3 % 64);
        }
        let mut value = vec![0u64; child.len()];
        for x in &tree.full_lowers[f..f_end] {
            value[x.3 as usize / 64] |= 1 << (x.3 % 64);
        }
        put_words(o, &child)?;
        put_node_values(o, &value, buffers)?;
        for x in &tree.lowers[l..l_end] {
            let mut child = [0u64; 16 * 16 * 16 / 64];
            for leaf in &tree.leaves[x.leaves.clone()] {
                let n = leaf.order().4 as usize;
                child[n / 64] |= 1 << (n % 64);
            }
            put_words(o, &child)?;
            put_node_values(o, &x.tiles[..], buffers)?;
            for leaf in &tree.leaves[x.leaves.clone()] {
                put_words(o, &leaf.mask)?;
            }
        }
        (l, f) = (l_end, f_end);
    }
    match buffers {
        Buffers::Occupancy => put_bool_leaves(o, tree),
        Buffers::Attribute(v) => put_attribute_leaves(o, tree, v),
        Buffers::LevelSet(field) => {
            for leaf in &tree.leaves {
                put_words(o, &leaf.mask)?;
                // Counted from the masks alone: the values are made once, when written.
                o.put_with(level_set::leaf_values_len(field, leaf), &mut |buf| {
                    buf.extend_from_slice(&level_set::leaf_values(field, leaf));
                    Ok(())
                })?;
            }
            Ok(())
        }
    }
}

/// Each leaf's active values after its mask (an attribute grid).
fn put_attribute_leaves(o: &mut dyn Out, tree: &Tree, v: &Values<'_>) -> std::io::Result<()> {
    for leaf in &tree.leaves {
        // Value mask, then OpenVDB's compressed values: metadata 0 (every
        // inactive value is the background), the active values in
        // index order (`x·64 + y·8 + z`).
        put_words(o, &leaf.mask)?;
        let active: u32 = leaf.mask.iter().map(|w| w.count_ones()).sum();
        o.put_with(1 + active as usize * v.size, &mut |buf| {
            buf.push(0);
            for (x, &w) in leaf.mask.iter().enumerate() {
                let mut w = w;
                while w != 0 {
                    let b = w.trailing_zeros();
                    w &= w - 1;
                    let p = [leaf.origin[0] + x as u32, leaf.origin[1] + (b >> 3), leaf.origin[2] + (b & 7)];
                    let slot = v.attrs.slot(p[0], p[1], p[2]).ok_or_else(|| {
                        std::io::Error::other(format!("voxel {p:?} is set but has no attributes (voxels and attributes differ)"))
                    })?;
                    (v.put)(slot, buf);
                }
            }
            Ok(())
        })?;
    }
    Ok(())
}

/// Each leaf of a bool grid: value mask (active), origin, values.
fn put_bool_leaves(o: &mut dyn Out, tree: &Tree) -> std::io::Result<()> {
    let mut buf = [0u8; 140];
    for leaf in &tree.leaves {
        for (n, w) in leaf.mask.iter().enumerate() {
            buf[8 * n..8 * n + 8].copy_from_slice(&w.to_le_bytes());
            buf[76 + 8 * n..84 + 8 * n].copy_from_slice(&w.to_le_bytes());
        }
        for a in 0..3 {
            buf[64 + 4 * a..68 + 4 * a].copy_from_slice(&(leaf.origin[a] as i32).to_le_bytes());
        }
        o.put(&buf)?;
    }
    Ok(())
}

/// A deterministic UUID-shaped identifier of the contents.
fn uuid(grid: &GridSpec, count: u64) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let sizes = grid.size().recorded().into_iter().map(f64::to_bits);
    for v in grid.dims().iter().map(|&d| d as u64).chain([count]).chain(sizes) {
        h = (h ^ v).wrapping_mul(0x0100_0000_01b3);
    }
    let g = h.wrapping_mul(0x9e37_79b9_7f4a_7c15);
    let hex = format!("{h:016x}{g:016x}");
    format!("{}-{}-4{}-8{}-{}", &hex[0..8], &hex[8..12], &hex[13..16], &hex[17..20], &hex[20..32])
}

/// Appends the value of the voxel in an attribute slot, little-endian.
type PutValue<'a> = Box<dyn Fn(usize, &mut Vec<u8>) + 'a>;

/// An attribute grid's values: bytes per value, and each voxel's value
/// (by its attribute slot).
struct Values<'a> {
    attrs: &'a VoxelAttributes,
    size: usize,
    put: PutValue<'a>,
}

fn f32s(buf: &mut Vec<u8>, v: &[f32]) {
    for x in v {
        buf.extend_from_slice(&x.to_le_bytes());
    }
}

/// The attribute grids of `attrs`, as `(name, tree type, values)`: `Cd`
/// (colour, linear RGB), `normal`, `coverage` and `material` (the id as a
/// float, -1 for none; pyopenvdb reads no integer grids).
fn attribute_grids(attrs: &VoxelAttributes) -> Vec<(&'static str, &'static str, Values<'_>)> {
    let mut out: Vec<(&'static str, &'static str, Values<'_>)> = Vec::new();
    if let Some(c) = &attrs.colour {
        let put = move |s: usize, b: &mut Vec<u8>| f32s(b, &c[s].map(|v| to_linear(v) as f32));
        out.push((ATTR_COLOUR, VEC3_TYPE, Values { attrs, size: 12, put: Box::new(put) }));
    }
    if let Some(n) = &attrs.normal {
        out.push((ATTR_NORMAL, VEC3_TYPE, Values { attrs, size: 12, put: Box::new(move |s, b| f32s(b, &n[s])) }));
    }
    if let Some(c) = &attrs.coverage {
        out.push((ATTR_COVERAGE, FLOAT_TYPE, Values { attrs, size: 4, put: Box::new(move |s, b| f32s(b, &[c[s]])) }));
    }
    if let Some(m) = &attrs.material {
        let put = move |s: usize, b: &mut Vec<u8>| f32s(b, &[if m[s] == NO_MATERIAL { -1.0 } else { m[s] as f32 }]);
        out.push((ATTR_MATERIAL, FLOAT_TYPE, Values { attrs, size: 4, put: Box::new(put) }));
    }
    out
}

/// Writes `bits` on `grid` as a `.vdb` file: the `voxels` bool grid, then,
/// with `attrs`, one grid per attribute over the same voxels (see the
/// module doc). Grids larger than 2^31 voxels per axis cannot be indexed
/// by OpenVDB's 32-bit coordinates and are refused by the caller's grid
/// limits long before.
pub fn write(w: &mut dyn Write, bits: &dyn VoxelSource, grid: &GridSpec, attrs: Option<&VoxelAttributes>) -> std::io::Result<()> {
    let tree = Tree::of(bits, true);
    let count = bits.count();
    let extra = attrs.map(attribute_grids).unwrap_or_default();
    let value_tree = (!extra.is_empty()).then(|| Tree::of(bits, false));
    let mut grids: Vec<GridOut<'_>> =
        vec![GridOut { name: GRID_NAME, ty: GRID_TYPE, class: None, tree: &tree, buffers: Buffers::Occupancy, count }];
    for (name, ty, v) in &extra {
        let tree = value_tree.as_ref().expect("built when there are attributes");
        grids.push(GridOut { name, ty, class: None, tree, buffers: Buffers::Attribute(v), count });
    }
    write_grids(w, &grids, grid)
}

/// One grid to write: name, tree type, class (metadata `class`), tree,
/// values and active voxel count.
struct GridOut<'a> {
    name: &'a str,
    ty: &'a str,
    class: Option<&'a str>,
    tree: &'a Tree,
    buffers: Buffers<'a>,
    count: u64,
}

/// The file: header, then each grid (descriptor, head, tree).
fn write_grids(w: &mut dyn Write, grids: &[GridOut<'_>], grid: &GridSpec) -> std::io::Result<()> {
    let count = grids.first().map_or(0, |g| g.count);
    let mut header = Vec::new();
    let mut o = Stream(&mut header);
    let o: &mut dyn Out = &mut o;
    o.put(&MAGIC.to_le_bytes())?;
    o.put(&FILE_VERSION.to_le_bytes())?;
    o.put(&10u32.to_le_bytes())?; // library version the layout follows: 10.0
    o.put(&0u32.to_le_bytes())?;
    o.put(&[1])?; // grid offsets present
    o.put(uuid(grid, count).as_bytes())?;
    o.put(&1u32.to_le_bytes())?; // file metadata: one entry
    put_meta(o, "creator", "string", format!("topovox {}", env!("CARGO_PKG_VERSION")).as_bytes())?;
    o.put(&(grids.len() as i32).to_le_bytes())?;
    w.write_all(&header)?;
    // Each grid: its descriptor with the offsets of its head, its tree and
    // its end (where the next descriptor starts), the head (metadata and
    // transform, small: built in memory), then the tree, streamed after a
    // first pass that only counts its bytes.
    let mut at = header.len() as u64;
    let mut o = Stream(w);
    let o: &mut dyn Out = &mut o;
    for g in grids {
        let mut desc = Count(0);
        put_str(&mut desc, g.name)?;
        put_str(&mut desc, g.ty)?;
        put_str(&mut desc, "")?;
        let mut head = Vec::new();
        put_grid_head(&mut Stream(&mut head), g, grid)?;
        let mut tree_len = Count(0);
        put_tree(&mut tree_len, g.tree, g.buffers)?;
        let grid_pos = at + desc.0 + 24;
        let block_pos = grid_pos + head.len() as u64;
        let end_pos = block_pos + tree_len.0;
        put_str(o, g.name)?;
        put_str(o, g.ty)?;
        put_str(o, "")?;
        for p in [grid_pos, block_pos, end_pos] {
            o.put(&(p as i64).to_le_bytes())?;
        }
        o.put(&head)?;
        put_tree(o, g.tree, g.buffers)?;
        at = end_pos;
    }
    Ok(())
}

/// A cursor over untrusted bytes: every read is bounds-checked.
struct Cur<'a> {
    b: &'a [u8],
    at: usize,
}

fn bad(what: impl Into<String>) -> ErrorKind {
    ErrorKind::malformed("VDB", what.into())
}

impl<'a> Cur<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], ErrorKind> {
        if n > self.b.len() - self.at {
            return Err(bad(format!("truncated at byte {} (needs {n} more)", self.at)));
        }
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    fn u8(&mut self) -> Result<u8, ErrorKind> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32, ErrorKind> {
        Ok(u32::from_le_bytes(self.take(4)?.try_into().expect("4 bytes")))
    }
    fn i32(&mut self) -> Result<i32, ErrorKind> {
        Ok(self.u32()? as i32)
    }
    fn i64(&mut self) -> Result<i64, ErrorKind> {
        Ok(i64::from_le_bytes(self.take(8)?.try_into().expect("8 bytes")))
    }
    fn f64(&mut self) -> Result<f64, ErrorKind> {
        Ok(f64::from_bits(self.i64()? as u64))
    }
    fn vec3d(&mut self) -> Result<[f64; 3], ErrorKind> {
        Ok([self.f64()?, self.f64()?, self.f64()?])
    }
    fn coord(&mut self) -> Result<[i32; 3], ErrorKind> {
        Ok([self.i32()?, self.i32()?, self.i32()?])
    }
    fn string(&mut self) -> Result<String, ErrorKind> {
        let n = self.u32()? as usize;
        Ok(String::from_utf8_lossy(self.take(n)?).into_owned())
    }
    fn words(&mut self, n: usize) -> Result<Vec<u64>, ErrorKind> {
        Ok(self.take(n * 8)?.chunks_exact(8).map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes"))).collect())
    }
    fn seek(&mut self, pos: i64) -> Result<(), ErrorKind> {
        if pos < 0 || pos as usize > self.b.len() {
            return Err(bad(format!("offset {pos} outside the file")));
        }
        self.at = pos as usize;
        Ok(())
    }
}

/// Metadata entries as (name, type, value bytes).
fn read_meta(c: &mut Cur<'_>) -> Result<Vec<(String, String, Vec<u8>)>, ErrorKind> {
    let n = c.u32()?;
    let mut out = Vec::new();
    for _ in 0..n {
        let name = c.string()?;
        let ty = c.string()?;
        let size = c.u32()? as usize;
        out.push((name, ty, c.take(size)?.to_vec()));
    }
    Ok(out)
}

fn bit(words: &[u64], n: usize) -> bool {
    words[n / 64] >> (n % 64) & 1 == 1
}

/// A tree as read: active tiles (origin, edge length, value bytes) and
/// leaves (origin, active mask in OpenVDB's layout, active values in index
/// order; none for a bool grid, whose leaves' activity is the occupancy).
#[derive(Default)]
struct Found {
    tiles: Vec<([i64; 3], i64, [u8; 12])>,
    leaves: Vec<[i64; 3]>,
}

/// One node's values as OpenVDB's `readCompressedValues` stores them: the
/// metadata byte, the inactive values and selection mask it announces,
/// then every value or, with active-mask compression, only the active
/// ones. Returns the active values' bytes in index order.
fn read_values(c: &mut Cur<'_>, active: &[u64], n: usize, mask_compressed: bool, vs: usize) -> Result<Vec<u8>, ErrorKind> {
    let meta = c.u8()?;
    match meta {
        // 0: inactive values are the background, 1: its negative, 3: a
        // mask selects between the two, 6: every value stored.
        0 | 1 | 3 | 6 => {}
        2 | 4 => {
            c.take(vs)?; // one inactive value
        }
        5 => {
            c.take(2 * vs)?; // two inactive values
        }
        m => return Err(bad(format!("unknown node compression metadata {m}"))),
    }
    if matches!(meta, 3..=5) {
        c.take(n / 8)?; // selection mask
    }
    let on: usize = active.iter().map(|w| w.count_ones() as usize).sum();
    if mask_compressed && meta != 6 {
        return Ok(c.take(on * vs)?.to_vec());
    }
    let all = c.take(n * vs)?;
    let mut out = Vec::with_capacity(on * vs);
    for idx in (0..n).filter(|&i| bit(active, i)) {
        out.extend_from_slice(&all[idx * vs..(idx + 1) * vs]);
    }
    Ok(out)
}

/// How a distance field's values are read as voxels: its background, and
/// which values are inside (see [`read_level_set`]).
#[derive(Clone, Copy)]
struct Inside<'a> {
    background: [u8; 4],
    test: &'a dyn Fn(f32) -> bool,
}

/// An internal node's topology: masks, compressed tile values, children.
/// With `inside`, its tiles are those whose value (active or not) is
/// inside, not the active ones.
fn read_internal(
    c: &mut Cur<'_>,
    origin: [i64; 3],
    (log2, child_log2): (u32, u32),
    mask_compressed: bool,
    vs: usize,
    found: &mut Found,
    inside: Option<Inside<'_>>,
) -> Result<(), ErrorKind> {
    let dim = log2 - child_log2;
    let n = 1usize << (3 * dim);
    let child = c.words(n / 64)?;
    let value = c.words(n / 64)?;
    let offset = |idx: usize| -> [i64; 3] {
        let off = [(idx >> (2 * dim)) as i64, ((idx >> dim) & ((1 << dim) - 1)) as i64, (idx & ((1 << dim) - 1)) as i64];
        std::array::from_fn(|a| origin[a] + (off[a] << child_log2))
    };
    if let Some(ins) = inside {
        let all = read_all_values(c, &value, n, mask_compressed, ins.background)?;
        for idx in (0..n).filter(|&i| !bit(&child, i) && (ins.test)(all[i])) {
            found.tiles.push((offset(idx), 1 << child_log2, [1; 12]));
        }
    } else {
        let vals = read_values(c, &value, n, mask_compressed, vs)?;
        for (v, idx) in (0..n).filter(|&i| bit(&value, i)).enumerate() {
            if !bit(&child, idx) {
                let mut val = [0u8; 12];
                val[..vs].copy_from_slice(&vals[v * vs..(v + 1) * vs]);
                found.tiles.push((offset(idx), 1 << child_log2, val));
            }
        }
    }
    for idx in (0..n).filter(|&i| bit(&child, i)) {
        let o = offset(idx);
        if child_log2 == LEAF {
            c.take(64)?; // the leaf's value mask, read again with its buffer
            found.leaves.push(o);
        } else {
            read_internal(c, o, (child_log2, LEAF), mask_compressed, vs, found, inside)?;
        }
    }
    Ok(())
}

/// Every one of a float node's `n` values as OpenVDB's
/// `readCompressedValues` restores them: the active ones as stored, the
/// inactive ones by the metadata byte (0: the background, 1: its negative,
/// 2/4/5: values stored once, 3–5: a selection mask choosing between two
/// of them, 6: every value stored).
fn read_all_values(c: &mut Cur<'_>, active: &[u64], n: usize, mask_compressed: bool, background: [u8; 4]) -> Result<Vec<f32>, ErrorKind> {
    let bg = f32::from_le_bytes(background);
    let f = |b: &[u8]| f32::from_le_bytes(b.try_into().expect("4 bytes"));
    let meta = c.u8()?;
    if meta > 6 {
        return Err(bad(format!("unknown node compression metadata {meta}")));
    }
    let mut inactive = [if meta == 0 { bg } else { -bg }, bg];
    if matches!(meta, 2 | 4 | 5) {
        inactive[0] = f(c.take(4)?);
    }
    if meta == 5 {
        inactive[1] = f(c.take(4)?);
    }
    let selection = if matches!(meta, 3..=5) { Some(c.take(n / 8)?) } else { None };
    let chosen = |i: usize| inactive[selection.is_some_and(|m| m[i / 8] >> (i % 8) & 1 == 1) as usize];
    if mask_compressed && meta != 6 {
        let on: usize = active.iter().map(|w| w.count_ones() as usize).sum();
        let mut stored = c.take(on * 4)?.chunks_exact(4);
        return Ok((0..n).map(|i| if bit(active, i) { stored.next().map_or(bg, f) } else { chosen(i) }).collect());
    }
    Ok(c.take(n * 4)?.chunks_exact(4).map(f).collect())
}

/// A grid's descriptor: name, tree type, where its head starts.
struct Descriptor {
    name: String,
    ty: String,
    pos: i64,
}

/// A file's grid descriptors, after its header.
fn descriptors(bytes: &[u8]) -> Result<Vec<Descriptor>, ErrorKind> {
    let mut c = Cur { b: bytes, at: 0 };
    if c.i64().ok() != Some(MAGIC) {
        return Err(bad("not an OpenVDB file (bad magic number)"));
    }
    let version = c.u32()?;
    if version < MIN_VERSION {
        return Err(bad(format!("file format {version} is older than {MIN_VERSION}, the oldest topovox reads")));
    }
    c.u32()?;
    c.u32()?;
    let has_offsets = c.u8()? != 0;
    c.take(36)?; // UUID
    read_meta(&mut c)?;
    let grids = c.i32()?;
    if !has_offsets {
        return Err(bad("streamed VDB files (without grid offsets) are not supported"));
    }
    let mut found = Vec::new();
    for _ in 0..grids.max(0) {
        let name = c.string()?;
        let ty = c.string()?;
        if version >= 223 {
            c.string()?;
        }
        let (pos, _block, end) = (c.i64()?, c.i64()?, c.i64()?);
        // Grids follow one another: an end before this descriptor would
        // read the same grids again, billions of times.
        if end <= c.at as i64 {
            return Err(bad(format!("grid '{name}' ends at byte {end}, before its own descriptor")));
        }
        found.push(Descriptor { name, ty, pos });
        c.seek(end)?;
    }
    Ok(found)
}

fn in_grid(name: &str, e: ErrorKind) -> ErrorKind {
    match e {
        ErrorKind::Malformed { format, detail } => ErrorKind::Malformed { format, detail: format!("grid '{name}': {detail}") },
        e => e,
    }
}

/// The voxels of a file: its first bool grid; without one, its first
/// float grid that is a level set or topovox's distance field (`surface`),
/// read as the voxels inside (negative; unsigned: within half a voxel
/// diagonal of the surface).
fn occupancy(bytes: &[u8], found: &[Descriptor]) -> Result<Occupancy, ErrorKind> {
    let bool_grid = found.iter().find(|d| d.ty == GRID_TYPE);
    let distance = || {
        found.iter().filter(|d| d.ty == FLOAT_TYPE).find(|d| {
            let mut c = Cur { b: bytes, at: 0 };
            d.name == level_set::LEVEL_SET_NAME
                || (c.seek(d.pos).is_ok() && read_head(&mut c).is_ok_and(|h| h.meta.iter().any(|m| m.0 == "class" && m.2 == b"level set")))
        })
    };
    let Some((d, is_distance)) = bool_grid.map(|d| (d, false)).or_else(|| distance().map(|d| (d, true))) else {
        let types: Vec<String> = found.iter().map(|d| format!("{} ({})", d.name, d.ty)).collect();
        return Err(bad(if types.is_empty() {
            "no grids".to_string()
        } else {
            format!("no bool grid or level set (topovox reads {GRID_TYPE}, and {FLOAT_TYPE} level sets); grids: {}", types.join(", "))
        }));
    };
    let mut c = Cur { b: bytes, at: 0 };
    c.seek(d.pos)?;
    read_grid(&mut c, is_distance).map_err(|e| in_grid(&d.name, e))
}

/// The attribute grids topovox reads: name and tree type.
const ATTRIBUTE_GRIDS: [(&str, &str); 4] =
    [(ATTR_COLOUR, VEC3_TYPE), (ATTR_NORMAL, VEC3_TYPE), (ATTR_COVERAGE, FLOAT_TYPE), (ATTR_MATERIAL, FLOAT_TYPE)];

/// A `.vdb` file's voxels without a dense grid: its first bool grid as
/// sparse bricks (active tiles as runs of full bricks), the placement,
/// and with `attributes` the attribute grids of its set voxels (memory:
/// about 32 bytes per voxel); otherwise whether any were left unread.
pub fn read_sparse(bytes: &[u8], attributes: bool) -> Result<SparseVoxels, ErrorKind> {
    let found = descriptors(bytes)?;
    let occ = occupancy(bytes, &found)?;
    let has = found.iter().any(|d| ATTRIBUTE_GRIDS.contains(&(d.name.as_str(), d.ty.as_str())));
    let (bits, placement, offset) = (occ.sparse()?, occ.placement, occ.offset);
    drop(occ);
    let attrs = if attributes && has { read_attributes(bytes, &found, offset, &bits)? } else { None };
    Ok(SparseVoxels { bits, placement, attributes_left: has && attrs.is_none(), attributes: attrs })
}

/// Parses a `.vdb` file: its first bool grid's active voxels and, when
/// grids named as topovox writes them are present (`Cd`, `normal`,
/// `coverage`, `material`), those attributes of each voxel.
pub fn read(bytes: &[u8]) -> Result<LoadedVoxels, ErrorKind> {
    let found = descriptors(bytes)?;
    let occ = occupancy(bytes, &found)?;
    let mut loaded = LoadedVoxels { bits: occ.dense()?, placement: occ.placement, attributes: None };
    let offset = occ.offset;
    drop(occ);
    loaded.attributes = read_attributes(bytes, &found, offset, &loaded.bits)?;
    Ok(loaded)
}

/// The attribute grids topovox writes (`Cd`, `normal`, `coverage`,
/// `material`) at the set voxels of `voxels` (any storage; index
/// coordinates shifted by `offset`), or `None` when the file has none.
fn read_attributes(
    bytes: &[u8],
    found: &[Descriptor],
    offset: [i64; 3],
    voxels: &dyn VoxelSource,
) -> Result<Option<VoxelAttributes>, ErrorKind> {
    let wanted = ATTRIBUTE_GRIDS;
    if !found.iter().any(|d| wanted.contains(&(d.name.as_str(), d.ty.as_str()))) {
        return Ok(None);
    }
    let mut c = Cur { b: bytes, at: 0 };
    let mut attrs = VoxelAttributes { dims: voxels.dims(), keys: VoxelAttributes::keys_of(voxels), ..Default::default() };
    for (name, ty) in wanted {
        let Some(d) = found.iter().find(|d| d.name == name && d.ty == ty) else { continue };
        c.seek(d.pos)?;
        let values = read_values_grid(&mut c, if ty == VEC3_TYPE { 12 } else { 4 }).map_err(|e| in_grid(name, e))?;
        let mut read = values.reader();
        let mut at = |key: u64| {
            let v = attrs.voxel(key);
            read(std::array::from_fn(|a| v[a] as i64 + offset[a]))
        };
        let f = |b: &[u8], n: usize| f32::from_le_bytes(b[4 * n..4 * n + 4].try_into().expect("4 bytes"));
        // One lookup per voxel, its three components read from it.
        match name {
            ATTR_COLOUR => {
                attrs.colour = Some(
                    attrs
                        .keys
                        .iter()
                        .map(|&k| {
                            let v = at(k);
                            std::array::from_fn(|n| from_linear(f(&v, n) as f64))
                        })
                        .collect(),
                )
            }
            ATTR_NORMAL => {
                attrs.normal = Some(
                    attrs
                        .keys
                        .iter()
                        .map(|&k| {
                            let v = at(k);
                            std::array::from_fn(|n| f(&v, n))
                        })
                        .collect(),
                )
            }
            ATTR_COVERAGE => attrs.coverage = Some(attrs.keys.iter().map(|&k| f(&at(k), 0)).collect()),
            _ => {
                let id = |v: f32| if v >= 0.0 && v.fract() == 0.0 && v < NO_MATERIAL as f32 { v as u32 } else { NO_MATERIAL };
                attrs.material = Some(attrs.keys.iter().map(|&k| id(f(&at(k), 0))).collect());
            }
        }
    }
    Ok(Some(attrs))
}

/// The grid head up to its tree: compression flags, metadata, transform.
struct Head {
    mask_compressed: bool,
    meta: Vec<(String, String, Vec<u8>)>,
    translation: [f64; 3],
    scale: [f64; 3],
}

fn read_head(c: &mut Cur<'_>) -> Result<Head, ErrorKind> {
    let compression = c.u32()?;
    if compression & (COMPRESS_ZIP | COMPRESS_BLOSC) != 0 {
        return Err(bad("zip/blosc-compressed grids are not supported (topovox writes uncompressed VDB; re-save without compression)"));
    }
    let mask_compressed = compression & COMPRESS_ACTIVE_MASK != 0;
    let meta = read_meta(c)?;
    let map = c.string()?;
    let (translation, scale) = match map.as_str() {
        "UniformScaleTranslateMap" | "ScaleTranslateMap" => {
            let t = c.vec3d()?;
            let s = c.vec3d()?;
            for _ in 0..4 {
                c.vec3d()?;
            }
            (t, s)
        }
        "UniformScaleMap" | "ScaleMap" => {
            let s = c.vec3d()?;
            for _ in 0..4 {
                c.vec3d()?;
            }
            ([0.0; 3], s)
        }
        "TranslationMap" => (c.vec3d()?, [1.0; 3]),
        m => return Err(bad(format!("transform {m} is not supported (topovox reads scale and translation maps)"))),
    };
    Ok(Head { mask_compressed, meta, translation, scale })
}

/// A tree's root and internal nodes, values `vs` bytes each.
fn read_topology(
    c: &mut Cur<'_>,
    mask_compressed: bool,
    vs: usize,
    test: Option<&dyn Fn(f32) -> bool>,
) -> Result<(Found, [u8; 12]), ErrorKind> {
    if c.i32()? != 1 {
        return Err(bad("multi-buffer trees are not supported"));
    }
    let mut background = [0u8; 12];
    background[..vs].copy_from_slice(c.take(vs)?);
    let inside = test.map(|test| Inside { background: background[..4].try_into().expect("4 bytes"), test });
    let (ntiles, nchildren) = (c.u32()? as usize, c.u32()? as usize);
    // Each tile takes 13 + vs bytes, each child at least 12 + 2·4096 + 1.
    if ntiles.saturating_mul(13 + vs).saturating_add(nchildren.saturating_mul(8205)) > c.b.len() - c.at {
        return Err(bad(format!("root claims {ntiles} tiles and {nchildren} children, more than the file holds")));
    }
    let mut found = Found::default();
    for _ in 0..ntiles {
        let o = c.coord()?;
        let mut val = [0u8; 12];
        val[..vs].copy_from_slice(c.take(vs)?);
        let active = c.u8()? != 0;
        // A distance field's root tile counts when inside, active or not.
        let counts = match inside {
            Some(ins) => (ins.test)(f32::from_le_bytes(val[..4].try_into().expect("4 bytes"))),
            None => active,
        };
        if counts {
            found.tiles.push((o.map(|v| v as i64), 1 << UPPER, val));
        }
    }
    for _ in 0..nchildren {
        let o = c.coord()?;
        read_internal(c, o.map(|v| v as i64), (UPPER, LOWER), mask_compressed, vs, &mut found, inside)?;
    }
    Ok((found, background))
}

/// An attribute grid's active values, looked up by index coordinate.
struct GridValues {
    vs: usize,
    /// Leaf origin → (active mask, active values).
    leaves: std::collections::HashMap<[i64; 3], (Vec<u64>, Vec<u8>)>,
    /// (Tile origin, edge) → value.
    tiles: std::collections::HashMap<([i64; 3], i64), [u8; 12]>,
}

/// Where one leaf-sized block of an attribute grid takes its values.
#[derive(Clone, Copy)]
enum Block<'a> {
    Leaf(&'a [u64], &'a [u8]),
    Constant([u8; 12]),
}

impl GridValues {
    /// The leaf-sized block at `origin` (a multiple of 8): its leaf, else
    /// the active tile holding it, else zero (the background topovox writes).
    fn block(&self, origin: [i64; 3]) -> Block<'_> {
        if let Some((mask, vals)) = self.leaves.get(&origin) {
            return Block::Leaf(mask, vals);
        }
        for edge in [1i64 << LEAF, 1 << LOWER, 1 << UPPER] {
            if let Some(v) = self.tiles.get(&(origin.map(|c| c & !(edge - 1)), edge)) {
                return Block::Constant(*v);
            }
        }
        Block::Constant([0; 12])
    }

    /// A lookup of values by index coordinate that finds each block once
    /// per run of voxels in it (voxels come in row order, so a leaf's
    /// eight voxels along x cost one map lookup, not eight).
    fn reader(&self) -> impl FnMut([i64; 3]) -> [u8; 12] + '_ {
        let mut last: Option<([i64; 3], Block<'_>)> = None;
        move |p| {
            let origin = p.map(|c| c & !7);
            let block = match last {
                Some((o, b)) if o == origin => b,
                _ => {
                    let b = self.block(origin);
                    last = Some((origin, b));
                    b
                }
            };
            match block {
                Block::Constant(v) => v,
                Block::Leaf(mask, vals) => {
                    let mut out = [0u8; 12];
                    let n = ((p[0] & 7) * 64 + (p[1] & 7) * 8 + (p[2] & 7)) as usize;
                    if bit(mask, n) {
                        let below = mask[..n / 64].iter().map(|w| w.count_ones() as usize).sum::<usize>()
                            + (mask[n / 64] & ((1u64 << (n % 64)) - 1)).count_ones() as usize;
                        out[..self.vs].copy_from_slice(&vals[below * self.vs..(below + 1) * self.vs]);
                    }
                    out
                }
            }
        }
    }
}

fn read_values_grid(c: &mut Cur<'_>, vs: usize) -> Result<GridValues, ErrorKind> {
    let head = read_head(c)?;
    if head.meta.iter().any(|m| m.0 == "is_saved_as_half_float" && m.2.first().is_some_and(|&b| b != 0)) {
        return Err(bad("half-float grids are not supported (topovox writes 32-bit floats)"));
    }
    let (found, _) = read_topology(c, head.mask_compressed, vs, None)?;
    let mut leaves = std::collections::HashMap::with_capacity(found.leaves.len());
    for o in &found.leaves {
        let active = c.words(8)?;
        let vals = read_values(c, &active, 512, head.mask_compressed, vs)?;
        leaves.insert(*o, (active, vals));
    }
    let tiles = found.tiles.iter().map(|(o, e, v)| ((*o, *e), *v)).collect();
    Ok(GridValues { vs, leaves, tiles })
}

/// The bool grid as read, before it becomes voxels: leaves (origin,
/// active mask in OpenVDB's layout), active `true` tiles (origin, edge),
/// the index coordinate of voxel (0, 0, 0), the grid's dims and placement.
struct Occupancy {
    leaves: Vec<([i64; 3], [u64; 8])>,
    tiles: Vec<([i64; 3], i64)>,
    offset: [i64; 3],
    dims: [u32; 3],
    placement: Option<(DVec3, DVec3)>,
}

impl Occupancy {
    /// Voxel coordinates of index coordinate `p`, which must be in the grid.
    fn inside(&self, p: [i64; 3]) -> Result<[u32; 3], ErrorKind> {
        let q: [i64; 3] = std::array::from_fn(|a| p[a] - self.offset[a]);
        if (0..3).any(|a| q[a] < 0 || q[a] >= self.dims[a] as i64) {
            return Err(bad(format!("active voxel {p:?} outside the recorded grid {:?}", self.dims)));
        }
        Ok(q.map(|c| c as u32))
    }

    /// Calls `f` with every active voxel of the leaves (voxel coordinates).
    fn leaf_voxels(&self, mut f: impl FnMut([u32; 3])) -> Result<(), ErrorKind> {
        for (o, m) in &self.leaves {
            for (x, &w) in m.iter().enumerate() {
                let mut w = w;
                while w != 0 {
                    let b = w.trailing_zeros() as i64;
                    w &= w - 1;
                    f(self.inside([o[0] + x as i64, o[1] + (b >> 3), o[2] + (b & 7)])?);
                }
            }
        }
        Ok(())
    }

    /// The voxels in a dense grid (active tiles filled a row of words at a time).
    fn dense(&self) -> Result<topovox::DenseBits, ErrorKind> {
        // First: a grid that cannot be dense says so (`TooLarge`; the sparse
        // reader takes such files).
        let mut bits = crate::dense_grid(self.dims)?;
        // Tiles of one tree never overlap, so together they cover at most
        // the grid, which fits (checked above): any number of voxels a
        // solid's interior takes reads back. More means overlapping tiles,
        // which a 200-byte file can claim by the thousand (each would be
        // filled again): refused.
        let grid_voxels = self.dims.iter().map(|&d| d as i64).product::<i64>();
        let tile_voxels: i64 = self.tiles.iter().fold(0i64, |n, t| n.saturating_add(t.1.saturating_mul(t.1).saturating_mul(t.1)));
        if tile_voxels > grid_voxels {
            return Err(bad(format!("active tiles cover {tile_voxels} voxels, more than the grid's {grid_voxels}: they overlap")));
        }
        let mut tiles = Vec::with_capacity(self.tiles.len());
        for (o, e) in &self.tiles {
            // A tile is inside the grid when its two corners are.
            tiles.push((self.inside(*o)?, self.inside(o.map(|c| c + e - 1))?));
        }
        self.leaf_voxels(|q| bits.set(q[0], q[1], q[2]))?;
        for (lo, hi) in tiles {
            bits.fill_box(lo, hi);
        }
        Ok(bits)
    }

    /// The voxels as sparse bricks: leaves become bricks, active tiles runs
    /// of full bricks (never voxels), so memory follows the file, not the
    /// grid. Needs the grid to start on a brick (topovox's files do).
    fn sparse(&self) -> Result<SparseBricks, ErrorKind> {
        if self.offset.iter().any(|o| o % 8 != 0) {
            return Err(ErrorKind::Unsupported(format!(
                "this grid's voxels start at index {:?}, not on an 8-voxel brick, so it is read only into a dense grid",
                self.offset
            )));
        }
        if self.dims.iter().any(|&d| d > SparseBricks::MAX_DIM) {
            return Err(bad(format!("grid {:?} beyond {} voxels per axis", self.dims, SparseBricks::MAX_DIM)));
        }
        // The offset is a multiple of 8, so a leaf's voxels, visited
        // together, all fall in one brick.
        let mut bricks: Vec<([u32; 3], Brick)> = Vec::with_capacity(self.leaves.len());
        self.leaf_voxels(|q| {
            let b = q.map(|c| c / 8);
            if bricks.last().is_none_or(|l| l.0 != b) {
                bricks.push((b, [0; 8]));
            }
            set_in_brick(&mut bricks.last_mut().expect("pushed above").1, q[0], q[1], q[2]);
        })?;
        let mut runs: Vec<([u32; 3], u32)> = Vec::new();
        for (o, e) in &self.tiles {
            let (lo, _) = (self.inside(*o)?, self.inside(o.map(|c| c + e - 1))?);
            let n = (*e / 8) as u32;
            if runs.len() as u64 + (n as u64) * (n as u64) > MAX_SPARSE_RUNS {
                return Err(bad(format!("active tiles make more than {MAX_SPARSE_RUNS} brick rows")));
            }
            let b = lo.map(|c| c / 8);
            for bk in b[2]..b[2] + n {
                for bj in b[1]..b[1] + n {
                    runs.push(([b[0], bj, bk], n));
                }
            }
        }
        Ok(SparseBricks::from_parts(self.dims, bricks, runs))
    }
}

/// Most rows of full bricks the sparse reader makes from active tiles (16
/// bytes each: 1 GiB; a 4096³ tile is 262 144 rows).
const MAX_SPARSE_RUNS: u64 = 1 << 26;

/// Tiles and leaves (OpenVDB's mask layout) as a grid's voxels.
type TreeVoxels = (Vec<([i64; 3], i64)>, Vec<([i64; 3], [u64; 8])>);

/// A bool tree's active tiles and leaves.
fn read_bool_tree(c: &mut Cur<'_>, mask_compressed: bool) -> Result<TreeVoxels, ErrorKind> {
    let (found, _) = read_topology(c, mask_compressed, 1, None)?;
    let tiles: Vec<([i64; 3], i64)> = found.tiles.iter().filter(|t| t.2[0] != 0).map(|t| (t.0, t.1)).collect();
    // Masks inline: a heap vector per leaf would more than double the
    // memory of a large file's tree.
    let mut leaves: Vec<([i64; 3], [u64; 8])> = Vec::with_capacity(found.leaves.len());
    for expect in &found.leaves {
        let active = c.words(8)?;
        let o = c.coord()?.map(|v| v as i64);
        if o != *expect {
            return Err(bad(format!("leaf at {o:?} where the topology has {expect:?}")));
        }
        c.words(8)?; // values: occupancy is activity
        leaves.push((o, active.try_into().expect("8 words")));
    }
    Ok((tiles, leaves))
}

/// A float tree (a distance field) as the voxels whose values, active or
/// not, pass `test`: tiles wholly inside, and per leaf a mask of them.
fn read_level_set(c: &mut Cur<'_>, mask_compressed: bool, test: &dyn Fn(f32) -> bool) -> Result<TreeVoxels, ErrorKind> {
    let (found, background) = read_topology(c, mask_compressed, 4, Some(test))?;
    let tiles = found.tiles.iter().map(|t| (t.0, t.1)).collect();
    let mut leaves = Vec::with_capacity(found.leaves.len());
    for o in &found.leaves {
        let active = c.words(8)?;
        let values = read_all_values(c, &active, 512, mask_compressed, background[..4].try_into().expect("4 bytes"))?;
        let mut mask = [0u64; 8];
        for (n, _) in values.iter().enumerate().filter(|(_, &v)| test(v)) {
            mask[n / 64] |= 1 << (n % 64);
        }
        leaves.push((*o, mask));
    }
    Ok((tiles, leaves))
}

/// The bool grid at the cursor.
fn read_grid(c: &mut Cur<'_>, distance: bool) -> Result<Occupancy, ErrorKind> {
    let Head { mask_compressed, meta, translation, scale } = read_head(c)?;
    let find = |n: &str| meta.iter().find(|m| m.0 == n).map(|m| m.2.clone());
    // Our own keys (`topovox_dims`, …), or as written before the rename.
    let get = |n: &str| {
        find(n).or_else(|| n.strip_prefix("topovox_").and_then(|rest| find(&format!("{}{rest}", crate::former_name::VDB_META_PREFIX))))
    };
    let (tiles, leaves) = if distance {
        // A level set's inside: its negative values; an unsigned field's
        // voxels within half a voxel diagonal of the surface.
        let level_set = find("class").is_some_and(|c| c == b"level set");
        let near = crate::half_diagonal(DVec3::from(scale));
        let test = move |v: f32| if level_set { v < 0.0 } else { (v as f64) <= near };
        read_level_set(c, mask_compressed, &test)?
    } else {
        read_bool_tree(c, mask_compressed)?
    };
    // The index box of the active voxels.
    let mut lo = [i64::MAX; 3];
    let mut hi = [i64::MIN; 3];
    let mut grow = |p: [i64; 3], q: [i64; 3]| {
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(q[a]);
        }
    };
    for (o, e) in &tiles {
        grow(*o, o.map(|c| c + e - 1));
    }
    for (o, m) in &leaves {
        if m.iter().any(|&w| w != 0) {
            grow(*o, o.map(|c| c + 7));
        }
    }
    let dims_meta = get("topovox_dims").filter(|v| v.len() == 12).map(|v| {
        let d: [i32; 3] = std::array::from_fn(|a| i32::from_le_bytes(v[4 * a..4 * a + 4].try_into().expect("4 bytes")));
        d
    });
    let (offset, dims) = match dims_meta {
        Some(d) if d.iter().all(|&x| x > 0) => ([0i64; 3], d.map(|x| x as u32)),
        _ if lo[0] == i64::MAX => ([0; 3], [1, 1, 1]),
        _ => (lo, std::array::from_fn(|a| u32::try_from(hi[a] - lo[a] + 1).unwrap_or(u32::MAX))),
    };
    let vec3d = |v: Vec<u8>| {
        DVec3::from(std::array::from_fn::<f64, 3, _>(|a| f64::from_le_bytes(v[8 * a..8 * a + 8].try_into().expect("8 bytes"))))
    };
    let origin_meta = get("topovox_origin").filter(|v| v.len() == 24).map(vec3d);
    // A `double` for cubes, a `vec3d` for boxes.
    let size_meta = get("topovox_voxel_size").and_then(|v| match v.len() {
        8 => Some(DVec3::splat(f64::from_le_bytes(v[..8].try_into().expect("8 bytes")))),
        24 => Some(vec3d(v)),
        _ => None,
    });
    let scale = DVec3::from(scale);
    let placement = match (origin_meta, size_meta) {
        (Some(o), Some(s)) if dims_meta.is_some() => Some((o, s)),
        _ if scale.is_finite() && scale.min_element() > 0.0 => {
            Some((DVec3::from(translation) + DVec3::new(offset[0] as f64, offset[1] as f64, offset[2] as f64) * scale - 0.5 * scale, scale))
        }
        _ => None,
    };
    Ok(Occupancy { leaves, tiles, offset, dims, placement })
}

#[cfg(test)]
mod tests {
    use super::*;
    use topovox::DenseBits;

    #[test]
    fn round_trip_across_node_borders() {
        let dims = [300, 140, 9];
        let mut d = DenseBits::new(dims);
        for (i, j, k) in [(0, 0, 0), (7, 8, 8), (127, 127, 8), (128, 0, 0), (299, 139, 8), (130, 7, 3)] {
            d.set(i, j, k);
        }
        let grid = GridSpec::new(DVec3::new(-1.0, 2.0, 0.5), 0.25, dims.map(|x| x as u64)).unwrap();
        let mut buf = Vec::new();
        write(&mut buf, &d, &grid, None).unwrap();
        let back = read(&buf).unwrap();
        assert_eq!(back.bits, d);
        let (o, s) = back.placement.unwrap();
        assert_eq!((o, s), (grid.origin(), DVec3::splat(0.25)));
        // Every truncation is an error, never a panic.
        for n in (0..buf.len()).step_by(97) {
            assert!(read(&buf[..n]).is_err() && read_sparse(&buf[..n], true).is_err());
        }
        assert_eq!(read_sparse(&buf, false).unwrap().bits.to_dense(), d);
    }

    /// Full runs become tiles (of 8³, and of 128³ where a whole 16³ node is
    /// full), read back voxel for voxel; the file stays small.
    #[test]
    fn full_runs_are_written_as_tiles() {
        use topovox::grid::sparse::SparseBricks;
        let dims = [300, 140, 136];
        // Bricks 0..16 × 0..16 × 0..16 (one whole 128³ node) and a run of 3
        // further along x, plus partial bricks either side of a run.
        let mut full = Vec::new();
        for bk in 0..16 {
            for bj in 0..16 {
                full.push(([0, bj, bk], if (bj, bk) == (2, 3) { 20 } else { 16 }));
            }
        }
        full.sort_by_key(|(b, _)| (b[2], b[1], b[0]));
        let mut partial = [0u64; 8];
        partial[3] = 0x81;
        let bricks = vec![([20, 2, 3], partial), ([30, 16, 16], partial)];
        let mut all: Vec<([u32; 3], Brick)> = bricks.clone();
        let sparse = SparseBricks::from_sorted(
            dims,
            {
                all.sort_by_key(|(b, _)| (b[2], b[1], b[0]));
                all
            },
            full,
        );
        let grid = GridSpec::new(DVec3::ZERO, 0.5, dims.map(|x| x as u64)).unwrap();
        let mut buf = Vec::new();
        write(&mut buf, &sparse, &grid, None).unwrap();
        assert!(buf.len() < 20_000, "{} bytes", buf.len());
        let back = read(&buf).unwrap();
        assert_eq!(back.bits, sparse.to_dense());
        assert_eq!(back.bits.count(), 128 * 128 * 128 + 4 * 512 + 4);
        // Read without a dense grid: the same bricks, the tiles as full runs.
        let again = read_sparse(&buf, false).unwrap();
        assert_eq!(again.bits.to_dense(), back.bits);
        assert_eq!(again.bits.full_bricks(), 16 * 16 * 16 + 4);
        assert_eq!(again.bits.brick_count(), 2);
        assert_eq!((again.placement, again.attributes_left), (back.placement, false));
    }

    /// Active tiles are filled whole, quickly (the file fuzzing found
    /// claims 10 M tile voxels; filled one by one that took minutes).
    #[test]
    fn active_tiles_are_filled() {
        let bytes = include_bytes!("../../../../fuzz/seeds/voxels_vdb/tiles_timeout.vdb");
        let v = read(bytes).unwrap();
        let n = v.bits.count();
        assert!(n >= 10_000_000, "{n}");
    }

    /// A grid descriptor whose end points back at itself, in a file that
    /// claims 2^31 grids, is refused at once (it would be read 2^31 times).
    #[test]
    fn grid_end_before_its_descriptor_is_refused() {
        let mut d = DenseBits::new([4, 4, 4]);
        d.set(1, 2, 3);
        let grid = GridSpec::new(DVec3::ZERO, 1.0, [4, 4, 4]).unwrap();
        let mut buf = Vec::new();
        write(&mut buf, &d, &grid, None).unwrap();
        let ty = buf.windows(GRID_TYPE.len()).position(|w| w == GRID_TYPE.as_bytes()).unwrap();
        let desc = ty - 4 - 4 - "voxels".len();
        buf[desc - 4..desc].copy_from_slice(&i32::MAX.to_le_bytes());
        buf[ty..ty + 4].copy_from_slice(b"Tree");
        buf[ty + 5..ty + 9].copy_from_slice(b"char");
        let end = ty + GRID_TYPE.len() + 4 + 16;
        buf[end..end + 8].copy_from_slice(&(desc as i64).to_le_bytes());
        let e = read(&buf).unwrap_err().to_string();
        assert!(e.contains("before its own descriptor"), "{e}");
    }

    /// Attributes are written as `Cd`, `normal`, `coverage` and `material`
    /// grids over the voxels (full bricks as leaves, not tiles) and read
    /// back exactly: colours byte for byte through linear light, the
    /// other values bit for bit, "no material" as -1.
    #[test]
    fn attributes_round_trip() {
        let dims = [140, 20, 17];
        let mut d = DenseBits::new(dims);
        d.fill_box([8, 8, 8], [15, 15, 15]); // one full brick
        for (i, j, k) in [(0, 0, 0), (139, 19, 16), (128, 3, 9), (16, 8, 8), (7, 7, 7)] {
            d.set(i, j, k);
        }
        let keys = VoxelAttributes::keys_of(&d);
        let n = keys.len();
        let attrs = VoxelAttributes {
            dims,
            colour: Some((0..n).map(|s| [(s * 37 % 256) as u8, (s * 101 % 256) as u8, 255 - (s % 256) as u8]).collect()),
            material: Some((0..n).map(|s| if s % 3 == 0 { NO_MATERIAL } else { s as u32 }).collect()),
            normal: Some((0..n).map(|s| [s as f32 * 0.25, -0.5, 1.0 / (s as f32 + 1.0)]).collect()),
            coverage: Some((0..n).map(|s| s as f32 / 7.0).collect()),
            keys,
        };
        let grid = GridSpec::new(DVec3::new(1.0, -2.0, 3.0), 0.5, dims.map(|x| x as u64)).unwrap();
        let mut buf = Vec::new();
        write(&mut buf, &d, &grid, Some(&attrs)).unwrap();
        let back = read(&buf).unwrap();
        assert_eq!(back.bits, d);
        assert_eq!(back.attributes.as_ref(), Some(&attrs));
        let sparse = read_sparse(&buf, false).unwrap();
        assert_eq!((sparse.bits.to_dense(), sparse.attributes_left), (d.clone(), true), "the sparse reader says it left the attributes");
        let sparse = read_sparse(&buf, true).unwrap();
        assert_eq!((sparse.bits.to_dense(), sparse.attributes_left), (d.clone(), false));
        assert_eq!(sparse.attributes.as_ref(), Some(&attrs), "the sparse reader reads the same attributes");
        // Without attributes: the bool grid alone, as before.
        let mut plain = Vec::new();
        write(&mut plain, &d, &grid, None).unwrap();
        assert!(read(&plain).unwrap().attributes.is_none());
        for n in (0..buf.len()).step_by(61) {
            assert!(read(&buf[..n]).is_err());
        }
        // Every sRGB byte survives linear f32 storage.
        for c in 0..=255u8 {
            assert_eq!(from_linear(to_linear(c) as f32 as f64), c);
        }
    }

    /// Attributes that do not cover a set voxel are an error, not a
    /// silently zero value.
    #[test]
    fn attributes_must_cover_the_voxels() {
        let mut d = DenseBits::new([4, 4, 4]);
        d.set(1, 2, 3);
        d.set(2, 2, 3);
        let attrs = VoxelAttributes {
            dims: [4, 4, 4],
            keys: vec![VoxelAttributes::key([4, 4, 4], 1, 2, 3)],
            coverage: Some(vec![1.0]),
            ..Default::default()
        };
        let grid = GridSpec::new(DVec3::ZERO, 1.0, [4, 4, 4]).unwrap();
        let e = write(&mut Vec::new(), &d, &grid, Some(&attrs)).unwrap_err().to_string();
        assert!(e.contains("no attributes"), "{e}");
    }

    /// Node values in each of OpenVDB's seven compression-metadata layouts
    /// (`io::writeCompressedValues`): inactive values after the byte for 2
    /// and 4 (one) and 5 (two), a selection mask for 3, 4 and 5, then the
    /// active values only — or all of them for 6 or without mask
    /// compression. Each is read to its last byte and gives the active values.
    #[test]
    fn node_values_in_every_metadata_layout() {
        let mut active = [0u64; 8];
        active[0] = 0b1011;
        active[7] = 1 << 63;
        let on: Vec<usize> = (0..512).filter(|&i| bit(&active, i)).collect();
        let value = |i: usize| (i as f32 * 1.5).to_le_bytes();
        let want: Vec<u8> = on.iter().flat_map(|&i| value(i)).collect();
        let actives: Vec<u8> = want.clone();
        let all: Vec<u8> = (0..512).flat_map(value).collect();
        let mask = vec![0xa5u8; 64];
        for (meta, extra, body, compressed) in [
            (0u8, vec![], &actives, true),
            (1, vec![], &actives, true),
            (2, vec![9u8; 4], &actives, true),
            (3, mask.clone(), &actives, true),
            (4, [vec![9u8; 4], mask.clone()].concat(), &actives, true),
            (5, [vec![9u8; 8], mask.clone()].concat(), &actives, true),
            (6, vec![], &all, true),
            (0, vec![], &all, false),
        ] {
            let bytes = [vec![meta], extra, body.clone(), vec![0xee]].concat();
            let mut c = Cur { b: &bytes, at: 0 };
            let got = read_values(&mut c, &active, 512, compressed, 4).unwrap();
            assert_eq!(got, want, "metadata {meta}");
            assert_eq!(c.at, bytes.len() - 1, "metadata {meta}: read to the wrong byte");
        }
        let mut c = Cur { b: &[7], at: 0 };
        assert!(read_values(&mut c, &active, 512, true, 4).is_err());
    }
}
