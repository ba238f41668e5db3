//! Fuzzes every surface and line mode: triangles (and the same points as
//! segments) from raw bytes on a small grid; each fast path (on both
//! drivers), and each scanline path, must equal its reference.
#![no_main]

use libfuzzer_sys::fuzz_target;
use topovox::glam::DVec3;
use topovox::voxelize::driver::Driver;
use topovox::voxelize::{self, Mode, Options};
use topovox::{GridSpec, Mesh};

fuzz_target!(|data: &[u8]| {
    let coords: Vec<f64> = data.chunks_exact(2).map(|c| i16::from_le_bytes([c[0], c[1]]) as f64 / 2048.0).collect();
    let positions: Vec<DVec3> = coords.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
    let n = positions.len() as u32;
    let triangles: Vec<[u32; 3]> = (0..n / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    let segments: Vec<[u32; 2]> = (1..n).map(|i| [i - 1, i]).collect();
    let Ok(grid) = GridSpec::new(DVec3::splat(-4.0), 0.75, [11, 11, 11]) else { return };
    for mode in Mode::ALL {
        let is_line = matches!(mode, Mode::Line26 | Mode::Line6);
        let mesh = Mesh {
            positions: positions.clone(),
            triangles: if is_line { Vec::new() } else { triangles.clone() },
            segments: if is_line { segments.clone() } else { Vec::new() },
        };
        let (slow, _) = voxelize::reference(mode, mesh.as_ref(), &grid);
        for driver in [Driver::Triangles, Driver::Slabs] {
            let (fast, _) = voxelize::fast(mode, mesh.as_ref(), &grid, &Options { driver, ..Options::default() });
            assert_eq!(fast.to_dense().first_difference(&slow), None, "{mode:?} {driver:?}");
        }
        if let Some((scan, _)) = voxelize::scanline::scanline(mode, mesh.as_ref(), &grid, &Options::default()) {
            assert_eq!(scan.to_dense().first_difference(&slow), None, "{mode:?} scanline");
        }
    }
});
