//! Fuzzes the surface from voxels and the mesh certificate: voxel labels
//! from raw bytes on a small grid; the fast extraction must equal the
//! every-cube reference (up to vertex numbering) and, slab by slab, itself;
//! the blocky and smooth surfaces must certify watertight; the bytes read
//! as a triangle soup must be certified without a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use topovox::distance::nearest::Hierarchy;
use topovox::distance::Pieces;
use topovox::glam::DVec3;
use topovox::grid::dense::DenseBits;
use topovox::mesh_check::check_mesh;
use topovox::stop::Stop;
use topovox::surface::{blocky, smooth, tets, Smooth};
use topovox::{GridSpec, MeshRef};

fuzz_target!(|data: &[u8]| {
    let Some((&shape, bits)) = data.split_first() else { return };
    let dims = [1 + (shape & 3) as u32, 1 + (shape >> 2 & 3) as u32, 1 + (shape >> 4 & 7) as u32];
    let mut inside = DenseBits::new(dims);
    let mut n = 0usize;
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                if bits.get(n / 8).is_some_and(|b| b >> (n % 8) & 1 == 1) {
                    inside.set(i, j, k);
                }
                n += 1;
            }
        }
    }
    let stop = Stop::new();
    let key = |e: &tets::Extracted| {
        let mut t: Vec<[([i64; 3], [i64; 3]); 3]> = e.triangles.iter().map(|t| t.map(|v| e.crossings[v as usize])).collect();
        for tri in &mut t {
            let m = (0..3).min_by_key(|&x| tri[x]).unwrap_or(0);
            tri.rotate_left(m);
        }
        t.sort();
        t
    };
    let fast = tets::extract(&inside, &stop).expect("not stopped");
    assert_eq!(key(&fast), key(&tets::reference::extract(&inside)));
    // Slab by slab, any thickness: the same surface, concatenated.
    let mut slabs = tets::Extracted::default();
    tets::extract_slabs(&inside, 1 + (shape >> 7) as u32, &stop, |s| {
        assert_eq!(s.first_vertex as usize, slabs.crossings.len());
        slabs.crossings.extend(s.crossings);
        slabs.triangles.extend(s.triangles);
        Ok::<(), ()>(())
    })
    .expect("no error")
    .expect("not stopped");
    assert_eq!(slabs, fast);
    let Ok(grid) = GridSpec::new(DVec3::new(-1.0, 0.5, 2.0), [0.5, 0.75, 0.25], dims.map(u64::from)) else { return };
    // At most 100 triangles: the certificate's cost grows with their pairs.
    let coords: Vec<f64> = data[..data.len().min(1800)].chunks_exact(2).map(|c| i16::from_le_bytes([c[0], c[1]]) as f64 / 8192.0).collect();
    let positions: Vec<DVec3> = coords.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
    let triangles: Vec<[u32; 3]> = (0..positions.len() as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    let _ = check_mesh(&positions, &triangles, &stop);
    if inside.count() == 0 {
        return;
    }
    let surfaces = [Some(blocky(&inside, &grid, &stop).expect("not stopped"))];
    let pieces = Pieces::of(MeshRef { positions: &positions, triangles: &triangles, segments: &[] }).ok();
    let smooth =
        pieces.map(|p| smooth(&inside, &grid, Smooth { pieces: &p, tree: &Hierarchy::new(&p), offset: None }, &stop).expect("not stopped"));
    for m in surfaces.into_iter().chain([smooth]).flatten() {
        let c = check_mesh(&m.positions, &m.triangles, &stop).expect("a surface has faces");
        assert!(c.watertight(), "{c:?}");
    }
});
