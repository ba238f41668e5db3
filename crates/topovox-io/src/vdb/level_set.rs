//! Distance fields as OpenVDB level sets: one `FloatGrid`
//! (`Tree_float_5_4_3`) of class `level set` (signed fields) or `unknown`
//! (unsigned), the transform and `topovox_*` metadata of the occupancy
//! grids (see the parent module), background `W·h`.
//!
//! **Layout** (as OpenVDB's `meshToLevelSet` leaves its grids). The band
//! voxels are the active voxels, each in a leaf holding its value. Every
//! inactive voxel is `+background` outside and `−background` inside: a
//! leaf says which by OpenVDB's node compression (metadata 0: all outside,
//! 1: all inside, 3: a selection mask, set bits outside), and the constant
//! interior is inactive `−background` tiles of the internal nodes (8³ and
//! 128³), never voxels: a brick of the inside that holds no band voxel is
//! a tile, a 128³ node of such bricks a tile of its parent. Bricks the
//! inside only partly fills are leaves without active voxels.

use rayon::prelude::*;
use topovox::distance::field::Field;
use topovox::grid::sparse::FULL;
use topovox::GridSpec;

use super::{mark_full, to_vdb, write_grids, Buffers, FullBricks, GridOut, Leaf, Tree, FLOAT_TYPE, LEAF};

/// The grid's name.
pub const LEVEL_SET_NAME: &str = "surface";

/// Writes `field` on `grid` as a `.vdb` file holding one float grid named
/// `surface` (see the module doc); `signed` selects the class.
pub fn write_level_set(w: &mut dyn std::io::Write, field: &Field, grid: &GridSpec, signed: bool) -> std::io::Result<()> {
    let tree = tree(field);
    let class = if signed { "level set" } else { "unknown" };
    let g = GridOut {
        name: LEVEL_SET_NAME,
        ty: FLOAT_TYPE,
        class: Some(class),
        tree: &tree,
        buffers: Buffers::LevelSet(field),
        count: field.band.count(),
    };
    write_grids(w, &[g], grid)
}

/// Brick key in the order of `bk`, then `bj`, then `bi`.
fn key(b: [u32; 3]) -> (u32, u32, u32) {
    (b[2], b[1], b[0])
}

/// The leaves (band bricks, and bricks the inside fills in part) and the
/// inside's full bricks that are not leaves, as tiles.
fn tree(field: &Field) -> Tree {
    let mut leaf_bricks: Vec<[u32; 3]> = field.band.bricks.iter().map(|b| b.at).collect();
    let mut runs: Vec<([u32; 3], u32)> = Vec::new();
    if let Some(inside) = &field.inside {
        topovox::VoxelSource::for_each_brick_run(inside, &mut |b, bits, n| {
            if *bits == FULL {
                runs.push((b, n));
            } else {
                leaf_bricks.push(b);
            }
        });
    }
    leaf_bricks.par_sort_unstable_by_key(|b| key(*b));
    leaf_bricks.dedup();
    let mut full = FullBricks::new();
    for (b, n) in runs {
        // The run's bricks that are not leaves, as runs of tiles.
        let mut start = b[0];
        for x in b[0]..=b[0] + n {
            let is_leaf = x < b[0] + n && leaf_bricks.binary_search_by_key(&key([x, b[1], b[2]]), |l| key(*l)).is_ok();
            if x == b[0] + n || is_leaf {
                if x > start {
                    mark_full(&mut full, [start, b[1], b[2]], x - start);
                }
                start = x + 1;
            }
        }
    }
    let leaves = leaf_bricks
        .iter()
        .map(|&at| {
            let mask = field.band.brick(at).map_or([0; 8], |(b, _)| to_vdb(&b.mask));
            Leaf { origin: at.map(|c| c << LEAF), mask }
        })
        .collect();
    Tree::assemble(leaves, full, None)
}

/// The length of [`leaf_values`] from the masks alone: the metadata byte,
/// the selection mask when the inactive voxels are both inside and
/// outside, and four bytes per active voxel.
pub(super) fn leaf_values_len(field: &Field, leaf: &Leaf) -> usize {
    let inside = field.inside.as_ref().map_or([0; 8], |i| to_vdb(&i.brick_bits(leaf.origin.map(|c| c >> LEAF))));
    let (mut any_in, mut any_out) = (false, false);
    for (a, i) in leaf.mask.iter().zip(inside) {
        any_in |= i & !a != 0;
        any_out |= !i & !a != 0;
    }
    let active: u32 = leaf.mask.iter().map(|w| w.count_ones()).sum();
    1 + if any_in && any_out { 64 } else { 0 } + 4 * active as usize
}

/// A leaf's compressed values: metadata (0: every inactive voxel outside,
/// 1: every one inside, 3: a selection mask follows, set bits outside),
/// then the active values in OpenVDB's index order (`x·64 + y·8 + z`).
pub(super) fn leaf_values(field: &Field, leaf: &Leaf) -> Vec<u8> {
    let (values, _) = field.brick_values(leaf.origin.map(|c| c >> LEAF));
    let value = |n: usize| values[(n & 7) * 64 + (n >> 3 & 7) * 8 + (n >> 6)];
    let active = |n: usize| leaf.mask[n / 64] >> (n % 64) & 1 == 1;
    let mut outside = [0u64; 8];
    let (mut any_in, mut any_out) = (false, false);
    for n in (0..512).filter(|&n| !active(n)) {
        if value(n) > 0.0 {
            outside[n / 64] |= 1 << (n % 64);
            any_out = true;
        } else {
            any_in = true;
        }
    }
    let mut out = Vec::with_capacity(65 + 4 * 512);
    match (any_in, any_out) {
        (true, true) => {
            out.push(3);
            outside.iter().for_each(|w| out.extend_from_slice(&w.to_le_bytes()));
        }
        (true, false) => out.push(1),
        _ => out.push(0),
    }
    for n in (0..512).filter(|&n| active(n)) {
        out.extend_from_slice(&value(n).to_le_bytes());
    }
    out
}
