//! Fuzzes the `.off` reader: any bytes give a mesh or an error, never a
//! panic or an allocation the file's counts claim; triangles index
//! existing, finite points.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(
    init: topovox_fuzz::fence_panics(),
    |data: &[u8]| {
    if let Ok(m) = topovox_io::read_mesh_bytes(data, topovox_io::MeshFormat::Off, None) {
        assert!(m.mesh.triangles.iter().flatten().all(|&i| (i as usize) < m.mesh.positions.len()));
        assert!(m.mesh.positions.iter().all(|&p| topovox::in_range(p)));
    }
    }
);
