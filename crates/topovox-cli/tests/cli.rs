//! The `topovox` binary end to end: outputs, JSON summaries, the explicit
//! grid form, and one-line errors with a non-zero exit for bad input.

use std::path::PathBuf;
use std::process::{Command, Output};

fn topovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_topovox")).args(args).output().expect("run topovox")
}

fn tmp(name: &str) -> String {
    let d = std::env::temp_dir().join(format!("topovox-cli-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name).to_string_lossy().into_owned()
}

fn shared(name: &str) -> String {
    let p = topovox_testkit::shared_meshes_dir().join(name);
    assert!(p.exists(), "missing {}", p.display());
    p.to_string_lossy().into_owned()
}

fn json(out: &Output) -> serde_json::Value {
    assert!(out.status.success(), "failed: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("one JSON object on stdout")
}

/// Writes the unit cube as an OBJ of six outward quads; returns its path.
fn unit_cube_obj(name: &str) -> String {
    let path = tmp(name);
    let mut obj = String::new();
    for c in 0..8 {
        obj += &format!("v {} {} {}\n", c & 1, (c >> 1) & 1, (c >> 2) & 1);
    }
    for q in [[1, 3, 4, 2], [5, 6, 8, 7], [1, 2, 6, 5], [3, 7, 8, 4], [1, 5, 7, 3], [2, 4, 8, 6]] {
        obj += &format!("f {} {} {} {}\n", q[0], q[1], q[2], q[3]);
    }
    std::fs::write(&path, obj).unwrap();
    path
}

/// Runs a failing command and returns its single stderr line.
fn error_line(args: &[&str]) -> String {
    let out = topovox(args);
    assert!(!out.status.success(), "{args:?} succeeded");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let lines: Vec<&str> = err.lines().filter(|l| !l.starts_with("topovox: warning")).collect();
    assert_eq!(lines.len(), 1, "{args:?}: expected one error line, got {err:?}");
    assert!(lines[0].starts_with("topovox: error: "), "{err}");
    lines[0].to_string()
}

#[test]
fn bunny_at_256_fast_equals_reference_and_json_has_the_fields() {
    let bunny = shared("stanford-bunny.obj");
    let (a, b) = (tmp("fast.npy"), tmp("ref.npy"));
    let fast = json(&topovox(&["voxelize", &bunny, "-o", &a, "--mode", "cover", "--resolution", "256", "--json"]));
    let reference = json(&topovox(&["voxelize", &bunny, "-o", &b, "--resolution", "256", "--method", "reference", "--json"]));
    for key in ["mode", "method", "origin", "voxel_size", "dims", "voxels", "voxelize_s", "total_s"] {
        assert!(fast.get(key).is_some(), "missing {key}");
    }
    assert_eq!(fast["mode"], "cover");
    assert_eq!(fast["method"], "fast");
    assert_eq!(reference["method"], "reference");
    assert_eq!(fast["dims"], serde_json::json!([256, 254, 199]));
    assert_eq!(fast["voxels"], reference["voxels"]);
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn explicit_grid_matches_the_fitted_grid() {
    let cow = shared("cow.obj");
    let fitted = json(&topovox(&["voxelize", &cow, "-o", &tmp("fit.txt"), "--resolution", "64", "--json"]));
    let o: Vec<String> = fitted["origin"].as_array().unwrap().iter().map(|v| v.to_string()).collect();
    let d: Vec<String> = fitted["dims"].as_array().unwrap().iter().map(|v| v.to_string()).collect();
    let s = fitted["voxel_size"].to_string();
    let explicit = json(&topovox(&[
        "voxelize",
        &cow,
        "-o",
        &tmp("exp.txt"),
        "--origin",
        &o.join(","),
        "--voxel-size",
        &s,
        "--dims",
        &d.join(","),
        "--json",
    ]));
    assert_eq!(explicit["voxels"], fitted["voxels"]);
    let a = std::fs::read_to_string(tmp("fit.txt")).unwrap();
    let b = std::fs::read_to_string(tmp("exp.txt")).unwrap();
    assert_eq!(a, b);
}

#[test]
fn voxel_size_fits_the_bounding_box() {
    let out =
        json(&topovox(&["voxelize", &shared("cow.obj"), "-o", &tmp("vs.binvox"), "--voxel-size", "0.05", "--json", "--threads", "1"]));
    assert_eq!(out["voxel_size"], 0.05);
    assert_eq!(out["threads"], 1);
}

#[test]
fn every_output_format_is_written() {
    let cow = shared("cow.obj");
    for name in ["o.npy", "o.binvox", "o.vox", "o.txt", "o.schem", "o.vti", "o.ply", "o.glb", "o.obj"] {
        let p = tmp(name);
        json(&topovox(&["voxelize", &cow, "-o", &p, "--resolution", "32", "--json"]));
        assert!(std::fs::metadata(&p).unwrap().len() > 0);
    }
    json(&topovox(&["voxelize", &cow, "-o", &tmp("b.bin"), "--format", "npy-bool", "--resolution", "16", "--json"]));
}

#[test]
fn info_reports_the_mesh() {
    let v = json(&topovox(&["info", &shared("suzanne.obj"), "--json"]));
    assert_eq!(v["vertices"], 507);
    assert!(v["triangles"].as_u64().unwrap() > 500);
}

#[test]
fn bad_input_gives_one_line_errors() {
    let out = tmp("x.npy");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec!["voxelize".into(), "/no/such/mesh.obj".into(), "-o".into(), out.clone()], "/no/such/mesh.obj: cannot read"),
        (vec!["voxelize".into(), "mesh.dxf".into(), "-o".into(), out.clone()], "unknown file extension"),
        (vec!["voxelize".into(), shared("cow.obj"), "-o".into(), tmp("x.unknown")], "cannot tell the output format"),
        (vec!["voxelize".into(), shared("cow.obj"), "-o".into(), "/no/such/dir/x.npy".into()], "does not exist"),
        (vec!["voxelize".into(), shared("cow.obj"), "-o".into(), out.clone(), "--resolution".into(), "0".into()], "resolution must be"),
        (
            vec!["voxelize".into(), shared("cow.obj"), "-o".into(), out.clone(), "--voxel-size".into(), "1e-9".into()],
            "at most 65536 per axis",
        ),
        (
            vec!["voxelize".into(), shared("cow.obj"), "-o".into(), out.clone(), "--resolution".into(), "60000".into()],
            "cannot be held densely",
        ),
        (
            vec![
                "voxelize".into(),
                shared("cow.obj"),
                "-o".into(),
                out.clone(),
                "--mode".into(),
                "ss6".into(),
                "--method".into(),
                "scanline".into(),
            ],
            "exists for cover, sep26 and sep6",
        ),
        (
            vec![
                "voxelize".into(),
                shared("cow.obj"),
                "-o".into(),
                out.clone(),
                "--method".into(),
                "gpu".into(),
                "--mode".into(),
                "line6".into(),
            ],
            "not built yet",
        ),
        (vec!["voxelize".into(), shared("cow.obj"), "-o".into(), out.clone(), "--origin".into(), "0,0,0".into()], "explicit grid needs"),
        (
            vec![
                "voxelize".into(),
                shared("cow.obj"),
                "-o".into(),
                out.clone(),
                "--origin".into(),
                "0,0".into(),
                "--voxel-size".into(),
                "1".into(),
                "--dims".into(),
                "2,2,2".into(),
            ],
            "three comma-separated",
        ),
        (vec!["voxelize".into(), shared("cow.obj"), "-o".into(), out.clone(), "--threads".into(), "0".into()], "--threads"),
    ];
    for (args, expect) in cases {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let line = error_line(&a);
        assert!(line.contains(expect), "{a:?}: {line}");
    }
    assert!(!std::path::Path::new(&out).exists(), "a failed run left an output");
}

#[test]
fn malformed_meshes_name_the_file() {
    let corpus = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../topovox-io/tests/corpus/malformed");
    for name in ["nan_vertex.obj", "truncated_binary.stl", "index_out_of_range.ply", "bad_accessor_index.gltf", "no_faces.obj"] {
        let p = corpus.join(name).to_string_lossy().into_owned();
        let line = error_line(&["voxelize", &p, "-o", &tmp("m.npy")]);
        assert!(line.contains(name), "{line}");
    }
}

#[test]
fn every_topological_mode_is_certified_by_check() {
    let cow = shared("cow.obj");
    for (mode, sep26) in [("cover", true), ("sep26", true), ("sep6", false), ("ss6", false)] {
        let out = tmp(&format!("{mode}.npy"));
        let v = json(&topovox(&["voxelize", &cow, "-o", &out, "--mode", mode, "--resolution", "48", "--json"]));
        assert_eq!(v["mode"], mode);
        let c = json(&topovox(&["check", &out, "--mesh", &cow, "--json"]));
        for key in ["voxels", "components_6", "components_26", "separating_6", "separating_26", "thin_removable"] {
            assert!(c.get(key).is_some(), "missing {key}");
        }
        assert_eq!(c["voxels"], v["voxels"]);
        assert_eq!(c["closed"], true);
        assert_eq!(c["separating_6"], true, "{mode}");
        assert_eq!(c["separating_26"], sep26, "{mode}");
        assert_eq!(c["grid"]["source"], "inferred");
        // The explicit grid form gives the same certificate.
        let g = &v["origin"];
        let o = format!("{},{},{}", g[0], g[1], g[2]);
        let d = format!("{},{},{}", v["dims"][0], v["dims"][1], v["dims"][2]);
        let s = v["voxel_size"].to_string();
        let e = json(&topovox(&["check", &out, "--mesh", &cow, "--origin", &o, "--voxel-size", &s, "--dims", &d, "--json"]));
        assert_eq!(e["separating_26"], c["separating_26"]);
    }
    // Without the mesh: components only, separation unknown.
    let c = json(&topovox(&["check", &tmp("sep6.npy"), "--json"]));
    assert_eq!(c["separating_6"], serde_json::Value::Null);
    assert_eq!(c["thin_removable"], serde_json::Value::Null);
    // An open mesh: tunnels, no separation.
    let bunny = shared("stanford-bunny.obj");
    let out = tmp("bunny6.binvox");
    json(&topovox(&["voxelize", &bunny, "-o", &out, "--mode", "sep6", "--resolution", "40", "--json"]));
    let c = json(&topovox(&["check", &out, "--mesh", &bunny, "--json"]));
    assert_eq!(c["closed"], false);
    assert_eq!(c["separating_6"], serde_json::Value::Null);
    assert_eq!(c["tunnel_free_6"], true);
}

#[test]
fn polylines_voxelize_connected() {
    let lines = tmp("p.lines");
    // Two polylines, the second starting where the first ends.
    std::fs::write(&lines, "0 0 0 10 3 7 2 9 9\n2,9,9, 10,0,0, 0,10,10\n").unwrap();
    for (mode, key) in [("line26", "components_26"), ("line6", "components_6")] {
        let out = tmp(&format!("{mode}.txt"));
        let v = json(&topovox(&["voxelize", &lines, "-o", &out, "--mode", mode, "--resolution", "32", "--json"]));
        assert!(v["voxels"].as_u64().unwrap() > 32);
        let c = json(&topovox(&["check", &out, "--json"]));
        assert_eq!(c[key], 1, "{mode}");
    }
    let e = error_line(&["voxelize", &lines, "-o", &tmp("x.npy"), "--mode", "sep6"]);
    assert!(e.contains("only line segments"), "{e}");
    let e = error_line(&["check", &tmp("sep6.npy"), "--mesh", &shared("cow.obj"), "--resolution", "20"]);
    assert!(e.contains("pass the grid options"), "{e}");
}

#[test]
fn pad_leaves_the_margin_empty_even_for_faces_on_grid_planes() {
    // A cube: on a fitted grid its faces lie exactly in grid planes, where
    // the tie rule gives the high faces to the voxels beyond. Padded, the
    // fit keeps it two lattice units clear of the pad on every side.
    let cube = unit_cube_obj("cube.obj");
    let (a, b) = (tmp("cube0.npy"), tmp("cube1.npy"));
    let plain = json(&topovox(&["voxelize", &cube, "-o", &a, "--mode", "sep6", "--resolution", "8", "--json"]));
    let padded = json(&topovox(&["voxelize", &cube, "-o", &b, "--mode", "sep6", "--resolution", "8", "--pad", "1", "--json"]));
    assert_eq!(padded["dims"], serde_json::json!([10, 10, 10]));
    // Every face now lies strictly inside the first or last interior layer,
    // whose crosshairs it crosses: the interior's boundary layer, 8³ − 6³,
    // and nothing in the pad.
    assert_eq!(padded["voxels"], 8 * 8 * 8 - 6 * 6 * 6);
    let npy = std::fs::read(&b).unwrap();
    let bits = &npy[npy.len() - 1000..];
    let in_pad = |n: usize| [n / 100, n / 10 % 10, n % 10].iter().any(|&c| c == 0 || c == 9);
    assert!(bits.iter().enumerate().all(|(n, &v)| v == 0 || !in_pad(n)), "a pad voxel is set");
    // Unpadded, the high faces' voxels lie beyond the grid.
    assert_eq!(plain["voxels"], 8 * 8 * 8 - 7 * 7 * 7);
    let c = json(&topovox(&["check", &b, "--mesh", &cube, "--resolution", "8", "--pad", "1", "--json"]));
    assert_eq!(c["separating_6"], true);
    assert_eq!(c["inside_voxels"], 8 * 8 * 8);
    let e = error_line(&["voxelize", &cube, "-o", &a, "--origin", "0,0,0", "--voxel-size", "1", "--dims", "2,2,2", "--pad", "1"]);
    assert!(e.contains("--pad applies to fitted grids"), "{e}");
}

#[test]
fn solid_modes_say_what_they_did() {
    let cube = unit_cube_obj("solid_cube.obj");
    let out = tmp("solid.npy");
    let run = |extra: &[&str]| {
        let mut args = vec!["voxelize", &cube, "-o", &out, "--resolution", "8", "--json"];
        args.extend_from_slice(extra);
        json(&topovox(&args))
    };
    let s = run(&["--mode", "solid"]);
    assert_eq!((s["voxels"].as_u64(), s["method"].as_str()), (Some(512), Some("winding")));
    assert_eq!(s["solid"]["closed"], true);
    assert_eq!(s["solid"]["inside_rule"], "nonzero winding");
    assert_eq!(s["solid"]["orientation"]["closed_parts"], 1);
    assert_eq!(s["solid"]["orientation"]["faces_reoriented"], 0);
    let p = run(&["--mode", "solid", "--method", "parity"]);
    assert_eq!(
        (p["voxels"].as_u64(), p["method"].as_str(), p["solid"]["inside_rule"].as_str()),
        (Some(512), Some("parity"), Some("parity"))
    );
    assert_eq!(run(&["--mode", "solid", "--method", "winding"])["voxels"], 512);
    assert_eq!(run(&["--mode", "solid", "--method", "reference"])["voxels"], 512);
    assert_eq!(run(&["--mode", "solid", "--hollow", "6"])["voxels"], 512 - 216);
    assert_eq!(run(&["--mode", "solid", "--fill", "flood", "--pad", "1"])["method"], "flood");
    // Padded, the cube's surface voxels lie in its solid's layer: the pad stays empty.
    assert_eq!(run(&["--mode", "solid+surface", "--pad", "1"])["voxels"], 512);
    // An open mesh: auto takes the generalized winding number, and says so.
    let bunny = shared("stanford-bunny.obj");
    let w = json(&topovox(&["voxelize", &bunny, "-o", &out, "--mode", "solid", "--resolution", "32", "--json"]));
    assert_eq!((w["method"].as_str(), w["solid"]["closed"].as_bool()), (Some("winding"), Some(false)));
    let ws = json(&topovox(&["voxelize", &bunny, "-o", &out, "--mode", "solid+surface", "--resolution", "32", "--json"]));
    assert!(ws["voxels"].as_u64() > w["voxels"].as_u64(), "the surface adds voxels to the solid");
    assert!(w["solid"]["generalized_winding"]["boundary_cycles"].as_u64().unwrap() > 0);
    let p = json(&topovox(&["voxelize", &bunny, "-o", &out, "--mode", "solid", "--method", "parity", "--resolution", "32", "--json"]));
    assert_eq!(p["solid"]["closed"], false);
    let e = error_line(&["voxelize", &cube, "-o", &out, "--mode", "sep6", "--hollow", "6"]);
    assert!(e.contains("apply to --mode solid"), "{e}");
}

#[test]
fn scanline_method_writes_the_same_file_as_fast_and_auto_says_which_ran() {
    let mesh = shared("stanford-bunny.obj");
    for mode in ["cover", "sep26", "sep6"] {
        let (a, b) = (tmp(&format!("scan-{mode}.binvox")), tmp(&format!("fast-{mode}.binvox")));
        let s = json(&topovox(&["voxelize", &mesh, "-o", &a, "--mode", mode, "--resolution", "96", "--method", "scanline", "--json"]));
        let f = json(&topovox(&["voxelize", &mesh, "-o", &b, "--mode", mode, "--resolution", "96", "--method", "fast", "--json"]));
        assert_eq!(s["method"], "scanline");
        assert_eq!(f["method"], "fast");
        assert_eq!(s["voxels"], f["voxels"]);
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "{mode}: files differ");
    }
    // auto: the scanline path only for cover on faces of hundreds of voxels
    // (issue 45 item 7: elsewhere it was as often slower as faster).
    let out = tmp("auto.binvox");
    for (mode, res) in [("cover", 1024), ("cover", 64), ("sep26", 1024), ("sep6", 1024)] {
        let r = json(&topovox(&["voxelize", &mesh, "-o", &out, "--mode", mode, "--resolution", &res.to_string(), "--json"]));
        assert_eq!(r["method"], "fast", "{mode} at {res}");
    }
    let boxr = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes/box-rotated.obj");
    let boxr = boxr.to_string_lossy();
    for (mode, method) in [("cover", "scanline"), ("sep26", "fast"), ("sep6", "fast")] {
        let b = json(&topovox(&["voxelize", &boxr, "-o", &out, "--mode", mode, "--resolution", "256", "--json"]));
        assert_eq!(b["method"], method, "{mode} on the box");
    }
}

#[test]
fn pos_runs_and_gaps_reports_what_it_misses() {
    let out = tmp("pos.binvox");
    let p = json(&topovox(&["voxelize", &shared("cow.obj"), "-o", &out, "--mode", "pos", "--resolution", "64", "--json"]));
    assert_eq!(p["mode"], "pos");
    assert!(p["voxels"].as_u64().unwrap() > 0);
    let g = topovox(&["gaps", &shared("cow.obj"), "--resolutions", "64", "--json"]);
    assert!(g.status.success(), "{}", String::from_utf8_lossy(&g.stderr));
    let v: serde_json::Value = serde_json::from_slice(&g.stdout).unwrap();
    assert_eq!(v["voxels"], p["voxels"]);
    assert_eq!(v["closed"], true);
    assert!(v["missing"]["cover"].as_u64().unwrap() > 0, "{v}");
    assert!(v["separating_6"].is_boolean());
}

/// Width and height of a PNG written by topovox.
fn png_size(path: &str) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{path}: not a PNG");
    // IHDR is the first chunk: width and height, big-endian, at 16..24.
    (u32::from_be_bytes(bytes[16..20].try_into().unwrap()), u32::from_be_bytes(bytes[20..24].try_into().unwrap()))
}

#[test]
fn render_draws_voxel_files_and_meshes_and_voxelize_previews() {
    let vox = tmp("r.binvox");
    let png = tmp("r.png");
    topovox(&["voxelize", &shared("cow.obj"), "-o", &vox, "--resolution", "48", "--quiet"]);
    let v = json(&topovox(&["render", &vox, "-o", &png, "--size", "160x120", "--view", "30,20", "--json"]));
    assert_eq!(v["kind"], "voxel file");
    assert_eq!(png_size(&png), (160, 120));
    let covered = v["covered_pixels"].as_u64().unwrap();
    assert!(covered > 500 && covered < 160 * 120, "{v}");
    let png2 = tmp("r2.png");
    let m = json(&topovox(&[
        "render",
        &shared("cow.obj"),
        "-o",
        &png2,
        "--resolution",
        "48",
        "--size",
        "160x120",
        "--view",
        "30,20",
        "--json",
    ]));
    assert_eq!(m["kind"], "mesh");
    // The same voxels from the file (binvox pads to a cube; the picture frames the grid,
    // so compare coverage only loosely) and from the mesh.
    assert!(m["covered_pixels"].as_u64().unwrap() > 500);
    let pre = tmp("pre.png");
    let out = tmp("pre.npy");
    let p =
        json(&topovox(&["voxelize", &shared("cow.obj"), "-o", &out, "--resolution", "48", "--preview", &pre, "--size", "96x64", "--json"]));
    assert_eq!(p["preview"], pre.as_str());
    assert_eq!(png_size(&pre), (96, 64));
    // Bad picture options are one-line errors, before any work.
    for (args, expect) in [
        (vec!["render", &vox, "-o", &png, "--size", "0x10"], "--size"),
        (vec!["render", &vox, "-o", &png, "--size", "big"], "WIDTHxHEIGHT"),
        (vec!["render", &vox, "-o", &png, "--view", "sideways"], "--view"),
        (vec!["render", &vox, "-o", &tmp("r.jpg")], ".png"),
        (vec!["render", "/no/such.binvox", "-o", &png], "/no/such.binvox"),
    ] {
        let line = error_line(&args);
        assert!(line.contains(expect), "{args:?}: {line}");
    }
}

#[test]
fn convert_round_trips_every_voxel_format() {
    let npy = tmp("c.npy");
    json(&topovox(&["voxelize", &shared("cow.obj"), "-o", &npy, "--resolution", "40", "--json"]));
    let want = std::fs::read(&npy).unwrap();
    // npy -> every format -> npy gives the same bytes back (binvox pads to a
    // cube, so it goes last with explicit dims checked separately).
    for ext in ["txt", "vox", "npy"] {
        let mid = tmp(&format!("c-mid.{ext}"));
        let back = tmp(&format!("c-back-{ext}.npy"));
        let a = json(&topovox(&["convert", &npy, &mid, "--json"]));
        let b = json(&topovox(&["convert", &mid, &back, "--json"]));
        assert_eq!(a["voxels"], b["voxels"], "{ext}");
        assert_eq!(std::fs::read(&back).unwrap(), want, "{ext}: npy -> {ext} -> npy changed the voxels");
    }
    let bv = tmp("c.binvox");
    let c = json(&topovox(&["convert", &npy, &bv, "--origin", "1,-2,3", "--voxel-size", "0.5", "--json"]));
    assert_eq!(c["grid_from"], "options");
    let back = json(&topovox(&["convert", &bv, &tmp("c-bv.txt"), "--json"]));
    assert_eq!(back["grid_from"], "input");
    assert_eq!(back["origin"], serde_json::json!([1.0, -2.0, 3.0]));
    assert_eq!(back["voxels"], c["voxels"]);
    let line = error_line(&["convert", &npy, &tmp("c.unknown")]);
    assert!(line.contains("cannot tell the output format"), "{line}");
}

#[test]
fn convert_to_obj_gives_a_mesh_that_voxelizes_back_to_the_same_voxels() {
    let npy = tmp("m.npy");
    let s = json(&topovox(&["voxelize", &shared("cow.obj"), "-o", &npy, "--mode", "solid", "--resolution", "24", "--json"]));
    let (o, size, d) = (&s["origin"], s["voxel_size"].as_f64().unwrap(), &s["dims"]);
    let origin = format!("{},{},{}", o[0], o[1], o[2]);
    let dims = format!("{},{},{}", d[0], d[1], d[2]);
    let obj = tmp("m.obj");
    let size_s = size.to_string();
    let c = json(&topovox(&["convert", &npy, &obj, "--origin", &origin, "--voxel-size", &size_s, "--json"]));
    assert!(c["export"]["quads"].as_u64().unwrap() > 6);
    let back = tmp("m-back.npy");
    let args = [
        "voxelize",
        &obj,
        "-o",
        &back,
        "--mode",
        "solid",
        "--method",
        "parity",
        "--origin",
        &origin,
        "--voxel-size",
        &size_s,
        "--dims",
        &dims,
        "--json",
    ];
    let b = json(&topovox(&args));
    assert_eq!(b["voxels"], s["voxels"]);
    assert_eq!(std::fs::read(&back).unwrap(), std::fs::read(&npy).unwrap(), "the mesh of the voxels does not bound the same voxels");
}

#[test]
fn textured_spot_goes_to_every_coloured_format_and_back() {
    let spot = shared("spot-textured.obj");
    let vox = tmp("spot.vox");
    let png = tmp("spot.png");
    let s = json(&topovox(&[
        "voxelize",
        &spot,
        "-o",
        &vox,
        "--resolution",
        "48",
        "--preview",
        &png,
        "--outline",
        "--size",
        "160x120",
        "--json",
    ]));
    assert_eq!(s["attributes"]["colour"], true);
    assert_eq!(s["attributes"]["colour_rule"], "dominant");
    assert_eq!(png_size(&png), (160, 120));
    for ext in ["schem", "vti", "ply", "glb", "obj", "npy"] {
        let out = tmp(&format!("spot.{ext}"));
        let c = json(&topovox(&["convert", &vox, &out, "--json"]));
        assert_eq!(c["voxels"], s["voxels"], "{ext}");
        assert!(std::fs::metadata(&out).unwrap().len() > 100, "{ext}");
    }
    assert!(std::fs::metadata(tmp("spot.mtl")).is_ok(), "a coloured .obj comes with its .mtl");
    // Every voxel file renders, with its colours.
    for ext in ["vox", "schem", "vti", "ply"] {
        let r = json(&topovox(&["render", &tmp(&format!("spot.{ext}")), "-o", &tmp("r.png"), "--size", "64x48", "--json"]));
        assert_eq!(r["voxels"], s["voxels"], "{ext}");
    }
    // The same voxels whatever the format: read back by check.
    let c = json(&topovox(&["check", &tmp("spot.vti"), "--json"]));
    assert_eq!(c["voxels"], s["voxels"]);
    // Blend and normals are accepted; a bad palette file is one line naming it.
    let vti = tmp("spot-blend.vti");
    let b = json(&topovox(&["voxelize", &spot, "-o", &vti, "--resolution", "32", "--colour-rule", "blend", "--normals", "--json"]));
    assert_eq!(b["attributes"]["normal"], true);
    let pal = tmp("bad-palette.txt");
    std::fs::write(&pal, "stone red\n").unwrap();
    let line = error_line(&["voxelize", &spot, "-o", &tmp("x.schem"), "--block-palette", &pal]);
    assert!(line.contains("bad-palette.txt") && line.contains("line 1"), "{line}");
    let line = error_line(&["render", &vox, "-o", &tmp("x.png"), "--outline"]);
    assert!(line.contains("--outline") && line.contains("mesh"), "{line}");
}

#[test]
fn method_gpu_writes_the_cpu_file_or_says_why_not() {
    let cow = shared("cow.obj");
    let line = error_line(&["voxelize", &cow, "-o", &tmp("g.npy"), "--method", "gpu", "--mode", "ss6"]);
    assert!(line.contains("so far") && line.contains("ss6"), "{line}");
    let gpu = tmp("g.npy");
    let out = topovox(&["voxelize", &cow, "-o", &gpu, "--method", "gpu", "--resolution", "80", "--json"]);
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(err.contains("no GPU adapter") || err.contains("lacks"), "{err}");
        assert!(std::env::var("TOPOVOX_REQUIRE_GPU").as_deref() != Ok("1"), "TOPOVOX_REQUIRE_GPU=1 but: {err}");
        eprintln!("skipping: {err}");
        return;
    }
    let s = json(&out);
    assert_eq!(s["method"], "gpu");
    assert!(s["gpu"]["gpu_triangles"].as_u64().unwrap() > 0);
    let cpu = tmp("c.npy");
    json(&topovox(&["voxelize", &cow, "-o", &cpu, "--method", "fast", "--resolution", "80", "--json"]));
    assert_eq!(std::fs::read(&gpu).unwrap(), std::fs::read(&cpu).unwrap());
    let r = json(&topovox(&["voxelize", &cow, "-o", &gpu, "--method", "gpu", "--gpu-path", "raster", "--resolution", "80", "--json"]));
    assert_eq!(r["gpu"]["path"], "raster");
    assert_eq!(std::fs::read(&gpu).unwrap(), std::fs::read(&cpu).unwrap(), "raster");
    let m = json(&topovox(&["voxelize", &cow, "-o", &gpu, "--method", "gpu", "--gpu-path", "msaa-approx", "--resolution", "80", "--json"]));
    let missed = m["gpu"]["missed_voxels"].as_u64().unwrap();
    assert_eq!(m["voxels"].as_u64().unwrap() + missed, s["voxels"].as_u64().unwrap());
    for (mode, cpu_method) in [("sep26", "fast"), ("sep6", "fast"), ("solid", "parity")] {
        json(&topovox(&["voxelize", &cow, "-o", &gpu, "--method", "gpu", "--mode", mode, "--resolution", "80", "--json"]));
        json(&topovox(&["voxelize", &cow, "-o", &cpu, "--method", cpu_method, "--mode", mode, "--resolution", "80", "--json"]));
        assert_eq!(std::fs::read(&gpu).unwrap(), std::fs::read(&cpu).unwrap(), "{mode}");
    }
}

#[test]
fn tiled_runs_write_the_same_files_and_vdb_reads_back() {
    let bunny = shared("stanford-bunny.obj");
    for mode in ["cover", "sep6", "diagonal"] {
        let (a, b) = (tmp(&format!("dense-{mode}.npy")), tmp(&format!("tiled-{mode}.npy")));
        json(&topovox(&["voxelize", &bunny, "-o", &a, "--resolution", "200", "--mode", mode, "--json"]));
        let t = json(&topovox(&["voxelize", &bunny, "-o", &b, "--resolution", "200", "--mode", mode, "--tile", "64", "--json"]));
        assert_eq!(t["method"], "tiled");
        assert_eq!(t["tile"], 64);
        assert!(t["peak_memory_bytes"].as_u64().unwrap() > 0);
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "{mode}: tiled .npy differs");
        if mode != "diagonal" {
            // The scanline kernel in the tiles: the same file.
            let c = tmp(&format!("tiled-scan-{mode}.npy"));
            let t = json(&topovox(&[
                "voxelize",
                &bunny,
                "-o",
                &c,
                "--resolution",
                "200",
                "--mode",
                mode,
                "--tile",
                "64",
                "--method",
                "scanline",
                "--json",
            ]));
            assert_eq!((&t["method"], &t["tile_kernel"]), (&serde_json::json!("tiled"), &serde_json::json!("scanline")));
            assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&c).unwrap(), "{mode}: tiled scanline .npy differs");
        }
    }
    let e = error_line(&[
        "voxelize",
        &bunny,
        "-o",
        &tmp("x.npy"),
        "--resolution",
        "64",
        "--mode",
        "ss6",
        "--tile",
        "64",
        "--method",
        "scanline",
    ]);
    assert!(e.contains("scanline exists for cover, sep26 and sep6"), "{e}");
    // .vdb: what topovox writes it reads back (convert to .npy: the same file).
    let (v, n) = (tmp("tiled.vdb"), tmp("from-vdb.npy"));
    json(&topovox(&["voxelize", &bunny, "-o", &v, "--resolution", "200", "--tile", "64", "--json"]));
    let c = topovox(&["convert", &v, &n]);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    assert_eq!(std::fs::read(&n).unwrap(), std::fs::read(tmp("dense-cover.npy")).unwrap());
    // .zarr: the same, through a directory of chunks.
    let (z, zn) = (tmp("tiled.zarr"), tmp("from-zarr.npy"));
    json(&topovox(&["voxelize", &bunny, "-o", &z, "--resolution", "200", "--tile", "64", "--json"]));
    json(&topovox(&["voxelize", &bunny, "-o", &z, "--resolution", "200", "--tile", "64", "--json"])); // replaces it
    let c = topovox(&["convert", &z, &zn]);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    assert_eq!(std::fs::read(&zn).unwrap(), std::fs::read(tmp("dense-cover.npy")).unwrap());
    let chk = topovox(&["check", &v, "--mesh", &bunny, "--json"]);
    assert!(chk.status.success(), "{}", String::from_utf8_lossy(&chk.stderr));
}

/// `--attributes` writes the surface's attributes into `.vdb` as grids
/// beside the voxels (and into `.zarr` as a group of arrays): converting
/// that file to `.vti` gives the very bytes `voxelize` writes to `.vti`
/// (colour, material, coverage, normal), for a surface and for a solid; a
/// tiled run writes the same file. Attributes past the memory limit are
/// refused in one line, and nothing is written.
#[test]
fn vdb_attributes_carry_every_array() {
    let spot = shared("spot-textured.obj");
    for mode in ["cover", "solid"] {
        let (v, direct, back) =
            (tmp(&format!("attrs-{mode}.vdb")), tmp(&format!("attrs-{mode}.vti")), tmp(&format!("attrs-back-{mode}.vti")));
        let j = json(&topovox(&["voxelize", &spot, "-o", &v, "--resolution", "48", "--mode", mode, "--attributes", "--json"]));
        for a in ["colour", "material", "normal", "coverage"] {
            assert_eq!(j["attributes"][a], true, "{mode}: {a} not carried: {}", j["attributes"]);
        }
        json(&topovox(&["voxelize", &spot, "-o", &direct, "--resolution", "48", "--mode", mode, "--normals", "--json"]));
        let c = topovox(&["convert", &v, &back]);
        assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
        assert_eq!(std::fs::read(&direct).unwrap(), std::fs::read(&back).unwrap(), "{mode}: .vdb attributes differ from .vti's");
    }
    // Without the flag, the bool grid alone (no attributes come back).
    let (plain, plain_vti) = (tmp("attrs-plain.vdb"), tmp("attrs-plain.vti"));
    let j = json(&topovox(&["voxelize", &spot, "-o", &plain, "--resolution", "48", "--json"]));
    assert!(j["attributes"].is_null(), "{}", j["attributes"]);
    assert!(std::fs::metadata(&plain).unwrap().len() < std::fs::metadata(tmp("attrs-cover.vdb")).unwrap().len());
    let c = topovox(&["convert", &plain, &plain_vti, "--json"]);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    // A tiled run carries the same attributes: the same file, byte for byte.
    for mode in ["cover", "solid"] {
        let tiled = tmp(&format!("attrs-tiled-{mode}.vdb"));
        let j = json(&topovox(&[
            "voxelize",
            &spot,
            "-o",
            &tiled,
            "--resolution",
            "48",
            "--mode",
            mode,
            "--tile",
            "16",
            "--attributes",
            "--json",
        ]));
        assert_eq!(j["tile"], 16);
        assert_eq!(
            std::fs::read(&tiled).unwrap(),
            std::fs::read(tmp(&format!("attrs-{mode}.vdb"))).unwrap(),
            "{mode}: tiled attributes differ"
        );
    }
    // Attributes that would not fit in --max-memory: one line, nothing written.
    let big = tmp("attrs-too-big.vdb");
    let e = error_line(&["voxelize", &spot, "-o", &big, "--resolution", "300", "--max-memory", "1M", "--attributes"]);
    assert!(e.contains("attributes of") && e.contains("1.0 MiB"), "{e}");
    assert!(!std::path::Path::new(&big).exists());
    // For a format without attribute grids the flag is named as unused.
    let out = topovox(&["voxelize", &spot, "-o", &tmp("attrs.npy"), "--resolution", "16", "--attributes"]);
    assert!(out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--attributes (for .vdb and .zarr) does nothing"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // .zarr: a group of arrays, converted back to the same .vti.
    let (z, back) = (tmp("attrs.zarr"), tmp("attrs-back-zarr.vti"));
    json(&topovox(&["voxelize", &spot, "-o", &z, "--resolution", "48", "--attributes", "--json"]));
    let c = topovox(&["convert", &z, &back]);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    assert_eq!(std::fs::read(tmp("attrs-cover.vti")).unwrap(), std::fs::read(&back).unwrap(), ".zarr attributes differ from .vti's");
}

/// `convert` of a `.vdb`, `.zarr` or `.npz` grid that cannot be dense
/// (20000³ here, 932 GiB of bits) into a format holding only the set
/// voxels reads and writes it without a dense grid: `.vdb` → `.zarr` →
/// `.vdb` and `.vdb` → `.npz` → `.vdb` give the same bytes, `.txt` the
/// voxels `voxelize` lists; a dense format is one line naming the sparse
/// ones.
#[test]
fn convert_sparse_grids_past_memory() {
    let cube = unit_cube_obj("sparse-cube.obj");
    let (v, z, v2, t, direct) =
        (tmp("sparse.vdb"), tmp("sparse.zarr"), tmp("sparse2.vdb"), tmp("sparse-from-zarr.txt"), tmp("sparse-direct.txt"));
    let grid = ["--voxel-size", "0.01", "--origin", "-0.5,-0.5,-0.5", "--dims", "20000,20000,20000", "--mode", "solid"];
    let s = json(&topovox(&[&["voxelize", cube.as_str(), "-o", &v, "--json"][..], &grid[..]].concat()));
    assert_eq!(s["tile"], 512);
    json(&topovox(&[&["voxelize", cube.as_str(), "-o", &direct, "--json"][..], &grid[..]].concat()));
    let c = json(&topovox(&["convert", &v, &z, "--json"]));
    assert_eq!((c["sparse"].as_bool(), &c["voxels"]), (Some(true), &s["voxels"]));
    json(&topovox(&["convert", &z, &v2, "--json"]));
    assert_eq!(std::fs::read(&v).unwrap(), std::fs::read(&v2).unwrap(), ".vdb -> .zarr -> .vdb changed the file");
    json(&topovox(&["convert", &z, &t, "--json"]));
    assert_eq!(std::fs::read(&direct).unwrap(), std::fs::read(&t).unwrap());
    // .npz of indices too: .vdb -> .npz -> .vdb.
    let (n, v3) = (tmp("sparse.npz"), tmp("sparse3.vdb"));
    json(&topovox(&["convert", &v, &n, "--json"]));
    let c = json(&topovox(&["convert", &n, &v3, "--json"]));
    assert_eq!(c["sparse"].as_bool(), Some(true));
    assert_eq!(std::fs::read(&v).unwrap(), std::fs::read(&v3).unwrap(), ".vdb -> .npz -> .vdb changed the file");
    let e = error_line(&["convert", &v, &tmp("sparse.npy")]);
    assert!(e.contains("932") && e.contains(".zarr"), "{e}");
}

/// Solids past memory: parity and winding run brick row by brick row into
/// sparse bricks with full runs, and write the dense run's files.
#[test]
fn sparse_solids_write_the_same_files() {
    let bunny = shared("stanford-bunny.obj");
    let cow = shared("cow.obj");
    for (mesh, mode, method) in [
        (&bunny, "solid", "parity"),
        (&bunny, "solid+surface", "parity"),
        (&cow, "solid", "winding"),
        (&cow, "solid", "auto"),
        (&bunny, "solid", "auto"),
    ] {
        let (a, b) = (tmp(&format!("dense-{mode}-{method}.npy")), tmp(&format!("sparse-{mode}-{method}.npy")));
        let common = ["--resolution", "150", "--mode", mode, "--method", method, "--json"];
        let d = json(&topovox(&[&["voxelize", mesh.as_str(), "-o", &a][..], &common[..]].concat()));
        let t = json(&topovox(&[&["voxelize", mesh.as_str(), "-o", &b, "--tile", "64"][..], &common[..]].concat()));
        assert_eq!(t["tile"], 64);
        assert_eq!(t["method"], d["method"]);
        assert_eq!(t["voxels"], d["voxels"]);
        // The open bunny by the generalized winding number: the same caps.
        assert_eq!(t["solid"]["generalized_winding"], d["solid"]["generalized_winding"]);
        assert!(t["solid"]["full_bricks"].as_u64().unwrap() > 0, "{mode}: no full bricks");
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "{mode} {method}: sparse .npy differs");
    }
    // Flood fills of a tiled shell, plane by plane: the dense fill's file.
    for (mesh, shell) in [(&cow, "cover"), (&bunny, "sep26")] {
        let (a, b) = (tmp(&format!("dense-flood-{shell}.npy")), tmp(&format!("sparse-flood-{shell}.npy")));
        let common = ["--resolution", "150", "--mode", "solid", "--fill", "flood", "--surface", shell, "--json"];
        let d = json(&topovox(&[&["voxelize", mesh.as_str(), "-o", &a][..], &common[..]].concat()));
        let t = json(&topovox(&[&["voxelize", mesh.as_str(), "-o", &b, "--tile", "64"][..], &common[..]].concat()));
        assert_eq!((&t["tile"], &t["method"]), (&serde_json::json!(64), &d["method"]));
        assert_eq!(t["solid"]["enclosed_voxels"], d["solid"]["enclosed_voxels"]);
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "flood {shell}: sparse .npy differs");
    }
    // Hollowed: skinned brick by brick on the sparse solid, the dense skin.
    for (mesh, hollow, extra) in [(&bunny, "6", ["--method", "parity"]), (&cow, "26", ["--surface", "sep26"])] {
        let (a, b) = (tmp(&format!("dense-hollow-{hollow}.npy")), tmp(&format!("sparse-hollow-{hollow}.npy")));
        let mode = if extra[0] == "--surface" { "solid+surface" } else { "solid" };
        let mut common = vec!["--resolution", "150", "--mode", mode, "--hollow", hollow, "--json"];
        common.extend(extra);
        let d = json(&topovox(&[&["voxelize", mesh.as_str(), "-o", &a][..], &common[..]].concat()));
        let t = json(&topovox(&[&["voxelize", mesh.as_str(), "-o", &b, "--tile", "64"][..], &common[..]].concat()));
        assert_eq!((&t["tile"], &t["solid"]["hollow"]), (&serde_json::json!(64), &serde_json::json!(hollow.parse::<u32>().unwrap())));
        assert_eq!(t["voxels"], d["voxels"]);
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "hollow {hollow}: sparse .npy differs");
    }
}

/// Line modes run tile by tile too (`--tile`, or on their own past the
/// memory budget) and write the dense run's file.
#[test]
fn line_modes_run_tiled() {
    let helix = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/meshes/helix.lines");
    let helix = helix.to_str().unwrap();
    for mode in ["line26", "line6"] {
        let (a, b) = (tmp(&format!("dense-{mode}.npy")), tmp(&format!("tiled-{mode}.npy")));
        let common = ["--resolution", "100", "--mode", mode, "--json"];
        let d = json(&topovox(&[&["voxelize", helix, "-o", &a][..], &common[..]].concat()));
        let t = json(&topovox(&[&["voxelize", helix, "-o", &b, "--tile", "16"][..], &common[..]].concat()));
        assert_eq!(t["tile"], 16);
        assert!(d["voxels"].as_u64().unwrap() > 100);
        assert_eq!(t["voxels"], d["voxels"]);
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "{mode}: tiled .npy differs");
    }
}

#[test]
fn grids_past_memory_errors() {
    let cow = shared("cow.obj");
    for (args, says) in [
        (vec!["--resolution", "16384", "--max-memory", "1G"], ".vdb"),
        (vec!["--tile", "12"], "multiple of 8"),
        (vec!["--tile", "64", "--mode", "solid", "--method", "reference"], "reference and gpu solids"),
        (vec!["--tile", "64", "--method", "reference"], "scanline or gpu path"),
        (vec!["--max-memory", "lots"], "unknown unit"),
        (vec!["--max-memory", "1.2.3G"], "not a size"),
        (vec!["--resolution", "16384", "--max-memory", "1G", "--mode", "solid", "--method", "reference"], "reference and gpu solids"),
    ] {
        let mut a = vec!["voxelize", &cow, "-o"];
        let out = tmp(if args.contains(&"solid") { "past.vdb" } else { "past.npy" });
        a.push(&out);
        a.extend(args.iter().copied());
        let o = topovox(&a);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{args:?} succeeded");
        assert!(err.contains(says) && err.trim_end().lines().count() == 1, "{args:?}: {err}");
    }
}

/// `render --gpu` needs an adapter: without one it must fail with the
/// lavapipe hint (and CI, which sets TOPOVOX_REQUIRE_GPU=1, must have one).
fn gpu_available(out: &Output) -> bool {
    if out.status.success() {
        return true;
    }
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no GPU adapter found") && err.contains("lavapipe"), "unexpected failure: {err}");
    assert!(std::env::var("TOPOVOX_REQUIRE_GPU").as_deref() != Ok("1"), "TOPOVOX_REQUIRE_GPU=1 but {err}");
    false
}

/// Issue 45, item 9: on a machine without a display (no
/// `XDG_RUNTIME_DIR`), GPU runs that succeed print nothing on stderr (a
/// Vulkan layer probing for Wayland printed "error:" lines), and `render`
/// takes `--quiet`.
#[test]
fn gpu_runs_without_a_display_are_quiet() {
    let cow = shared("cow.obj");
    let headless = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_topovox"))
            .args(args)
            .env_remove("XDG_RUNTIME_DIR")
            .env_remove("WAYLAND_DISPLAY")
            .env_remove("DISPLAY")
            .output()
            .expect("run topovox")
    };
    let runs: [&[&str]; 2] = [
        &["voxelize", &cow, "-o", &tmp("quiet-gpu.npy"), "--method", "gpu", "--resolution", "48", "--quiet"],
        &["render", &cow, "--gpu", "-o", &tmp("quiet-gpu.png"), "--size", "64x48", "--quiet"],
    ];
    for args in runs {
        let out = headless(args);
        if !out.status.success() && !gpu_available(&out) {
            return;
        }
        assert!(
            out.stderr.is_empty() && out.stdout.is_empty(),
            "{args:?}: {}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

#[test]
fn the_gpu_renderer_draws_the_cornell_box_and_reports_its_frame() {
    let obj = tmp("cornell.obj");
    let out = topovox(&["scene", "cornell", "-o", &obj]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::read_to_string(tmp("cornell.mtl")).unwrap().contains("Ke 12 12 12"));
    let (png, stats) = (tmp("cornell-gpu.png"), tmp("cornell-stats.json"));
    let out = topovox(&["render", &obj, "--gpu", "-o", &png, "--size", "64x48", "--stats-json", &stats, "--prepass", "on", "--json"]);
    if !gpu_available(&out) {
        return;
    }
    let v = json(&out);
    let s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!(v, s, "--json and --stats-json say the same");
    for key in ["clusters", "clusters_after_frustum", "triangles_drawn", "lights", "multi_draw", "frame_ms"] {
        assert!(s.get(key).is_some(), "{key} missing");
    }
    assert_eq!(s["triangles"], 36);
    assert_eq!(s["multi_draw"], "multi_draw_indexed_indirect");
    assert!(s["lights"].as_u64().unwrap() >= 1);
    assert!(s["light_grid"]["total"].as_u64().unwrap() > 0);
    assert!(s["clusters_after_frustum"].as_u64().unwrap() <= s["clusters"].as_u64().unwrap());
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    // A camera path: one picture per camera, median times over repeats.
    let path = tmp("cornell-path.txt");
    std::fs::write(&path, "# two cameras\n0.5,0.5,2.4,0.5,0.5,0,40\n\n0.5,0.9,0.9, 0.2,0.1,0.2 # inside\n").unwrap();
    let out = topovox(&["render", &obj, "--gpu", "-o", &tmp("path.png"), "--size", "40x30", "--frames", &path, "--repeat", "3", "--json"]);
    let v = json(&out);
    let frames = v["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 2);
    assert_eq!(frames[1]["frame_ms"]["repeats"], 3);
    for n in 0..2 {
        assert!(std::path::Path::new(&tmp(&format!("path-{n:04}.png"))).exists());
    }
    std::fs::write(&path, "0.5,0.5,2.4,0.5,0.5\n").unwrap();
    let e = error_line(&["render", &obj, "--gpu", "-o", &tmp("path.png"), "--frames", &path]);
    assert!(e.contains("line 1") && e.contains("--camera takes"), "{e}");
    // A voxel file is drawn as its greedy quads.
    let npy = tmp("cornell-vox.npy");
    assert!(topovox(&["voxelize", &obj, "-o", &npy, "--resolution", "16"]).status.success());
    let out = topovox(&["render", &npy, "--gpu", "-o", &tmp("vox-gpu.png"), "--size", "32x32", "--json", "--culling", "none"]);
    let v = json(&out);
    assert_eq!(v["kind"], "voxel file");
    assert_eq!(v["clusters_after_frustum"], v["clusters"]);
    // The cluster boxes over the same frame: same counts, another picture.
    let boxed = tmp("vox-gpu-boxes.png");
    let out = topovox(&["render", &npy, "--gpu", "-o", &boxed, "--size", "32x32", "--json", "--culling", "none", "--boxes", "on"]);
    assert_eq!(json(&out)["clusters_after_frustum"], v["clusters"]);
    assert_ne!(std::fs::read(&boxed).unwrap(), std::fs::read(tmp("vox-gpu.png")).unwrap());
}

#[test]
fn spray_writes_a_cloud_the_gpu_renderer_draws() {
    let obj = tmp("spray-cornell.obj");
    assert!(topovox(&["scene", "cornell", "-o", &obj]).status.success());
    let cam = "0.5,0.5,2.2,0.5,0.45,0,45";
    let (one, two) = (tmp("spray-1.ply"), tmp("spray-2.ply"));
    let args = |out: &str, threads: &'static str| {
        let mut a: Vec<String> =
            ["spray", obj.as_str(), "-o", out, "--rays", "30000", "--camera", cam, "--light-samples", "4", "--size", "500x500", "--json"]
                .map(String::from)
                .to_vec();
        a.extend(["--threads".to_string(), threads.to_string()]);
        a
    };
    let run = |a: Vec<String>| topovox(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let v = json(&run(args(&one, "1")));
    let _ = json(&run(args(&two, "2")));
    assert_eq!(std::fs::read(&one).unwrap(), std::fs::read(&two).unwrap(), "the cloud does not depend on the thread count");
    assert_eq!(v["rays"], 30000);
    assert_eq!(v["emissive_triangles"], 2);
    let points = v["points"].as_u64().unwrap();
    assert!(points > 15000 && points + v["misses"].as_u64().unwrap() == 30000, "{v}");
    let bytes = std::fs::read(&one).unwrap();
    assert!(bytes.starts_with(b"ply\nformat binary_little_endian 1.0\n"));
    let head = String::from_utf8_lossy(&bytes[..bytes.windows(10).position(|w| w == b"end_header").unwrap()]).into_owned();
    assert!(head.contains(&format!("element vertex {points}\n")) && head.contains("property float light_r"), "{head}");
    // Drawn by render --gpu, with and without the mesh.
    let out = topovox(&["render", &obj, "--gpu", "--points", &one, "--mesh", "off", "-o", &tmp("spray.png"), "--size", "64x64", "--json"]);
    if gpu_available(&out) {
        let r = json(&out);
        assert_eq!(r["points_drawn"].as_u64(), Some(points));
        assert_eq!(r["triangles_drawn"], 0);
    }
    // Errors: one line each, nothing written.
    let bad = tmp("spray-bad.ply");
    for (extra, says) in [
        (vec!["--rays", "0"], "--rays must be"),
        (vec!["--light-samples", "100000"], "--light-samples must be"),
        (vec!["--camera", "1,2,3"], "--camera takes"),
        (vec!["--size", "0x5"], "--size"),
    ] {
        let mut a = vec!["spray", obj.as_str(), "-o", bad.as_str()];
        a.extend(extra.iter().copied());
        let e = error_line(&a);
        assert!(e.contains(says), "{extra:?}: {e}");
    }
    let e = error_line(&["spray", &obj, "-o", &tmp("spray.npy")]);
    assert!(e.contains("PLY"), "{e}");
    let e = error_line(&["render", &obj, "--gpu", "--points", &obj, "-o", &tmp("spray-bad.png")]);
    assert!(e.contains("PLY") || e.contains("vertex"), "{e}");
    assert!(!std::path::Path::new(&bad).exists());
}

#[test]
fn cut_outs_survive_the_obj_round_trip_and_every_culling_setting() {
    let obj = tmp("cuts.obj");
    let out = topovox(&["scene", "cut-outs", "-o", &obj]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mtl = std::fs::read_to_string(tmp("cuts.mtl")).unwrap();
    assert!(mtl.contains("map_Kd cuts-checker.png") && mtl.contains("map_d cuts-checker.png"), "{mtl}");
    assert!(std::fs::read(tmp("cuts-checker.png")).unwrap().starts_with(b"\x89PNG"));
    // Straight on, the checker quad filling the picture.
    let cam = "0.5,0.5,1.366,0.5,0.5,0,60";
    let mut pictures = Vec::new();
    for (n, (culling, prepass)) in
        [("none", "off"), ("occlusion", "off"), ("occlusion", "on"), ("occlusion-two-pass", "on")].iter().enumerate()
    {
        let png = tmp(&format!("cuts-{n}.png"));
        let out =
            topovox(&["render", &obj, "--gpu", "-o", &png, "--size", "64x64", "--camera", cam, "--culling", culling, "--prepass", prepass]);
        if !gpu_available(&out) {
            return;
        }
        pictures.push(std::fs::read(&png).unwrap());
    }
    assert!(pictures.windows(2).all(|w| w[0] == w[1]), "culling or the prepass changed the cut-out picture");
    // The cut-outs came through the OBJ, MTL and PNG: sprayed rays stop on
    // the front quad (z = 0.5) and pass through it to the quads behind.
    let cloud = tmp("cuts.ply");
    let out = topovox(&["spray", &obj, "-o", &cloud, "--camera", cam, "--size", "64x64", "--rays", "4000", "--light-samples", "0"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(&cloud).unwrap();
    let body = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    // 15 floats and 3 colour bytes per point; z is the third float.
    let z: Vec<f32> = bytes[body..].chunks_exact(63).map(|p| f32::from_le_bytes(p[8..12].try_into().unwrap())).collect();
    let front = z.iter().filter(|&&z| (z - 0.5).abs() < 1e-4).count();
    let behind = z.iter().filter(|&&z| z < 0.3).count();
    assert!(front > 500 && behind > 500 && front + behind == z.len(), "{front} on the checker, {behind} behind, of {}", z.len());
}

#[test]
fn gpu_renderer_options_give_one_line_errors() {
    let obj = unit_cube_obj("gpu-opts.obj");
    let png = tmp("gpu-opts.png");
    for (args, says) in [
        (vec!["--gpu", "--camera", "1,2,3"], "--camera takes"),
        (vec!["--gpu", "--camera", "1,1,1,1,1,1"], "must differ"),
        (vec!["--gpu", "--camera", "0,0,5,0,0,0,200"], "field of view"),
        (vec!["--camera", "0,0,5,0,0,0"], "add --gpu"),
        (vec!["--gpu", "--view", "x"], "not --view"),
    ] {
        let mut all = vec!["render", obj.as_str(), "-o", png.as_str()];
        all.extend(args.iter().copied());
        let e = error_line(&all);
        assert!(e.contains(says), "{args:?}: {e}");
    }
    assert!(!std::path::Path::new(&png).exists());
    // A camera with negative coordinates, written as a new user would.
    let out = topovox(&["render", obj.as_str(), "--gpu", "--camera", "-5,2,3,0,0,0", "-o", png.as_str(), "--size", "32x24"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
}

#[test]
fn view_without_a_display_says_so_in_one_line() {
    let obj = unit_cube_obj("view-cube.obj");
    let out = Command::new(env!("CARGO_BIN_EXE_topovox"))
        .args(["view", obj.as_str(), "--frames", "1"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("topovox:")).collect();
    assert_eq!(lines.len(), 1, "{err}");
    assert!(lines[0].contains("display") || lines[0].contains("no GPU adapter"), "{err}");
    let e = error_line(&["view", obj.as_str(), "--frames", "0"]);
    assert!(e.contains("--frames must be at least 1"), "{e}");
}

/// `check` of a grid that cannot be dense (20000³, 932 GiB of bits) reads
/// the `.vdb` sparsely and checks it window by window: its report equals
/// the same cube's on a small grid (voxels shifted by whole voxels,
/// witnesses too); `--sparse` gives the dense report on a small `.vdb`;
/// `--sparse` of a dense format is one line.
#[test]
fn check_past_memory_window_by_window() {
    let cube = unit_cube_obj("check-sparse-cube.obj");
    for mode in ["sep6", "cover"] {
        let (big, small, small_npy) =
            (tmp(&format!("check-big-{mode}.vdb")), tmp(&format!("check-small-{mode}.vdb")), tmp(&format!("check-small-{mode}.npy")));
        let at = |o: &str, d: &str| ["--voxel-size", "0.125", "--origin", o, "--dims", d, "--mode", mode].map(String::from);
        let (big_grid, small_grid) = (at("-1248.5,-1248.5,-1248.5", "20000,20000,20000"), at("-0.5,-0.5,-0.5", "16,16,16"));
        for (out, grid) in [(&big, &big_grid), (&small, &small_grid), (&small_npy, &small_grid)] {
            let args: Vec<&str> =
                ["voxelize", cube.as_str(), "-o", out.as_str(), "--json"].into_iter().chain(grid.iter().map(String::as_str)).collect();
            json(&topovox(&args));
        }
        let b = json(&topovox(&["check", &big, "--mesh", &cube, "--json"]));
        let s = json(&topovox(&["check", &small, "--mesh", &cube, "--json"]));
        assert_eq!((b["sparse"].as_bool(), s["sparse"].as_bool()), (Some(true), Some(false)));
        assert!(b["windows"].as_u64().unwrap() >= 1);
        assert!(s["voxels"].as_u64().unwrap() > 0 && s["separating_6"].as_bool() == Some(true));
        for (key, want) in s.as_object().unwrap() {
            if matches!(key.as_str(), "check_s" | "sparse" | "windows" | "dims" | "grid") {
                continue;
            }
            let got = &b[key];
            if key.starts_with("witness_") && !want.is_null() {
                for end in ["inside", "outside"] {
                    let shifted: Vec<u64> = want[end].as_array().unwrap().iter().map(|c| c.as_u64().unwrap() + 9984).collect();
                    assert_eq!(got[end], serde_json::json!(shifted), "{mode} {key}");
                }
                continue;
            }
            assert_eq!(got, want, "{mode}: {key} differs past memory");
        }
        // --sparse on a grid that fits: the same report.
        let mut sp = json(&topovox(&["check", &small, "--mesh", &cube, "--json", "--sparse"]));
        assert_eq!(sp["sparse"].as_bool(), Some(true));
        let mut dense = s.clone();
        for v in [&mut sp, &mut dense] {
            let o = v.as_object_mut().unwrap();
            for key in ["check_s", "sparse", "windows"] {
                o.remove(key);
            }
        }
        assert_eq!(sp, dense, "{mode}: --sparse differs");
    }
    let e = error_line(&["check", &tmp("check-small-cover.npy"), "--sparse"]);
    assert!(e.contains("--sparse") && e.contains(".vdb"), "{e}");
}

/// Pictures of grids past memory: `render` draws a `.vdb` that cannot be
/// dense from its bricks, and `voxelize --preview` of a tiled run draws
/// the same picture, byte for byte, as the dense run's.
#[test]
fn pictures_of_sparse_grids() {
    let bunny = shared("stanford-bunny.obj");
    let (dense_png, tiled_png) = (tmp("preview-dense.png"), tmp("preview-tiled.png"));
    for (png, extra) in [(&dense_png, None), (&tiled_png, Some("64"))] {
        let out = tmp("preview-run.vdb");
        let mut args = vec!["voxelize", bunny.as_str(), "-o", out.as_str(), "--resolution", "200", "--preview", png.as_str(), "--json"];
        if let Some(t) = extra {
            args.extend(["--tile", t]);
        }
        let v = json(&topovox(&args));
        assert_eq!(v["tile"].is_null(), extra.is_none(), "{v}");
    }
    assert_eq!(std::fs::read(&dense_png).unwrap(), std::fs::read(&tiled_png).unwrap(), "tiled preview differs");
    let cube = unit_cube_obj("render-sparse-cube.obj");
    let big = tmp("render-big.vdb");
    let grid = ["--voxel-size", "0.004", "--origin", "-40,-40,-40", "--dims", "20000,20000,20000"];
    json(&topovox(&[&["voxelize", cube.as_str(), "-o", &big, "--json"][..], &grid[..]].concat()));
    let r = json(&topovox(&["render", &big, "-o", &tmp("render-big.png"), "--json"]));
    assert_eq!(r["dims"], serde_json::json!([20000, 20000, 20000]));
    assert!(r["covered_pixels"].as_u64().unwrap() > 0, "{r}");
}

/// Attributes past memory: a textured mesh in a 20000³ grid runs tiled and
/// carries `--attributes` into `.vdb`; `convert` reads them back without a
/// dense grid into `.zarr` (a group with the attribute arrays) and back
/// into the very same `.vdb`.
#[test]
fn attributes_past_memory_round_trip() {
    let spot = shared("spot-textured.obj");
    let (v, z, v2) = (tmp("attrs-big.vdb"), tmp("attrs-big.zarr"), tmp("attrs-big2.vdb"));
    let grid = ["--voxel-size", "0.02", "--origin", "-200,-200,-200", "--dims", "20000,20000,20000"];
    let j = json(&topovox(&[&["voxelize", spot.as_str(), "-o", &v, "--attributes", "--json"][..], &grid[..]].concat()));
    assert!(j["tile"].as_u64().is_some() && j["attributes"]["colour"] == true, "{j}");
    let c = topovox(&["convert", &v, &z, "--json"]);
    assert!(c.status.success() && c.stderr.is_empty(), "{}", String::from_utf8_lossy(&c.stderr));
    assert!(std::path::Path::new(&z).join("colour/zarr.json").is_file(), "no colour array");
    let c = topovox(&["convert", &z, &v2, "--json"]);
    assert!(c.status.success() && c.stderr.is_empty(), "{}", String::from_utf8_lossy(&c.stderr));
    assert_eq!(std::fs::read(&v).unwrap(), std::fs::read(&v2).unwrap(), ".vdb -> .zarr -> .vdb lost attributes");
}

/// `--method gpu` runs tile by tile (`--tile`, or past memory): each tile's
/// triangles, snapped once to the whole grid, on the GPU — the fast path's
/// voxels, byte for byte, for every GPU mode and both exact paths.
#[test]
fn gpu_tiles_give_the_fast_paths_voxels() {
    let bunny = shared("stanford-bunny.obj");
    for (mode, path) in [("cover", "compute"), ("sep26", "raster"), ("sep6", "compute")] {
        let (a, b) = (tmp(&format!("gpu-tiled-fast-{mode}.npy")), tmp(&format!("gpu-tiled-{mode}.npy")));
        let common = ["--resolution", "120", "--mode", mode, "--json"];
        json(&topovox(&[&["voxelize", bunny.as_str(), "-o", &a, "--method", "fast"][..], &common[..]].concat()));
        let out = topovox(
            &[&["voxelize", bunny.as_str(), "-o", &b, "--method", "gpu", "--gpu-path", path, "--tile", "48"][..], &common[..]].concat(),
        );
        if !gpu_available(&out) {
            return;
        }
        let t = json(&out);
        assert_eq!(
            (&t["tile"], &t["tile_kernel"], &t["method"]),
            (&serde_json::json!(48), &serde_json::json!("gpu"), &serde_json::json!("tiled"))
        );
        assert!(t["gpu"]["tiles"].as_u64().unwrap() > 8, "{}", t["gpu"]);
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "{mode} {path}: GPU tiles differ from the fast path");
    }
}
