//! Hostile files and concurrent writers (issue 44): nothing is read outside
//! the folder the user named, special files are never read, nothing the
//! user has is deleted or half-replaced, and writers never share a
//! temporary.

#![cfg(unix)]

mod common;

use std::path::{Path, PathBuf};

use common::{leftovers, scratch};
use std::time::Duration;

use glam::DVec3;
use topovox::{DenseBits, GridSpec};
use topovox_io::{read_voxels, read_voxels_sparse, write_voxels, VoxelFormat};

fn grid(dims: [u32; 3]) -> GridSpec {
    GridSpec::new(DVec3::ZERO, 1.0, dims.map(u64::from)).unwrap()
}

fn some_voxels(dims: [u32; 3]) -> DenseBits {
    let mut d = DenseBits::new(dims);
    d.set(1, 2, 3);
    d.set(dims[0] - 1, dims[1] - 1, dims[2] - 1);
    d
}

/// A Zarr array of `dims` written by topovox at `dir/name.zarr`.
fn zarr_array(dir: &Path, name: &str, dims: [u32; 3]) -> PathBuf {
    let p = dir.join(format!("{name}.zarr"));
    write_voxels(&p, VoxelFormat::Zarr, &some_voxels(dims), &grid(dims)).unwrap();
    p
}

fn edit_json(path: &Path, f: impl FnOnce(&mut serde_json::Value)) {
    let file = path.join("zarr.json");
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(&file).unwrap()).unwrap();
    f(&mut v);
    std::fs::write(&file, serde_json::to_vec(&v).unwrap()).unwrap();
}

fn mkfifo(path: &Path) {
    let ok = std::process::Command::new("mkfifo").arg(path).status().unwrap().success();
    assert!(ok, "mkfifo {}", path.display());
}

/// Runs `f` on a thread and fails the test if it has not returned within
/// a minute (a hang is the bug some of these tests catch).
fn within_a_minute<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(60)).expect("hung: no answer within a minute")
}

#[test]
fn zarr_separator_that_climbs_out_is_refused() {
    let d = scratch("sep");
    let a = zarr_array(&d, "sep", [64, 64, 128]);
    // What the traversal would have read: a file outside the array.
    std::fs::create_dir_all(d.join("OUT")).unwrap();
    std::fs::write(d.join("OUT/1"), vec![1u8; 64 * 64 * 64]).unwrap();
    edit_json(&a, |v| {
        v["chunk_key_encoding"]["configuration"]["separator"] = "/../../OUT/".into();
        v["codecs"] = serde_json::json!([{"name": "bytes"}]);
        v["chunk_grid"]["configuration"]["chunk_shape"] = serde_json::json!([64, 64, 64]);
    });
    for e in [
        read_voxels(&a, &topovox_io::ReadOptions::default()).unwrap_err().to_string(),
        read_voxels_sparse(&a, &topovox_io::ReadOptions { attributes: false, ..Default::default() }).unwrap_err().to_string(),
    ] {
        assert!(e.contains("separator") && e.contains("sep.zarr"), "{e}");
    }
}

#[test]
fn dot_separated_chunk_keys_still_read() {
    let d = scratch("dot");
    let a = d.join("dot.zarr");
    std::fs::create_dir_all(&a).unwrap();
    let meta = serde_json::json!({
        "zarr_format": 3, "node_type": "array", "shape": [4, 4, 4], "data_type": "uint8",
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [2, 4, 4]}},
        "chunk_key_encoding": {"name": "default", "configuration": {"separator": "."}},
        "fill_value": 0, "codecs": [{"name": "bytes"}]
    });
    std::fs::write(a.join("zarr.json"), serde_json::to_vec(&meta).unwrap()).unwrap();
    let mut chunk = vec![0u8; 32];
    chunk[5] = 1; // (0, 1, 1) of chunk (1, 0, 0): voxel (2, 1, 1)
    std::fs::write(a.join("c.1.0.0"), &chunk).unwrap();
    std::fs::write(a.join("c.9.0.0"), &chunk).unwrap(); // not a chunk of this shape: ignored
    let v = read_voxels(&a, &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!(v.bits.count(), 1);
    assert!(v.bits.get(2, 1, 1));
}

#[test]
fn links_inside_a_zarr_folder_do_not_lead_outside() {
    let d = scratch("links");
    let inside = zarr_array(&d, "inside", [16, 16, 16]);
    let other = zarr_array(&d, "other", [16, 16, 16]);
    // A chunk file that is a link to another array's chunk.
    std::fs::remove_file(inside.join("c/0/0/0")).unwrap();
    std::os::unix::fs::symlink(other.join("c/0/0/0"), inside.join("c/0/0/0")).unwrap();
    let e = read_voxels(&inside, &topovox_io::ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("outside the Zarr folder") && e.contains("--allow-external-paths"), "{e}");
    assert!(read_voxels_sparse(&inside, &topovox_io::ReadOptions { attributes: false, ..Default::default() }).is_err());
    // Allowed, it reads the other array's voxels.
    let v = read_voxels(&inside, &topovox_io::ReadOptions { up: Default::default(), allow_external_paths: true, ..Default::default() })
        .unwrap();
    assert_eq!(v.bits.count(), 2);
    // The whole `c/` folder as a link.
    std::fs::remove_dir_all(inside.join("c")).unwrap();
    std::os::unix::fs::symlink(other.join("c"), inside.join("c")).unwrap();
    assert!(read_voxels(&inside, &topovox_io::ReadOptions::default()).unwrap_err().to_string().contains("outside the Zarr folder"));
    // An attribute array of a group pointing at another array.
    let group = d.join("group.zarr");
    std::fs::create_dir_all(&group).unwrap();
    std::fs::write(group.join("zarr.json"), br#"{"zarr_format": 3, "node_type": "group", "attributes": {}}"#).unwrap();
    std::os::unix::fs::symlink(&other, group.join("voxels")).unwrap();
    assert!(read_voxels(&group, &topovox_io::ReadOptions::default()).unwrap_err().to_string().contains("outside the Zarr folder"));
}

#[test]
fn special_files_inside_a_zarr_folder_are_not_read() {
    let d = scratch("special");
    let a = zarr_array(&d, "fifo", [16, 16, 16]);
    std::fs::remove_file(a.join("c/0/0/0")).unwrap();
    mkfifo(&a.join("c/0/0/0"));
    let p = a.clone();
    let e = within_a_minute(move || read_voxels(&p, &topovox_io::ReadOptions::default()).map(|_| ()).unwrap_err().to_string());
    assert!(e.contains("not a regular file"), "{e}");
    // A device (an endless stream of zeros) as a chunk, and as zarr.json.
    std::fs::remove_file(a.join("c/0/0/0")).unwrap();
    std::os::unix::fs::symlink("/dev/zero", a.join("c/0/0/0")).unwrap();
    let p = a.clone();
    let e = within_a_minute(move || {
        read_voxels(&p, &topovox_io::ReadOptions { up: Default::default(), allow_external_paths: true, ..Default::default() })
            .unwrap_err()
            .to_string()
    });
    assert!(e.contains("not a regular file"), "{e}");
    std::fs::remove_file(a.join("zarr.json")).unwrap();
    mkfifo(&a.join("zarr.json"));
    let p = a.clone();
    let e = within_a_minute(move || {
        read_voxels_sparse(&p, &topovox_io::ReadOptions { attributes: false, ..Default::default() }).unwrap_err().to_string()
    });
    assert!(e.contains("not a regular file"), "{e}");
}

#[test]
fn an_mtllib_that_is_a_fifo_is_a_warning_not_a_hang() {
    let d = scratch("mtlfifo");
    mkfifo(&d.join("m.mtl"));
    std::fs::write(d.join("a.obj"), "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let p = d.join("a.obj");
    let loaded = within_a_minute(move || topovox_io::read_mesh(&p, &topovox_io::ReadOptions::default())).unwrap();
    assert!(loaded.warnings.iter().any(|w| w.contains("not a regular file")), "{:?}", loaded.warnings);
}

#[test]
fn a_zarr_claiming_a_vast_grid_reads_only_what_it_stores() {
    let d = scratch("vast");
    let a = zarr_array(&d, "vast", [64, 64, 64]);
    // A billion chunks claimed, one stored.
    edit_json(&a, |v| v["shape"] = serde_json::json!([65536, 65536, 65536]));
    let s = read_voxels_sparse(&a, &topovox_io::ReadOptions { attributes: false, ..Default::default() }).unwrap();
    assert_eq!(s.bits.dims(), [65536, 65536, 65536]);
    assert_eq!(s.bits.count(), 2);
}

#[test]
fn writing_over_a_zarr_folder_that_is_not_ours_is_refused() {
    let d = scratch("group");
    let user = d.join("userdata.zarr");
    std::fs::create_dir_all(user.join("mine")).unwrap();
    std::fs::write(user.join("zarr.json"), br#"{"zarr_format": 3, "node_type": "group", "attributes": {}}"#).unwrap();
    std::fs::write(user.join("README"), "my notes").unwrap();
    let e = write_voxels(&user, VoxelFormat::Zarr, &some_voxels([8, 8, 8]), &grid([8, 8, 8])).unwrap_err().to_string();
    assert!(e.contains("refusing to replace it"), "{e}");
    assert_eq!(std::fs::read_to_string(user.join("README")).unwrap(), "my notes");
    assert!(user.join("mine").is_dir());
    // Our own array with a file of the user's put inside: refused too.
    let ours = zarr_array(&d, "ours", [8, 8, 8]);
    std::fs::write(ours.join("notes.txt"), "x").unwrap();
    let e = write_voxels(&ours, VoxelFormat::Zarr, &some_voxels([8, 8, 8]), &grid([8, 8, 8])).unwrap_err().to_string();
    assert!(e.contains("notes.txt"), "{e}");
    // A plain folder with files, and a regular file: refused.
    std::fs::create_dir_all(d.join("plain.zarr")).unwrap();
    std::fs::write(d.join("plain.zarr/a"), "a").unwrap();
    assert!(write_voxels(&d.join("plain.zarr"), VoxelFormat::Zarr, &some_voxels([8, 8, 8]), &grid([8, 8, 8])).is_err());
    // Our own array, and an empty folder, are replaced.
    std::fs::remove_file(ours.join("notes.txt")).unwrap();
    write_voxels(&ours, VoxelFormat::Zarr, &some_voxels([9, 9, 9]), &grid([9, 9, 9])).unwrap();
    assert_eq!(read_voxels(&ours, &topovox_io::ReadOptions::default()).unwrap().bits.dims(), [9, 9, 9]);
    std::fs::create_dir_all(d.join("empty.zarr")).unwrap();
    write_voxels(&d.join("empty.zarr"), VoxelFormat::Zarr, &some_voxels([8, 8, 8]), &grid([8, 8, 8])).unwrap();
    assert_eq!(read_voxels(&d.join("empty.zarr"), &topovox_io::ReadOptions::default()).unwrap().bits.count(), 2);
    assert_eq!(leftovers(&d), Vec::<String>::new());
}

#[test]
fn staged_outputs_are_put_in_place_only_when_all_are_complete() {
    let d = scratch("pair");
    let (obj, mtl) = (d.join("out.obj"), d.join("out.mtl"));
    std::fs::write(&obj, "old obj").unwrap();
    std::fs::write(&mtl, "old mtl").unwrap();
    // The .mtl is complete, the .obj fails (a full disk): neither changes.
    let m = topovox_io::atomic::stage(&mtl, |w| w.write_all(b"new mtl")).unwrap();
    let o = topovox_io::atomic::stage(&obj, |w| {
        w.write_all(b"new o")?;
        Err(std::io::Error::other("No space left on device"))
    });
    assert!(o.is_err());
    drop(m);
    assert_eq!(std::fs::read_to_string(&obj).unwrap(), "old obj");
    assert_eq!(std::fs::read_to_string(&mtl).unwrap(), "old mtl");
    assert_eq!(leftovers(&d), Vec::<String>::new());
}

#[test]
fn threads_saving_to_one_path_never_share_a_temporary() {
    let d = scratch("threads");
    let out = d.join("same.npy");
    let contents: Vec<Vec<u8>> = (0..8u8).map(|t| vec![t; 200_000 + t as usize]).collect();
    for _round in 0..5 {
        std::thread::scope(|s| {
            for c in &contents {
                let out = &out;
                s.spawn(move || {
                    topovox_io::atomic::write_atomically(out, |w| {
                        for part in c.chunks(4096) {
                            w.write_all(part)?;
                        }
                        Ok(())
                    })
                    .unwrap()
                });
            }
        });
        let got = std::fs::read(&out).unwrap();
        assert!(contents.contains(&got), "the file matches none of the writes ({} bytes)", got.len());
        assert_eq!(leftovers(&d), Vec::<String>::new());
    }
}

#[test]
fn temporaries_of_a_killed_run_are_removed_by_the_next_write() {
    let d = scratch("stale");
    let out = d.join("out.txt");
    // A pid above the kernel's limit is never a live process.
    let dead = std::fs::read_to_string("/proc/sys/kernel/pid_max").map(|s| s.trim().parse::<u64>().unwrap() + 1).unwrap_or(99_999_999);
    std::fs::write(d.join(format!(".out.txt.topovox-tmp-{dead}")), vec![0u8; 1000]).unwrap();
    std::fs::write(d.join(format!(".out.txt.topovox-tmp-{dead}-3")), vec![0u8; 1000]).unwrap();
    std::fs::create_dir_all(d.join(format!(".out.txt.topovox-tmp-{dead}-4/c"))).unwrap();
    // A live process's temporary (ours) and someone else's file stay.
    let mine = d.join(format!(".out.txt.topovox-tmp-{}-999", std::process::id()));
    std::fs::write(&mine, "writing").unwrap();
    std::fs::write(d.join(".out.txt.notes"), "keep").unwrap();
    write_voxels(&out, VoxelFormat::Text, &some_voxels([4, 4, 4]), &grid([4, 4, 4])).unwrap();
    assert_eq!(leftovers(&d), vec![mine.file_name().unwrap().to_string_lossy().into_owned()]);
    assert!(d.join(".out.txt.notes").exists());
}

#[test]
fn a_killed_runs_hidden_zarr_array_is_put_back_by_the_next_write() {
    // Issue 54: killed between moving the old array aside and renaming the
    // new one in, a run left the output missing and the old array hidden.
    let d = scratch("recover");
    let dead = std::fs::read_to_string("/proc/sys/kernel/pid_max").map(|s| s.trim().parse::<u64>().unwrap() + 1).unwrap_or(99_999_999);
    let out = zarr_array(&d, "out", [8, 8, 8]);
    let aside = d.join(format!(".out.zarr.topovox-old-{dead}-7"));
    std::fs::rename(&out, &aside).unwrap();
    // Our own aside folder (a live process) is never touched.
    let mine = d.join(format!(".out.zarr.topovox-old-{}-1", std::process::id()));
    std::fs::create_dir(&mine).unwrap();
    topovox_io::atomic::recover_replaced(&out);
    assert!(!aside.exists());
    assert_eq!(read_voxels(&out, &topovox_io::ReadOptions::default()).unwrap().bits.count(), some_voxels([8, 8, 8]).count());
    // Left beside a complete new output, the old one is removed; a write
    // does both first, then replaces the output.
    std::fs::create_dir(&aside).unwrap();
    write_voxels(&out, VoxelFormat::Zarr, &some_voxels([9, 9, 9]), &grid([9, 9, 9])).unwrap();
    assert_eq!(read_voxels(&out, &topovox_io::ReadOptions::default()).unwrap().bits.dims(), [9, 9, 9]);
    std::fs::remove_dir(&mine).unwrap();
    assert_eq!(leftovers(&d), Vec::<String>::new());
}

#[test]
fn a_vdb_whose_tiles_cover_more_than_a_billion_voxels_reads_back() {
    // Issue 54: topovox called its own .vdb malformed when its active
    // tiles covered more than 2³⁰ voxels (a solid past about 1.07 G voxels).
    use topovox::grid::sparse::SparseBricks;
    let n = 1152u32; // 9 lower nodes of 128 a side: all tiles
    let b = n / 8;
    let runs: Vec<([u32; 3], u32)> = (0..b).flat_map(|k| (0..b).map(move |j| ([0, j, k], b))).collect();
    let solid = SparseBricks::from_parts([n; 3], Vec::new(), runs);
    let d = scratch("tiles");
    let out = d.join("solid.vdb");
    write_voxels(&out, VoxelFormat::Vdb, &solid, &grid([n; 3])).unwrap();
    assert!(std::fs::metadata(&out).unwrap().len() < 1 << 20, "tiles, not leaves");
    let back = read_voxels(&out, &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!((back.bits.dims(), back.bits.count()), ([n; 3], (n as u64).pow(3)));
}

#[test]
fn errors_and_warnings_quote_a_short_prefix_of_the_input() {
    // Issue 54: a 100 MB binvox header line was echoed whole into the
    // error, a 1 MB mtllib name into a warning, 300-digit numbers likewise.
    let d = scratch("echo");
    let long = "9".repeat(1 << 20);
    let binvox = d.join("h.binvox");
    std::fs::write(&binvox, format!("#binvox 1\ndim {long}\n")).unwrap();
    let obj_number = d.join("n.obj");
    std::fs::write(&obj_number, format!("v 0 0 {}\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "1".repeat(300) + "x")).unwrap();
    let text = d.join("t.txt");
    std::fs::write(&text, format!("# dims 4 4 4\n{long}\n")).unwrap();
    for p in [&binvox, &obj_number, &text] {
        let e = match topovox_io::read_voxels(p, &topovox_io::ReadOptions::default()) {
            Err(e) => e.to_string(),
            Ok(_) => topovox_io::read_mesh(p, &topovox_io::ReadOptions::default()).unwrap_err().to_string(),
        };
        assert!(e.len() < 500, "{}: {} bytes: {}", p.display(), e.len(), &e[..200]);
    }
    let e = topovox_io::read_mesh(&obj_number, &topovox_io::ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("bad number \"1111") && e.contains("bytes)"), "{e}");
    let mtl = d.join("m.obj");
    std::fs::write(&mtl, format!("mtllib {}.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "a".repeat(1 << 20))).unwrap();
    let m = topovox_io::read_mesh(&mtl, &topovox_io::ReadOptions::default()).unwrap();
    assert!(
        !m.warnings.is_empty() && m.warnings.iter().all(|w| w.len() < 500),
        "{:?}",
        m.warnings.iter().map(|w| w.len()).collect::<Vec<_>>()
    );
}

#[test]
fn a_vti_with_a_bad_spacing_is_refused_not_read_as_unit_cubes() {
    // Issue 54: a bad Spacing (0, negative, NaN) was dropped without a word.
    let d = scratch("spacing");
    let good = d.join("g.vti");
    write_voxels(&good, VoxelFormat::Vti, &some_voxels([4, 4, 4]), &grid([4, 4, 4])).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    let head =
        String::from_utf8_lossy(&bytes[..bytes.windows(7).position(|w| w == b"_").map_or(600, |p| p + 1).min(bytes.len())]).into_owned();
    let spacing = head.split("Spacing=\"").nth(1).and_then(|t| t.split('"').next()).unwrap().to_string();
    for bad in ["0 1 1", "-1 1 1", "NaN 1 1", "1 1"] {
        let p = d.join("b.vti");
        let find = format!("Spacing=\"{spacing}\"");
        let at = bytes.windows(find.len()).position(|w| w == find.as_bytes()).unwrap();
        let mut b = bytes[..at].to_vec();
        b.extend(format!("Spacing=\"{bad}\"").as_bytes());
        b.extend(&bytes[at + find.len()..]);
        std::fs::write(&p, b).unwrap();
        let e = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap_err().to_string();
        assert!(e.contains("Spacing") && e.lines().count() == 1, "{bad}: {e}");
    }
    assert!(read_voxels(&good, &topovox_io::ReadOptions::default()).unwrap().placement.is_some());
}
