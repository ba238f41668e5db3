//! `topovox raster INPUT.svg -o OUT.png|.npy --mode M`: 2D rasterization
//! with a stated connectivity (see `topovox::raster`).

use std::time::Instant;

use anyhow::{bail, Context, Result};
use serde_json::json;
use topovox::choice::Choice;
use topovox::glam::DVec2;
use topovox::raster::{self, Grid2};

use crate::args::RasterArgs;

pub fn run(a: &RasterArgs) -> Result<()> {
    let t0 = Instant::now();
    let mode = a.mode;
    let ext = a.output.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("png" | "npy")) {
        bail!("{}: raster writes .png or .npy", a.output.display());
    }
    topovox_job::output::check_output_path(&a.output)?;
    topovox_io::atomic::refuse_overwriting_inputs(&a.output, std::slice::from_ref(&a.input))?;
    let svg = topovox_io::read_svg(&a.input, &topovox_io::svg::SvgOptions { tolerance: a.tolerance })?;
    for w in &svg.warnings {
        eprintln!("topovox: warning: {}: {w}", a.input.display());
    }
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in svg.outlines.iter().flat_map(|o| &o.points) {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let grid = if a.origin.is_some() || a.dims.is_some() {
        let (Some(o), Some(s), Some(d)) = (&a.origin, a.pixel_size, &a.dims) else {
            bail!("an explicit grid needs all of --origin X,Y --pixel-size S --dims W,H");
        };
        if o.len() != 2 || d.len() != 2 || a.resolution.is_some() {
            bail!("--origin and --dims take two values (X,Y and W,H), and exclude --resolution");
        }
        Grid2::new(DVec2::new(o[0], o[1]), s, [d[0], d[1]])
    } else {
        match (a.resolution, a.pixel_size) {
            (Some(_), Some(_)) => bail!("give either --resolution or --pixel-size, not both"),
            (None, Some(s)) => Grid2::from_pixel_size(lo, hi, s),
            (n, None) => Grid2::from_resolution(lo, hi, n.unwrap_or(128)),
        }
    }
    .context("invalid grid")?;
    let t = Instant::now();
    let (px, rep) = raster::run(a.method, mode, &svg.outlines, &grid);
    let raster_s = t.elapsed().as_secs_f64();
    if rep.skipped > 0 {
        eprintln!("topovox: warning: {}: {} segments too far from the grid or not finite were skipped", a.input.display(), rep.skipped);
    }
    topovox_io::pixels::write_pixels(&a.output, &px)?;
    let dims = grid.dims();
    let o = grid.origin();
    // `fill` leaves out the outlines the SVG does not fill.
    let drawn = raster::drawn(mode, &svg.outlines);
    let unfilled = svg.outlines.len() - drawn;
    if a.json {
        let v = json!({"mode": mode.name(), "method": a.method.name(), "origin": [o.x, o.y], "pixel_size": grid.pixel_size(), "dims": dims,
            "pixels": rep.pixels, "outlines": drawn, "unfilled_outlines_left_out": unfilled, "segments": rep.segments, "degenerate_segments": rep.degenerate,
            "skipped_segments": rep.skipped, "raster_s": raster_s, "total_s": t0.elapsed().as_secs_f64(), "output": a.output});
        return crate::console::print_stdout(&v.to_string());
    }
    crate::console::print_stdout(&format!(
        "{}: {} pixels set on a {}x{} grid (origin {}, {}; pixel size {}) from {} outlines{} in {:.1} ms -> {}",
        mode.name(),
        rep.pixels,
        dims[0],
        dims[1],
        o.x,
        o.y,
        grid.pixel_size(),
        drawn,
        if unfilled > 0 { format!(" ({unfilled} unfilled left out)") } else { String::new() },
        raster_s * 1e3,
        a.output.display()
    ))
}
