//! Coloured and attribute-carrying formats: `.vox` palettes, `.schem`,
//! `.vti`, `.ply` point clouds, and the greedy `.obj` / `.glb` meshes of the
//! voxels, read back by topovox and by third-party crates (`dot_vox` inside
//! topovox's reader, `gltf`, `tobj`, `fastnbt`).

use std::path::PathBuf;

use glam::DVec3;
use topovox::attributes::{VoxelAttributes, NO_MATERIAL};
use topovox::export::greedy::greedy_quads_by_class;
use topovox::{DenseBits, GridSpec};
use topovox_io::{read_voxels, write_voxels_with, VoxelFormat, WriteOptions};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("topovox-io-coloured-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// A random voxel set with colours from `palette` (a function of the position).
fn scene(dims: [u32; 3], colours: u32, n: usize) -> (DenseBits, VoxelAttributes) {
    let mut b = DenseBits::new(dims);
    let mut x: u64 = 777;
    for _ in 0..n {
        x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        b.set((x >> 11) as u32 % dims[0], (x >> 27) as u32 % dims[1], (x >> 43) as u32 % dims[2]);
    }
    let mut v = Vec::new();
    b.for_each_set(|i, j, k| {
        let c = (i * 31 + j * 17 + k * 7) % colours;
        v.push(([i, j, k], [(c * 37 % 256) as u8, (c * 91 % 256) as u8, (c * 13 % 256) as u8]));
    });
    let mut a = VoxelAttributes::from_coloured(dims, v);
    let n = a.keys.len();
    a.material = Some((0..n).map(|s| if s % 5 == 0 { NO_MATERIAL } else { s as u32 % 3 }).collect());
    a.coverage = Some((0..n).map(|s| s as f32 * 0.01).collect());
    a.normal = Some((0..n).map(|s| [s as f32, -1.0, 0.5]).collect());
    (b, a)
}

#[test]
fn vox_keeps_up_to_255_colours_exactly_and_quantizes_more() {
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [300, 40, 30]).unwrap();
    let (b, a) = scene([300, 40, 30], 200, 5000);
    let p = tmp("c.vox");
    write_voxels_with(&p, VoxelFormat::Vox, &b, &grid, Some(&a), &WriteOptions::default()).unwrap();
    let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert!(back.bits.first_difference(&b).is_none());
    assert_eq!(back.attributes.unwrap().colour, a.colour);

    let (b, a) = scene([50, 40, 30], 2000, 8000);
    for dither in [false, true] {
        write_voxels_with(&p, VoxelFormat::Vox, &b, &grid, Some(&a), &WriteOptions { dither, blocks: None, ..Default::default() }).unwrap();
        let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap().attributes.unwrap();
        let got: std::collections::HashSet<_> = back.colour.as_ref().unwrap().iter().copied().collect();
        let input: std::collections::HashSet<_> = a.colour.as_ref().unwrap().iter().copied().collect();
        assert!(got.len() <= 255 && got.len() > 100, "{}", got.len());
        assert!(got.is_subset(&input), "the palette holds only voxel colours");
    }
}

#[test]
fn vti_round_trips_every_array() {
    let grid = GridSpec::new(DVec3::new(-1.0, 2.0, 0.5), 0.25, [37, 20, 9]).unwrap();
    let (b, a) = scene([37, 20, 9], 50, 900);
    let p = tmp("c.vti");
    write_voxels_with(&p, VoxelFormat::Vti, &b, &grid, Some(&a), &WriteOptions::default()).unwrap();
    let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert!(back.bits.first_difference(&b).is_none());
    assert_eq!(back.placement, Some((grid.origin(), glam::DVec3::splat(0.25))));
    assert_eq!(back.attributes.unwrap(), a);
    // Without attributes: occupancy only.
    write_voxels_with(&p, VoxelFormat::Vti, &b, &grid, None, &WriteOptions::default()).unwrap();
    let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert!(back.bits.first_difference(&b).is_none());
    assert!(back.attributes.unwrap().colour.is_none());
}

#[test]
fn ply_point_cloud_round_trips_voxels_and_colours() {
    let grid = GridSpec::new(DVec3::new(3.0, -2.0, 1.0), 0.1, [30, 20, 10]).unwrap();
    let (b, a) = scene([30, 20, 10], 60, 700);
    let p = tmp("c.ply");
    write_voxels_with(&p, VoxelFormat::Ply, &b, &grid, Some(&a), &WriteOptions::default()).unwrap();
    assert!(topovox_io::is_voxel_file(&p));
    let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert!(back.bits.first_difference(&b).is_none());
    assert_eq!(back.attributes.unwrap().colour, a.colour);
    // As a mesh file it is a point cloud without faces: not a surface.
    assert!(topovox_io::read_mesh(&p, &topovox_io::ReadOptions::default()).is_err());
}

#[test]
fn schem_past_a_hundred_million_blocks_reads_back() {
    // Issue 54: `voxelize bunny -o b.schem --resolution 512` wrote 1.03·10⁸
    // blocks, which fastnbt's default limit of 10⁸ then refused to read.
    let dims: [u32; 3] = [512, 508, 397];
    let grid = GridSpec::new(DVec3::ZERO, 1.0, dims.map(u64::from)).unwrap();
    let mut b = topovox::DenseBits::new(dims);
    for (i, j, k) in [(0, 0, 0), (511, 507, 396), (100, 7, 300), (3, 400, 1)] {
        b.set(i, j, k);
    }
    let p = tmp("big.schem");
    write_voxels_with(&p, VoxelFormat::Schem, &b, &grid, None, &WriteOptions::default()).unwrap();
    let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(back.bits.first_difference(&b).is_none());
    // Past 2³¹ − 1 blocks (NBT's longest array) nothing is written, in one line.
    let e = VoxelFormat::Schem.refuses_dims([2048, 2048, 513]).unwrap();
    assert!(e.contains("at most 2147483647 blocks"), "{e}");
    assert!(VoxelFormat::Schem.refuses_dims([2048, 2048, 511]).is_none());
    assert!(VoxelFormat::Schem.refuses_dims([65536, 1, 1]).unwrap().contains("65535 blocks on a side"));
}

#[test]
fn schem_is_valid_nbt_and_round_trips_voxels() {
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [20, 12, 7]).unwrap();
    let (b, a) = scene([20, 12, 7], 40, 400);
    let p = tmp("c.schem");
    write_voxels_with(&p, VoxelFormat::Schem, &b, &grid, Some(&a), &WriteOptions::default()).unwrap();
    let back = read_voxels(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert!(back.bits.first_difference(&b).is_none());
    // Every voxel became a block of the built-in table, nearest in colour.
    let table: std::collections::HashSet<[u8; 3]> = topovox_io::schem::BLOCKS.iter().map(|b| b.1).collect();
    assert!(back.attributes.unwrap().colour.unwrap().iter().all(|c| table.contains(c)));
    // The raw NBT, read generically.
    let gz = std::fs::read(&p).unwrap();
    let mut nbt = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(&gz[..]), &mut nbt).unwrap();
    let v: fastnbt::Value = fastnbt::from_bytes(&nbt).unwrap();
    let fastnbt::Value::Compound(root) = v else { panic!("root is not a compound") };
    assert_eq!(root.get("Version"), Some(&fastnbt::Value::Int(2)));
    // Up = y (the default): the grid's y is Minecraft's height.
    assert_eq!(root.get("Width"), Some(&fastnbt::Value::Short(20)));
    assert_eq!(root.get("Height"), Some(&fastnbt::Value::Short(12)));
    assert_eq!(root.get("Length"), Some(&fastnbt::Value::Short(7)));
    // WorldEdit's offsets (mcschematic needs them) and the recorded up axis.
    let Some(fastnbt::Value::Compound(meta)) = root.get("Metadata") else { panic!("no Metadata") };
    for k in ["WEOffsetX", "WEOffsetY", "WEOffsetZ"] {
        assert_eq!(meta.get(k), Some(&fastnbt::Value::Int(0)), "{k}");
    }
    assert_eq!(meta.get("TopovoxUp"), Some(&fastnbt::Value::String("y".into())));
    // Up = z: z is the height; read back through the recorded axis (even
    // when the reader is told otherwise).
    let pz = tmp("cz.schem");
    let up_z = WriteOptions { up: topovox_io::orient::Up::Z, ..Default::default() };
    write_voxels_with(&pz, VoxelFormat::Schem, &b, &grid, Some(&a), &up_z).unwrap();
    let mut nbt = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(&std::fs::read(&pz).unwrap()[..]), &mut nbt).unwrap();
    let fastnbt::Value::Compound(rz) = fastnbt::from_bytes::<fastnbt::Value>(&nbt).unwrap() else { panic!() };
    assert_eq!(rz.get("Height"), Some(&fastnbt::Value::Short(7)));
    let back = topovox_io::read_voxels(&pz, &topovox_io::ReadOptions { up: topovox_io::orient::Up::X, ..Default::default() }).unwrap();
    assert!(back.bits.first_difference(&b).is_none());
    // A user palette with two blocks: only those (and air) appear.
    let pal = tmp("blocks.txt");
    std::fs::write(&pal, "# two blocks\nminecraft:black_wool 0 0 0\nwhite_wool 255 255 255\n").unwrap();
    let blocks = topovox_io::schem::BlockPalette::read(&pal).unwrap();
    write_voxels_with(
        &p,
        VoxelFormat::Schem,
        &b,
        &grid,
        Some(&a),
        &WriteOptions { dither: false, blocks: Some(blocks), ..Default::default() },
    )
    .unwrap();
    let gz = std::fs::read(&p).unwrap();
    let mut nbt = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(&gz[..]), &mut nbt).unwrap();
    let fastnbt::Value::Compound(root) = fastnbt::from_bytes::<fastnbt::Value>(&nbt).unwrap() else { panic!() };
    let Some(fastnbt::Value::Compound(palette)) = root.get("Palette") else { panic!("no palette") };
    let names: std::collections::BTreeSet<&str> = palette.keys().map(|s| s.as_str()).collect();
    assert!(
        names.is_subset(&["minecraft:air", "minecraft:black_wool", "minecraft:white_wool", "minecraft:light_gray_concrete"].into()),
        "{names:?}"
    );
    std::fs::write(&pal, "minecraft:stone 1 2\n").unwrap();
    let e = topovox_io::schem::BlockPalette::read(&pal).unwrap_err().to_string();
    assert!(e.contains("blocks.txt") && e.contains("line 1"), "{e}");
}

#[test]
fn coloured_greedy_meshes_load_in_gltf_and_tobj() {
    let grid = GridSpec::new(DVec3::new(1.0, 2.0, 3.0), 0.5, [16, 12, 10]).unwrap();
    let (b, a) = scene([16, 12, 10], 4, 300);
    let palette: Vec<[u8; 3]> = {
        let mut p: Vec<[u8; 3]> = a.colour.as_ref().unwrap().clone();
        p.sort();
        p.dedup();
        p
    };
    let class = |i: u32, j: u32, k: u32| {
        let c = a.colour_of(i, j, k).unwrap();
        palette.iter().position(|&p| p == c).unwrap() as u32 + 1
    };
    let quads = greedy_quads_by_class(&b, &class);
    // The quads as they are (the watertight split has its own tests).
    let plain = topovox_io::voxel_mesh::MeshOptions { watertight: false, triangulate: false };
    let glb = tmp("m.glb");
    let nv = topovox_io::voxel_mesh::write_quads_glb(&glb, &quads, &grid, Some(&palette), &plain).unwrap();
    let (doc, buffers, _) = gltf::import(&glb).unwrap();
    let prim = doc.meshes().next().unwrap().primitives().next().unwrap();
    let reader = prim.reader(|buf| buffers.get(buf.index()).map(|d| &d.0[..]));
    assert_eq!(reader.read_positions().unwrap().count(), nv);
    assert_eq!(reader.read_indices().unwrap().into_u32().count(), quads.len() * 6);
    let colours: std::collections::HashSet<[u32; 3]> = reader
        .read_colors(0)
        .unwrap()
        .into_rgb_f32()
        .map(|c| c.map(|x| topovox::attributes::colour::from_linear(x as f64) as u32))
        .collect();
    assert_eq!(colours.len(), palette.len());
    // The voxelized-back GLB (topovox's own reader, which uses the gltf crate) is the voxels again.
    let loaded = topovox_io::read_mesh(&glb, &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!(loaded.appearance.vertex_colour.len(), nv);
    let obj = tmp("m.obj");
    topovox_io::voxel_mesh::write_quads_obj(&obj, &quads, &grid, Some(&palette), &plain).unwrap();
    let (models, mats) = tobj::load_obj(&obj, &tobj::LoadOptions { triangulate: true, ..Default::default() }).unwrap();
    assert_eq!(mats.unwrap().len(), palette.len());
    assert_eq!(models.iter().map(|m| m.mesh.indices.len()).sum::<usize>(), quads.len() * 6);
}
