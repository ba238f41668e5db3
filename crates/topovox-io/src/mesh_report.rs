//! A loaded mesh with its report and warnings, and the validation every
//! reader ends with.

use glam::DVec3;
use rayon::prelude::*;
use topovox::attributes::Appearance;
use topovox::{Aabb, Mesh};

use crate::error::ErrorKind;

/// Facts about a loaded mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshReport {
    /// Vertices.
    pub vertices: usize,
    /// Triangles (after fan triangulation of polygons).
    pub triangles: usize,
    /// Triangles with repeated indices or zero area; voxelizers skip them.
    pub degenerate: usize,
    /// Line segments (polyline input).
    pub segments: usize,
    /// Bounding box of the vertices used by triangles and segments.
    pub bounds: Aabb,
}

/// A mesh as read from a file.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    /// The geometry.
    pub mesh: Mesh,
    /// Counts and bounds.
    pub report: MeshReport,
    /// Non-fatal problems (for example a missing material library).
    pub warnings: Vec<String>,
    /// Materials, textures, UVs and vertex colours, aligned with the
    /// triangles and vertices of `mesh` (empty lists where the file has none).
    pub appearance: Appearance,
    /// The files it was read from: the mesh file and every file it named
    /// that was read (material libraries, textures, buffers), resolved.
    /// Writers refuse to write over any of them.
    pub sources: Vec<std::path::PathBuf>,
}

/// Validates and packages reader output: every coordinate finite and
/// within ±[`topovox::COORDINATE_LIMIT`], every index in range, at least
/// one triangle.
pub(crate) fn finish(positions: Vec<DVec3>, triangles: Vec<[i64; 3]>, warnings: Vec<String>) -> Result<LoadedMesh, ErrorKind> {
    finish_with_segments(positions, triangles, Vec::new(), warnings)
}

/// A mesh built by a caller from arrays (the Python package's numpy input),
/// validated as every reader's output is: every coordinate finite, every
/// index in range, at least one triangle or segment.
pub fn validate_mesh(positions: Vec<DVec3>, triangles: Vec<[i64; 3]>, segments: Vec<[i64; 2]>) -> Result<LoadedMesh, ErrorKind> {
    finish_with_segments(positions, triangles, segments, Vec::new())
}

/// [`finish`] for input that may carry line segments: at least one
/// triangle or segment.
pub(crate) fn finish_with_segments(
    positions: Vec<DVec3>,
    triangles: Vec<[i64; 3]>,
    segments: Vec<[i64; 2]>,
    warnings: Vec<String>,
) -> Result<LoadedMesh, ErrorKind> {
    // In parallel for large meshes; the first bad vertex is named, as a sequential pass would.
    let bad_vertex = |p: &DVec3| !topovox::in_range(*p);
    let first_bad = if positions.len() < PARALLEL_ITEMS {
        positions.iter().position(bad_vertex)
    } else {
        positions.par_iter().position_first(bad_vertex)
    };
    if let Some(index) = first_bad {
        let p = positions[index].to_array();
        return Err(match p.iter().find(|c| !c.is_finite()) {
            Some(&value) => ErrorKind::NonFinite { index, value },
            None => ErrorKind::OutOfRange { index, value: *p.iter().find(|c| c.abs() > topovox::COORDINATE_LIMIT).expect("out of range") },
        });
    }
    let count = positions.len();
    let tris = checked_indices(&triangles, count, |face, index| ErrorKind::IndexOutOfRange { face, index, count })?;
    let segs = checked_indices(&segments, count, |line, index| ErrorKind::SegmentIndexOutOfRange { line, index, count })?;
    if tris.is_empty() && segs.is_empty() {
        return Err(ErrorKind::Empty);
    }
    let mesh = Mesh { positions, triangles: tris, segments: segs };
    let (bounds, degenerate) = mesh.as_ref().bounds_and_degenerate_count();
    let report = MeshReport { vertices: count, triangles: mesh.triangles.len(), degenerate, segments: mesh.segments.len(), bounds };
    // A warning may quote the file (a material library's name): never at length.
    let warnings = warnings.iter().map(|w| crate::error::cut(w, crate::error::MAX_MESSAGE)).collect();
    Ok(LoadedMesh { mesh, report, warnings, appearance: Appearance::default(), sources: Vec::new() })
}

/// Converts index tuples to `u32`, or the error `bad(element, index)` for
/// the first index outside `0..count`.
fn checked_indices<const N: usize>(
    items: &[[i64; N]],
    count: usize,
    bad: impl Fn(usize, i64) -> ErrorKind,
) -> Result<Vec<[u32; N]>, ErrorKind> {
    let out_of_range = |i: &i64| *i < 0 || *i as usize >= count;
    // One pass narrows and checks; only a refused mesh is looked at again, for its first bad index.
    let narrow = |t: &[i64; N]| if t.iter().any(out_of_range) { None } else { Some(t.map(|i| i as u32)) };
    let narrowed: Option<Vec<[u32; N]>> =
        if items.len() < PARALLEL_ITEMS { items.iter().map(narrow).collect() } else { items.par_iter().map(narrow).collect() };
    narrowed.ok_or_else(|| {
        let e = items.iter().position(|t| t.iter().any(out_of_range)).expect("a refused item");
        bad(e, *items[e].iter().find(|i| out_of_range(i)).expect("an index out of range"))
    })
}

/// Items from which the checks run on all threads (below, waking the
/// thread pool costs more than the pass).
const PARALLEL_ITEMS: usize = 1 << 15;

/// Fan-triangulates a polygon given by vertex indices: (0,1,2), (0,2,3), …
pub(crate) fn fan(poly: &[i64], out: &mut Vec<[i64; 3]>) {
    for w in 1..poly.len().saturating_sub(1) {
        out.push([poly[0], poly[w], poly[w + 1]]);
    }
}
