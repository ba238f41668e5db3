//! `voxkit render`: a PNG picture of a voxel file or of a mesh's voxels,
//! and the picture behind `voxelize --preview`.

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use serde_json::json;
use voxkit::render::raycast::{render, Image, RenderOptions, View};
use voxkit::voxelize::{self, Options};
use voxkit::{BrickBits, VoxelSource};
use voxkit_io::VoxelFormat;

use crate::args::{PictureArgs, RenderArgs};
use crate::plan::{self, GridRequest};

/// Largest picture side and pixel count accepted.
const MAX_SIDE: u32 = 16_384;
const MAX_PIXELS: u64 = 64 << 20;

/// Validates the picture options.
pub fn options(p: &PictureArgs) -> Result<RenderOptions> {
    let view = match p.view.as_str() {
        "iso" => View::Iso,
        "x" => View::Axis(0),
        "y" => View::Axis(1),
        "z" => View::Axis(2),
        other => {
            let parts: Vec<&str> = other.split(',').collect();
            let angles: Option<Vec<f64>> = parts.iter().map(|s| s.trim().parse::<f64>().ok().filter(|v| v.is_finite())).collect();
            match angles.as_deref() {
                Some([az, el]) => View::Angles(*az, *el),
                _ => bail!("--view takes iso, x, y, z or AZIMUTH,ELEVATION in degrees, not {other:?}"),
            }
        }
    };
    let size: Option<(u32, u32)> = p.size.split_once(['x', 'X']).and_then(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)));
    let Some((width, height)) = size else { bail!("--size takes WIDTHxHEIGHT in pixels, e.g. 1024x768, not {:?}", p.size) };
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE || width as u64 * height as u64 > MAX_PIXELS {
        bail!("--size {width}x{height}: each side must be 1..={MAX_SIDE} and the picture at most {MAX_PIXELS} pixels");
    }
    let up = match p.up.as_str() {
        "x" => 0,
        "z" => 2,
        _ => 1,
    };
    Ok(RenderOptions { width, height, view, up, ..RenderOptions::default() })
}

/// Renders `bits` and writes the PNG atomically.
pub fn picture(bits: &dyn VoxelSource, path: &Path, o: &RenderOptions) -> Result<Image> {
    let bricks = BrickBits::from_source(bits);
    let img = render(&bricks, o);
    voxkit_io::write_png(path, img.width, img.height, &img.rgb)?;
    Ok(img)
}

/// Refuses an output that is not a `.png` or whose folder does not exist.
pub fn check_png_path(path: &Path) -> Result<()> {
    if path.extension().and_then(|e| e.to_str()).map(|e| e.eq_ignore_ascii_case("png")) != Some(true) {
        bail!("{}: pictures are written as PNG; give a .png file name", path.display());
    }
    crate::commands::voxelize::check_output_dir(path)
}

pub fn run(a: &RenderArgs) -> Result<()> {
    let t0 = Instant::now();
    let o = options(&a.picture)?;
    check_png_path(&a.output)?;
    let pool = crate::thread_pool(a.threads)?;
    let (bits, what): (Box<dyn VoxelSource + Send>, &str) = if VoxelFormat::from_path(&a.input).is_some() {
        (Box::new(voxkit_io::read_voxels(&a.input)?.bits), "voxel file")
    } else {
        let (mode, _) = plan::resolve_method(a.mode, crate::args::Method::Fast)
            .context("render voxelizes meshes with a surface or line mode; voxelize solids to a file first")?;
        let loaded = voxkit_io::read_mesh(&a.input)?;
        let grid = GridRequest::from_args(&a.grid)?.fit(&loaded.report.bounds)?;
        plan::check_memory(&grid)?;
        let (b, _) = pool.install(|| voxelize::fast(mode, loaded.mesh.as_ref(), &grid, &Options::default()));
        (Box::new(b), "mesh")
    };
    let img = pool.install(|| picture(bits.as_ref(), &a.output, &o))?;
    let total_s = t0.elapsed().as_secs_f64();
    if a.json {
        let v = json!({"input": a.input, "kind": what, "output": a.output, "width": img.width, "height": img.height,
            "dims": bits.dims(), "voxels": bits.count(), "covered_pixels": img.covered, "total_s": total_s});
        return crate::print_stdout(&v.to_string());
    }
    crate::print_stdout(&format!(
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
