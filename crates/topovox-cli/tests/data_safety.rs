//! Never destroy what the user has (issue 18): outputs that would overwrite
//! inputs by any spelling are refused, special files are written in place,
//! external files a model names are read only inside its folder, and a
//! successful run is quiet.

#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn topovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_topovox")).args(args).output().expect("run topovox")
}

fn topovox_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_topovox")).current_dir(dir).args(args).output().expect("run topovox")
}

/// A fresh folder for one test.
fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("topovox-safety-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn shared(name: &str) -> PathBuf {
    let p = topovox_testkit::shared_meshes_dir().join(name);
    assert!(p.exists(), "missing {}", p.display());
    p
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The single error line of a failed run.
fn refused(out: &Output) -> String {
    assert!(!out.status.success(), "succeeded: {}", String::from_utf8_lossy(&out.stdout));
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    let lines: Vec<&str> = err.lines().filter(|l| !l.starts_with("topovox: warning")).collect();
    assert_eq!(lines.len(), 1, "expected one error line: {err:?}");
    lines[0].to_string()
}

#[test]
fn output_over_the_input_is_refused_by_every_spelling() {
    let d = folder("same");
    let mesh = d.join("bunny.obj");
    std::fs::copy(shared("cow.obj"), &mesh).unwrap();
    let before = std::fs::read(&mesh).unwrap();
    std::os::unix::fs::symlink(&mesh, d.join("link.obj")).unwrap();
    std::fs::hard_link(&mesh, d.join("hard.obj")).unwrap();
    for out in ["bunny.obj", "./bunny.obj", "link.obj", "hard.obj", "../", "sub/../bunny.obj"] {
        if out == "../" {
            continue;
        }
        std::fs::create_dir_all(d.join("sub")).unwrap();
        let line = refused(&topovox_in(&d, &["voxelize", "bunny.obj", "-o", out, "--resolution", "16"]));
        assert!(line.contains("same file as the input") && line.contains(out.trim_start_matches("./")), "{out}: {line}");
        assert_eq!(std::fs::read(&mesh).unwrap(), before, "{out}: the input changed");
    }
    // The absolute path too.
    refused(&topovox(&["voxelize", s(&mesh), "-o", s(&mesh), "--resolution", "16"]));
    assert_eq!(std::fs::read(&mesh).unwrap(), before);
}

#[test]
fn convert_refuses_its_input() {
    let d = folder("convert");
    let v = d.join("v.binvox");
    assert!(topovox(&["voxelize", s(&shared("cow.obj")), "-o", s(&v), "--resolution", "16", "--quiet"]).status.success());
    let before = std::fs::read(&v).unwrap();
    std::os::unix::fs::symlink(&v, d.join("v2.binvox")).unwrap();
    refused(&topovox(&["convert", s(&v), s(&d.join("v2.binvox"))]));
    refused(&topovox_in(&d, &["convert", "v.binvox", "./v.binvox"]));
    assert_eq!(std::fs::read(&v).unwrap(), before);
}

#[test]
fn outputs_over_the_mtl_or_texture_the_mesh_uses_are_refused() {
    let d = folder("mtl");
    for f in ["spot-textured.obj", "spot.mtl", "spot_texture.png"] {
        std::fs::copy(shared(f), d.join(f)).unwrap();
    }
    let mtl = std::fs::read(d.join("spot.mtl")).unwrap();
    // `-o spot.obj` writes spot.mtl beside it: the input's material library.
    let line = refused(&topovox_in(&d, &["voxelize", "spot-textured.obj", "-o", "spot.obj", "--resolution", "16"]));
    assert!(line.contains("spot.mtl") && line.contains("same file as the input"), "{line}");
    assert_eq!(std::fs::read(d.join("spot.mtl")).unwrap(), mtl);
    let png = std::fs::read(d.join("spot_texture.png")).unwrap();
    refused(&topovox_in(&d, &["voxelize", "spot-textured.obj", "-o", "x.npy", "--preview", "spot_texture.png", "--resolution", "16"]));
    refused(&topovox_in(&d, &["voxelize", "spot-textured.obj", "-o", "spot.mtl", "--format", "txt", "--resolution", "16"]));
    assert_eq!(std::fs::read(d.join("spot_texture.png")).unwrap(), png);
    assert_eq!(std::fs::read(d.join("spot.mtl")).unwrap(), mtl);
    // Another name works.
    assert!(topovox_in(&d, &["voxelize", "spot-textured.obj", "-o", "voxels.obj", "--resolution", "16", "--quiet"]).status.success());
    assert!(d.join("voxels.mtl").exists());
}

#[test]
fn special_files_are_written_in_place() {
    let cow = shared("cow.obj");
    // /dev/null stays a device.
    let out = topovox(&["voxelize", s(&cow), "-o", "/dev/null", "--format", "npy", "--resolution", "16", "--quiet"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata("/dev/null").unwrap().file_type().is_char_device());
    // /dev/full fails with "no space left".
    if Path::new("/dev/full").exists() {
        let line = refused(&topovox(&["voxelize", s(&cow), "-o", "/dev/full", "--format", "npy", "--resolution", "16"]));
        assert!(line.to_lowercase().contains("no space left"), "{line}");
        assert!(std::fs::metadata("/dev/full").unwrap().file_type().is_char_device());
    }
    // A FIFO gets the bytes, and stays a FIFO.
    let d = folder("fifo");
    let fifo = d.join("pipe");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let reader = {
        let f = fifo.clone();
        std::thread::spawn(move || std::fs::read(f).unwrap())
    };
    let out = topovox(&["voxelize", s(&cow), "-o", s(&fifo), "--format", "npy", "--resolution", "16", "--quiet"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let got = reader.join().unwrap();
    assert!(got.starts_with(b"\x93NUMPY"));
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
}

#[test]
fn dash_is_standard_output() {
    let cow = shared("cow.obj");
    let file = folder("stdout").join("cow.npy");
    assert!(topovox(&["voxelize", s(&cow), "-o", s(&file), "--resolution", "16", "--quiet"]).status.success());
    let out = topovox(&["voxelize", s(&cow), "-o", "-", "--format", "npy", "--resolution", "16"]);
    assert!(out.status.success());
    assert_eq!(out.stdout, std::fs::read(&file).unwrap(), "stdout holds exactly the file's bytes");
    assert!(String::from_utf8_lossy(&out.stderr).contains("voxels set"), "the summary goes to stderr");
    let line = refused(&topovox(&["voxelize", s(&cow), "-o", "-", "--resolution", "16"]));
    assert!(line.contains("--format"), "{line}");
}

#[test]
fn gltf_buffers_outside_the_folder_are_an_error() {
    let d = folder("gltf");
    let inner = d.join("model");
    std::fs::create_dir_all(&inner).unwrap();
    // A real buffer one folder up: 3 vertices and 3 indices.
    let mut bin = Vec::new();
    for v in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
        for c in v {
            bin.extend(c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2] {
        bin.extend(i.to_le_bytes());
    }
    std::fs::write(d.join("outside.bin"), &bin).unwrap();
    let gltf = gltf_naming;
    let escaping = inner.join("escape.gltf");
    std::fs::write(&escaping, gltf("../outside.bin")).unwrap();
    let line = refused(&topovox(&["voxelize", s(&escaping), "-o", s(&d.join("o.npy")), "--resolution", "8"]));
    assert!(line.contains("outside the model's folder") && line.contains("--allow-external-paths"), "{line}");
    let hostname = inner.join("host.gltf");
    std::fs::write(&hostname, gltf("../../../../../../../../etc/hostname")).unwrap();
    refused(&topovox(&["voxelize", s(&hostname), "-o", s(&d.join("o.npy")), "--resolution", "8"]));
    let absolute = inner.join("abs.gltf");
    std::fs::write(&absolute, gltf(s(&d.join("outside.bin")))).unwrap();
    refused(&topovox(&["voxelize", s(&absolute), "-o", s(&d.join("o.npy")), "--resolution", "8"]));
    // Allowed when asked for.
    let ok = topovox(&["voxelize", s(&escaping), "-o", s(&d.join("o.npy")), "--resolution", "8", "--allow-external-paths", "--quiet"]);
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    // Inside the folder is fine.
    std::fs::copy(d.join("outside.bin"), inner.join("in.bin")).unwrap();
    let fine = inner.join("fine.gltf");
    std::fs::write(&fine, gltf("in.bin")).unwrap();
    assert!(topovox(&["voxelize", s(&fine), "-o", s(&d.join("o.npy")), "--resolution", "8", "--quiet"]).status.success());
}

#[test]
fn obj_materials_and_textures_outside_the_folder_are_warnings() {
    let d = folder("objext");
    let inner = d.join("m");
    std::fs::create_dir_all(&inner).unwrap();
    std::fs::copy(shared("spot_texture.png"), d.join("tex.png")).unwrap();
    std::fs::write(d.join("up.mtl"), "newmtl a\nKd 1 0 0\nmap_Kd tex.png\n").unwrap();
    std::fs::write(inner.join("in.mtl"), "newmtl a\nKd 1 0 0\nmap_Kd ../tex.png\n").unwrap();
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n";
    std::fs::write(inner.join("lib.obj"), format!("mtllib ../up.mtl\n{tri}")).unwrap();
    std::fs::write(inner.join("tex.obj"), format!("mtllib in.mtl\n{tri}")).unwrap();
    std::fs::write(inner.join("abs.obj"), format!("mtllib {}\n{tri}", s(&d.join("up.mtl")))).unwrap();
    for (name, what) in [("lib.obj", "material library"), ("tex.obj", "tex.png"), ("abs.obj", "material library")] {
        let out = topovox(&["voxelize", s(&inner.join(name)), "-o", s(&d.join("o.vox")), "--resolution", "8", "--quiet"]);
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("outside the model's folder") && err.contains(what), "{name}: {err}");
        let allowed = topovox(&[
            "voxelize",
            s(&inner.join(name)),
            "-o",
            s(&d.join("o.vox")),
            "--resolution",
            "8",
            "--quiet",
            "--allow-external-paths",
        ]);
        assert!(allowed.status.success() && !String::from_utf8_lossy(&allowed.stderr).contains("outside"), "{name}");
    }
}

#[test]
fn a_successful_run_prints_nothing_on_stderr() {
    let d = folder("quiet");
    for res in ["64", "512"] {
        let out = Command::new(env!("CARGO_BIN_EXE_topovox"))
            .env_remove("XDG_RUNTIME_DIR")
            .args(["voxelize", s(&shared("stanford-bunny.obj")), "-o", s(&d.join("b.npy")), "--resolution", res])
            .output()
            .unwrap();
        assert!(out.status.success());
        assert_eq!(String::from_utf8_lossy(&out.stderr), "", "at {res}");
    }
}

/// A glTF whose one buffer is `uri` (42 bytes declared, three vertices).
fn gltf_naming(uri: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"{uri}","byteLength":42}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                     {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
        "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#
    )
}

#[test]
fn file_uris_to_system_files_are_refused_by_every_command() {
    let d = folder("file-uri");
    for (k, uri) in
        ["file:///etc/passwd", "file:///proc/self/environ", "FILE://localhost/etc/passwd", "file:/etc/hostname", "file:///dev/zero"]
            .iter()
            .enumerate()
    {
        let m = d.join(format!("m{k}.gltf"));
        std::fs::write(&m, gltf_naming(uri)).unwrap();
        let o = |name: &str| d.join(name).to_str().unwrap().to_string();
        let runs: Vec<Vec<String>> = vec![
            vec!["voxelize".into(), s(&m).into(), "-o".into(), o("v.npy"), "--resolution".into(), "8".into()],
            vec!["sdf".into(), s(&m).into(), "-o".into(), o("f.npy"), "--resolution".into(), "8".into()],
            vec!["sample".into(), s(&m).into(), "-o".into(), o("s.npz"), "--near".into(), "10".into()],
            vec!["remesh".into(), s(&m).into(), "-o".into(), o("r.ply"), "--resolution".into(), "8".into()],
            vec!["info".into(), s(&m).into()],
            vec!["check".into(), s(&m).into()],
        ];
        for run in runs {
            let args: Vec<&str> = run.iter().map(String::as_str).collect();
            let line = refused(&topovox(&args));
            assert!(line.contains("outside the model's folder") && line.contains("--allow-external-paths"), "{uri} {}: {line}", run[0]);
            assert!(!line.contains("refers to vertex") && !line.contains("root"), "{uri}: {line}");
        }
    }
}

#[test]
fn a_fifo_or_device_as_the_input_is_refused_not_waited_on() {
    let d = folder("fifo-input");
    let fifo = d.join("pipe.obj");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let zero = d.join("zero.stl");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    for input in [&fifo, &zero] {
        for cmd in ["voxelize", "sdf", "remesh", "info"] {
            let mut args = vec![cmd, s(input)];
            let out = d.join(if cmd == "remesh" { "o.ply" } else { "o.npy" });
            if cmd != "info" {
                args.extend(["-o", s(&out), "--resolution", "8"]);
            }
            let mut child = Command::new(env!("CARGO_BIN_EXE_topovox"))
                .args(&args)
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap();
            let start = std::time::Instant::now();
            while child.try_wait().unwrap().is_none() {
                if start.elapsed() > std::time::Duration::from_secs(30) {
                    let _ = child.kill();
                    panic!("{cmd} {} waited on it", input.display());
                }
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            let line = refused(&child.wait_with_output().unwrap());
            assert!(line.contains("not a regular file"), "{cmd}: {line}");
        }
    }
}

#[test]
fn names_with_control_and_bidirectional_characters_are_escaped_in_one_line() {
    let d = folder("names");
    for name in ["two\nlines.obj", "tab\there.obj", "rev\u{202e}lbo.obj", "bell\u{7}.obj"] {
        let p = d.join(name);
        std::fs::write(&p, "v 0 0 0\nf 1 2 3\n").unwrap();
        let line = refused(&topovox(&["voxelize", s(&p), "-o", s(&d.join("o.npy")), "--resolution", "8"]));
        assert!(!line.contains(['\n', '\t', '\u{202e}', '\u{7}']), "{line:?}");
        assert!(line.contains("\\n") || line.contains("\\t") || line.contains("\\u{202e}") || line.contains("\\u{7}"), "{line:?}");
    }
}

#[test]
fn memory_sizes_too_large_say_so() {
    let d = folder("max-memory");
    let m = d.join("t.obj");
    std::fs::write(&m, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    for size in ["18446744073709551615", "99999999999T", "2000T"] {
        let line = refused(&topovox(&["voxelize", s(&m), "-o", s(&d.join("o.npy")), "--max-memory", size]));
        assert!(line.contains("too large"), "{size}: {line}");
    }
    let line = refused(&topovox(&["voxelize", s(&m), "-o", s(&d.join("o.npy")), "--max-memory", "10K"]));
    assert!(line.contains("at least 1M"), "{line}");
}
