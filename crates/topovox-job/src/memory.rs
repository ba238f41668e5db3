//! How much memory there is, and refusing grids that cannot fit.

use topovox::voxelize::{self, Mode, Options};
use topovox::{GridSpec, MeshRef};

use crate::error::{JobError, Result};

pub use topovox_io::{available_memory, bytes};

/// Grids whose dense storage is below this are not checked (every machine
/// topovox runs on has that much; reading `/proc/meminfo` per job would cost
/// more than a small job itself).
const UNCHECKED_BYTES: u64 = 256 << 20;

/// The memory a run may use: `max_memory` if given, else nine tenths of
/// the available memory (headroom for the mesh, the writer's buffers and
/// the system); `u64::MAX` when neither is known.
pub fn budget(max_memory: Option<u64>) -> u64 {
    max_memory.or_else(|| available_memory().map(|a| a / 10 * 9)).unwrap_or(u64::MAX)
}

/// True when a dense grid of `grid` (1 bit per voxel) fits in `budget`.
pub fn dense_fits(grid: &GridSpec, budget: u64) -> bool {
    let need = grid.dense_bytes();
    need < UNCHECKED_BYTES || need <= budget
}

/// Fails if a dense grid of `grid` would not fit in `budget` (see
/// [`budget`]); `why` names what needs it dense.
pub fn check_memory(grid: &GridSpec, budget: u64, why: &str) -> Result<()> {
    if dense_fits(grid, budget) {
        return Ok(());
    }
    let [x, y, z] = grid.dims();
    Err(JobError::failed(format!(
        "grid {x}x{y}x{z} needs {} of dense storage (1 bit per voxel) for {why}, more than the {} this run may use; lower the resolution, raise --max-memory, or use a surface mode with --method auto/fast (tiled, sparse)",
        bytes(grid.dense_bytes()),
        bytes(budget)
    )))
}

/// What every estimate adds for the process itself: the binary, the mesh
/// as read, one tile and the writer's buffers.
pub(crate) const PROCESS_BYTES: u64 = 24 << 20;

/// Bytes per brick a tiled run holds: the 64-byte brick and its 8-byte key
/// (the 4-byte index that puts them in order comes and goes within the
/// base below). With the per-triangle and base terms of
/// [`tiled_estimate`], measured on the bunny at 3000, 4096 and 8192 and
/// the cow at 4096 to stay at or above the peak (2026-11-27).
const BYTES_PER_BRICK: u64 = 72;

/// What a tiled surface run is expected to hold, for a refusal before
/// any work rather than a run past `--max-memory`.
#[derive(Clone, Copy, Debug)]
pub struct TiledEstimate {
    /// At most this many bricks (8³ voxels) hold voxels.
    pub bricks: u64,
    /// About this many bytes at the peak.
    pub bytes: u64,
}

/// The memory a tiled surface run of `mesh` on `grid` needs. Every voxel
/// any surface or line mode sets lies in a brick the mesh meets, so the
/// non-empty bricks are at most the `cover` voxels of the grid of bricks
/// (voxels 8 times larger), found by a tiled run there (1/512 of the
/// voxels). To that: the lattice triangles and their tile bins (88 bytes
/// a triangle), and 24 MiB for the process, the mesh as read, one tile and
/// the writer's buffers.
pub fn tiled_estimate(mesh: MeshRef<'_>, grid: &GridSpec) -> TiledEstimate {
    let dims = grid.dims().map(|d| u64::from(d.div_ceil(8)));
    let bricks = GridSpec::new(grid.origin(), grid.voxel_size().0 * 8.0, dims)
        .ok()
        .and_then(|coarse| voxelize::tiled::tiled(Mode::Cover, mesh, &coarse, voxelize::tiled::DEFAULT_TILE, &Options::default()).ok())
        .map(|(b, _)| b.count())
        .unwrap_or(0);
    // Segments (polylines) set few voxels: a brick per 8 voxels of length
    // at most, bounded here by the grid's longest axis per segment.
    let segments = mesh.segments.len() as u64 * dims.iter().copied().max().unwrap_or(1);
    let prims = (mesh.triangles.len() + mesh.segments.len()) as u64 * 88 + mesh.positions.len() as u64 * 24;
    TiledEstimate { bricks: bricks + segments, bytes: (bricks + segments) * BYTES_PER_BRICK + prims + PROCESS_BYTES }
}

/// Bytes a point query holds per triangle of its mesh: the distance
/// pieces and their hierarchy, the ray index, the winding number's tree
/// and the caps of open boundaries (a soup caps every triangle). Measured
/// at the peak of `topovox sample` on 10⁶-triangle meshes (2026-12-02):
/// a closed sphere 1150, an open sheet 1070, a soup 2130; rounded up.
const QUERY_BYTES_PER_TRIANGLE: u64 = 2304;

/// The memory a point query over `mesh` holds with the mesh as loaded
/// (the vertices in f64, the triangles in u32, a moved copy of the
/// vertices) and 24 MiB for the process: what `sample`, `query` and the
/// Python `Query` need before their points.
pub fn query_bytes(mesh: MeshRef<'_>) -> u64 {
    let triangles = (mesh.triangles.len() + mesh.segments.len()) as u64;
    let vertices = mesh.positions.len() as u64;
    triangles.saturating_mul(QUERY_BYTES_PER_TRIANGLE + 12).saturating_add(vertices.saturating_mul(48)).saturating_add(PROCESS_BYTES)
}

/// Bytes per triangle a sparse solid holds beyond a tiled surface: the
/// snapped triangles, the copy closed by caps, their band bins, and the
/// oriented triangles the winding rules decide on (12; orienting's own
/// scratch, about 130 a triangle, is freed before the solid starts).
const SOLID_BYTES_PER_TRIANGLE: u64 = 172;

/// Bytes per surface brick a sparse solid holds beyond a tiled surface:
/// the runs of full bricks between them, and one band's ray crossings and
/// cap spans. Measured (with the terms above) on the bunny at 4096 and
/// 8192 (28–29 bytes a brick past the rest) and the cow at 4096, solid
/// and flood-filled (the cow's flood fill peaks at 120 MiB, estimated
/// 132), to stay above the peak (2026-11-27).
const SOLID_BYTES_PER_BRICK: u64 = 40;

/// The memory a sparse solid of `mesh` on `grid` needs: the bricks the
/// surface meets (the only ones stored; the interior is runs of full
/// bricks) as for a tiled surface, and as many again for a flood fill
/// (the tiled shell and the solid are both held, and its planes' runs),
/// the runs and one band's crossings, and the triangles' copies; and a
/// third more for the allocator. glibc raises its mmap threshold (up
/// to 32 MiB) as large blocks are freed, then serves blocks below it from
/// a heap that keeps what is freed and copies what grows: the bunny's
/// solid at 2048 peaked at 79, 94 or 98 MiB from one run to the next,
/// where the refusal named 82 MiB without this (and at 64 MiB, every run,
/// with the threshold fixed, which `unsafe_code = "forbid"` keeps us from
/// setting).
pub fn sparse_solid_estimate(mesh: MeshRef<'_>, grid: &GridSpec, flood: bool) -> TiledEstimate {
    let e = tiled_estimate(mesh, grid);
    let shell = if flood { e.bricks * (BYTES_PER_BRICK + SOLID_BYTES_PER_BRICK) } else { 0 };
    let solid = e.bricks * SOLID_BYTES_PER_BRICK + mesh.triangles.len() as u64 * SOLID_BYTES_PER_TRIANGLE;
    let bytes = e.bytes + shell + solid;
    TiledEstimate { bricks: e.bricks, bytes: bytes + bytes / 3 }
}

/// The largest memory size accepted: 1024 TiB (2⁵⁰ bytes), far past any
/// machine; larger numbers are a typo, and past 2⁶⁴ would not fit.
const MAX_SIZE: u64 = 1 << 50;

/// Parses a memory size: bytes, or a number with `K`, `M`, `G`, `T`
/// (powers of 1024; `KiB`/`KB`/… accepted the same), e.g. `8G`, `1.5GiB`.
pub fn parse_size(s: &str) -> Result<u64> {
    let t = s.trim();
    let split = t.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let shift = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 0,
        "k" | "kb" | "kib" => 10,
        "m" | "mb" | "mib" => 20,
        "g" | "gb" | "gib" => 30,
        "t" | "tb" | "tib" => 40,
        _ => return Err(JobError::invalid(format!("--max-memory {s:?}: unknown unit (use bytes or K, M, G, T)"))),
    };
    let v: f64 = num.parse().map_err(|_| JobError::invalid(format!("--max-memory {s:?}: not a size (e.g. 8G, 512M)")))?;
    let b = v * (1u64 << shift) as f64;
    if b < (1u64 << 20) as f64 {
        return Err(JobError::invalid(format!("--max-memory {s:?}: must be at least 1M")));
    }
    if b > MAX_SIZE as f64 {
        return Err(JobError::invalid(format!("--max-memory {s:?}: too large (at most 1024T)")));
    }
    Ok(b as u64)
}

/// The process's peak resident memory so far (`VmHWM`), if the OS says.
pub fn peak_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = text.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!(parse_size("8G").unwrap(), 8 << 30);
        assert_eq!(parse_size("1.5GiB").unwrap(), 3 << 29);
        assert_eq!(parse_size("512m").unwrap(), 512 << 20);
        assert_eq!(parse_size("2097152").unwrap(), 2 << 20);
        for bad in ["", "G", "8X", "-1G", "100", "nanG"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }
}
