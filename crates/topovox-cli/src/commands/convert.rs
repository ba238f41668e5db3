//! `topovox convert IN OUT`: a voxel file in another voxel format.

use anyhow::{bail, Context, Result};
use serde_json::json;
use topovox::glam::DVec3;
use topovox::GridSpec;

use crate::args::ConvertArgs;

pub fn run(a: &ConvertArgs) -> Result<()> {
    let format = topovox_job::output::output_format(a.format, &a.output)?;
    topovox_job::output::check_output_path(&a.output)?;
    topovox_job::output::refuse_overwriting(&a.output, format, std::slice::from_ref(&a.input))?;
    let job = &a.export.options;
    let write_opts = job.write_options()?;
    use topovox_io::VoxelFormat as F;
    let input_format = F::from_path(&a.input);
    let input_has_up = matches!(input_format, Some(F::Vox | F::Schem));
    crate::export::warn_unused(job, &a.export.given, format, &a.output, false, input_has_up);
    // The up axis is the data's: .vox and .schem files are read back with it too.
    let loaded = match topovox_io::read_voxels(
        &a.input,
        &topovox_io::ReadOptions { up: job.up, allow_external_paths: a.allow_external_paths, ..Default::default() },
    ) {
        Ok(l) => l,
        // A .vdb or .zarr grid past memory, to a format that holds only the
        // set voxels: read and written without a dense grid.
        Err(e) if matches!(e.kind, topovox_io::ErrorKind::TooLarge { .. }) && topovox_job::output::is_sparse(format) => {
            let sparse = match topovox_io::read_voxels_sparse(
                &a.input,
                &topovox_io::ReadOptions { attributes: false, allow_external_paths: a.allow_external_paths, ..Default::default() },
            ) {
                Ok(s) => s,
                // Formats read only densely: the grid's size is the error.
                Err(s) if matches!(s.kind, topovox_io::ErrorKind::Unsupported(_)) && !input_format.is_some_and(F::reads_sparsely) => {
                    return Err(e.into())
                }
                Err(s) => return Err(s.into()),
            };
            // Attributes the output stores are read too (a second pass over
            // the file, at the set voxels only) while they fit in memory.
            let wanted = format.has_colour() || topovox_job::every_attribute(format, true);
            let need = sparse.bits.count().saturating_mul(topovox_job::ATTRIBUTE_BYTES_PER_VOXEL);
            let attributes = if sparse.attributes_left && wanted {
                if need <= topovox_job::budget(None) {
                    topovox_io::read_voxels_sparse(
                        &a.input,
                        &topovox_io::ReadOptions { attributes: true, allow_external_paths: a.allow_external_paths, ..Default::default() },
                    )?
                    .attributes
                } else {
                    eprintln!(
                        "topovox: warning: {}: its attributes are not carried: they would need {} of memory",
                        a.input.display(),
                        topovox_job::bytes(need)
                    );
                    None
                }
            } else {
                None
            };
            return finish(a, format, &sparse.bits, sparse.placement, attributes.as_ref(), &write_opts, true);
        }
        Err(e) if matches!(e.kind, topovox_io::ErrorKind::TooLarge { .. }) && input_format.is_some_and(F::reads_sparsely) => {
            bail!("{e}; {} is a dense format: convert it to .vdb, .zarr, .npz, .txt or .ply, which need no dense grid", format.name())
        }
        Err(e) => return Err(e.into()),
    };
    finish(a, format, &loaded.bits, loaded.placement, loaded.attributes.as_ref(), &write_opts, false)
}

/// Writes the voxels read (`sparse`: without a dense grid) and prints the summary.
fn finish(
    a: &ConvertArgs,
    format: topovox_job::output::Output,
    bits: &dyn topovox::VoxelSource,
    recorded: Option<(DVec3, DVec3)>,
    attributes: Option<&topovox::attributes::VoxelAttributes>,
    write_opts: &topovox_io::WriteOptions,
    sparse: bool,
) -> Result<()> {
    let dims = bits.dims();
    let (grid, source) = placement(a, dims, recorded)?;
    let facts = topovox_job::output::write(&a.output, format, bits, &grid, attributes, write_opts)?;
    let voxels = bits.count();
    if a.json {
        let o = grid.origin();
        let v = json!({"input": a.input, "output": a.output, "format": format.name(), "dims": dims, "voxels": voxels,
            "origin": [o.x, o.y, o.z], "voxel_size": topovox_io::size_json(grid.voxel_size()), "grid_from": source, "export": facts, "sparse": sparse});
        return crate::console::print_stdout(&v.to_string());
    }
    if a.quiet {
        return Ok(());
    }
    let what = match (facts.get("quads"), facts.get("vertices")) {
        (Some(q), Some(v)) => format!(" as {q} greedy quads, {v} vertices"),
        _ => String::new(),
    };
    crate::console::print_stdout(&format!(
        "convert: {voxels} voxels on a {}x{}x{} grid (placement from the {source}){what} -> {}",
        dims[0],
        dims[1],
        dims[2],
        a.output.display()
    ))
}

/// The grid: what the input records, else the options, else unit voxels at the origin.
fn placement(a: &ConvertArgs, dims: [u32; 3], recorded: Option<(DVec3, DVec3)>) -> Result<(GridSpec, &'static str)> {
    let (origin, size, source) = match (recorded, &a.origin, a.voxel_size.map(|s| s.0)) {
        (Some((o, s)), None, None) => (o, s, "input"),
        (placement, o, s) => {
            let origin = match o {
                Some(v) if v.len() == 3 => DVec3::new(v[0], v[1], v[2]),
                Some(_) => bail!("--origin takes three comma-separated values X,Y,Z"),
                None => placement.map(|p| p.0).unwrap_or(DVec3::ZERO),
            };
            let size = s.or(placement.map(|p| p.1)).unwrap_or(DVec3::ONE);
            (origin, size, "options")
        }
    };
    Ok((GridSpec::new(origin, size, dims.map(u64::from)).context("invalid grid")?, source))
}
