//! Fuzzes the Gltf reader: any bytes give a mesh or an error, never a panic
//! that escapes (the reader's own fence turns third-party panics into
//! errors; a panic reaching libFuzzer is a bug in topovox-io).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(
    init: topovox_fuzz::fence_panics(),
    |data: &[u8]| {
    if let Ok(m) = topovox_io::read_mesh_bytes(data, topovox_io::MeshFormat::Gltf, None) {
        assert!(m.mesh.triangles.iter().flatten().all(|&i| (i as usize) < m.mesh.positions.len()));
        assert!(m.mesh.positions.iter().all(|&p| topovox::in_range(p)));
    }
    }
);
