//! Exports that land right (issue 19): the up axis of .vox and .schem,
//! watertight and triangulated voxel meshes, single-model .vox files, and
//! warnings for options and names that do nothing.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn topovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_topovox")).args(args).output().expect("run topovox")
}

fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("topovox-exports-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn shared(name: &str) -> String {
    let p = topovox_testkit::shared_meshes_dir().join(name);
    assert!(p.exists(), "missing {}", p.display());
    p.to_string_lossy().into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn ok(out: Output) -> Output {
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    out
}

fn json(out: &Output) -> serde_json::Value {
    serde_json::from_slice(&out.stdout).expect("JSON")
}

/// The dims of a grid as `[nx, ny, nz]`.
fn dims(v: &serde_json::Value) -> [u64; 3] {
    let d = v["dims"].as_array().unwrap();
    [d[0].as_u64().unwrap(), d[1].as_u64().unwrap(), d[2].as_u64().unwrap()]
}

#[test]
fn schem_and_vox_stand_upright_and_read_back() {
    let d = folder("up");
    let spot = shared("spot-textured.obj");
    let npy = d.join("spot.npy");
    let v = json(&ok(topovox(&["voxelize", &spot, "-o", s(&npy), "--resolution", "40", "--json"])));
    let [nx, ny, nz] = dims(&v);
    for (up, mc_height, mv_height) in [("y", ny, ny), ("z", nz, nz), ("x", nx, nx)] {
        for ext in ["schem", "vox"] {
            let f = d.join(format!("spot-{up}.{ext}"));
            let mut args = vec!["voxelize", &spot, "-o", s(&f), "--resolution", "40", "--quiet"];
            if up != "y" {
                args.extend(["--up", up]);
            }
            ok(topovox(&args));
            // Read back, by the recorded axis or by --up, into the npy's voxels.
            let back = d.join(format!("back-{up}-{ext}.npy"));
            ok(topovox(&["convert", s(&f), s(&back), "--up", up]));
            assert!(std::fs::read(&back).unwrap() == std::fs::read(&npy).unwrap(), "{up} {ext} round trip");
            // The height in the file is the up axis's extent.
            let height = if ext == "schem" { schem_height(&f) } else { vox_height(&f) };
            assert_eq!(height, if ext == "schem" { mc_height } else { mv_height }, "{up} {ext}");
        }
    }
}

/// Minecraft's Height of a schematic.
fn schem_height(p: &Path) -> u64 {
    let gz = std::fs::read(p).unwrap();
    let mut nbt = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(&gz[..]), &mut nbt).unwrap();
    let fastnbt::Value::Compound(root) = fastnbt::from_bytes::<fastnbt::Value>(&nbt).unwrap() else { panic!("not a compound") };
    match root.get("Height") {
        Some(fastnbt::Value::Short(h)) => *h as u16 as u64,
        other => panic!("Height: {other:?}"),
    }
}

/// The chunks of a .vox file: (id, content).
fn vox_chunks(p: &Path) -> Vec<([u8; 4], Vec<u8>)> {
    let raw = std::fs::read(p).unwrap();
    assert_eq!(&raw[..4], b"VOX ");
    let mut out = Vec::new();
    // MAIN's children start after MAIN's 12-byte header at byte 8.
    let mut at = 20;
    while at + 12 <= raw.len() {
        let id: [u8; 4] = raw[at..at + 4].try_into().unwrap();
        let n = u32::from_le_bytes(raw[at + 4..at + 8].try_into().unwrap()) as usize;
        let m = u32::from_le_bytes(raw[at + 8..at + 12].try_into().unwrap()) as usize;
        out.push((id, raw[at + 12..at + 12 + n].to_vec()));
        at += 12 + n + m;
    }
    out
}

/// MagicaVoxel's height (SIZE z) of a single-model .vox.
fn vox_height(p: &Path) -> u64 {
    let size = vox_chunks(p).into_iter().find(|c| &c.0 == b"SIZE").expect("SIZE").1;
    u32::from_le_bytes(size[8..12].try_into().unwrap()) as u64
}

#[test]
fn a_small_vox_is_one_model_without_a_scene_graph() {
    let d = folder("vox");
    let f = d.join("cow.vox");
    ok(topovox(&["voxelize", &shared("cow.obj"), "-o", s(&f), "--resolution", "64", "--quiet"]));
    let ids: Vec<[u8; 4]> = vox_chunks(&f).into_iter().map(|c| c.0).collect();
    assert_eq!(ids.iter().filter(|i| *i == b"SIZE").count(), 1);
    assert!(!ids.iter().any(|i| matches!(i, b"nTRN" | b"nGRP" | b"nSHP")), "{ids:?}");
}

/// Edge use counts of an OBJ after merging vertices by position: (once, twice, more).
fn obj_edges(p: &Path) -> (usize, usize, usize, usize) {
    let text = std::fs::read_to_string(p).unwrap();
    let mut verts: Vec<[i64; 3]> = Vec::new();
    let mut edges: HashMap<([i64; 3], [i64; 3]), usize> = HashMap::new();
    let mut non_triangles = 0;
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first() {
            Some(&"v") => verts.push([1, 2, 3].map(|i| (w[i].parse::<f64>().unwrap() * 1e6).round() as i64)),
            Some(&"f") => {
                let f: Vec<[i64; 3]> = w[1..].iter().map(|x| verts[x.parse::<usize>().unwrap() - 1]).collect();
                non_triangles += (f.len() != 3) as usize;
                for i in 0..f.len() {
                    let (a, b) = (f[i], f[(i + 1) % f.len()]);
                    *edges.entry(if a < b { (a, b) } else { (b, a) }).or_default() += 1;
                }
            }
            _ => {}
        }
    }
    let once = edges.values().filter(|&&n| n == 1).count();
    let twice = edges.values().filter(|&&n| n == 2).count();
    (once, twice, edges.len() - once - twice, non_triangles)
}

#[test]
fn voxel_meshes_are_watertight_by_default_and_triangulate_on_request() {
    let d = folder("mesh");
    let bunny = shared("stanford-bunny.obj");
    let (plain, tight, tri) = (d.join("plain.obj"), d.join("tight.obj"), d.join("tri.obj"));
    ok(topovox(&["voxelize", &bunny, "-o", s(&plain), "--resolution", "64", "--watertight", "off", "--quiet"]));
    ok(topovox(&["voxelize", &bunny, "-o", s(&tight), "--resolution", "64", "--quiet"]));
    ok(topovox(&["voxelize", &bunny, "-o", s(&tri), "--resolution", "64", "--triangulate", "--quiet"]));
    let (once, ..) = obj_edges(&plain);
    assert!(once > 1000, "the plain greedy quads have T-junctions ({once} edges used once)");
    assert_eq!(obj_edges(&tight).0, 0, "watertight: no edge used once");
    let (once, _, _, non_tri) = obj_edges(&tri);
    assert_eq!((once, non_tri), (0, 0), "triangulated and still watertight");
    // Still exactly the voxels: voxelized back as a solid on the same grid.
    let v = json(&ok(topovox(&["voxelize", &bunny, "-o", s(&d.join("a.npy")), "--resolution", "64", "--json"])));
    let o = v["origin"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap().to_string()).collect::<Vec<_>>().join(",");
    let size = v["voxel_size"].as_f64().unwrap().to_string();
    let dd = dims(&v).map(|x| x.to_string()).join(",");
    for m in [&tight, &tri] {
        let back = d.join("back.npy");
        ok(topovox(&[
            "voxelize",
            s(m),
            "-o",
            s(&back),
            "--mode",
            "solid",
            "--method",
            "parity",
            "--origin",
            &o,
            "--voxel-size",
            &size,
            "--dims",
            &dd,
            "--quiet",
        ]));
        assert!(std::fs::read(&back).unwrap() == std::fs::read(d.join("a.npy")).unwrap(), "{}", m.display());
    }
    // GLB too.
    let glb = d.join("t.glb");
    ok(topovox(&["voxelize", &bunny, "-o", s(&glb), "--resolution", "32", "--quiet"]));
    let loaded = topovox_io::read_mesh(&glb, &topovox_io::ReadOptions::default()).unwrap();
    let mut edges: HashMap<([i64; 3], [i64; 3]), usize> = HashMap::new();
    let key = |i: u32| loaded.mesh.positions[i as usize].to_array().map(|c| (c * 1e5).round() as i64);
    for t in &loaded.mesh.triangles {
        for e in 0..3 {
            let (a, b) = (key(t[e]), key(t[(e + 1) % 3]));
            *edges.entry(if a < b { (a, b) } else { (b, a) }).or_default() += 1;
        }
    }
    assert_eq!(edges.values().filter(|&&n| n == 1).count(), 0, "GLB watertight");
}

#[test]
fn options_that_do_nothing_and_mismatched_names_warn() {
    let d = folder("warn");
    let cow = shared("cow.obj");
    let warns = |args: &[&str]| String::from_utf8_lossy(&ok(topovox(args)).stderr).into_owned();
    let e = warns(&["voxelize", &cow, "-o", s(&d.join("a.npy")), "--dither", "--resolution", "16"]);
    assert!(e.contains("--dither (for .vox) does nothing for npy output"), "{e}");
    let e = warns(&["voxelize", &cow, "-o", s(&d.join("x.vox")), "--format", "binvox", "--resolution", "16"]);
    assert!(e.contains("extension says vox"), "{e}");
    let e = warns(&["voxelize", &cow, "-o", s(&d.join("b.npy")), "--up", "z", "--triangulate", "--resolution", "16"]);
    assert!(e.contains("--up") && e.contains("--triangulate"), "{e}");
    let v = d.join("c.binvox");
    ok(topovox(&["voxelize", &cow, "-o", s(&v), "--resolution", "16", "--quiet"]));
    let e = warns(&["convert", s(&v), s(&d.join("c.vti")), "--normals"]);
    assert!(e.contains("--normals"), "{e}");
    // An empty result: every triangle outside an explicit grid.
    let e = warns(&["voxelize", &cow, "-o", s(&d.join("e.npy")), "--origin", "100,100,100", "--voxel-size", "0.1", "--dims", "4,4,4"]);
    assert!(e.contains("the result is empty") && e.contains("outside the grid"), "{e}");
    // Help lists every format.
    let help = String::from_utf8_lossy(&topovox(&["voxelize", "--help"]).stdout).into_owned();
    for f in ["npy", "binvox", "vox", "txt", "schem", "vti", "ply", "obj", "glb"] {
        assert!(help.contains(f), "voxelize --help lacks {f}");
    }
}
