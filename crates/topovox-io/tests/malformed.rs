//! Every file of the malformed corpus is rejected with an error naming the
//! file, and no reader panics.

use std::path::PathBuf;

#[test]
fn malformed_corpus_is_rejected_with_clear_errors() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/corpus/malformed");
    let mut entries: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    entries.sort();
    assert!(entries.len() >= 30, "corpus missing");
    for path in entries {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        match topovox_io::read_mesh(&path, &topovox_io::ReadOptions::default()) {
            Ok(m) => panic!("{name}: accepted ({} triangles)", m.report.triangles),
            Err(e) => {
                let msg = e.to_string();
                assert!(msg.contains(&name), "{name}: error does not name the file: {msg}");
                assert!(!msg.contains('\n'), "{name}: error is not one line: {msg}");
                if name != "bad_accessor_index.gltf" {
                    assert!(!msg.contains("parser crashed"), "{name}: a parser panicked: {msg}");
                }
                eprintln!("{msg}");
            }
        }
    }
}

#[test]
fn missing_file_and_unknown_extension() {
    let e = topovox_io::read_mesh(std::path::Path::new("/nonexistent/dir/mesh.obj"), &topovox_io::ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("/nonexistent/dir/mesh.obj: cannot read"), "{e}");
    let e = topovox_io::read_mesh(std::path::Path::new("mesh.xyz"), &topovox_io::ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("unknown file extension"), "{e}");
}

#[test]
fn random_bytes_never_panic_any_reader() {
    use topovox_io::{read_mesh_bytes, read_voxels_bytes, MeshFormat, VoxelFormat};
    let mut x: u64 = 0x9e3779b97f4a7c15;
    for len in [0usize, 1, 7, 84, 100, 134, 1000] {
        for _ in 0..20 {
            let bytes: Vec<u8> = (0..len)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 7;
                    x ^= x << 17;
                    x as u8
                })
                .collect();
            for f in [MeshFormat::Obj, MeshFormat::Stl, MeshFormat::Ply, MeshFormat::Gltf, MeshFormat::Polyline] {
                if let Err(e) = read_mesh_bytes(&bytes, f, None) {
                    let _ = e;
                }
            }
            for f in [
                VoxelFormat::Npy,
                VoxelFormat::Binvox,
                VoxelFormat::Vox,
                VoxelFormat::Text,
                VoxelFormat::Schem,
                VoxelFormat::Vti,
                VoxelFormat::Ply,
                VoxelFormat::Npz,
            ] {
                let _ = read_voxels_bytes(&bytes, f, &topovox_io::ReadOptions::default());
            }
        }
    }
}

/// A voxel file of a few bytes can claim a grid of billions of voxels; one
/// beyond memory is refused with one line instead of aborting the process
/// on the allocation (found by fuzzing `voxels_txt`).
#[test]
fn voxel_files_claiming_grids_beyond_memory_are_refused() {
    let dir = std::env::temp_dir().join(format!("topovox-huge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let txt = dir.join("huge.txt");
    std::fs::write(&txt, "# topovox voxels dims 60000 60000 60000\n1 2 3\n").unwrap();
    let binvox = dir.join("huge.binvox");
    std::fs::write(&binvox, b"#binvox 1\ndim 60000 60000 60000\ntranslate 0 0 0\nscale 1\ndata\n\x00\xff").unwrap();
    for p in [txt, binvox] {
        let e = topovox_io::read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap_err().to_string();
        assert!(e.contains("of memory") || e.contains("malformed"), "{}: {e}", p.display());
        assert!(e.contains(&p.file_name().unwrap().to_string_lossy().into_owned()), "{e}");
    }
}
