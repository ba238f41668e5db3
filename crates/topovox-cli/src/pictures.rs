//! Pictures of voxels for `render`, `voxelize --preview` and `view`: the
//! picture options, the CPU ray caster's PNGs and the silhouette outline.

use std::path::Path;

use anyhow::{bail, Result};
use topovox::attributes::VoxelAttributes;
use topovox::glam::DVec3;
use topovox::grid::sparse::SparseBricks;
use topovox::render::raycast::{render_grid, render_with, Image, RenderGrid, RenderOptions};
use topovox::{BrickBits, VoxelSource};
use topovox_io::orient::Up;

use crate::args::PictureArgs;

/// The picture options.
pub fn options(p: &PictureArgs, up: Option<Up>) -> Result<RenderOptions> {
    Ok(RenderOptions { width: p.size.width, height: p.size.height, view: p.view, up: up_axis(up), ..RenderOptions::default() })
}

/// The `--up` axis's index (default y).
pub fn up_axis(up: Option<Up>) -> usize {
    match up.unwrap_or_default() {
        Up::X => 0,
        Up::Y => 1,
        Up::Z => 2,
    }
}

/// A mesh's triangles in grid units, for the silhouette outline.
pub fn outline_triangles(mesh: topovox::MeshRef<'_>, grid: &topovox::GridSpec) -> Vec<[DVec3; 3]> {
    mesh.triangles
        .iter()
        .filter_map(|t| {
            let p = [0, 1, 2].map(|c| mesh.positions.get(t[c] as usize).map(|&p| grid.to_grid_units(p)));
            Some([p[0]?, p[1]?, p[2]?])
        })
        .collect()
}

/// Renders `bits` (coloured by `colours` where present, with the outline of
/// `outline`'s triangles) and writes the PNG atomically.
pub fn picture(
    bits: &dyn VoxelSource,
    path: &Path,
    o: &RenderOptions,
    colours: Option<&VoxelAttributes>,
    outline: Option<&[[DVec3; 3]]>,
) -> Result<Image> {
    let bricks = BrickBits::from_source(bits);
    let img = render_with(&bricks, o, colours, outline);
    topovox_io::write_png(path, img.width, img.height, &img.rgb)?;
    Ok(img)
}

/// [`picture`] of a grid held as sparse bricks (past memory), without a
/// dense grid or brick index: the ray caster indexes 64³-voxel blocks.
pub fn picture_sparse(
    bits: &SparseBricks,
    path: &Path,
    o: &RenderOptions,
    colours: Option<&VoxelAttributes>,
    outline: Option<&[[DVec3; 3]]>,
) -> Result<Image> {
    let Some(grid) = RenderGrid::from_sparse(bits) else {
        let [x, y, z] = bits.dims();
        bail!("grid {x}x{y}x{z} is too large to render: its index of 64^3-voxel blocks would pass 1 GiB");
    };
    let img = render_grid(&grid, o, colours, outline);
    topovox_io::write_png(path, img.width, img.height, &img.rgb)?;
    Ok(img)
}

/// Refuses an output that is not a `.png` or whose folder does not exist.
pub fn check_png_path(path: &Path) -> Result<()> {
    if path.extension().and_then(|e| e.to_str()).map(|e| e.eq_ignore_ascii_case("png")) != Some(true) {
        bail!("{}: pictures are written as PNG; give a .png file name", path.display());
    }
    Ok(topovox_job::output::check_output_path(path)?)
}
