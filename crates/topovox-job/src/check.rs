//! Certifying voxels against their mesh (`topovox check`): which grid they
//! are on, and the report as one JSON object.

use serde_json::{json, Value};
use topovox::grid::sparse::SparseBricks;
use topovox::topology::{certify, certify_sparse, CheckReport};
use topovox::{DenseBits, GridSpec, MeshRef};

use topovox::mesh_check::{check_mesh, MeshCheck, MeshCheckError};
use topovox::voxelize::Stop;

use crate::error::{JobError, Result};
use crate::grid::{GridOptions, GridRequest};

/// The grid to check voxels of `dims` against a mesh with `bounds` on:
/// the grid options if any were given, else the placement the voxel file
/// records, else the fitted grid at resolution = the largest dimension.
/// Returns the grid and where it came from (`options`, `file`, `inferred`).
pub fn check_grid(
    dims: [u32; 3],
    placement: Option<(glam::DVec3, glam::DVec3)>,
    options: &GridOptions,
    bounds: &topovox::Aabb,
    voxels_name: &str,
    mesh_name: &str,
) -> Result<(GridSpec, &'static str)> {
    let (grid, source) = if options.any() {
        (GridRequest::new(options)?.fit(bounds)?, "options")
    } else if let Some((origin, s)) = placement {
        (
            GridSpec::new(origin, s, dims.map(u64::from)).map_err(|e| JobError::invalid(format!("invalid grid in the voxel file: {e}")))?,
            "file",
        )
    } else {
        let n = *dims.iter().max().unwrap_or(&1) as u64;
        (GridSpec::from_resolution(bounds, n).map_err(|e| JobError::invalid(format!("invalid grid: {e}")))?, "inferred")
    };
    if grid.dims() != dims {
        let [x, y, z] = grid.dims();
        return Err(JobError::invalid(format!(
            "{voxels_name}: holds a {}x{}x{} grid but the {} grid for {mesh_name} is {x}x{y}x{z}; pass the grid options used to voxelize it",
            dims[0],
            dims[1],
            dims[2],
            if source == "inferred" { "fitted" } else { source },
        )));
    }
    Ok((grid, source))
}

/// Certifies `bits` (with the mesh and its grid, if given; `source` says
/// where the grid came from): the report `topovox check --json` prints,
/// without the timing.
pub fn report(bits: &DenseBits, mesh: Option<(MeshRef<'_>, &GridSpec, &str)>) -> Result<Value> {
    let report = certify(bits, mesh.map(|(m, g, _)| (m, g))).map_err(|e| JobError::invalid(e.to_string()))?;
    let mut v = to_json(&report, bits.dims(), mesh.map(|(_, g, s)| (g, s)));
    v["sparse"] = json!(false);
    Ok(v)
}

/// Brick layers (8 planes each) per window of [`report_sparse`] for a grid
/// of `dims` within `budget` bytes: a window's brick index, parity and
/// run rows take about `bx·by·4 + 80·ny` bytes per layer; a quarter of the
/// budget goes to them (the rest to the grid's bricks and the mesh), and
/// at most [`WINDOW_BYTES`]: larger windows save nothing but memory (the
/// work follows the voxels and rows, not the windows).
pub fn window_layers(dims: [u32; 3], budget: u64) -> u32 {
    let per_layer = dims[0].div_ceil(8) as u64 * dims[1].div_ceil(8) as u64 * 4 + 80 * dims[1] as u64;
    ((budget / 4).min(WINDOW_BYTES) / per_layer.max(1)).clamp(1, dims[2].div_ceil(8).max(1) as u64) as u32
}

/// Most bytes a window's index and rows take (see [`window_layers`]).
pub const WINDOW_BYTES: u64 = 512 << 20;

/// [`report`] for a grid held as sparse bricks, checked window by window
/// ([`topovox::topology::certify_sparse`]) in windows of `layers` brick
/// layers; the report is the same, with `sparse` true and the number of
/// windows.
pub fn report_sparse(bits: &SparseBricks, mesh: Option<(MeshRef<'_>, &GridSpec, &str)>, layers: u32) -> Result<Value> {
    let report = certify_sparse(bits, mesh.map(|(m, g, _)| (m, g)), layers).map_err(|e| JobError::invalid(e.to_string()))?;
    let mut v = to_json(&report, bits.dims(), mesh.map(|(_, g, s)| (g, s)));
    v["sparse"] = json!(true);
    v["windows"] = json!(topovox::topology::certify::sparse_windows(bits.dims(), layers));
    Ok(v)
}

fn to_json(report: &CheckReport, dims: [u32; 3], grid: Option<(&GridSpec, &str)>) -> Value {
    let facts = report.mesh.as_ref();
    let sep = facts.and_then(|f| f.separation.as_ref());
    let witness = |w: Option<[[u32; 3]; 2]>| w.map(|p| json!({"inside": p[0], "outside": p[1]}));
    json!({
        "voxels": report.voxels,
        "dims": dims,
        "components_6": report.components_6,
        "components_26": report.components_26,
        "thick_voxels": report.thick_voxels,
        "closed": facts.map(|f| f.closed),
        "boundary_edges": facts.map(|f| f.boundary_edges),
        "separating_6": sep.map(|s| s.witness_6.is_none()),
        "separating_26": sep.map(|s| s.witness_26.is_none()),
        "witness_6": sep.and_then(|s| witness(s.witness_6)),
        "witness_26": sep.and_then(|s| witness(s.witness_26)),
        "inside_voxels": sep.map(|s| s.inside_voxels),
        "thin_removable": sep.map(|s| s.thin_removable),
        "tunnels_6": facts.map(|f| f.tunnels_6),
        "tunnels_18": facts.map(|f| f.tunnels_18),
        "tunnels_26": facts.map(|f| f.tunnels_26),
        "tunnel_free_6": facts.map(|f| f.tunnels_6 == 0),
        "tunnel_free_18": facts.map(|f| f.tunnels_18 == 0),
        "tunnel_free_26": facts.map(|f| f.tunnels_26 == 0),
        "columns": facts.map(|f| {
            let c = f.columns;
            json!({"samples": c.samples, "empty": c.empty, "one": c.one, "two": c.two, "three_or_more": c.more, "max": c.max})
        }),
        "grid": grid.map(|(g, source)| {
            let o = g.origin();
            json!({"origin": [o.x, o.y, o.z], "voxel_size": topovox_io::size_json(g.voxel_size()), "dims": g.dims(), "source": source})
        }),
    })
}

topovox::choice! {
    /// A property `topovox check MESH` can require.
    pub enum MeshProperty: "property" default Watertight {
        /// All of the others, and a positive volume (normals outwards).
        Watertight = "watertight",
        /// Every edge has exactly two faces.
        Closed = "closed",
        /// No edge with more than two faces, every vertex's faces one disk.
        Manifold = "manifold",
        /// Every edge's two faces run it in opposite directions.
        Oriented = "oriented",
        /// No two faces meet beyond the vertices and edge they share.
        IntersectionFree = "intersection-free",
        /// No face of zero area.
        NoDegenerate = "no-degenerate",
    }
}

impl MeshProperty {
    /// Whether the certificate has this property.
    pub fn holds(self, c: &MeshCheck) -> bool {
        match self {
            MeshProperty::Watertight => c.watertight(),
            MeshProperty::Closed => c.closed(),
            MeshProperty::Manifold => c.manifold(),
            MeshProperty::Oriented => c.oriented(),
            MeshProperty::IntersectionFree => c.self_intersections == 0,
            MeshProperty::NoDegenerate => c.degenerate_faces == 0,
        }
    }
}

/// The certificate of `mesh` (named `name` in messages); see
/// [`topovox::mesh_check`]. Segments are not faces and are not checked.
pub fn mesh_certificate(mesh: MeshRef<'_>, name: &str, stop: Option<&Stop>) -> Result<MeshCheck> {
    let never = Stop::new();
    check_mesh(mesh.positions, mesh.triangles, stop.unwrap_or(&never)).map_err(|e| match e {
        MeshCheckError::Stopped => JobError::Interrupted,
        e => JobError::invalid(format!("{name}: {e}")),
    })
}

/// A certificate as JSON.
pub fn certificate_json(c: &MeshCheck) -> Value {
    json!({
        "watertight": c.watertight(), "closed": c.closed(), "manifold": c.manifold(), "oriented": c.oriented(),
        "faces": c.faces, "vertices": c.vertices, "edges": c.edges,
        "degenerate_faces": c.degenerate_faces, "boundary_edges": c.boundary_edges,
        "non_manifold_edges": c.non_manifold_edges, "inconsistent_edges": c.inconsistent_edges,
        "non_manifold_vertices": c.non_manifold_vertices, "self_intersections": c.self_intersections,
        "intersecting_pairs": c.intersecting_pairs, "components": c.components, "euler": c.euler,
        "genus": c.genus, "volume": c.volume,
    })
}
