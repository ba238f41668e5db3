//! The tiled driver: surface and line modes on grids too large for a
//! whole-grid brick index, in memory that follows the surface instead of
//! the grid.
//!
//! **Algorithm.** The mesh is snapped once to the whole grid's lattice
//! (exactly as every other path does). The grid is cut into cubic tiles of
//! `tile` voxels (a multiple of 8). Each lattice triangle is binned into
//! every tile its voxel bounding box meets; the bins are sorted by
//! `(tile, triangle)`. Tiles are visited in order of `tk`, `tj`, `ti`;
//! each one's triangles are translated by the tile's origin — a whole
//! number of voxels, so an exact integer shift of the lattice — and run
//! through the mode's own fast kernel on a grid of the tile's size
//! ([`fast_lattice`]; for the line modes, their segments and triangles
//! through [`super::line::line_lattice`]; for `cover`, `sep26` and
//! `sep6`, on request, the scanline path's kernel,
//! [`super::scanline::scanline_lattice`]); the kernels only set voxels of
//! the box they are
//! given, so a triangle spanning tiles contributes to each exactly its
//! voxels there. The tile's bricks move into a [`SparseBricks`] and the
//! tile's storage is freed.
//!
//! **Guarantee.** The same voxels as the mode's fast path (and so as its
//! reference) for any tile size and thread count: the lattice triangles
//! are the same, every mode's definition is invariant under whole-voxel
//! translation except where a target depends on the voxel's index in the
//! whole grid — `diagonal` (parity: tiles are multiples of 8) and `bubble`
//! (its random points are drawn for whole-grid indices: the kernel is told
//! the tile's offset). Tested against the dense fast path with tiles of
//! 8–64 on the shared meshes, rotated and random triangles.
//!
//! **Memory.** The lattice triangles (72 bytes each; line modes' elements
//! 80), one bin entry per
//! (triangle, tile) pair (16 bytes), one tile's brick index (`4 bytes ×
//! (tile/8)³`, 256 KiB at 512) and the result's non-empty bricks (72
//! bytes each). Nothing is proportional to the grid's volume.

use std::convert::Infallible;

use rayon::prelude::*;

use super::driver::Primitive;
use super::line::{line_lattice, prepare_elements, LineTarget};
use super::targets::Element;
use super::{Mode, Options, Report};
use crate::geom::fixed::ONE;
use crate::geom::lattice::{prepare, LatticeTriangle};
use crate::grid::bricks::{BrickBits, BRICK};
use crate::grid::sparse::SparseBricks;
use crate::grid::spec::GridSpec;
use crate::mesh::MeshRef;

/// Default tile edge in voxels.
pub const DEFAULT_TILE: u32 = 512;

/// The mode's fast path on prepared triangles of a grid of `dims` whose
/// voxel `(0,0,0)` is voxel `offset` of the whole grid (`[0; 3]` for a
/// whole grid; a multiple of 2 on every axis). `None` for the line modes,
/// whose primitives are not triangles.
pub fn fast_lattice(mode: Mode, tris: &[LatticeTriangle], dims: [u32; 3], offset: [i64; 3], opts: &Options<'_>) -> Option<BrickBits> {
    Some(match mode {
        Mode::Cover => super::cover::cover_lattice(tris, dims, opts),
        Mode::Sep26 => super::sep26::sep26_lattice(tris, dims, opts),
        Mode::Sep6 => super::sep6::sep6_lattice(tris, dims, opts),
        Mode::Ss6 => super::ss6::ss6_lattice(tris, dims, opts),
        Mode::Pos => super::pos::pos_lattice(tris, dims, opts),
        Mode::Tunnel18 => super::tunnel::tunnel_lattice(tris, dims, super::tunnel::TunnelTarget::Eighteen, opts),
        Mode::Tunnel26 => super::tunnel::tunnel_lattice(tris, dims, super::tunnel::TunnelTarget::TwentySix, opts),
        Mode::Bubble { seed } => super::bubble::bubble_lattice(tris, dims, seed, offset, opts),
        Mode::Diagonal => super::diagonal::diagonal_lattice(tris, dims, opts),
        Mode::Line26 | Mode::Line6 => return None,
    })
}

/// The kernel each tile runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TileKernel {
    /// The mode's fast path ([`fast_lattice`]).
    #[default]
    Fast,
    /// The scanline path ([`super::scanline::scanline_lattice`]; `cover`,
    /// `sep26` and `sep6` only).
    Scanline,
}

/// Why a tiled run cannot start.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TiledError {
    /// The tile edge is not a positive multiple of 8.
    Tile(u32),
    /// An axis exceeds [`SparseBricks::MAX_DIM`].
    Grid([u32; 3]),
    /// The kernel does not implement the mode.
    Kernel(Mode),
}

impl std::fmt::Display for TiledError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TiledError::Tile(t) => write!(f, "tile size {t} is not a positive multiple of 8"),
            TiledError::Grid(d) => write!(f, "grid {}x{}x{} exceeds {} voxels per axis", d[0], d[1], d[2], SparseBricks::MAX_DIM),
            TiledError::Kernel(m) => write!(f, "--method scanline exists for cover, sep26 and sep6, not {}", m.name()),
        }
    }
}

impl std::error::Error for TiledError {}

/// Runs `mode` tile by tile on `grid` (tiles of `tile` voxels) with the
/// fast path's kernels. Returns the voxels as sorted sparse bricks and the
/// usual report.
pub fn tiled(mode: Mode, mesh: MeshRef<'_>, grid: &GridSpec, tile: u32, opts: &Options<'_>) -> Result<(SparseBricks, Report), TiledError> {
    tiled_with(mode, TileKernel::Fast, mesh, grid, tile, opts)
}

/// [`tiled`] with the kernel each tile runs: the fast path's, or the
/// scanline path's (the same voxels; faster where triangles span many
/// voxels, as they do on very large grids).
pub fn tiled_with(
    mode: Mode,
    kernel: TileKernel,
    mesh: MeshRef<'_>,
    grid: &GridSpec,
    tile: u32,
    opts: &Options<'_>,
) -> Result<(SparseBricks, Report), TiledError> {
    if kernel == TileKernel::Scanline && !super::scanline::supports(mode) {
        return Err(TiledError::Kernel(mode));
    }
    if tile == 0 || tile % BRICK != 0 {
        return Err(TiledError::Tile(tile));
    }
    let dims = grid.dims();
    if dims.iter().any(|&d| d > SparseBricks::MAX_DIM) {
        return Err(TiledError::Grid(dims));
    }
    let line = match mode {
        Mode::Line26 => Some(LineTarget::Squares26),
        Mode::Line6 => Some(LineTarget::Surface6),
        _ => None,
    };
    Ok(match line {
        Some(target) => {
            let (elems, prepare) = prepare_elements(mesh, grid);
            let run = |e: &[Element], size: [u32; 3], _: [i64; 3], o: &Options<'_>| Ok::<_, Infallible>(line_lattice(e, size, target, o));
            let Ok((out, voxels)) = by_tiles(&elems, dims, tile, opts, Element::translated, run);
            (out, Report { prepare, voxels })
        }
        None => {
            let (tris, prepare) = prepare(mesh, grid);
            let run = |t: &[LatticeTriangle], size: [u32; 3], origin: [i64; 3], o: &Options<'_>| {
                Ok::<_, Infallible>(match kernel {
                    TileKernel::Fast => fast_lattice(mode, t, size, origin, o).expect("line modes take their own path"),
                    TileKernel::Scanline => super::scanline::scanline_lattice(mode, t, size, o).expect("checked above"),
                })
            };
            let Ok((out, voxels)) = by_tiles(&tris, dims, tile, opts, LatticeTriangle::translated, run);
            (out, Report { prepare, voxels })
        }
    })
}

/// [`tiled`] with the caller's kernel for a triangle mode (the GPU's, which
/// the core crate does not know): `run(triangles, size)` voxelizes one
/// tile's triangles, moved by whole voxels to the tile's origin, on a grid
/// of the tile's size, and must give the mode's voxels there. The outer
/// error is the run's set-up, the inner one the first error of `run`
/// (which stops the run).
#[allow(clippy::type_complexity)]
pub fn tiled_by<E>(
    mesh: MeshRef<'_>,
    grid: &GridSpec,
    tile: u32,
    opts: &Options<'_>,
    mut run: impl FnMut(&[LatticeTriangle], [u32; 3]) -> Result<BrickBits, E>,
) -> Result<Result<(SparseBricks, Report), E>, TiledError> {
    if tile == 0 || tile % BRICK != 0 {
        return Err(TiledError::Tile(tile));
    }
    let dims = grid.dims();
    if dims.iter().any(|&d| d > SparseBricks::MAX_DIM) {
        return Err(TiledError::Grid(dims));
    }
    let (tris, prepare) = prepare(mesh, grid);
    Ok(by_tiles(&tris, dims, tile, opts, LatticeTriangle::translated, |t, size, _, _| run(t, size))
        .map(|(out, voxels)| (out, Report { prepare, voxels })))
}

/// The driver proper: bins `prims` into the tiles of `tile` voxels their
/// voxel boxes meet, and per tile in order, moves its primitives by the
/// tile's origin (`shift`) and runs them (`run`, given the tile's size and
/// origin; tiles one after another) on a grid of the tile's size. Returns the voxels and their count.
fn by_tiles<P: Primitive, E>(
    prims: &[P],
    dims: [u32; 3],
    tile: u32,
    opts: &Options<'_>,
    shift: impl Fn(&P, [i64; 3]) -> P,
    mut run: impl FnMut(&[P], [u32; 3], [i64; 3], &Options<'_>) -> Result<BrickBits, E>,
) -> Result<(SparseBricks, u64), E> {
    let tdims = dims.map(|d| d.div_ceil(tile) as u64);
    let tile_id = |t: [u64; 3]| (t[2] * tdims[1] + t[1]) * tdims[0] + t[0];
    // (tile, primitive) pairs, sorted: each tile's primitives in input order.
    let mut pairs: Vec<(u64, u32)> = prims
        .par_iter()
        .enumerate()
        .flat_map_iter(|(n, t)| {
            let b = t.voxel_bounds(dims);
            let (lo, hi) =
                b.map(|(lo, hi)| (lo.map(|c| c as u64 / tile as u64), hi.map(|c| c as u64 / tile as u64))).unwrap_or(([1; 3], [0; 3]));
            (lo[2]..=hi[2])
                .flat_map(move |tk| (lo[1]..=hi[1]).flat_map(move |tj| (lo[0]..=hi[0]).map(move |ti| (tile_id([ti, tj, tk]), n as u32))))
        })
        .collect();
    pairs.par_sort_unstable();
    let starts: Vec<usize> = (0..pairs.len()).filter(|&n| n == 0 || pairs[n].0 != pairs[n - 1].0).collect();
    if let Some(p) = opts.progress {
        p.set_total(starts.len() as u64);
    }
    let inner = Options { progress: None, ..*opts };
    let mut out = SparseBricks::new(dims);
    out.reserve(opts.brick_capacity);
    let mut local: Vec<P> = Vec::new();
    let mut voxels = 0;
    for (s, &start) in starts.iter().enumerate() {
        if opts.stopped() {
            break;
        }
        let end = starts.get(s + 1).copied().unwrap_or(pairs.len());
        let id = pairs[start].0;
        let t = [id % tdims[0], (id / tdims[0]) % tdims[1], id / (tdims[0] * tdims[1])];
        let origin: [u32; 3] = t.map(|c| (c * tile as u64) as u32);
        let size: [u32; 3] = std::array::from_fn(|a| tile.min(dims[a] - origin[a]));
        let back: [i64; 3] = origin.map(|o| -(o as i64) * ONE);
        local.clear();
        local.extend(pairs[start..end].iter().map(|&(_, n)| shift(&prims[n as usize], back)));
        let bits = run(&local, size, origin.map(|o| o as i64), &inner)?;
        voxels += bits.count();
        out.push_tile(origin, &bits);
        if let Some(p) = opts.progress {
            p.advance(1);
        }
    }
    out.finish();
    Ok((out, voxels))
}
