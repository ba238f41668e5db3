//! Every way a glTF model names another file obeys the one folder rule
//! (issue 65): `file:` URIs in any spelling, percent-encoded paths,
//! absolute paths and links are read only inside the model's folder
//! unless external paths are allowed; only regular files are read, never
//! past a buffer's `byteLength`; `data:` URIs stay allowed; and no message
//! quotes the bytes of a file the user did not name.

#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::time::Duration;

use topovox_io::{read_mesh, ReadOptions};

/// A fresh folder for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("topovox-uris-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Three vertices and three `u16` indices: 42 bytes.
fn triangle_buffer() -> Vec<u8> {
    let mut bin = Vec::new();
    for c in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        bin.extend(c.to_le_bytes());
    }
    for i in [0u16, 1, 2] {
        bin.extend(i.to_le_bytes());
    }
    bin
}

/// A glTF document whose one buffer has `uri` (42 bytes declared) and
/// whose image, if given, has `image`.
fn gltf(uri: &str, image: Option<&str>) -> String {
    let uri = serde_json::to_string(uri).unwrap();
    let images = match image {
        Some(i) => format!(
            r#","images":[{{"uri":{}}}],"textures":[{{"source":0}}],"materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}}}}}}]"#,
            serde_json::to_string(i).unwrap()
        ),
        None => String::new(),
    };
    let material = if image.is_some() { r#","material":0"# } else { "" };
    format!(
        r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":{uri},"byteLength":42}}],
        "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                     {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1{material}}}]}}],
        "nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0{images}}}"#
    )
}

/// Every byte of `s` as `%XX`.
fn percent_all(s: &str) -> String {
    s.bytes().map(|b| format!("%{b:02X}")).collect()
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            out.push(if k <= c.len() { A[(n >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    out
}

const ALLOW: ReadOptions = ReadOptions { allow_external_paths: true, up: topovox_io::orient::Up::Y, attributes: false, max_memory: None };

/// Reads `text` as `dir/model/NAME.gltf` on a thread, failing the test if
/// it takes a minute (a FIFO or a device would hang an unguarded read).
fn read(dir: &Path, name: &str, text: &str, opts: ReadOptions) -> Result<topovox_io::LoadedMesh, String> {
    let path = dir.join("model").join(format!("{name}.gltf"));
    std::fs::write(&path, text).unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(read_mesh(&path, &opts).map_err(|e| e.to_string()));
    });
    rx.recv_timeout(Duration::from_secs(60)).expect("hung: no answer within a minute")
}

/// `d/outside.bin` (the buffer) beside `d/model/`, the model's folder.
fn layout(name: &str) -> (PathBuf, PathBuf) {
    let d = scratch(name);
    std::fs::create_dir_all(d.join("model")).unwrap();
    let outside = d.join("outside.bin");
    std::fs::write(&outside, triangle_buffer()).unwrap();
    (d, outside)
}

#[test]
fn file_uris_outside_the_folder_are_refused_in_every_spelling() {
    let (d, outside) = layout("file-uris");
    let abs = outside.to_str().unwrap();
    std::os::unix::fs::symlink(&outside, d.join("model/link.bin")).unwrap();
    std::fs::create_dir_all(d.join("model/sub")).unwrap();
    let spellings = [
        format!("file://{abs}"),
        format!("file:{abs}"),
        format!("file://localhost{abs}"),
        format!("FILE://{abs}"),
        format!("File:{abs}"),
        format!("file://LOCALHOST{abs}"),
        format!("file:///{}", percent_all(&abs[1..])),
        format!("file:{}", percent_all(abs)),
        format!("file:{abs}?query#fragment"),
        abs.to_string(),
        percent_all(abs),
        "../outside.bin".to_string(),
        "%2E%2E/outside.bin".to_string(),
        "%2e%2e%2foutside.bin".to_string(),
        "link.bin".to_string(),
        "./sub/../../outside.bin".to_string(),
    ];
    for (k, uri) in spellings.iter().enumerate() {
        let e = read(&d, &format!("m{k}"), &gltf(uri, None), ReadOptions::default()).unwrap_err();
        assert!(e.contains("outside the model's folder") && e.contains("--allow-external-paths"), "{uri}: {e}");
        let m = read(&d, &format!("m{k}"), &gltf(uri, None), ALLOW).unwrap_or_else(|e| panic!("{uri} allowed: {e}"));
        assert_eq!(m.mesh.triangles.len(), 1, "{uri}");
        assert!(m.sources.iter().any(|p| p == &std::fs::canonicalize(&outside).unwrap()), "{uri}: {:?}", m.sources);
    }
}

#[test]
fn system_files_are_never_read_and_never_quoted() {
    let (d, _) = layout("system");
    for uri in ["file:///etc/passwd", "file:///proc/self/environ", "file://localhost/etc/hostname", "/etc/passwd", "file:/etc/passwd"] {
        let e = read(&d, "sys", &gltf(uri, None), ReadOptions::default()).unwrap_err();
        assert!(e.contains("outside the model's folder"), "{uri}: {e}");
        assert!(!e.contains("root:") && !e.contains("refers to vertex"), "{uri}: {e}");
    }
    // Allowed, /etc/passwd is read but none of its bytes appear in the
    // message: its text makes indices far past the three vertices.
    let e = read(&d, "sys", &gltf("file:///etc/passwd", None), ALLOW).unwrap_err();
    assert!(e.contains("refers past its 3 vertices") || e.contains("fewer than"), "{e}");
    let (_, said) = e.split_once(".gltf: ").unwrap();
    let numbers: Vec<u64> = said.split(|c: char| !c.is_ascii_digit()).filter_map(|w| w.parse().ok()).collect();
    assert!(numbers.iter().all(|&n| n <= 42), "a number from the file's bytes: {e}");
    // A /proc file reports no length: it holds "0 bytes", fewer than declared.
    let e = read(&d, "proc", &gltf("file:///proc/self/environ", None), ALLOW).unwrap_err();
    assert!(e.contains("fewer than the 42"), "{e}");
}

#[test]
fn devices_and_fifos_are_refused_even_when_external_paths_are_allowed() {
    let (d, _) = layout("devices");
    let fifo = d.join("model/pipe.bin");
    assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    for uri in ["file:///dev/zero", "/dev/zero", "file:///dev/urandom", "pipe.bin", "file:///dev/stdin", "."] {
        for opts in [ReadOptions::default(), ALLOW] {
            let e = read(&d, "dev", &gltf(uri, None), opts).unwrap_err();
            assert!(e.contains("not a regular file") || e.contains("outside the model's folder"), "{uri}: {e}");
        }
    }
}

#[test]
fn a_buffer_is_read_to_its_byte_length_and_no_further() {
    let (d, _) = layout("length");
    let mut long = triangle_buffer();
    long.extend(vec![7u8; 1 << 20]);
    std::fs::write(d.join("model/long.bin"), &long).unwrap();
    let m = read(&d, "long", &gltf("long.bin", None), ReadOptions::default()).unwrap();
    assert_eq!(m.mesh.triangles.len(), 1);
    std::fs::write(d.join("model/short.bin"), &triangle_buffer()[..40]).unwrap();
    let e = read(&d, "short", &gltf("short.bin", None), ReadOptions::default()).unwrap_err();
    assert!(e.contains("fewer than the 42"), "{e}");
}

#[test]
fn data_uris_inside_paths_and_file_uris_inside_the_folder_are_read() {
    let (d, _) = layout("inside");
    std::fs::copy(d.join("outside.bin"), d.join("model/in side.bin")).unwrap();
    let inside = std::fs::canonicalize(d.join("model/in side.bin")).unwrap();
    let encoded = format!("data:application/octet-stream;base64,{}", base64(&triangle_buffer()));
    for uri in [
        encoded.clone(),
        encoded.replacen("data:", "DATA:", 1),
        "in%20side.bin".into(),
        "in side.bin".into(),
        format!("file://{}", inside.to_str().unwrap().replace(' ', "%20")),
        inside.to_str().unwrap().to_string(),
    ] {
        let m = read(&d, "in", &gltf(&uri, None), ReadOptions::default()).unwrap_or_else(|e| panic!("{uri}: {e}"));
        assert_eq!(m.mesh.triangles.len(), 1, "{uri}");
    }
}

#[test]
fn other_schemes_and_hosts_are_refused() {
    let (d, _) = layout("schemes");
    for (uri, says) in [
        ("http://example.com/a.bin", "scheme"),
        ("https://example.com/a.bin", "scheme"),
        ("ftp://example.com/a.bin", "scheme"),
        ("file://otherhost/etc/passwd", "host"),
        ("file:relative.bin", "absolute path"),
        ("file://%2Fetc%2Fpasswd", "host"),
    ] {
        for opts in [ReadOptions::default(), ALLOW] {
            let e = read(&d, "s", &gltf(uri, None), opts).unwrap_err();
            assert!(e.contains(says) && e.lines().count() == 1, "{uri}: {e}");
        }
    }
}

#[test]
fn images_obey_the_same_rule_as_a_warning() {
    let (d, _) = layout("images");
    std::fs::copy(d.join("outside.bin"), d.join("model/in.bin")).unwrap();
    let png = topovox_testkit_free_png();
    std::fs::write(d.join("outside.png"), &png).unwrap();
    std::fs::write(d.join("model/in.png"), &png).unwrap();
    let abs = std::fs::canonicalize(d.join("outside.png")).unwrap();
    for uri in [format!("file://{}", abs.display()), "file:///etc/passwd".into(), "../outside.png".into(), percent_all("../outside.png")] {
        let m = read(&d, "img", &gltf("in.bin", Some(&uri)), ReadOptions::default()).unwrap();
        assert!(m.warnings.iter().any(|w| w.contains("outside the model's folder")), "{uri}: {:?}", m.warnings);
        assert!(m.appearance.textures.is_empty(), "{uri}");
    }
    let m = read(&d, "img", &gltf("in.bin", Some("file:///dev/zero")), ALLOW).unwrap();
    assert!(m.warnings.iter().any(|w| w.contains("not a regular file")), "{:?}", m.warnings);
    let m = read(&d, "img", &gltf("in.bin", Some("in.png")), ReadOptions::default()).unwrap();
    assert_eq!(m.appearance.textures.len(), 1, "{:?}", m.warnings);
    let m = read(&d, "img", &gltf("in.bin", Some(&format!("file://{}", abs.display()))), ALLOW).unwrap();
    assert_eq!(m.appearance.textures.len(), 1, "{:?}", m.warnings);
}

/// A 2×1 RGB PNG, encoded by the `image` crate's writer in topovox-io.
fn topovox_testkit_free_png() -> Vec<u8> {
    let p = scratch("png-maker").join("t.png");
    topovox_io::write_png(&p, 2, 1, &[255, 0, 0, 0, 255, 0]).unwrap();
    std::fs::read(p).unwrap()
}
