//! Fuzzes `cover`: triangles from raw bytes on a small grid; the fast path
//! must equal the reference.
#![no_main]

use libfuzzer_sys::fuzz_target;
use voxkit::glam::DVec3;
use voxkit::voxelize::{cover, Options};
use voxkit::{GridSpec, Mesh};

fuzz_target!(|data: &[u8]| {
    let coords: Vec<f64> = data.chunks_exact(2).map(|c| i16::from_le_bytes([c[0], c[1]]) as f64 / 2048.0).collect();
    let positions: Vec<DVec3> = coords.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
    let triangles = (0..positions.len() as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    let mesh = Mesh { positions, triangles, segments: Vec::new() };
    let Ok(grid) = GridSpec::new(DVec3::splat(-4.0), 0.75, [11, 11, 11]) else { return };
    let (fast, _) = cover::cover(mesh.as_ref(), &grid, &Options::default());
    let (slow, _) = cover::reference::cover(mesh.as_ref(), &grid);
    assert_eq!(fast.to_dense().first_difference(&slow), None);
});
