//! Fuzzes an OBJ with its material library and texture as files in a
//! folder: the input is split at 0xFF bytes into the OBJ (after an
//! `mtllib m.mtl` line), the MTL and the texture `t.png`. Exercises
//! `mtllib` and `map_Kd` resolution (names escaping the folder included)
//! and texture decoding: a mesh or an error, never a panic; nothing is
//! read outside the folder.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

fn folder() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = std::env::temp_dir().join(format!("topovox-fuzz-obj-mtl-{}", std::process::id()));
        std::fs::create_dir_all(d.join("model")).expect("temp folder");
        d
    })
}

fuzz_target!(
    init: topovox_fuzz::fence_panics(),
    |data: &[u8]| {
    let mut parts = data.split(|&b| b == 0xFF);
    let (obj, mtl, png) = (parts.next().unwrap_or(&[]), parts.next().unwrap_or(&[]), parts.next().unwrap_or(&[]));
    let dir = folder().join("model");
    let mut text = b"mtllib m.mtl\n".to_vec();
    text.extend_from_slice(obj);
    let (o, m, t) = (dir.join("a.obj"), dir.join("m.mtl"), dir.join("t.png"));
    if std::fs::write(&o, &text).is_err() || std::fs::write(&m, mtl).is_err() || std::fs::write(&t, png).is_err() {
        return;
    }
    if let Ok(loaded) = topovox_io::read_mesh(&o, &topovox_io::ReadOptions::default()) {
        assert!(loaded.mesh.triangles.iter().flatten().all(|&i| (i as usize) < loaded.mesh.positions.len()));
        let root = std::fs::canonicalize(&dir).expect("folder");
        assert!(loaded.sources.iter().all(|s| s.starts_with(&root)), "read outside the folder: {:?}", loaded.sources);
    }
    }
);
