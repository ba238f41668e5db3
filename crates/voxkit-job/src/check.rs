//! Certifying voxels against their mesh (`voxkit check`): which grid they
//! are on, and the report as one JSON object.

use serde_json::{json, Value};
use voxkit::topology::certify;
use voxkit::{DenseBits, GridSpec, MeshRef};

use crate::error::{JobError, Result};
use crate::grid::{GridOptions, GridRequest};

/// The grid to check voxels of `dims` against a mesh with `bounds` on:
/// the grid options if any were given, else the placement the voxel file
/// records, else the fitted grid at resolution = the largest dimension.
/// Returns the grid and where it came from (`options`, `file`, `inferred`).
pub fn check_grid(
    dims: [u32; 3],
    placement: Option<(glam::DVec3, f64)>,
    options: &GridOptions,
    bounds: &voxkit::Aabb,
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
/// where the grid came from): the report `voxkit check --json` prints,
/// without the timing.
pub fn report(bits: &DenseBits, mesh: Option<(MeshRef<'_>, &GridSpec, &str)>) -> Result<Value> {
    let report = certify(bits, mesh.map(|(m, g, _)| (m, g))).map_err(|e| JobError::invalid(e.to_string()))?;
    let facts = report.mesh.as_ref();
    let sep = facts.and_then(|f| f.separation.as_ref());
    let witness = |w: Option<[[u32; 3]; 2]>| w.map(|p| json!({"inside": p[0], "outside": p[1]}));
    Ok(json!({
        "voxels": report.voxels,
        "dims": bits.dims(),
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
        "grid": mesh.map(|(_, g, source)| {
            let o = g.origin();
            json!({"origin": [o.x, o.y, o.z], "voxel_size": g.voxel_size(), "dims": g.dims(), "source": source})
        }),
    }))
}
