//! Writing a voxel result with its attributes: every voxel format, and the
//! mesh of the voxels (`.obj`, `.glb`). Shared by `voxelize` and `convert`.

use std::path::Path;

use anyhow::Result;
use serde_json::{json, Value};
use voxkit::attributes::{quantize, VoxelAttributes};
use voxkit::export::greedy::greedy_quads_by_class;
use voxkit::{DenseBits, GridSpec, VoxelSource};
use voxkit_io::schem::BlockPalette;
use voxkit_io::WriteOptions;

use crate::args::{ColourRule, ExportArgs};
use crate::plan::{MeshKind, Output};

/// The core's colour rule for `--colour-rule`.
pub fn colour_rule(r: ColourRule) -> voxkit::attributes::ColourRule {
    match r {
        ColourRule::Dominant => voxkit::attributes::ColourRule::Dominant,
        ColourRule::Blend => voxkit::attributes::ColourRule::Blend,
    }
}

/// Checks the export options that name files (before any work is done).
pub fn writer_options(e: &ExportArgs) -> Result<WriteOptions> {
    let blocks = e.block_palette.as_deref().map(BlockPalette::read).transpose()?;
    Ok(WriteOptions { dither: e.dither, blocks })
}

/// Writes `bits` (with `attrs`) to `out`; returns facts for `--json`.
pub fn write(
    out: &Path,
    target: Output,
    bits: &dyn VoxelSource,
    grid: &GridSpec,
    attrs: Option<&VoxelAttributes>,
    opts: &WriteOptions,
) -> Result<Value> {
    match target {
        Output::Voxels(f) => {
            voxkit_io::write_voxels_with(out, f, bits, grid, attrs, opts)?;
            Ok(json!({"colours": attrs.and_then(|a| a.colour.as_ref()).is_some() && f.has_colour()}))
        }
        Output::Mesh(kind) => {
            let mut dense = DenseBits::new(bits.dims());
            bits.for_each_set(&mut |i, j, k| dense.set(i, j, k));
            let coloured = attrs.and_then(|a| a.colour.as_ref().map(|c| (a, c)));
            let (palette, quads) = match coloured {
                Some((a, colours)) => {
                    let palette = quantize::palette(colours, 255);
                    let index = quantize::map_to_palette(colours, &palette);
                    let class = move |i: u32, j: u32, k: u32| a.slot(i, j, k).map(|s| index[s] as u32 + 1).unwrap_or(0);
                    (Some(palette), greedy_quads_by_class(&dense, &class))
                }
                None => (None, voxkit::export::greedy::greedy_quads(&dense)),
            };
            let vertices = match kind {
                MeshKind::Obj => voxkit_io::voxel_mesh::write_quads_obj(out, &quads, grid, palette.as_deref())?,
                MeshKind::Glb => voxkit_io::voxel_mesh::write_quads_glb(out, &quads, grid, palette.as_deref())?,
            };
            Ok(json!({"quads": quads.len(), "vertices": vertices, "colours": palette.as_ref().map(|p| p.len())}))
        }
    }
}
