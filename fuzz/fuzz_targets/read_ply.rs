//! Fuzzes the Ply reader: any bytes give a mesh or an error, never a panic
//! that escapes (the reader's own fence turns third-party panics into
//! errors; a panic reaching libFuzzer is a bug in topovox-io). Where
//! `ply-rs-bw`'s own payload parser (the reference) reads the bytes, the
//! in-place readers give the same mesh and colours; they may read what
//! it refuses (an ASCII value past its type's range, a malformed line of
//! an element no mesh uses), never refuse what it reads.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(
    init: topovox_fuzz::fence_panics(),
    |data: &[u8]| {
    let ours = topovox_io::read_mesh_bytes(data, topovox_io::MeshFormat::Ply, None);
    if let Ok(m) = &ours {
        assert!(m.mesh.triangles.iter().flatten().all(|&i| (i as usize) < m.mesh.positions.len()));
        assert!(m.mesh.positions.iter().all(|&p| topovox::in_range(p)));
    }
    if let Ok(Ok(r)) = topovox_io::fenced(|| topovox_io::ply::reference::read(data)) {
        let m = ours.unwrap_or_else(|e| panic!("the reference reads it, the in-place reader says: {e}"));
        assert_eq!(m.mesh, r.mesh);
        assert_eq!(m.appearance.vertex_colour, r.appearance.vertex_colour);
    }
    }
);
