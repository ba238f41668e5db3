//! Fuzzes `remesh`'s pipeline at extreme scales and offsets (issue 65):
//! a small random mesh, scaled by 2^±300 and moved by up to 2^±100, on a
//! small grid. Every step either refuses (the coordinate range, the grid's
//! range, the output's precision) or gives a surface whose certificate
//! passes: in f64, and rounded to f32 where the precision rule allowed f32.
#![no_main]

use libfuzzer_sys::fuzz_target;
use topovox::distance::nearest::Hierarchy;
use topovox::distance::Pieces;
use topovox::glam::DVec3;
use topovox::mesh_check::check_mesh;
use topovox::stop::Stop;
use topovox::surface::{blocky, check_precision, smooth, Smooth};
use topovox::voxelize::solid;
use topovox::{GridSpec, MeshRef};

fuzz_target!(|data: &[u8]| {
    let Some((head, rest)) = data.split_at_checked(4) else { return };
    let scale = 2f64.powi(head[0] as i8 as i32 * 300 / 128);
    let offset = (head[1] as i8 as f64).signum() * 2f64.powi((head[1] as i8 as i32).abs() * 100 / 128) * (head[1] != 0) as u8 as f64;
    let resolution = 2 + (head[2] % 12) as u64;
    let single = head[3] & 1 == 1;
    // Up to 24 vertices from i16 triples; triangles from the bytes after.
    let (coords, faces) = rest.split_at(rest.len().min(144));
    let positions: Vec<DVec3> = coords
        .chunks_exact(6)
        .map(|c| {
            let v = |k: usize| i16::from_le_bytes([c[k], c[k + 1]]) as f64 / 4096.0;
            DVec3::new(v(0), v(2), v(4)) * scale + offset
        })
        .collect();
    if positions.len() < 3 || !positions.iter().all(|&p| topovox::in_range(p)) {
        return; // the readers refuse these (ErrorKind::OutOfRange)
    }
    let n = positions.len() as u32;
    let mut triangles: Vec<[u32; 3]> =
        faces.chunks_exact(3).take(40).map(|t| [t[0] as u32 % n, t[1] as u32 % n, t[2] as u32 % n]).collect();
    if triangles.is_empty() {
        // A closed tetrahedron of the first four vertices (or a triangle).
        triangles = if n >= 4 { vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]] } else { vec![[0, 1, 2]] };
    }
    let mesh = MeshRef { positions: &positions, triangles: &triangles, segments: &[] };
    let Ok(grid) = GridSpec::from_resolution(&mesh.bounds(), resolution) else { return };
    if check_precision(&grid, single).is_err() {
        return;
    }
    let Ok((inside, _)) = solid::parity(mesh, &grid) else { return };
    if inside.count() == 0 {
        return;
    }
    let stop = Stop::new();
    let Ok(pieces) = Pieces::of(mesh) else { return };
    let tree = Hierarchy::new(&pieces);
    let surfaces = [
        blocky(&inside, &grid, &stop).expect("not stopped"),
        smooth(&inside, &grid, Smooth { pieces: &pieces, tree: &tree, offset: None }, &stop).expect("not stopped"),
    ];
    for m in surfaces {
        let c = check_mesh(&m.positions, &m.triangles, &stop).expect("a surface has faces");
        assert!(c.watertight(), "f64: {c:?}");
        if single {
            let rounded: Vec<DVec3> = m.positions.iter().map(|p| p.as_vec3().as_dvec3()).collect();
            let c = check_mesh(&rounded, &m.triangles, &stop).expect("a surface has faces");
            assert!(c.watertight(), "f32: {c:?}");
        }
    }
});
