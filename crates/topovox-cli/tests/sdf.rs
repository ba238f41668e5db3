//! `topovox sdf` end to end: every format written, the JSON summary, the
//! same grid as `voxelize`, and one-line errors with nothing written for
//! what it refuses.

use std::path::PathBuf;
use std::process::{Command, Output};

fn topovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_topovox")).args(args).output().expect("run topovox")
}

fn tmp(name: &str) -> String {
    let d = std::env::temp_dir().join(format!("topovox-sdf-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name).to_string_lossy().into_owned()
}

fn cow() -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes/cow.obj").to_string_lossy().into_owned()
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

#[test]
fn every_format_and_the_voxelize_grid() {
    for ext in ["vdb", "npy", "zarr", "vti"] {
        let out = tmp(&format!("cow.{ext}"));
        let j = json(&topovox(&["sdf", &cow(), "-o", &out, "--resolution", "48", "--json"]));
        assert_eq!(j["format"], ext);
        assert_eq!(j["signed"], true);
        assert!(j["stored_voxels"].as_u64().unwrap() > 1000, "{j}");
        assert!(std::path::Path::new(&out).exists());
    }
    // The same grid as voxelize at the same options.
    let v = json(&topovox(&["voxelize", &cow(), "-o", &tmp("cow-solid.npy"), "--resolution", "48", "--mode", "solid", "--json"]));
    let s = json(&topovox(&["sdf", &cow(), "-o", &tmp("cow2.npy"), "--resolution", "48", "--json"]));
    assert_eq!((&v["dims"], &v["origin"], &v["voxel_size"]), (&s["dims"], &s["origin"], &s["voxel_size"]), "{v} {s}");
    assert_eq!(v["voxels"], s["inside_voxels"]);
    // The .npy header: float32 of shape (nx, ny, nz).
    let bytes = std::fs::read(tmp("cow2.npy")).unwrap();
    let head = String::from_utf8_lossy(&bytes[10..120]).into_owned();
    let d = &s["dims"];
    assert!(head.contains("'descr': '<f4'") && head.contains(&format!("'shape': ({}, {}, {})", d[0], d[1], d[2])), "{head}");
    // --band all and --unsigned.
    let a = json(&topovox(&["sdf", &cow(), "-o", &tmp("all.npy"), "--resolution", "24", "--band", "all", "--unsigned", "--json"]));
    let n: u64 = a["dims"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).product();
    assert_eq!(a["stored_voxels"].as_u64().unwrap(), n);
    assert_eq!(a["signed"], false);
}

#[test]
fn refusals_are_one_line_and_write_nothing() {
    let out = tmp("never.vdb");
    for (args, says) in [
        (vec!["--band", "0"], "band"),
        (vec!["--band", "-2"], "band"),
        (vec!["--band", "wide"], "band"),
        (vec!["--sign", "odd"], "sign"),
        (vec!["--resolution", "0"], "resolution"),
    ] {
        let mut a = vec!["sdf", cow().leak() as &str, "-o", &out];
        a.extend(args.iter().copied());
        let o = topovox(&a);
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(!o.status.success() && err.trim().lines().count() == 1 && err.contains(says), "{args:?}: {err}");
        assert!(!std::path::Path::new(&out).exists());
    }
    // An extension that is not a distance format.
    let o = topovox(&["sdf", &cow(), "-o", &tmp("x.binvox")]);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains(".vdb, .npy, .zarr or .vti"));
    // A dense format past --max-memory.
    let o = topovox(&["sdf", &cow(), "-o", &tmp("big.npy"), "--resolution", "2048", "--max-memory", "64M"]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success() && err.contains("max-memory") && err.contains(".vdb and .zarr"), "{err}");
    assert!(!std::path::Path::new(&tmp("big.npy")).exists());
    // NaN coordinates name the file.
    let nan = tmp("nan.obj");
    std::fs::write(&nan, "v 0 0 0\nv 1 0 0\nv 0 nan 1\nf 1 2 3\n").unwrap();
    let o = topovox(&["sdf", &nan, "-o", &tmp("nan.vdb")]);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(!o.status.success() && err.contains("nan.obj"), "{err}");
}
