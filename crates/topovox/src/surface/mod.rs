//! Surfaces from voxels: a closed, 2-manifold, oriented,
//! self-intersection-free triangle mesh around the inside voxels, its
//! topology decided by the voxels alone ([`tets`]), its vertices placed on
//! the lattice edges by the caller's rule.
//!
//! - [`blocky`]: the boundary of the inside voxels. The voxels are split
//!   in two along each axis and the surface extracted between the
//!   half-voxel centres with every vertex at the middle of its edge, so
//!   flat stretches lie exactly on the voxel faces; where voxels meet only
//!   along an edge or at a corner the surface passes a quarter voxel from
//!   it, on one side (Kuhn's diagonal decides which), so it stays a
//!   manifold and never touches itself.
//! - [`smooth`]: the surface between the voxel centres, each vertex where
//!   the exact signed distance to the input mesh crosses zero along its
//!   edge (linear interpolation of the two exact distances), kept a
//!   twentieth of the edge away from the centres.
//! - [`wrap`]: the inside voxels for shells around any input: the solid,
//!   the cover grown by one voxel, and every cavity they enclose.

pub mod simplify;
pub mod tets;

use glam::DVec3;
use rayon::prelude::*;

use crate::distance::nearest::Hierarchy;
use crate::distance::Pieces;
use crate::grid::dense::DenseBits;
use crate::stop::Stop;
use crate::topology::runs::{components, Connectivity, Runs};
use crate::voxelize::fill::flood_fill;
use crate::GridSpec;

/// An indexed triangle mesh in world coordinates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// How far from the lattice points a smooth vertex is kept, as a fraction
/// of its edge: the triangles keep a size the output's precision can hold.
pub const MARGIN: f64 = 0.05;

/// The same for wrap's shells, whose inside ends lie anywhere from 0 to
/// about 2.6 voxels from the input: most would sit at the margin, in
/// near-coplanar pieces a twentieth of a voxel apart; a quarter keeps
/// them apart by half a voxel.
pub const WRAP_MARGIN: f64 = 0.25;

/// Steps of the output's numbers a voxel must span, as a power of two: a
/// smooth vertex keeps [`MARGIN`] (a twentieth) of an edge from the
/// lattice points, so 2⁸ steps a voxel keep some thirteen steps between
/// any two vertices, and rounding can neither merge vertices nor fold a
/// face. f64 has 53 bits, f32 (STL, GLB) 24.
pub const STEPS_PER_VOXEL: i32 = 8;

/// Whether a surface on `grid` survives being written in f64 (or, with
/// `single`, f32) numbers; else why not. A grid whose voxels are too small
/// beside its coordinates (a unit tetrahedron at 10¹⁵ on a 32³ grid:
/// voxels of 0.03 where f64's steps are 0.125) would come out with merged
/// vertices, degenerate faces and edges of more than two faces.
pub fn check_precision(grid: &GridSpec, single: bool) -> Result<(), String> {
    let [x, y, z] = grid.dims();
    let far = grid.origin() + DVec3::new(x as f64, y as f64, z as f64) * grid.voxel_size().0;
    let m = grid.origin().abs().max(far.abs()).max_element();
    let h = grid.voxel_size().0.min_element();
    let (bits, numbers) = if single { (24, "f32 numbers (STL, GLB)") } else { (53, "f64 numbers") };
    let most = 2f64.powi(bits - STEPS_PER_VOXEL);
    if m / h > most {
        return Err(format!(
            "the {x}x{y}x{z} grid's voxels ({h:.3e}) are too small beside its coordinates (up to {m:.3e}) for the output's {numbers}: \
             a surface needs voxels of at least 1/{most:.0} of the largest coordinate; move the mesh near the origin, lower the resolution"
        ));
    }
    Ok(())
}

/// One slab of a surface ([`tets::extract_slabs`]): the positions of
/// vertices `first_vertex..`, and triangles on those and on the previous
/// part's vertices. A surface's parts, concatenated, are the whole surface.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Part {
    /// The id of the first of `positions`.
    pub first_vertex: u32,
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Triangles (global vertex ids), counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// How a caller takes a surface's parts; its first error ends the surface.
pub type Parts<'a, E> = &'a mut dyn FnMut(Part) -> Result<(), E>;

/// The whole surface that `make` hands out in parts; `None` when stopped.
fn whole(make: impl FnOnce(Parts<'_, std::convert::Infallible>) -> Result<Option<()>, std::convert::Infallible>) -> Option<TriMesh> {
    let mut all = TriMesh::default();
    let done = make(&mut |p: Part| {
        all.positions.extend(p.positions);
        all.triangles.extend(p.triangles);
        Ok(())
    });
    match done {
        Ok(d) => d.map(|()| all),
        Err(never) => match never {},
    }
}

/// The blocky surface of `inside` on `grid` (see the module doc).
pub fn blocky(inside: &DenseBits, grid: &GridSpec, stop: &Stop) -> Option<TriMesh> {
    whole(|each| blocky_parts(inside, grid, u32::MAX, stop, each))
}

/// [`blocky`], handed to `each` slab by slab, `thickness` layers of half
/// voxels a slab (see [`Part`]); `Ok(None)` when `stop` was requested.
pub fn blocky_parts<E>(inside: &DenseBits, grid: &GridSpec, thickness: u32, stop: &Stop, each: Parts<'_, E>) -> Result<Option<()>, E> {
    let halves = refine(inside);
    let (o, q) = (grid.origin(), grid.voxel_size().0 / 4.0);
    tets::extract_slabs(&halves, thickness, stop, |s| {
        // Half-voxel centre s sits at (2s + 1) quarters; the middle of an
        // edge at the sum of its ends' quarters, halved: exact integers.
        let positions = s
            .crossings
            .par_iter()
            .map(|(a, b)| {
                let quarters = DVec3::new((a[0] + b[0] + 1) as f64, (a[1] + b[1] + 1) as f64, (a[2] + b[2] + 1) as f64);
                o + quarters * q
            })
            .collect();
        each(Part { first_vertex: s.first_vertex, positions, triangles: s.triangles })
    })
}

/// Where the smooth surface's vertices go: the signed distance's source and
/// the rule (see [`smooth`]).
#[derive(Clone, Copy)]
pub struct Smooth<'a> {
    /// The input's pieces.
    pub pieces: &'a Pieces,
    /// Their hierarchy (the caller may use it again).
    pub tree: &'a Hierarchy,
    /// Wrap's offset (world units), `None` for the input's own surface.
    pub offset: Option<f64>,
}

/// The smooth surface of `inside` on `grid`: each vertex on the zero of
/// the linear interpolation along its edge of the signed distance to
/// `at.pieces` (negative at inside centres), clamped to
/// [`MARGIN`]`..1 − MARGIN` of the edge; or with `at.offset` (world units)
/// of `distance − offset`, clamped to [`WRAP_MARGIN`] (wrap's shells,
/// which sit off the input).
pub fn smooth(inside: &DenseBits, grid: &GridSpec, at: Smooth<'_>, stop: &Stop) -> Option<TriMesh> {
    whole(|each| smooth_parts(inside, grid, at, u32::MAX, stop, each))
}

/// [`smooth`], handed to `each` slab by slab, `thickness` layers of voxel
/// centres a slab (see [`Part`]): only a slab's lattice ends and vertices
/// are held at once. `Ok(None)` when `stop` was requested.
pub fn smooth_parts<E>(
    inside: &DenseBits,
    grid: &GridSpec,
    at: Smooth<'_>,
    thickness: u32,
    stop: &Stop,
    each: Parts<'_, E>,
) -> Result<Option<()>, E> {
    tets::extract_slabs(inside, thickness, stop, |s| {
        let positions = smooth_positions(&s.crossings, grid, at);
        each(Part { first_vertex: s.first_vertex, positions, triangles: s.triangles })
    })
}

/// The smooth vertices on `crossings` (see [`smooth`]).
fn smooth_positions(crossings: &[([i64; 3], [i64; 3])], grid: &GridSpec, at: Smooth<'_>) -> Vec<DVec3> {
    let centre = |p: [i64; 3]| grid.origin() + (DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) + 0.5) * grid.voxel_size().0;
    // Every end once: inside ends come grouped (crossings are in order of
    // them), outside ends are sorted out; runs of neighbours share bounds.
    let mut ends: Vec<[i64; 3]> = crossings.iter().flat_map(|(a, b)| [*a, *b]).collect();
    ends.par_sort_unstable_by_key(|p| [p[2], p[1], p[0]]);
    ends.dedup();
    let dist: Vec<f64> = ends
        .par_chunks(256)
        .flat_map_iter(|chunk| {
            let mut best = (f64::INFINITY, u32::MAX);
            chunk.iter().map(move |&p| {
                let q = centre(p);
                // The previous end's nearest piece bounds this search.
                let bound = if best.1 == u32::MAX { best } else { (at.pieces.items[best.1 as usize].distance_squared(q), best.1) };
                best = at.tree.nearest(q, bound);
                best.0.sqrt()
            })
        })
        .collect();
    let d = |p: &[i64; 3]| dist[ends.binary_search_by_key(&[p[2], p[1], p[0]], |e| [e[2], e[1], e[0]]).expect("every end is listed")];
    crossings
        .par_iter()
        .map(|(a, b)| {
            // The inside end's value ≤ 0, the outside end's ≥ 0.
            let (fa, fb) = match at.offset {
                None => (-d(a), d(b)),
                Some(r) => ((d(a) - r).min(0.0), (d(b) - r).max(0.0)),
            };
            let t = if fb > fa { -fa / (fb - fa) } else { 0.5 };
            let (pa, pb) = (centre(*a), centre(*b));
            let margin = if at.offset.is_some() { WRAP_MARGIN } else { MARGIN };
            pa + (pb - pa) * t.clamp(margin, 1.0 - margin)
        })
        .collect()
}

/// Wrap's inside voxels: `solid`, `cover` grown by one voxel (26
/// neighbours), and every voxel they enclose. The grown cover puts every
/// point of every cover voxel's box strictly inside the extracted
/// surface, whichever surface, so the shell contains the whole input.
pub fn wrap(solid: &DenseBits, cover: &DenseBits) -> DenseBits {
    let mut shell = dilate(cover);
    shell.or_assign(solid);
    flood_fill(&shell).0
}

/// `bits` without its parts (26-connected components) of fewer than `min`
/// voxels, with how many parts were kept and dropped (`bits` itself, not a
/// copy, when none is dropped).
pub fn drop_small_parts(bits: DenseBits, min: u64) -> (DenseBits, u64, u64) {
    let runs = Runs::of(&bits, true);
    // Labels are each component's smallest run index.
    let (label, count) = components(&runs, Connectivity::TwentySix);
    let mut size = vec![0u64; runs.len()];
    for (n, &l) in label.iter().enumerate() {
        size[l as usize] += (runs.end[n] - runs.start[n] + 1) as u64;
    }
    let keep: Vec<bool> = size.iter().map(|&s| s >= min).collect();
    let kept = (0..runs.len()).filter(|&n| label[n] as usize == n && keep[n]).count() as u64;
    if kept == count as u64 {
        return (bits, kept, 0);
    }
    let mut out = DenseBits::new(bits.dims());
    for (r, row) in out.rows_mut().enumerate() {
        for n in runs.row_start[r] as usize..runs.row_start[r + 1] as usize {
            if keep[label[n] as usize] {
                DenseBits::fill_row(row, runs.start[n], runs.end[n]);
            }
        }
    }
    (out, kept, count as u64 - kept)
}

/// Every voxel within one step (26 neighbours) of a set voxel.
pub fn dilate(bits: &DenseBits) -> DenseBits {
    let [_, ny, nz] = bits.dims();
    let w = bits.words_per_row();
    let mut out = DenseBits::new(bits.dims());
    out.par_rows_mut().enumerate().for_each(|(r, row)| {
        let (j, k) = ((r % ny as usize) as i64, (r / ny as usize) as i64);
        for dk in -1..=1i64 {
            for dj in -1..=1i64 {
                let (jj, kk) = (j + dj, k + dk);
                if !(0..ny as i64).contains(&jj) || !(0..nz as i64).contains(&kk) {
                    continue;
                }
                let start = (kk as usize * ny as usize + jj as usize) * w;
                let src = &bits.words()[start..start + w];
                for (n, word) in row.iter_mut().enumerate() {
                    let [me, left, right] = row_words(src, n);
                    *word |= me | left | right;
                }
            }
        }
    });
    out.clear_padding();
    out
}

/// Word `n` of bit row `r` and of the row shifted one voxel either way:
/// bit `i` of each says whether voxel `i`, `i − 1` and `i + 1` is set
/// (outside the row: clear).
fn row_words(r: &[u64], n: usize) -> [u64; 3] {
    let lower = if n > 0 { r[n - 1] >> 63 } else { 0 };
    let upper = if n + 1 < r.len() { r[n + 1] << 63 } else { 0 };
    [r[n], r[n] << 1 | lower, r[n] >> 1 | upper]
}

/// Each voxel split in two along each axis (8 half-voxels of its label).
pub fn refine(bits: &DenseBits) -> DenseBits {
    let [nx, ny, nz] = bits.dims();
    let mut out = DenseBits::new([2 * nx, 2 * ny, 2 * nz]);
    let w = out.words_per_row();
    out.par_rows_mut().enumerate().for_each(|(r, row)| {
        let (j, k) = ((r % (2 * ny as usize)) as u32 / 2, (r / (2 * ny as usize)) as u32 / 2);
        let start = (k as usize * ny as usize + j as usize) * bits.words_per_row();
        let src = &bits.words()[start..start + bits.words_per_row()];
        for (n, word) in row.iter_mut().enumerate().take(w) {
            // Output bits 64n..64n+63 are input bits 32n..32n+31, each twice.
            let half = (src[n / 2] >> (32 * (n % 2))) as u32;
            *word = spread(half) * 3;
        }
    });
    out
}

/// The 32 bits of `x` spread to the even bits of a word.
fn spread(x: u32) -> u64 {
    let mut v = x as u64;
    v = (v | v << 16) & 0x0000_FFFF_0000_FFFF;
    v = (v | v << 8) & 0x00FF_00FF_00FF_00FF;
    v = (v | v << 4) & 0x0F0F_0F0F_0F0F_0F0F;
    v = (v | v << 2) & 0x3333_3333_3333_3333;
    (v | v << 1) & 0x5555_5555_5555_5555
}

#[cfg(test)]
mod tests;
