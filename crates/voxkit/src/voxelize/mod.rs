//! Voxelization algorithms, one per file, each with its slow reference
//! implementation in a `reference` submodule of the same file.
//!
//! | mode | file | guarantee |
//! |---|---|---|
//! | `cover` | [`cover`] | exactly the voxels whose closed box meets a triangle (26-separating for closed surfaces) |

pub mod cover;
pub mod driver;

use crate::geom::lattice::PrepareStats;

/// Receives progress of long voxelizations. Implemented by the CLI's
/// progress bar; core never prints.
pub trait Progress: Sync {
    /// The amount of work to come, in arbitrary units.
    fn set_total(&self, total: u64);
    /// `n` more units are done.
    fn advance(&self, n: u64);
}

/// How the fast `cover` path walks a triangle's voxels. Every choice gives
/// the same voxels; the choice exists so tests can pin each traversal and
/// benchmarks can compare them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Traversal {
    /// Scan the box of small triangles, walk rows of large ones (default).
    #[default]
    Auto,
    /// Scan every triangle's box column by column (triangles whose plane
    /// values need `i128` still walk rows).
    ScanBoxes,
    /// Walk rows with exact incremental edge bounds for every triangle.
    WalkRows,
}

/// Options shared by the voxelizers. `Options::default()` is the default
/// for every field.
#[derive(Clone, Copy, Default)]
pub struct Options<'a> {
    /// Progress sink. Default: none.
    pub progress: Option<&'a dyn Progress>,
    /// Layers per z-slab in the parallel driver; `0` (default) picks one
    /// from the grid and the thread count. The result does not depend on it.
    pub slab_height: u32,
    /// Traversal of the fast `cover` path. Default: [`Traversal::Auto`].
    /// The result does not depend on it.
    pub traversal: Traversal,
}

/// What a voxelization did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Report {
    /// Triangle preparation: skipped, clipped, degenerate counts.
    pub prepare: PrepareStats,
    /// Voxels set in the result.
    pub voxels: u64,
}
