//! Fuzzes the SVG reader of `topovox raster`, then rasterizes what it reads
//! in every 2D mode on a small grid: outlines or an error, never a panic;
//! each fast path equals its reference.
#![no_main]

use libfuzzer_sys::fuzz_target;
use topovox::choice::Choice;
use topovox::glam::DVec2;
use topovox::raster::{self, Grid2, RasterMode};

fuzz_target!(
    init: topovox_fuzz::fence_panics(),
    |data: &[u8]| {
    let Ok(svg) = topovox_io::svg::read(data, &topovox_io::svg::SvgOptions { tolerance: Some(0.05) }) else { return };
    assert!(svg.outlines.iter().flat_map(|o| &o.points).all(|p| p.is_finite()));
    let Ok(grid) = Grid2::new(DVec2::splat(-2.0), 0.5, [24, 24]) else { return };
    if svg.outlines.iter().map(|o| o.points.len()).sum::<usize>() > 2000 {
        return;
    }
    for &m in RasterMode::ALL {
        let (f, _) = raster::fast(m, &svg.outlines, &grid);
        let (r, _) = raster::reference(m, &svg.outlines, &grid);
        assert_eq!(f.first_difference(&r), None, "{m:?}");
    }
    }
);
