//! `topovox raster` end to end: every mode writes PNG and .npy, fast equals
//! reference, explicit grids, and one-line errors for what it refuses.

use std::path::PathBuf;
use std::process::{Command, Output};

fn topovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_topovox")).args(args).output().expect("run topovox")
}

fn tmp(name: &str) -> String {
    let d = std::env::temp_dir().join(format!("topovox-raster-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name).to_string_lossy().into_owned()
}

fn example() -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/svg/shapes.svg").to_string_lossy().into_owned()
}

#[test]
fn every_mode_to_png_and_npy_fast_equals_reference() {
    for mode in ["curve4", "curve8", "diamond", "fill"] {
        let (f, r, png) = (tmp(&format!("{mode}-f.npy")), tmp(&format!("{mode}-r.npy")), tmp(&format!("{mode}.png")));
        for (out, method) in [(&f, "fast"), (&r, "reference"), (&png, "fast")] {
            let o = topovox(&["raster", &example(), "-o", out, "--mode", mode, "--resolution", "80", "--method", method, "--json"]);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        }
        let (a, b) = (std::fs::read(&f).unwrap(), std::fs::read(&r).unwrap());
        assert!(a == b, "{mode}: fast and reference files differ");
        // npy header: shape (W, H).
        let header = String::from_utf8_lossy(&a[10..80]).into_owned();
        assert!(header.contains("'shape': (80, "), "{header}");
        assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    }
}

#[test]
fn explicit_grid_and_errors() {
    let out = tmp("e.npy");
    let o = topovox(&["raster", &example(), "-o", &out, "--origin=-10,0", "--pixel-size", "2", "--dims", "70,40", "--json"]);
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["dims"], serde_json::json!([70, 40]));
    let bad = tmp("bad.svg");
    for (svg, want) in [
        ("<svg><use href='#a'/></svg>", "<use>"),
        ("<svg><rect width='2' height='3' rx='1'/></svg>", "rounded"),
        ("<svg><path d='M 0 0 L 1'/></svg>", "path"),
        ("not an svg", "malformed SVG"),
    ] {
        std::fs::write(&bad, svg).unwrap();
        let o = topovox(&["raster", &bad, "-o", &out]);
        assert!(!o.status.success(), "{svg}");
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(want) && err.contains("bad.svg"), "{svg}: {err}");
    }
    let o = topovox(&["raster", &example(), "-o", &tmp("x.jpg")]);
    assert!(String::from_utf8_lossy(&o.stderr).contains(".png or .npy"));
}
