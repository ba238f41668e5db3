//! Extreme coordinates through every command (issue 65): a mesh at any
//! scale or offset gives a one-line refusal or a correct result, never a
//! panic, and every mesh `remesh` writes passes `topovox check`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn topovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_topovox")).args(args).output().expect("run topovox")
}

fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("topovox-extremes-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A closed tetrahedron, each vertex `v · scale + offset`, as an OBJ.
fn tetra(path: &Path, scale: f64, offset: f64) {
    let mut s = String::new();
    for v in [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] {
        let p = v.map(|c: f64| c * scale + offset);
        s += &format!("v {:e} {:e} {:e}\n", p[0], p[1], p[2]);
    }
    s += "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    std::fs::write(path, s).unwrap();
}

/// Exit 0, or exit 1 with one line naming the input; never a panic (101).
fn answered(out: &Output, what: &str) -> bool {
    let err = String::from_utf8_lossy(&out.stderr);
    let code = out.status.code();
    assert!(code == Some(0) || code == Some(1), "{what}: exit {code:?}: {err}");
    if code == Some(1) {
        let lines: Vec<&str> = err.lines().filter(|l| !l.starts_with("topovox: warning")).collect();
        assert_eq!(lines.len(), 1, "{what}: not one line: {err}");
        assert!(!err.contains("internal error") && !err.contains("panicked"), "{what}: {err}");
    }
    code == Some(0)
}

#[test]
fn every_command_answers_extreme_scales_and_offsets() {
    let d = folder("tetras");
    let cases: &[(&str, f64, f64)] = &[
        ("huge", 1e308, 0.0),
        ("max", 1.7e308, 0.0),
        ("past-range", 1e31, 0.0),
        ("in-range", 1e29, 0.0),
        ("tiny", 1e-300, 0.0),
        ("small", 1e-25, 0.0),
        ("far", 1.0, 1e15),
        ("far-f32", 1.0, 5e4),
        ("near-f32", 1.0, 1.9e3),
        ("negative-far", 1.0, -3e11),
        ("span", 1.5e308, -1e308),
    ];
    for &(name, scale, offset) in cases {
        let m = d.join(format!("{name}.obj"));
        tetra(&m, scale, offset);
        let o = |f: &str| d.join(format!("{name}-{f}")).to_str().unwrap().to_string();
        let ms = m.to_str().unwrap();
        for args in [
            vec!["voxelize", ms, "-o", &o("v.npy"), "--mode", "solid", "--resolution", "24"],
            vec!["voxelize", ms, "-o", &o("c.vdb"), "--resolution", "24"],
            vec!["sdf", ms, "-o", &o("f.npy"), "--resolution", "24"],
            vec!["sample", ms, "-o", &o("s.npz"), "--near", "200", "--uniform", "100", "--surface", "50"],
            vec!["info", ms],
            vec!["check", ms],
        ] {
            answered(&topovox(&args), &format!("{name} {}", args[0]));
        }
        for (style, out) in [
            (vec!["--check"], o("r.ply")),
            (vec!["--check"], o("r.glb")),
            (vec!["--inside", "wrap"], o("w.glb")),
            (vec!["--inside", "wrap"], o("w.obj")),
            (vec!["--surface", "blocky"], o("b.ply")),
            (vec!["--surface", "blocky"], o("b.stl")),
        ] {
            let mut args = vec!["remesh", ms, "-o", &out, "--resolution", "24", "--quiet"];
            args.extend(style.iter().copied());
            if answered(&topovox(&args), &format!("{name} remesh {style:?} {out}")) {
                let c = topovox(&["check", &out, "--json"]);
                let text = String::from_utf8_lossy(&c.stdout);
                assert!(
                    c.status.success() && text.contains("\"watertight\":true"),
                    "{name} {out}: {text}{}",
                    String::from_utf8_lossy(&c.stderr)
                );
            }
        }
    }
}

#[test]
fn training_samples_that_would_not_be_finite_are_refused() {
    let d = folder("sigma");
    let m = d.join("t.obj");
    tetra(&m, 1.0, 0.0);
    let ms = m.to_str().unwrap();
    let out = d.join("s.npz");
    let os = out.to_str().unwrap();
    for args in [
        vec!["sample", ms, "-o", os, "--near", "10", "--sigma", "1e308"],
        vec!["sample", ms, "-o", os, "--near", "10", "--sigma", "0.01,1e200"],
        vec!["sample", ms, "-o", os, "--near", "0", "--uniform", "10", "--bounds", "-1e308,-1e308,-1e308,1e308,1e308,1e308"],
        vec!["sample", ms, "-o", os, "--near", "0", "--uniform", "10", "--bounds", "0,0,0,1e39,1,1"],
    ] {
        assert!(!answered(&topovox(&args), &format!("{args:?}")), "{args:?} was accepted");
        assert!(!out.exists(), "{args:?} wrote a file");
    }
}
