//! Loading is counted like every other step (#65): a mesh whose reading
//! would hold more than `max_memory` is refused before it is parsed, from
//! the counts its file declares or its lines; a lying header stays the
//! reader's own error.

use std::path::{Path, PathBuf};

/// A fresh folder for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("topovox-load-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

use topovox_io::{read_mesh, ErrorKind, ReadOptions};

/// A binary STL of `n` triangles (no shared vertices: a soup).
fn binary_stl(path: &Path, n: u32) {
    let mut b = vec![0u8; 80];
    b.extend(n.to_le_bytes());
    for t in 0..n {
        b.extend([0u8; 12]);
        for v in 0..3u32 {
            for c in 0..3u32 {
                b.extend(((t * 9 + v * 3 + c) as f32).to_le_bytes());
            }
        }
        b.extend([0u8; 2]);
    }
    std::fs::write(path, b).unwrap();
}

fn opts(max: u64) -> ReadOptions {
    ReadOptions { max_memory: Some(max), ..Default::default() }
}

#[test]
fn a_binary_stl_that_cannot_fit_is_refused_before_parsing() {
    let dir = scratch("load-stl");
    let p = dir.join("soup.stl");
    // 15 MB of file, about 82 MB at the reader's peak.
    binary_stl(&p, 300_000);
    let e = read_mesh(&p, &opts(70 << 20)).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::TooLargeToRead { .. }), "{e}");
    let msg = e.to_string();
    assert!(msg.contains("soup.stl") && msg.contains("--max-memory") && !msg.contains('\n'), "{msg}");
    let loaded = read_mesh(&p, &opts(400 << 20)).unwrap();
    assert_eq!(loaded.report.triangles, 300_000);
}

#[test]
fn a_file_longer_than_the_budget_is_not_read() {
    let dir = scratch("load-long");
    // 80 MB (sparse: no disk), refused from its length alone.
    let p = dir.join("long.obj");
    std::fs::File::create(&p).unwrap().set_len(80 << 20).unwrap();
    let e = read_mesh(&p, &opts(64 << 20)).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::TooLargeToRead { .. }), "{e}");
    // Reads below 64 MiB are not checked (every machine has that much):
    // a small file over a tiny bound is read, and the run's own estimate
    // refuses the work.
    let p = dir.join("short.obj");
    let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    text.push_str(&"# padding\n".repeat(300_000));
    std::fs::write(&p, &text).unwrap();
    assert!(read_mesh(&p, &opts(1 << 20)).is_ok());
    assert!(read_mesh(&p, &opts(64 << 20)).is_ok());
}

#[test]
fn text_files_are_counted_by_their_lines() {
    let dir = scratch("load-lines");
    let p = dir.join("lines.obj");
    // Two million lines, 16 MB: about 100 MB at the reader's peak.
    let mut text = String::with_capacity(16 << 20);
    for i in 0..1_000_000u32 {
        text.push_str(&format!("v {i} 0 1\n"));
    }
    for i in 1..1_000_000u32 - 1 {
        text.push_str(&format!("f {} {} {}\n", i, i + 1, i + 2));
    }
    std::fs::write(&p, &text).unwrap();
    let e = read_mesh(&p, &opts(80 << 20)).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::TooLargeToRead { .. }), "{e}");
    assert!(read_mesh(&p, &opts(1 << 30)).is_ok());
}

#[test]
fn a_header_claiming_more_than_the_file_holds_is_still_truncation() {
    let dir = scratch("load-lie");
    let p = dir.join("lie.stl");
    let mut b = vec![0u8; 80];
    b.extend(u32::MAX.to_le_bytes());
    b.extend([0u8; 50]);
    std::fs::write(&p, b).unwrap();
    let e = read_mesh(&p, &opts(1 << 20)).unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Malformed { .. }), "{e}");
    assert!(e.to_string().contains("truncated"), "{e}");

    // A binary PLY whose header claims 10¹² vertices in a few bytes.
    let p = dir.join("lie.ply");
    let head = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    std::fs::write(&p, head.as_bytes()).unwrap();
    let e = read_mesh(&p, &opts(1 << 20)).unwrap_err();
    assert!(!matches!(e.kind, ErrorKind::TooLargeToRead { .. }), "{e}");
}
