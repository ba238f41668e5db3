//! `topovox render`: a PNG picture of a voxel file or of a mesh's voxels,
//! and the picture behind `voxelize --preview`.

use std::time::Instant;

use anyhow::{bail, Context, Result};
use serde_json::json;
use topovox::attributes::carry::{carry, CarryOptions};
use topovox::render::raycast::Image;
use topovox::voxelize::{self, Options};
use topovox::VoxelSource;

use crate::args::RenderArgs;
use crate::pictures::{check_png_path, options, outline_triangles, picture, picture_sparse};
use crate::plan;

#[cfg(feature = "gpu")]
mod gpu;

pub fn run(a: &RenderArgs) -> Result<()> {
    if a.gpu.gpu {
        #[cfg(feature = "gpu")]
        return gpu::run(a);
        #[cfg(not(feature = "gpu"))]
        bail!("--gpu: this topovox was built without the gpu feature");
    }
    let g = &a.gpu;
    if g.camera.is_some()
        || g.frames.is_some()
        || g.repeat != 1
        || g.stats_json.is_some()
        || g.culling != topovox::render::Culling::Occlusion
        || g.prepass.on()
        || !g.gamma.on()
        || g.light_grid.on()
    {
        bail!("--camera, --frames, --repeat, --culling, --prepass, --gamma, --light-grid and --stats-json belong to the GPU renderer; add --gpu");
    }
    let t0 = Instant::now();
    let mut o = options(&a.picture, a.up)?;
    check_png_path(&a.output)?;
    let pool = topovox_job::pool_for(a.threads, "--threads")?;
    topovox_io::atomic::refuse_overwriting_inputs(&a.output, std::slice::from_ref(&a.input))?;
    let (bits, what, colours, outline): (Box<dyn VoxelSource + Send>, &str, _, _) = if topovox_io::is_voxel_file(&a.input) {
        if a.picture.outline {
            bail!("--outline draws the source mesh's silhouette; it needs a mesh input (or voxelize --preview)");
        }
        // .vox and .schem are rotated back so the --up axis is up again.
        let up = a.up.unwrap_or_default();
        use topovox_io::VoxelFormat as F;
        match topovox_io::read_voxels(
            &a.input,
            &topovox_io::ReadOptions { up, allow_external_paths: a.allow_external_paths, ..Default::default() },
        ) {
            Ok(loaded) => {
                o.voxel_shape = shape(loaded.placement);
                (Box::new(loaded.bits), "voxel file", loaded.attributes, None)
            }
            // A .vdb, .zarr or .npz grid past memory: drawn from its bricks.
            Err(e) if matches!(e.kind, topovox_io::ErrorKind::TooLarge { .. }) && F::from_path(&a.input).is_some_and(F::reads_sparsely) => {
                let sparse = topovox_io::read_voxels_sparse(
                    &a.input,
                    &topovox_io::ReadOptions { attributes: false, allow_external_paths: a.allow_external_paths, ..Default::default() },
                )?;
                if sparse.attributes_left {
                    eprintln!("topovox: warning: {}: drawn without its colours: the grid does not fit densely", a.input.display());
                }
                o.voxel_shape = shape(sparse.placement);
                let img = pool.install(|| picture_sparse(&sparse.bits, &a.output, &o, None, None))?;
                return summary(a, &img, "voxel file", &sparse.bits, t0);
            }
            Err(e) => return Err(e.into()),
        }
    } else {
        let (mode, _) = topovox_job::resolve_method(a.mode, topovox_job::Method::Fast)
            .context("render voxelizes meshes with a surface or line mode; voxelize solids to a file first")?;
        let loaded = topovox_io::read_mesh(
            &a.input,
            &topovox_io::ReadOptions { allow_external_paths: a.allow_external_paths, ..Default::default() },
        )?;
        topovox_io::atomic::refuse_overwriting_inputs(&a.output, &loaded.sources)?;
        let grid = plan::grid_request(&a.grid)?.fit(&loaded.report.bounds)?;
        plan::check_memory(&grid)?;
        o.voxel_shape = grid.voxel_size().0.to_array();
        for w in &loaded.warnings {
            eprintln!("topovox: warning: {}: {w}", a.input.display());
        }
        let (b, _) = pool.install(|| voxelize::fast(mode, loaded.mesh.as_ref(), &grid, &Options::default()));
        let colours = loaded.appearance.has_colour().then(|| {
            let opts = CarryOptions { rule: a.colour_rule, normals: false };
            pool.install(|| carry(loaded.mesh.as_ref(), &loaded.appearance, &grid, &b, &opts))
        });
        let outline = a.picture.outline.then(|| outline_triangles(loaded.mesh.as_ref(), &grid));
        (Box::new(b), "mesh", colours, outline)
    };
    let img = pool.install(|| picture(bits.as_ref(), &a.output, &o, colours.as_ref(), outline.as_deref()))?;
    summary(a, &img, what, bits.as_ref(), t0)
}

/// A file's voxel shape (boxes drawn in their proportions); cubes when it
/// records none.
fn shape(placement: Option<(topovox::glam::DVec3, topovox::glam::DVec3)>) -> [f64; 3] {
    placement.map_or([1.0; 3], |p| p.1.to_array())
}

/// Prints what `render` drew.
fn summary(a: &RenderArgs, img: &Image, what: &str, bits: &dyn VoxelSource, t0: Instant) -> Result<()> {
    let total_s = t0.elapsed().as_secs_f64();
    if a.json {
        let v = json!({"input": a.input, "kind": what, "output": a.output, "width": img.width, "height": img.height,
            "dims": bits.dims(), "voxels": bits.count(), "covered_pixels": img.covered, "total_s": total_s});
        return crate::console::print_stdout(&v.to_string());
    }
    if a.quiet {
        return Ok(());
    }
    crate::console::print_stdout(&format!(
        "render: {}x{} picture of {} voxels ({}, grid {:?}) in {:.2} s -> {}",
        img.width,
        img.height,
        bits.count(),
        what,
        bits.dims(),
        total_s,
        a.output.display()
    ))
}
