//! The tree a writer builds: leaves from partial bricks, full bricks as
//! tiles of their lower node, lower nodes wholly full as tiles of their
//! upper node.

use super::*;

/// A leaf: origin and OpenVDB's bit layout (bit `x·64 + y·8 + z`, so word
/// `x`, bit `y·8 + z`).
pub(super) struct Leaf {
    pub(super) origin: [u32; 3],
    pub(super) mask: [u64; 8],
}

impl Leaf {
    /// Order of OpenVDB's traversal: root children by origin `(x, y, z)`,
    /// then children of internal nodes by their index (x slowest).
    pub(super) fn order(&self) -> (u32, u32, u32, u32, u32) {
        let [x, y, z] = self.origin;
        let up = |c: u32| c >> UPPER;
        let lower = ((x >> LOWER) & 31) << 10 | ((y >> LOWER) & 31) << 5 | ((z >> LOWER) & 31);
        let leaf = ((x >> LEAF) & 15) << 8 | ((y >> LEAF) & 15) << 4 | ((z >> LEAF) & 15);
        (up(x), up(y), up(z), lower, leaf)
    }
}

/// topovox's brick layout (word `z`, bit `y·8 + x`) to OpenVDB's.
pub(super) fn to_vdb(b: &Brick) -> [u64; 8] {
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

/// Full bricks by lower node: key → mask of its 16³ bricks.
pub(super) type FullBricks = std::collections::HashMap<(u32, u32, u32, u32), Box<[u64; 64]>>;

/// Marks the run of `n` full bricks from brick `b` along x in `full`,
/// cut where it crosses lower nodes (16 bricks each).
pub(super) fn mark_full(full: &mut FullBricks, b: [u32; 3], n: u32) {
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
pub(super) struct Lower {
    /// `(upper x, y, z, index in the upper node)`: OpenVDB's order.
    pub(super) key: (u32, u32, u32, u32),
    pub(super) leaves: std::ops::Range<usize>,
    pub(super) tiles: Box<[u64; 64]>,
}

/// The tree to write: leaves (partial bricks) in OpenVDB's order, lower
/// nodes holding leaves or tiles, and the lower nodes wholly full, which
/// become active tiles of their upper node.
pub(super) struct Tree {
    pub(super) leaves: Vec<Leaf>,
    pub(super) lowers: Vec<Lower>,
    /// Full lower nodes as `(upper x, y, z, index)`, sorted.
    pub(super) full_lowers: Vec<(u32, u32, u32, u32)>,
    /// Bounds of the tiles' voxels.
    pub(super) tile_box: Option<([i32; 3], [i32; 3])>,
}

pub(super) fn upper_of(k: &(u32, u32, u32, u32)) -> (u32, u32, u32) {
    (k.0, k.1, k.2)
}

impl Tree {
    /// Gathers the bricks of `bits`: partial ones as leaves, runs of full
    /// ones as tiles (never one by one: a solid's interior is a few runs
    /// per brick row), lower nodes all of whose 4096 bricks are full as
    /// tiles of 128³. Without `tiles` (attribute grids, whose voxels each
    /// hold their own value) every brick is a leaf.
    pub(super) fn of(bits: &dyn VoxelSource, tiles: bool) -> Tree {
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
    pub(super) fn assemble(mut leaves: Vec<Leaf>, mut full: FullBricks, tile_box: Option<([i32; 3], [i32; 3])>) -> Tree {
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
