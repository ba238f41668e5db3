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

#[test]
fn fill_paints_only_what_the_svg_fills() {
    // The reported case: a filled polygon, a filled path and a stroke-only
    // spiral. `fill` sets exactly the two filled shapes' pixels; the curve
    // modes still draw the spiral.
    let spiral: Vec<String> = (0..80)
        .map(|k| {
            let (a, r) = (k as f64 * 0.3, 2.0 + k as f64 * 0.45);
            format!("{:.3},{:.3}", 60.0 + r * a.cos(), 40.0 + r * a.sin())
        })
        .collect();
    let shapes = r#"<polygon points="5,5 35,5 20,30" fill="red"/><path d="M 70 50 h 30 v 25 h -30 z M 78 58 h 10 v 10 h -10 z" style="fill-rule:evenodd"/>"#;
    let all = tmp("painted.svg");
    std::fs::write(&all, format!(r#"<svg>{shapes}<polyline points="{}" fill="none" stroke="black"/></svg>"#, spiral.join(" "))).unwrap();
    let filled = tmp("filled.svg");
    std::fs::write(&filled, format!("<svg>{shapes}</svg>")).unwrap();
    let grid = ["--origin", "0,0", "--pixel-size", "0.5", "--dims", "220,180"];
    let run = |svg: &str, mode: &str, method: &str| -> serde_json::Value {
        let out = tmp(&format!("painted-{mode}-{method}.npy"));
        let o = topovox(&[&["raster", svg, "-o", &out, "--mode", mode, "--method", method, "--json"][..], &grid].concat());
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice(&o.stdout).unwrap()
    };
    for method in ["fast", "reference"] {
        let (a, b) = (run(&all, "fill", method), run(&filled, "fill", method));
        assert_eq!(a["pixels"], b["pixels"], "{method}");
        assert_eq!((a["outlines"].as_u64(), a["unfilled_outlines_left_out"].as_u64()), (Some(3), Some(1)));
        // 30×25 minus the evenodd hole 10×10, plus the triangle, in 0.5 px.
        let px = a["pixels"].as_u64().unwrap();
        assert!((4 * (750 - 100) + 4 * 375 - 300..4 * (750 - 100) + 4 * 375 + 300).contains(&px), "{px}");
    }
    assert!(run(&all, "curve8", "fast")["pixels"].as_u64() > run(&filled, "curve8", "fast")["pixels"].as_u64());
    let o = topovox(&[&["raster", &all, "-o", &tmp("painted.png"), "--mode", "fill"][..], &grid].concat());
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(text.contains("from 3 outlines (1 unfilled left out)"), "{text}");
}
