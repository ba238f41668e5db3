//! Voxelization algorithms, one per file, each with its slow reference
//! implementation in a `reference` submodule of the same file.
//!
//! | mode | file | guarantee |
//! |---|---|---|
//! | `cover` | [`cover`] | exactly the voxels whose closed box meets a triangle (26-separating for closed surfaces) |
//! | `sep26` | [`sep26`] | a triangle meets a space diagonal (26-separating, ⊆ `cover`) |
//! | `sep6` | [`sep6`] | a triangle meets the 3D crosshair (6-separating, thin) |
//! | `ss6` | [`ss6`] | Schwarz–Seidel plane + diamond tests (6-separating, ⊇ `sep6`) |
//! | `tunnel18`, `tunnel26` | [`tunnel`](mod@tunnel) | a triangle meets a segment from the centre to a face centre or edge midpoint (and corner) (18- / 26-tunnel-free) |
//! | `bubble` | [`bubble`](mod@bubble) | a triangle meets the randomized crosshair (6-separating, irregular) |
//! | `diagonal` | [`diagonal`](mod@diagonal) | a triangle meets the voxel's alternating body diagonal (6-separating) |
//! | `line26`, `line6` | [`line`](mod@line) | an element meets the bisecting squares / the surface (26- / 6-connected) |
//! | `pos` | [`pos`](mod@pos) | none: the published projected-optimal-scanline algorithm, kept to measure its gaps |
//! | `solid` | [`solid`] | the voxel's centre is inside (winding number); ray parity for watertight meshes |
//!
//! [`Mode`] with [`fast()`] and [`reference()`] dispatches over all of them.

pub mod bubble;
pub mod cover;
pub mod diagonal;
pub mod driver;
pub mod fill;
pub mod ilv;
pub mod line;
pub(crate) mod line_spans;
pub mod pos;
pub mod scanline;
pub mod sep26;
pub mod sep6;
pub mod solid;
pub mod ss6;
pub mod targets;
pub mod tiled;
pub mod tunnel;
pub mod winding;

use crate::geom::lattice::{prepare, LatticeTriangle, PrepareStats};
use crate::grid::dense::DenseBits;
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;
/// Where long work looks whether to stop (re-exported: `topovox::voxelize::Stop`).
pub use crate::stop::Stop;

/// The shared shape of the references: for every voxel of every
/// primitive's bounding box, evaluate the mode's definition. Serial, dense,
/// obviously correct.
pub(crate) fn brute_force<P: driver::Primitive>(prims: &[P], dims: [u32; 3], hit: impl Fn(&P, [i64; 3]) -> bool) -> DenseBits {
    let mut bits = DenseBits::new(dims);
    for t in prims {
        let Some((lo, hi)) = t.voxel_bounds(dims) else { continue };
        for k in lo[2]..=hi[2] {
            for j in lo[1]..=hi[1] {
                for i in lo[0]..=hi[0] {
                    if hit(t, [i, j, k]) {
                        bits.set(i as u32, j as u32, k as u32);
                    }
                }
            }
        }
    }
    bits
}

/// [`brute_force`] on a mesh's snapped triangles.
pub(crate) fn brute_force_triangles(
    mesh: MeshRef<'_>,
    grid: &GridSpec,
    hit: impl Fn(&LatticeTriangle, [i64; 3]) -> bool,
) -> (DenseBits, Report) {
    let (tris, prepare_stats) = prepare(mesh, grid);
    let bits = brute_force(&tris, grid.dims(), hit);
    let voxels = bits.count();
    (bits, Report { prepare: prepare_stats, voxels })
}

crate::choice! {
    /// The paths of `method gpu`. They run in the `topovox-gpu` crate; they
    /// are named here so that every crate above the core shares one list.
    pub enum GpuPath: "GPU path" default Compute {
        /// Compute shaders, one workgroup per triangle.
        Compute = "compute",
        /// The rasterizer: dominant-axis projection, conservative coverage,
        /// exact tests per fragment (the same voxels as compute).
        Raster = "raster",
        /// The rasterizer with 4x MSAA instead of conservative coverage:
        /// approximate, misses voxels (never sets a wrong one).
        MsaaApprox = "msaa-approx",
    }
}

/// A surface or 1D voxelization mode (the solid modes live elsewhere).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Mode {
    /// Conservative cover.
    Cover,
    /// Laine's 26-separating (space diagonals).
    Sep26,
    /// Laine's thin 6-separating (3D crosshair).
    Sep6,
    /// Schwarz–Seidel 6-separating.
    Ss6,
    /// 26-connected 1D (bisecting squares).
    Line26,
    /// 6-connected 1D (voxel surface).
    Line6,
    /// The published projected optimal scanline algorithm (no guarantee).
    Pos,
    /// 18-tunnel-free (centre to face centres and edge midpoints).
    Tunnel18,
    /// 26-tunnel-free (centre to face centres, edge midpoints and corners).
    Tunnel26,
    /// Randomized crosshair (6-separating), from a seed.
    Bubble {
        /// The seed of the random points: same seed, same voxels.
        seed: u64,
    },
    /// Alternating single body diagonal (6-separating).
    Diagonal,
}

impl Mode {
    /// Every mode, in documentation order.
    pub const ALL: [Mode; 11] = [
        Mode::Cover,
        Mode::Sep26,
        Mode::Sep6,
        Mode::Ss6,
        Mode::Line26,
        Mode::Line6,
        Mode::Pos,
        Mode::Tunnel18,
        Mode::Tunnel26,
        Mode::Bubble { seed: 0 },
        Mode::Diagonal,
    ];

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Cover => "cover",
            Mode::Sep26 => "sep26",
            Mode::Sep6 => "sep6",
            Mode::Ss6 => "ss6",
            Mode::Line26 => "line26",
            Mode::Line6 => "line6",
            Mode::Pos => "pos",
            Mode::Tunnel18 => "tunnel18",
            Mode::Tunnel26 => "tunnel26",
            Mode::Bubble { .. } => "bubble",
            Mode::Diagonal => "diagonal",
        }
    }
}

/// The mode's fast path (parallel, sparse bricks).
pub fn fast(mode: Mode, mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> (crate::grid::bricks::BrickBits, Report) {
    match mode {
        Mode::Cover => cover::cover(mesh, grid, opts),
        Mode::Sep26 => sep26::sep26(mesh, grid, opts),
        Mode::Sep6 => sep6::sep6(mesh, grid, opts),
        Mode::Ss6 => ss6::ss6(mesh, grid, opts),
        Mode::Line26 => line::line(mesh, grid, line::LineTarget::Squares26, opts),
        Mode::Line6 => line::line(mesh, grid, line::LineTarget::Surface6, opts),
        Mode::Pos => pos::pos(mesh, grid, opts),
        Mode::Tunnel18 => tunnel::tunnel(mesh, grid, tunnel::TunnelTarget::Eighteen, opts),
        Mode::Tunnel26 => tunnel::tunnel(mesh, grid, tunnel::TunnelTarget::TwentySix, opts),
        Mode::Bubble { seed } => bubble::bubble(mesh, grid, seed, opts),
        Mode::Diagonal => diagonal::diagonal(mesh, grid, opts),
    }
}

/// The mode's brute-force reference (serial, dense).
pub fn reference(mode: Mode, mesh: MeshRef<'_>, grid: &GridSpec) -> (DenseBits, Report) {
    match mode {
        Mode::Cover => cover::reference::cover(mesh, grid),
        Mode::Sep26 => sep26::reference::sep26(mesh, grid),
        Mode::Sep6 => sep6::reference::sep6(mesh, grid),
        Mode::Ss6 => ss6::reference::ss6(mesh, grid),
        Mode::Line26 => line::reference::line(mesh, grid, line::LineTarget::Squares26),
        Mode::Line6 => line::reference::line(mesh, grid, line::LineTarget::Surface6),
        Mode::Pos => pos::reference::pos(mesh, grid),
        Mode::Tunnel18 => tunnel::reference::tunnel(mesh, grid, tunnel::TunnelTarget::Eighteen),
        Mode::Tunnel26 => tunnel::reference::tunnel(mesh, grid, tunnel::TunnelTarget::TwentySix),
        Mode::Bubble { seed } => bubble::reference::bubble(mesh, grid, seed),
        Mode::Diagonal => diagonal::reference::diagonal(mesh, grid),
    }
}

/// Receives progress of long voxelizations. Implemented by the CLI's
/// progress bar; core never prints.
pub trait Progress: Sync {
    /// The amount of work to come, in arbitrary units.
    fn set_total(&self, total: u64);
    /// `n` more units are done.
    fn advance(&self, n: u64);
    /// A phase of unknown length begins (`"writing"`); nothing by default.
    fn phase(&self, _name: &'static str) {}
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
    /// Checked between slabs, tiles and triangle chunks (see [`Stop`]).
    /// Default: none (the work runs to the end).
    pub stop: Option<&'a Stop>,
    /// Layers per z-slab in the parallel driver; `0` (default) picks one
    /// from the grid and the thread count. The result does not depend on it.
    pub slab_height: u32,
    /// Traversal of the fast `cover` path. Default: [`Traversal::Auto`].
    /// The result does not depend on it.
    pub traversal: Traversal,
    /// Parallel driver of the fast paths. Default: [`driver::Driver::Auto`].
    /// The result does not depend on it.
    pub driver: driver::Driver,
    /// Voxel tests a slab of the slab driver may put off
    /// ([`driver::Deferred`]) before the driver has them run; `0`
    /// (default) means 2^18. The result does not depend on it (tests pin
    /// 1).
    pub defer_limit: usize,
    /// The tiled driver's expected number of non-empty bricks (`0`,
    /// default: unknown), reserved up front so its result is never grown
    /// by doubling. The result does not depend on it.
    pub brick_capacity: usize,
}

impl Options<'_> {
    /// Whether the caller asked the work to stop (see [`Stop`]).
    #[inline]
    pub fn stopped(&self) -> bool {
        self.stop.is_some_and(Stop::requested)
    }
}

/// What a voxelization did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Report {
    /// Triangle preparation: skipped, clipped, degenerate counts.
    pub prepare: PrepareStats,
    /// Voxels set in the result.
    pub voxels: u64,
}
