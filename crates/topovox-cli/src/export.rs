//! The export options of `voxelize` and `convert` (the writing itself is
//! `topovox_job::output::write`).

use std::path::Path;

use topovox_job::output::{MeshKind, Output};
use topovox_job::{ColourRule, ExportOptions};

/// Warns, before any work, about export options that do nothing for this
/// output (`from_mesh`: the voxels come from a mesh, so colours can be
/// carried; `up_used`: `--up` also serves the input or a preview; `given`:
/// the options given on the command line), and about an extension that
/// names another format.
pub fn warn_unused(e: &ExportOptions, given: &[&str], format: Output, output: &Path, from_mesh: bool, up_used: bool) {
    use topovox_io::VoxelFormat as F;
    let name = format.name();
    let mut unused = Vec::new();
    if e.dither && format != Output::Voxels(F::Vox) {
        unused.push("--dither (for .vox)");
    }
    if e.block_palette.is_some() && format != Output::Voxels(F::Schem) {
        unused.push("--block-palette (for .schem)");
    }
    if given.contains(&"up") && !up_used && !matches!(format, Output::Voxels(F::Vox | F::Schem)) {
        unused.push("--up (for .vox and .schem)");
    }
    if (given.contains(&"watertight") || e.triangulate) && !matches!(format, Output::Mesh(_)) {
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
