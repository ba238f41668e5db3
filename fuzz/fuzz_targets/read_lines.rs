//! Fuzzes the `.lines` polyline reader: any bytes give segments or an
//! error, never a panic; segments index existing, finite points.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(
    init: topovox_fuzz::fence_panics(),
    |data: &[u8]| {
    if let Ok(m) = topovox_io::read_mesh_bytes(data, topovox_io::MeshFormat::Polyline, None) {
        assert!(m.mesh.segments.iter().flatten().all(|&i| (i as usize) < m.mesh.positions.len()));
        assert!(m.mesh.positions.iter().all(|&p| topovox::in_range(p)));
    }
    }
);
