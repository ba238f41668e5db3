//! `--voxel-size SX,SY,SZ` end to end: every mode and method gives the same
//! voxels, the JSON summary reports three sizes (one when they are equal),
//! the formats that can store the spacing read it back, the cubes-only
//! formats refuse with a one-line error and write nothing, and `check`,
//! `convert` and `render` read the files.

use std::path::PathBuf;
use std::process::{Command, Output};

fn topovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_topovox")).args(args).output().expect("run topovox")
}

fn tmp(name: &str) -> String {
    let d = std::env::temp_dir().join(format!("topovox-boxes-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name).to_string_lossy().into_owned()
}

fn example(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes").join(name).to_string_lossy().into_owned()
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

const SIZES: &str = "0.05,0.05,0.18";

#[test]
fn every_mode_and_method_gives_the_same_voxels() {
    let cow = example("cow.obj");
    let modes: [(&str, &[&str]); 12] = [
        ("cover", &["fast", "reference", "scanline"]),
        ("sep26", &["fast", "reference", "scanline"]),
        ("sep6", &["fast", "reference", "scanline"]),
        ("ss6", &["fast", "reference"]),
        ("pos", &["fast", "reference"]),
        ("tunnel18", &["fast", "reference"]),
        ("tunnel26", &["fast", "reference"]),
        ("bubble", &["fast", "reference"]),
        ("diagonal", &["fast", "reference"]),
        ("solid", &["winding", "reference"]),
        ("solid+surface", &["parity", "auto"]),
        ("line26", &["fast", "reference"]),
    ];
    for (mode, methods) in modes {
        let mesh = if mode.starts_with("line") { example("helix.lines") } else { cow.clone() };
        let mut first: Option<Vec<u8>> = None;
        let mut runs: Vec<Vec<&str>> = methods.iter().map(|m| vec!["--method", m]).collect();
        // Tiles of 16 voxels, with the first method (parity and winding
        // differ where the cow's parts overlap).
        runs.push(vec!["--method", methods[0], "--tile", "16"]);
        for (n, extra) in runs.iter().enumerate() {
            let out = tmp(&format!("{mode}-{n}.npy"));
            let mut args = vec!["voxelize", &mesh, "-o", &out, "--mode", mode, "--voxel-size", SIZES, "--json"];
            args.extend(extra);
            let j = json(&topovox(&args));
            assert_eq!(j["voxel_size"], serde_json::json!([0.05, 0.05, 0.18]), "{mode} {extra:?}");
            let bytes = std::fs::read(&out).unwrap();
            match &first {
                None => {
                    assert!(j["voxels"].as_u64().unwrap() > 10, "{mode}: {j}");
                    first = Some(bytes);
                }
                Some(f) => assert!(f == &bytes, "{mode}: {extra:?} differs from {:?}", runs[0]),
            }
        }
    }
}

#[test]
fn one_size_keeps_the_scalar_and_three_equal_sizes_are_cubes() {
    let cow = example("cow.obj");
    let a = json(&topovox(&["voxelize", &cow, "-o", &tmp("c1.npy"), "--voxel-size", "0.1", "--json"]));
    let b = json(&topovox(&["voxelize", &cow, "-o", &tmp("c3.npy"), "--voxel-size", "0.1,0.1,0.1", "--json"]));
    assert_eq!(a["voxel_size"], serde_json::json!(0.1));
    assert_eq!(b["voxel_size"], serde_json::json!(0.1));
    assert_eq!(std::fs::read(tmp("c1.npy")).unwrap(), std::fs::read(tmp("c3.npy")).unwrap());
    // An explicit grid of boxes.
    let e = json(&topovox(&[
        "voxelize",
        &cow,
        "-o",
        &tmp("e.npy"),
        "--origin",
        "-1,-1,-1",
        "--dims",
        "20,20,8",
        "--voxel-size",
        "0.1,0.1,0.25",
        "--json",
    ]));
    assert_eq!((e["dims"].clone(), e["voxel_size"].clone()), (serde_json::json!([20, 20, 8]), serde_json::json!([0.1, 0.1, 0.25])));
    for bad in ["0.1,0", "0.1,0.1,-1", "a,b,c", "0.1,0.1,nan"] {
        let o = topovox(&["voxelize", &cow, "-o", &tmp("bad.npy"), &format!("--voxel-size={bad}")]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.trim().lines().count() == 1 && err.contains("voxel"), "{bad}: {err}");
    }
}

#[test]
fn formats_keep_the_spacing_or_refuse() {
    let cow = example("cow.obj");
    for ext in ["vti", "vdb", "zarr", "npz", "ply", "txt"] {
        let out = tmp(&format!("cow.{ext}"));
        let v = json(&topovox(&["voxelize", &cow, "-o", &out, "--voxel-size", SIZES, "--json"]));
        let back = tmp(&format!("back-{ext}.npz"));
        let c = json(&topovox(&["convert", &out, &back, "--json"]));
        assert_eq!(c["grid_from"], "input", "{ext}");
        assert_eq!((&c["voxel_size"], &c["origin"], &c["voxels"]), (&v["voxel_size"], &v["origin"], &v["voxels"]), "{ext}");
        // check certifies the file on the grid it records, in index space.
        let k = json(&topovox(&["check", &out, "--mesh", &cow, "--json"]));
        assert_eq!(k["grid"]["source"], "file", "{ext}: {k}");
        assert_eq!(k["grid"]["voxel_size"], v["voxel_size"]);
        assert_eq!((&k["closed"], &k["separating_26"]), (&serde_json::json!(true), &serde_json::json!(true)), "{ext}: {k}");
        let png = tmp(&format!("cow-{ext}.png"));
        json(&topovox(&["render", &out, "-o", &png, "--size", "64x48", "--json"]));
    }
    for ext in ["binvox", "vox", "schem"] {
        let out = tmp(&format!("never.{ext}"));
        let o = topovox(&["voxelize", &cow, "-o", &out, "--voxel-size", SIZES]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{ext}");
        assert!(err.trim().lines().count() == 1 && err.contains("cubic") && err.contains(".vti"), "{ext}: {err}");
        assert!(!std::path::Path::new(&out).exists(), "{ext}: written");
        // convert of a file of boxes refuses the same way.
        let c = topovox(&["convert", &tmp("cow.vti"), &out]);
        assert!(!c.status.success() && String::from_utf8_lossy(&c.stderr).contains("cubic"), "{ext}");
        assert!(!std::path::Path::new(&out).exists(), "{ext}: written by convert");
    }
}

#[test]
fn distance_fields_on_boxes() {
    let cow = example("cow.obj");
    let s = json(&topovox(&["sdf", &cow, "-o", &tmp("cow-sdf.vti"), "--voxel-size", SIZES, "--json"]));
    let v = json(&topovox(&["voxelize", &cow, "-o", &tmp("cow-solid.npy"), "--voxel-size", SIZES, "--mode", "solid", "--json"]));
    assert_eq!((&s["voxel_size"], &s["dims"]), (&v["voxel_size"], &v["dims"]));
    assert_eq!(s["inside_voxels"], v["voxels"]);
    // The band is measured in the largest edge: 3 × 0.18.
    assert!((s["background"].as_f64().unwrap() - 0.54).abs() < 1e-6, "{s}");
    let c = json(&topovox(&["convert", &tmp("cow-sdf.vti"), &tmp("cow-sdf-inside.npy"), "--json"]));
    assert_eq!(c["voxels"], v["voxels"]);
    assert_eq!(std::fs::read(tmp("cow-sdf-inside.npy")).unwrap(), std::fs::read(tmp("cow-solid.npy")).unwrap());
}
