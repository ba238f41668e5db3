//! Every voxel format round-trips through its reader; `.vox` grids over 256
//! are split into models that reassemble into the same grid.

use std::path::PathBuf;

use glam::DVec3;
use topovox::{DenseBits, GridSpec};
use topovox_io::{read_voxels, write_voxels, VoxelFormat};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("topovox-io-writers-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn pattern(dims: [u32; 3]) -> DenseBits {
    let mut b = DenseBits::new(dims);
    let mut x: u64 = 12345;
    for _ in 0..2000 {
        x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let (i, j, k) = ((x >> 11) as u32 % dims[0], (x >> 27) as u32 % dims[1], (x >> 43) as u32 % dims[2]);
        b.set(i, j, k);
    }
    b.set(dims[0] - 1, dims[1] - 1, dims[2] - 1);
    b.set(0, 0, 0);
    b
}

#[test]
fn npy_and_text_round_trip_exactly() {
    let dims = [13, 70, 5];
    let bits = pattern(dims);
    let grid = GridSpec::new(DVec3::new(-1.0, 2.0, 0.5), 0.25, [13, 70, 5]).unwrap();
    for (name, f) in [("a.npy", VoxelFormat::Npy), ("b.npy", VoxelFormat::NpyBool), ("c.txt", VoxelFormat::Text)] {
        let p = tmp(name);
        write_voxels(&p, f, &bits, &grid).unwrap();
        let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap();
        assert_eq!(back.bits, bits, "{name}");
    }
    let bytes = std::fs::read(tmp("a.npy")).unwrap();
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    assert_eq!((10 + header_len) % 64, 0);
    assert_eq!(bytes.len(), 10 + header_len + 13 * 70 * 5);
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(header.contains("'shape': (13, 70, 5)") && header.contains("'descr': '|u1'"), "{header}");
    // Element [i, j, k] is at (i*ny + j)*nz + k.
    assert_eq!(bytes[10 + header_len + (12 * 70 + 69) * 5 + 4], 1);
}

#[test]
fn binvox_is_a_padded_cube_that_round_trips() {
    let bits = pattern([9, 4, 6]);
    let grid = GridSpec::new(DVec3::new(1.0, 2.0, 3.0), 0.5, [9, 4, 6]).unwrap();
    let p = tmp("a.binvox");
    write_voxels(&p, VoxelFormat::Binvox, &bits, &grid).unwrap();
    let text = std::fs::read(&p).unwrap();
    assert!(text.starts_with(b"#binvox 1\ndim 9 9 9\ntranslate 1 2 3\nscale 4.5\ndata\n"));
    let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!(back.bits.dims(), [9, 9, 9]);
    assert_eq!(back.placement, Some((DVec3::new(1.0, 2.0, 3.0), DVec3::splat(0.5))));
    let mut a = Vec::new();
    bits.for_each_set(|i, j, k| a.push([i, j, k]));
    let mut b = Vec::new();
    back.bits.for_each_set(|i, j, k| b.push([i, j, k]));
    assert_eq!(a, b);
}

#[test]
fn vox_splits_large_grids_into_models_that_reassemble() {
    let dims = [300, 20, 513];
    let bits = pattern(dims);
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [300, 20, 513]).unwrap();
    let p = tmp("big.vox");
    write_voxels(&p, VoxelFormat::Vox, &bits, &grid).unwrap();
    let data = dot_vox_models(&p);
    assert!(data.0 >= 4, "expected several models, got {}", data.0);
    assert!(data.1.iter().all(|s| s.iter().all(|&d| d <= 256)));
    let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!(back.bits, bits);
}

fn dot_vox_models(p: &std::path::Path) -> (usize, Vec<[u32; 3]>) {
    // Read through the format crate directly, not our reader.
    let bytes = std::fs::read(p).unwrap();
    let sizes = parse_sizes(&bytes);
    (sizes.len(), sizes)
}

/// Minimal independent scan of the RIFF-like chunks for SIZE chunks.
fn parse_sizes(b: &[u8]) -> Vec<[u32; 3]> {
    assert_eq!(&b[..4], b"VOX ");
    let u = |o: usize| u32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
    let mut out = Vec::new();
    let mut o = 8 + 12; // header, MAIN chunk header
    while o + 12 <= b.len() {
        let id = &b[o..o + 4];
        let (content, children) = (u(o + 4) as usize, u(o + 8) as usize);
        if id == b"SIZE" {
            out.push([u(o + 12), u(o + 16), u(o + 20)]);
        }
        o += 12 + content + children;
    }
    out
}

#[test]
fn failed_write_leaves_no_file() {
    let bits = pattern([4, 4, 4]);
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [4, 4, 4]).unwrap();
    let p = std::path::Path::new("/nonexistent-dir/out.npy");
    let e = write_voxels(p, VoxelFormat::Npy, &bits, &grid).unwrap_err();
    assert!(e.to_string().starts_with("/nonexistent-dir/out.npy: cannot write"), "{e}");
    // Writing over an existing file replaces it whole.
    let dir = std::env::temp_dir().join(format!("topovox-io-replace-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let q = dir.join("replace.txt");
    std::fs::write(&q, "old").unwrap();
    write_voxels(&q, VoxelFormat::Text, &bits, &grid).unwrap();
    assert!(std::fs::read_to_string(&q).unwrap().starts_with("# topovox voxels"));
    let leftovers: Vec<_> = std::fs::read_dir(q.parent().unwrap())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("topovox-tmp"))
        .collect();
    assert!(leftovers.is_empty());
}

#[test]
fn brick_and_dense_storage_write_identical_files() {
    let dims = [37, 20, 300];
    let dense = pattern(dims);
    let mut bricks = topovox::BrickBits::new(dims);
    dense.for_each_set(|i, j, k| bricks.set(i, j, k));
    let grid = GridSpec::new(DVec3::new(0.5, -1.0, 2.0), 0.1, [37, 20, 300]).unwrap();
    for (name, f) in
        [("n.npy", VoxelFormat::Npy), ("n.binvox", VoxelFormat::Binvox), ("n.vox", VoxelFormat::Vox), ("n.txt", VoxelFormat::Text)]
    {
        let (a, b) = (tmp(&format!("dense-{name}")), tmp(&format!("bricks-{name}")));
        write_voxels(&a, f, &dense, &grid).unwrap();
        write_voxels(&b, f, &bricks, &grid).unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap(), "{name}");
    }
}

#[test]
fn truncated_npy_files_are_rejected_when_streamed() {
    let grid = GridSpec::new(glam::DVec3::ZERO, 1.0, [40, 30, 20]).unwrap();
    let p = tmp("trunc.npy");
    write_voxels(&p, VoxelFormat::Npy, &pattern([40, 30, 20]), &grid).unwrap();
    let bytes = std::fs::read(&p).unwrap();
    for cut in [5, 60, bytes.len() - 1] {
        std::fs::write(&p, &bytes[..cut]).unwrap();
        let e = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap_err().to_string();
        assert!(e.contains("trunc.npy") && (e.contains("truncated") || e.contains("magic")), "{cut}: {e}");
    }
}

#[test]
fn an_npy_header_promising_a_huge_grid_is_rejected_before_allocating() {
    let p = tmp("huge.npy");
    let mut h = b"\x93NUMPY\x01\x00".to_vec();
    let dict = "{'descr': '|u1', 'fortran_order': False, 'shape': (65536, 65536, 65536), }";
    let mut header = dict.to_string();
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    h.extend_from_slice(&(header.len() as u16).to_le_bytes());
    h.extend_from_slice(header.as_bytes());
    h.extend_from_slice(&[1, 0, 1]);
    std::fs::write(&p, h).unwrap();
    let e = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("huge.npy") && e.contains("truncated"), "{e}");
}

/// `.npz` of sparse coordinates: written from the set voxels alone, read
/// back to the same voxels and placement; archives as NumPy writes them
/// (deflated, other dtypes, no `dims`) read too; hostile ones are refused
/// in one line.
#[test]
fn npz_round_trips_and_refuses_hostile_archives() {
    use std::io::Write;
    let dims = [13, 70, 5];
    let bits = pattern(dims);
    let grid = GridSpec::new(DVec3::new(-1.0, 2.0, 0.5), 0.25, [13, 70, 5]).unwrap();
    let p = tmp("a.npz");
    write_voxels(&p, VoxelFormat::Npz, &bits, &grid).unwrap();
    let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!(back.bits, bits);
    assert_eq!(back.placement, Some((DVec3::new(-1.0, 2.0, 0.5), DVec3::splat(0.25))));
    // Without a dense grid (grids past memory): the same voxels and placement.
    let sparse =
        topovox_io::read_voxels_sparse(std::path::Path::new(&p), &topovox_io::ReadOptions { attributes: false, ..Default::default() })
            .unwrap();
    assert_eq!((sparse.bits.to_dense(), sparse.placement), (bits.clone(), back.placement));
    // From memory too, and an empty grid.
    let bytes = std::fs::read(&p).unwrap();
    assert_eq!(topovox_io::read_voxels_bytes(&bytes, VoxelFormat::Npz, &topovox_io::ReadOptions::default()).unwrap().bits, bits);
    let empty = DenseBits::new([3, 4, 5]);
    write_voxels(&p, VoxelFormat::Npz, &empty, &GridSpec::new(DVec3::ZERO, 1.0, [3, 4, 5]).unwrap()).unwrap();
    assert_eq!(read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap().bits, empty);

    // An archive built as numpy.savez_compressed would: deflated members,
    // big-endian int16 indices, no dims (the grid is the smallest holding them).
    let npy = |descr: &str, shape: &str, data: &[u8]| {
        let mut h = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
        while (10 + h.len() + 1) % 64 != 0 {
            h.push(' ');
        }
        h.push('\n');
        let mut v = b"\x93NUMPY\x01\x00".to_vec();
        v.extend_from_slice(&(h.len() as u16).to_le_bytes());
        v.extend_from_slice(h.as_bytes());
        v.extend_from_slice(data);
        v
    };
    let archive = |members: &[(&str, Vec<u8>)]| {
        let mut z = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
        let o = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        for (name, data) in members {
            z.start_file(*name, o).unwrap();
            z.write_all(data).unwrap();
        }
        z.finish().unwrap().into_inner()
    };
    let be16: Vec<u8> = [0i16, 0, 0, 4, 1, 2].iter().flat_map(|c| c.to_be_bytes()).collect();
    let a = archive(&[("indices.npy", npy(">i2", "(2, 3)", &be16))]);
    let got = topovox_io::read_voxels_bytes(&a, VoxelFormat::Npz, &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!(got.bits.dims(), [5, 2, 3]);
    assert!(got.bits.get(0, 0, 0) && got.bits.get(4, 1, 2));
    assert_eq!(got.placement, None);
    let sparse = topovox_io::npz::read_sparse_from(std::io::Cursor::new(&a), a.len() as u64).unwrap();
    assert_eq!(sparse.bits.to_dense(), got.bits, "no dims: sized after the indices, sparse too");

    // Hostile or wrong archives: one line each, no panic, no huge allocation.
    let le32 = |v: &[i32]| v.iter().flat_map(|c| c.to_le_bytes()).collect::<Vec<u8>>();
    let dims_member = ("dims.npy", npy("<i8", "(3,)", &[5i64, 5, 5].iter().flat_map(|c| c.to_le_bytes()).collect::<Vec<u8>>()));
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (b"PK\x03\x04 not really".to_vec(), "not a ZIP archive"),
        (archive(&[("other.npy", npy("<i4", "(1, 3)", &le32(&[0, 0, 0])))]), "no 'indices' array"),
        (archive(&[("indices.npy", npy("<f8", "(1, 3)", &[0u8; 24]))]), "expected integers"),
        (archive(&[("indices.npy", npy("<i4", "(1, 2)", &le32(&[0, 0])))]), "expected (k, 3)"),
        (archive(&[("indices.npy", npy("<i4", "(1000000000, 3)", &le32(&[0, 0, 0])))]), "claims 1000000000 rows"),
        (archive(&[("indices.npy", npy("<i4", "(1, 3)", &le32(&[0, -1, 0])))]), "is not a voxel"),
        (archive(&[dims_member.clone(), ("indices.npy", npy("<i4", "(1, 3)", &le32(&[0, 5, 0])))]), "outside the [5, 5, 5] grid"),
        (archive(&[("dims.npy", npy("<i8", "(3,)", &[0u8; 24])), ("indices.npy", npy("<i4", "(0, 3)", &[]))]), "out of range"),
        (archive(&[("indices.npy", b"\x93NUMPY\x01\x00\xff\xff{".to_vec())]), "header cut short"),
    ];
    for (bytes, want) in cases {
        let err = topovox_io::read_voxels_bytes(&bytes, VoxelFormat::Npz, &topovox_io::ReadOptions::default()).unwrap_err().to_string();
        assert!(err.contains(want), "expected {want:?} in {err:?}");
        assert!(!err.contains('\n'), "{err}");
    }
}

/// A voxel size per axis: every format that records the spacing gives back
/// exactly the origin and three sizes it was written with (and the voxels);
/// the cubes-only formats refuse the grid and write nothing.
#[test]
fn grids_of_boxes_round_trip_their_spacing() {
    let dims = [13, 30, 9];
    let bits = pattern(dims);
    let grid = GridSpec::new(DVec3::new(-1.3, 2.0, 0.5), [0.7, 0.7, 2.5], [13, 30, 9]).unwrap();
    let want = Some((grid.origin(), DVec3::new(0.7, 0.7, 2.5)));
    for (name, f) in [
        ("s.txt", VoxelFormat::Text),
        ("s.ply", VoxelFormat::Ply),
        ("s.vti", VoxelFormat::Vti),
        ("s.vdb", VoxelFormat::Vdb),
        ("s.npz", VoxelFormat::Npz),
        ("s.zarr", VoxelFormat::Zarr),
    ] {
        let p = tmp(name);
        write_voxels(&p, f, &bits, &grid).unwrap();
        let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap();
        assert_eq!(back.bits, bits, "{name}");
        assert_eq!(back.placement, want, "{name}");
        if f.reads_sparsely() {
            assert_eq!(
                topovox_io::read_voxels_sparse(&p, &topovox_io::ReadOptions { attributes: false, ..Default::default() }).unwrap().placement,
                want,
                "{name} sparse"
            );
        }
    }
    for (name, f) in [("s.binvox", VoxelFormat::Binvox), ("s.vox", VoxelFormat::Vox), ("s.schem", VoxelFormat::Schem)] {
        let p = tmp(name);
        let e = write_voxels(&p, f, &bits, &grid).unwrap_err().to_string();
        assert!(e.contains("cubic") && e.contains(".vti") && !e.contains('\n'), "{name}: {e}");
        assert!(!p.exists(), "{name}: written");
    }
    // Written before boxes: one size means cubes.
    let cubes = GridSpec::new(DVec3::ZERO, [0.5; 3], dims.map(u64::from)).unwrap();
    write_voxels(&tmp("c.npz"), VoxelFormat::Npz, &bits, &cubes).unwrap();
    assert_eq!(read_voxels(&tmp("c.npz"), &topovox_io::ReadOptions::default()).unwrap().placement, Some((DVec3::ZERO, DVec3::splat(0.5))));
}
