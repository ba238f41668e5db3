//! `voxkit convert IN OUT`: a voxel file in another voxel format.

use anyhow::{bail, Context, Result};
use serde_json::json;
use voxkit::glam::DVec3;
use voxkit::GridSpec;

use crate::args::ConvertArgs;
use crate::plan;

pub fn run(a: &ConvertArgs) -> Result<()> {
    let to_mesh = a.format.as_deref() == Some("obj")
        || (a.format.is_none() && a.output.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("obj")));
    if to_mesh {
        return mesh_of_voxels(a);
    }
    let format = plan::output_format(a.format.as_deref(), &a.output)?;
    crate::commands::voxelize::check_output_dir(&a.output)?;
    let loaded = voxkit_io::read_voxels(&a.input)?;
    let dims = loaded.bits.dims();
    let (grid, source) = placement(a, &loaded)?;
    voxkit_io::write_voxels(&a.output, format, &loaded.bits, &grid)?;
    let voxels = loaded.bits.count();
    if a.json {
        let o = grid.origin();
        let v = json!({"input": a.input, "output": a.output, "format": format.name(), "dims": dims, "voxels": voxels,
            "origin": [o.x, o.y, o.z], "voxel_size": grid.voxel_size(), "grid_from": source});
        return crate::print_stdout(&v.to_string());
    }
    crate::print_stdout(&format!(
        "convert: {voxels} voxels on a {}x{}x{} grid (placement from the {source}) -> {}",
        dims[0],
        dims[1],
        dims[2],
        a.output.display()
    ))
}

/// `convert VOXELS out.obj`: the greedy mesh of the voxels' boundary.
fn mesh_of_voxels(a: &ConvertArgs) -> Result<()> {
    crate::commands::voxelize::check_output_dir(&a.output)?;
    let loaded = voxkit_io::read_voxels(&a.input)?;
    let (grid, source) = placement(a, &loaded)?;
    let quads = voxkit::export::greedy::greedy_quads(&loaded.bits);
    let vertices = voxkit_io::voxel_mesh::write_quads_obj(&a.output, &quads, &grid)?;
    if a.json {
        let v = json!({"input": a.input, "output": a.output, "format": "obj", "voxels": loaded.bits.count(), "quads": quads.len(),
            "vertices": vertices, "grid_from": source});
        return crate::print_stdout(&v.to_string());
    }
    crate::print_stdout(&format!(
        "convert: {} voxels -> {} greedy quads, {vertices} vertices -> {}",
        loaded.bits.count(),
        quads.len(),
        a.output.display()
    ))
}

/// The grid: what the input records, else the options, else unit voxels at the origin.
fn placement(a: &ConvertArgs, loaded: &voxkit_io::LoadedVoxels) -> Result<(GridSpec, &'static str)> {
    let dims = loaded.bits.dims();
    let (origin, size, source) = match (loaded.placement, &a.origin, a.voxel_size) {
        (Some((o, s)), None, None) => (o, s, "input"),
        (placement, o, s) => {
            let origin = match o {
                Some(v) if v.len() == 3 => DVec3::new(v[0], v[1], v[2]),
                Some(_) => bail!("--origin takes three comma-separated values X,Y,Z"),
                None => placement.map(|p| p.0).unwrap_or(DVec3::ZERO),
            };
            let size = s.or(placement.map(|p| p.1)).unwrap_or(1.0);
            (origin, size, "options")
        }
    };
    Ok((GridSpec::new(origin, size, dims.map(u64::from)).context("invalid grid")?, source))
}
