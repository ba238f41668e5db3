//! The export options of `voxelize` and `convert` (the writing itself is
//! `voxkit_job::output::write`).

use anyhow::Result;
use voxkit_io::schem::BlockPalette;
use voxkit_io::WriteOptions;

use crate::args::{ColourRule, ExportArgs};

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
