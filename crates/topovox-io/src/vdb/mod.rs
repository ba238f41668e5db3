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

mod read;
mod tree;
mod write;

#[cfg(test)]
use read::*;
pub use read::{read, read_sparse};
use tree::*;
pub use write::write;
use write::*;

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
