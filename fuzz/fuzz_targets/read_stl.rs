//! Fuzzes the Stl reader: any bytes give a mesh or an error, never a panic
//! that escapes (the reader's own fence turns third-party panics into
//! errors; a panic reaching libFuzzer is a bug in voxkit-io).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(
    init: {
        // Third-party parsers that panic on malformed input run inside
        // voxkit-io's fence, which turns the panic into an error (as the CLI
        // does); only panics outside it are crashes.
        let abort = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !voxkit_io::panic_is_fenced() {
                abort(info)
            }
        }));
    },
    |data: &[u8]| {
    if let Ok(m) = voxkit_io::read_mesh_bytes(data, voxkit_io::MeshFormat::Stl, None) {
        assert!(m.mesh.triangles.iter().flatten().all(|&i| (i as usize) < m.mesh.positions.len()));
        assert!(m.mesh.positions.iter().all(|p| p.is_finite()));
    }
    }
);
