//! The export options of `voxelize` and `convert` (the writing itself is
//! `topovox_job::output::write`).

use std::path::Path;

use anyhow::Result;
use topovox_io::orient::Up;
use topovox_io::schem::BlockPalette;
use topovox_io::WriteOptions;
use topovox_job::output::{MeshKind, Output};

use crate::args::{ColourRule, ExportArgs};

/// The core's colour rule for `--colour-rule`.
pub fn colour_rule(r: ColourRule) -> topovox::attributes::ColourRule {
    match r {
        ColourRule::Dominant => topovox::attributes::ColourRule::Dominant,
        ColourRule::Blend => topovox::attributes::ColourRule::Blend,
    }
}

/// Checks the export options that name files (before any work is done).
pub fn writer_options(e: &ExportArgs) -> Result<WriteOptions> {
    let blocks = e.block_palette.as_deref().map(BlockPalette::read).transpose()?;
    Ok(WriteOptions {
        dither: e.dither,
        blocks,
        up: up(e),
        mesh: topovox_io::voxel_mesh::MeshOptions { watertight: e.watertight.as_deref() != Some("off"), triangulate: e.triangulate },
        // Ctrl-C ends the process (see main.rs), removing its temporaries.
        stop: None,
    })
}

/// `--up` (default y).
pub fn up(e: &ExportArgs) -> Up {
    e.up.as_deref().and_then(Up::from_name).unwrap_or_default()
}

/// Warns, before any work, about export options that do nothing for this
/// output (`from_mesh`: the voxels come from a mesh, so colours can be
/// carried; `up_used`: `--up` also serves the input or a preview), and
/// about an extension that names another format.
pub fn warn_unused(e: &ExportArgs, format: Output, output: &Path, from_mesh: bool, up_used: bool) {
    use topovox_io::VoxelFormat as F;
    let name = format.name();
    let mut unused = Vec::new();
    if e.dither && format != Output::Voxels(F::Vox) {
        unused.push("--dither (for .vox)");
    }
    if e.block_palette.is_some() && format != Output::Voxels(F::Schem) {
        unused.push("--block-palette (for .schem)");
    }
    if e.up.is_some() && !up_used && !matches!(format, Output::Voxels(F::Vox | F::Schem)) {
        unused.push("--up (for .vox and .schem)");
    }
    if (e.watertight.is_some() || e.triangulate) && !matches!(format, Output::Mesh(_)) {
        unused.push("--watertight and --triangulate (for .obj and .glb)");
    }
    if e.triangulate && format == Output::Mesh(MeshKind::Glb) {
        unused.push("--triangulate (.glb is always triangles)");
    }
    if e.normals && (!from_mesh || format != Output::Voxels(F::Vti)) {
        unused.push(if from_mesh { "--normals (for .vti)" } else { "--normals (normals come from a mesh)" });
    }
    if e.attributes && (!from_mesh || !matches!(format, Output::Voxels(F::Vdb | F::Zarr))) {
        unused.push(if from_mesh {
            "--attributes (for .vdb and .zarr)"
        } else {
            "--attributes (attributes come from a mesh; convert writes those the input has)"
        });
    }
    if e.colour_rule != ColourRule::Dominant && (!from_mesh || !format.has_colour()) {
        unused.push(if from_mesh { "--colour-rule (for coloured formats)" } else { "--colour-rule (colours come from a mesh)" });
    }
    for u in unused {
        eprintln!("topovox: warning: {u} does nothing for {name} output; ignored");
    }
    if let Some(ext) = output.extension().and_then(|x| x.to_str()) {
        if let Some(by_ext) = Output::from_name(ext) {
            if by_ext.name().trim_end_matches("-bool") != name.trim_end_matches("-bool") {
                eprintln!("topovox: warning: {}: writing {name} (--format) into a file whose extension says {ext}", output.display());
            }
        }
    }
}
