//! `voxkit convert IN OUT`: a voxel file in another voxel format.

use anyhow::{bail, Context, Result};
use serde_json::json;
use voxkit::glam::DVec3;
use voxkit::GridSpec;

use crate::args::ConvertArgs;

pub fn run(a: &ConvertArgs) -> Result<()> {
    let format = voxkit_job::output::output_format(a.format.as_deref(), &a.output)?;
    voxkit_job::output::check_output_path(&a.output)?;
    voxkit_job::output::refuse_overwriting(&a.output, format, std::slice::from_ref(&a.input))?;
    let write_opts = crate::commands::export::writer_options(&a.export)?;
    let input_has_up =
        matches!(voxkit_io::VoxelFormat::from_path(&a.input), Some(voxkit_io::VoxelFormat::Vox | voxkit_io::VoxelFormat::Schem));
    crate::commands::export::warn_unused(&a.export, format, &a.output, false, input_has_up);
    // The up axis is the data's: .vox and .schem files are read back with it too.
    let loaded = voxkit_io::read_voxels_with(&a.input, crate::commands::export::up(&a.export))?;
    let dims = loaded.bits.dims();
    let (grid, source) = placement(a, &loaded)?;
    let facts = voxkit_job::output::write(&a.output, format, &loaded.bits, &grid, loaded.attributes.as_ref(), &write_opts)?;
    let voxels = loaded.bits.count();
    if a.json {
        let o = grid.origin();
        let v = json!({"input": a.input, "output": a.output, "format": format.name(), "dims": dims, "voxels": voxels,
            "origin": [o.x, o.y, o.z], "voxel_size": grid.voxel_size(), "grid_from": source, "export": facts});
        return crate::print_stdout(&v.to_string());
    }
    let what = match (facts.get("quads"), facts.get("vertices")) {
        (Some(q), Some(v)) => format!(" as {q} greedy quads, {v} vertices"),
        _ => String::new(),
    };
    crate::print_stdout(&format!(
        "convert: {voxels} voxels on a {}x{}x{} grid (placement from the {source}){what} -> {}",
        dims[0],
        dims[1],
        dims[2],
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
