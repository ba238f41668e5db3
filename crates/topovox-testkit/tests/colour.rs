//! Colours carried into voxels: against direct texture lookups (an
//! independent OBJ + PNG reading of spot), the UV and wrap conventions on a
//! hand-made quad, vertex colours under both rules, solid interiors, and
//! independence from the thread count.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use glam::DVec3;
use topovox::attributes::carry::{carry, CarryOptions};
use topovox::attributes::{ColourRule, VoxelAttributes};
use topovox::voxelize::{self, Mode, Options};
use topovox::GridSpec;
use topovox_testkit::shared_meshes_dir;

fn spot_path() -> PathBuf {
    shared_meshes_dir().join("spot-textured.obj")
}

fn attrs_for(path: &Path, mode: Mode, res: u64, rule: ColourRule) -> (topovox_io::LoadedMesh, GridSpec, VoxelAttributes) {
    let loaded = topovox_io::read_mesh(path, &topovox_io::ReadOptions::default()).unwrap();
    let grid = GridSpec::from_resolution(&loaded.report.bounds, res).unwrap();
    let (bits, _) = voxelize::fast(mode, loaded.mesh.as_ref(), &grid, &Options::default());
    let a = carry(loaded.mesh.as_ref(), &loaded.appearance, &grid, &bits, &CarryOptions { rule, normals: true });
    assert_eq!(a.keys.len() as u64, bits.count());
    (loaded, grid, a)
}

fn texture_colours(path: &Path) -> HashSet<[u8; 3]> {
    let img = image::open(path).unwrap().to_rgb8();
    img.pixels().map(|p| p.0).collect()
}

#[test]
fn dominant_only_produces_texture_colours_in_every_mode() {
    let texels = texture_colours(&shared_meshes_dir().join("spot_texture.png"));
    for mode in [Mode::Cover, Mode::Sep26, Mode::Sep6, Mode::Ss6, Mode::Pos] {
        let (_, _, a) = attrs_for(&spot_path(), mode, 80, ColourRule::Dominant);
        let c = a.colour.as_ref().expect("spot has a texture");
        let distinct: HashSet<_> = c.iter().collect();
        assert!(distinct.len() > 20, "{mode:?}: only {} colours", distinct.len());
        for col in c {
            assert!(texels.contains(col), "{mode:?}: {col:?} is not a texture colour");
        }
        assert!(a.material.as_ref().unwrap().iter().all(|&m| m == 0));
    }
    // Blend makes colours between texels (area-weighted means).
    let (_, _, b) = attrs_for(&spot_path(), Mode::Cover, 80, ColourRule::Blend);
    let invented = b.colour.as_ref().unwrap().iter().filter(|c| !texels.contains(*c)).count();
    assert!(invented > 0, "blend produced only texel colours");
}

/// An independent reading of spot: OBJ `v`/`vt`/`f v/vt` records and the PNG,
/// v flipped by hand (row = (1 − v)·H).
struct Spot {
    tris: Vec<[DVec3; 3]>,
    uvs: Vec<[[f64; 2]; 3]>,
    img: image::RgbImage,
}

fn read_spot() -> Spot {
    let text = std::fs::read_to_string(spot_path()).unwrap();
    let (mut v, mut vt, mut tris, mut uvs) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first() {
            Some(&"v") => v.push(DVec3::new(w[1].parse().unwrap(), w[2].parse().unwrap(), w[3].parse().unwrap())),
            Some(&"vt") => vt.push([w[1].parse::<f64>().unwrap(), w[2].parse::<f64>().unwrap()]),
            Some(&"f") => {
                let c: Vec<(usize, usize)> = w[1..]
                    .iter()
                    .map(|c| {
                        let mut p = c.split('/');
                        (p.next().unwrap().parse::<usize>().unwrap() - 1, p.next().unwrap().parse::<usize>().unwrap() - 1)
                    })
                    .collect();
                for k in 1..c.len() - 1 {
                    let t = [c[0], c[k], c[k + 1]];
                    tris.push(t.map(|(p, _)| v[p]));
                    uvs.push(t.map(|(_, u)| vt[u]));
                }
            }
            _ => {}
        }
    }
    Spot { tris, uvs, img: image::open(shared_meshes_dir().join("spot_texture.png")).unwrap().to_rgb8() }
}

/// Area per texel colour of the surface inside voxel box `[lo, hi]`, by
/// dense stratified sampling of every triangle near it.
fn direct_lookup(s: &Spot, lo: DVec3, hi: DVec3) -> Vec<([u8; 3], f64)> {
    const N: usize = 120;
    let mut area: HashMap<[u8; 3], f64> = HashMap::new();
    let (w, h) = (s.img.width() as f64, s.img.height() as f64);
    for (t, uv) in s.tris.iter().zip(&s.uvs) {
        let tlo = t[0].min(t[1]).min(t[2]);
        let thi = t[0].max(t[1]).max(t[2]);
        if tlo.cmpgt(hi).any() || thi.cmplt(lo).any() {
            continue;
        }
        let a = 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length();
        let per = a / (N * N) as f64;
        for i in 0..N {
            for j in 0..N - i {
                for (di, dj) in [(1.0 / 3.0, 1.0 / 3.0), (2.0 / 3.0, 2.0 / 3.0)] {
                    if di > 0.5 && i + j + 1 >= N {
                        continue;
                    }
                    let (b1, b2) = ((i as f64 + di) / N as f64, (j as f64 + dj) / N as f64);
                    let p = t[0] + (t[1] - t[0]) * b1 + (t[2] - t[0]) * b2;
                    if p.cmplt(lo).any() || p.cmpgt(hi).any() {
                        continue;
                    }
                    let u = uv[0][0] + (uv[1][0] - uv[0][0]) * b1 + (uv[2][0] - uv[0][0]) * b2;
                    let v = uv[0][1] + (uv[1][1] - uv[0][1]) * b1 + (uv[2][1] - uv[0][1]) * b2;
                    let x = ((u.rem_euclid(1.0)) * w).floor().min(w - 1.0) as u32;
                    let y = (((1.0 - v).rem_euclid(1.0)) * h).floor().min(h - 1.0) as u32;
                    *area.entry(s.img.get_pixel(x, y).0).or_default() += per;
                }
            }
        }
    }
    let mut v: Vec<_> = area.into_iter().collect();
    v.sort_by(|a, b| b.1.total_cmp(&a.1));
    v
}

#[test]
fn spot_voxel_colours_match_direct_texture_lookups() {
    let (_, grid, a) = attrs_for(&spot_path(), Mode::Cover, 48, ColourRule::Dominant);
    let spot = read_spot();
    let colours = a.colour.as_ref().unwrap();
    let (mut checked, mut agree) = (0, 0);
    for slot in (0..a.keys.len()).step_by(a.keys.len() / 150) {
        let v = a.voxel(a.keys[slot]);
        let lo = grid.voxel_min(v);
        let hi = lo + grid.voxel_size().0;
        let direct = direct_lookup(&spot, lo, hi);
        let total: f64 = direct.iter().map(|d| d.1).sum();
        if total <= 0.0 {
            continue;
        }
        // Only voxels with a clear winner: sampling noise cannot flip them.
        let second = direct.get(1).map(|d| d.1).unwrap_or(0.0);
        if direct[0].1 < 0.5 * total || direct[0].1 - second < 0.25 * total {
            continue;
        }
        checked += 1;
        agree += (colours[slot] == direct[0].0) as usize;
        assert_eq!(
            colours[slot],
            direct[0].0,
            "voxel {v:?}: topovox {:?}, direct lookup {:?}",
            colours[slot],
            &direct[..direct.len().min(3)]
        );
        let cov = a.coverage.as_ref().unwrap()[slot] as f64;
        let s = grid.voxel_size().cube().unwrap();
        let want = total / (s * s);
        assert!((cov - want).abs() < 0.02 + 0.02 * want, "voxel {v:?}: coverage {cov} vs sampled {want}");
    }
    assert!(checked >= 40, "only {checked} voxels had a clear dominant colour");
    assert_eq!(agree, checked);
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("topovox-colour-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 2×2 texture: top row red, green; bottom row blue, white.
fn quad_scene(dir: &Path, u0: f64, map: &str) -> PathBuf {
    let mut img = image::RgbImage::new(2, 2);
    img.put_pixel(0, 0, image::Rgb([255, 0, 0]));
    img.put_pixel(1, 0, image::Rgb([0, 255, 0]));
    img.put_pixel(0, 1, image::Rgb([0, 0, 255]));
    img.put_pixel(1, 1, image::Rgb([255, 255, 255]));
    img.save(dir.join("t.png")).unwrap();
    std::fs::write(dir.join("q.mtl"), format!("newmtl q\nKd 1 1 1\nmap_Kd {map}\n")).unwrap();
    let obj = format!(
        "mtllib q.mtl\nusemtl q\nv 0 0 0.25\nv 1 0 0.25\nv 1 1 0.25\nv 0 1 0.25\nvt {u0} 0\nvt {} 0\nvt {} 1\nvt {u0} 1\nf 1/1 2/2 3/3 4/4\n",
        u0 + 1.0,
        u0 + 1.0
    );
    let p = dir.join("q.obj");
    std::fs::write(&p, obj).unwrap();
    p
}

fn quad_colours(path: &Path) -> Vec<[u8; 3]> {
    let loaded = topovox_io::read_mesh(path, &topovox_io::ReadOptions::default()).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let grid = GridSpec::new(DVec3::ZERO, 0.5, [2, 2, 1]).unwrap();
    let (bits, _) = voxelize::fast(Mode::Cover, loaded.mesh.as_ref(), &grid, &Options::default());
    let a = carry(loaded.mesh.as_ref(), &loaded.appearance, &grid, &bits, &CarryOptions::default());
    [[0, 0], [1, 0], [0, 1], [1, 1]].iter().map(|&[i, j]| a.colour_of(i, j, 0).unwrap()).collect()
}

#[test]
fn obj_uvs_are_flipped_and_wrapped() {
    let d = temp_dir("quad");
    // vt (0,0) is the bottom-left of the image in OBJ: voxel (0,0) is blue.
    let want = vec![[0, 0, 255], [255, 255, 255], [255, 0, 0], [0, 255, 0]];
    assert_eq!(quad_colours(&quad_scene(&d, 0.0, "t.png")), want);
    // u in [1, 2] repeats to the same picture ...
    assert_eq!(quad_colours(&quad_scene(&d, 1.0, "t.png")), want);
    // ... and clamps to the right column with `-clamp on`.
    let clamped = vec![[255, 255, 255], [255, 255, 255], [0, 255, 0], [0, 255, 0]];
    assert_eq!(quad_colours(&quad_scene(&d, 1.0, "-clamp on t.png")), clamped);
}

#[test]
fn a_missing_texture_warns_and_uses_the_material_colour() {
    let d = temp_dir("missing");
    std::fs::write(d.join("q.mtl"), "newmtl q\nKd 0.5 0.25 1\nmap_Kd nowhere.png\n").unwrap();
    std::fs::write(d.join("q.obj"), "mtllib q.mtl\nusemtl q\nv 0 0 0.25\nv 1 0 0.25\nv 1 1 0.25\nvt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\n")
        .unwrap();
    let loaded = topovox_io::read_mesh(&d.join("q.obj"), &topovox_io::ReadOptions::default()).unwrap();
    assert!(loaded.warnings.iter().any(|w| w.contains("nowhere.png") && w.contains("Kd")), "{:?}", loaded.warnings);
    let grid = GridSpec::new(DVec3::ZERO, 0.5, [2, 2, 1]).unwrap();
    let (bits, _) = voxelize::fast(Mode::Cover, loaded.mesh.as_ref(), &grid, &Options::default());
    let a = carry(loaded.mesh.as_ref(), &loaded.appearance, &grid, &bits, &CarryOptions::default());
    let want = [0.5f64, 0.25, 1.0].map(topovox::attributes::colour::from_linear);
    assert!(a.colour.unwrap().iter().all(|&c| c == want));
}

#[test]
fn vertex_colours_dominant_picks_a_vertex_colour_blend_mixes() {
    let d = temp_dir("ply");
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0.1 255 0 0\n4 0 0.1 0 255 0\n0 4 0.1 0 0 255\n3 0 1 2\n";
    let p = d.join("t.ply");
    std::fs::write(&p, ply).unwrap();
    let loaded = topovox_io::read_mesh(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!(loaded.appearance.vertex_colour.len(), 3);
    let grid = GridSpec::new(DVec3::ZERO, 0.5, [8, 8, 1]).unwrap();
    let (bits, _) = voxelize::fast(Mode::Cover, loaded.mesh.as_ref(), &grid, &Options::default());
    let dom = carry(loaded.mesh.as_ref(), &loaded.appearance, &grid, &bits, &CarryOptions { rule: ColourRule::Dominant, normals: false });
    let corners: HashSet<[u8; 3]> = [[255, 0, 0], [0, 255, 0], [0, 0, 255]].into();
    assert!(dom.colour.as_ref().unwrap().iter().all(|c| corners.contains(c)));
    assert_eq!(dom.colour_of(0, 0, 0), Some([255, 0, 0]));
    assert_eq!(dom.colour_of(7, 0, 0), Some([0, 255, 0]));
    let blend = carry(loaded.mesh.as_ref(), &loaded.appearance, &grid, &bits, &CarryOptions { rule: ColourRule::Blend, normals: false });
    let mid = blend.colour_of(3, 2, 0).unwrap();
    assert!(mid.iter().all(|&c| c > 40), "a voxel inside the triangle mixes all three: {mid:?}");
}

#[test]
fn solid_interiors_take_the_nearest_surface_colour() {
    let loaded = topovox_io::read_mesh(&spot_path(), &topovox_io::ReadOptions::default()).unwrap();
    let grid = GridSpec::from_resolution(&loaded.report.bounds, 40).unwrap();
    let (solid, _) = topovox::voxelize::solid::parity(loaded.mesh.as_ref(), &grid).unwrap();
    let a = carry(loaded.mesh.as_ref(), &loaded.appearance, &grid, &solid, &CarryOptions::default());
    let texels = texture_colours(&shared_meshes_dir().join("spot_texture.png"));
    let c = a.colour.as_ref().unwrap();
    assert_eq!(c.len() as u64, solid.count());
    assert!(c.iter().all(|col| texels.contains(col)));
    // Interior voxels (no surface inside) exist and are coloured from a neighbour.
    let cov = a.coverage.as_ref().unwrap();
    let interior = (0..c.len()).filter(|&s| cov[s] == 0.0).count();
    assert!(interior > 100, "{interior}");
}

#[test]
fn attributes_do_not_depend_on_the_thread_count() {
    let loaded = topovox_io::read_mesh(&spot_path(), &topovox_io::ReadOptions::default()).unwrap();
    let grid = GridSpec::from_resolution(&loaded.report.bounds, 64).unwrap();
    let (bits, _) = voxelize::fast(Mode::Cover, loaded.mesh.as_ref(), &grid, &Options::default());
    let run = |threads: usize, rule| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| carry(loaded.mesh.as_ref(), &loaded.appearance, &grid, &bits, &CarryOptions { rule, normals: true }))
    };
    for rule in [ColourRule::Dominant, ColourRule::Blend] {
        assert_eq!(run(1, rule), run(3, rule));
    }
}

/// A glTF quad with an external buffer and the 2×2 texture of [`quad_scene`];
/// glTF puts `v = 0` at the top of the image, so the UVs here are the OBJ
/// scene's with `v` flipped, and the voxel colours must come out the same.
fn gltf_quad(dir: &Path, u0: f32, wrap_s: u32, factor: [f32; 4]) -> PathBuf {
    quad_scene(dir, 0.0, "t.png");
    let pos: [[f32; 3]; 4] = [[0.0, 0.0, 0.25], [1.0, 0.0, 0.25], [1.0, 1.0, 0.25], [0.0, 1.0, 0.25]];
    let uv: [[f32; 2]; 4] = [[u0, 1.0], [u0 + 1.0, 1.0], [u0 + 1.0, 0.0], [u0, 0.0]];
    let idx: [u16; 6] = [0, 1, 2, 0, 2, 3];
    let mut bin = Vec::new();
    pos.iter().flatten().for_each(|v| bin.extend_from_slice(&v.to_le_bytes()));
    uv.iter().flatten().for_each(|v| bin.extend_from_slice(&v.to_le_bytes()));
    idx.iter().for_each(|v| bin.extend_from_slice(&v.to_le_bytes()));
    std::fs::write(dir.join("q.bin"), &bin).unwrap();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"indices":2,"material":0}}]}}],
        "materials":[{{"pbrMetallicRoughness":{{"baseColorFactor":{factor:?},"baseColorTexture":{{"index":0}}}}}}],
        "textures":[{{"source":0,"sampler":0}}],"samplers":[{{"wrapS":{wrap_s},"wrapT":10497}}],
        "images":[{{"uri":"t.png"}}],
        "buffers":[{{"uri":"q.bin","byteLength":{}}}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":32}},{{"buffer":0,"byteOffset":80,"byteLength":12}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0.25],"max":[1,1,0.25]}},
          {{"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"}},{{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}}]}}"#,
        bin.len()
    );
    let p = dir.join("q.gltf");
    std::fs::write(&p, json).unwrap();
    p
}

#[test]
fn gltf_uvs_are_not_flipped_and_samplers_wrap() {
    let d = temp_dir("gltf");
    let want = vec![[0, 0, 255], [255, 255, 255], [255, 0, 0], [0, 255, 0]];
    assert_eq!(quad_colours(&gltf_quad(&d, 0.0, 10497, [1.0; 4])), want);
    assert_eq!(quad_colours(&gltf_quad(&d, 1.0, 10497, [1.0; 4])), want, "REPEAT");
    let clamped = vec![[255, 255, 255], [255, 255, 255], [0, 255, 0], [0, 255, 0]];
    assert_eq!(quad_colours(&gltf_quad(&d, 1.0, 33071, [1.0; 4])), clamped, "CLAMP_TO_EDGE");
    let mirrored = vec![[255, 255, 255], [0, 0, 255], [0, 255, 0], [255, 0, 0]];
    assert_eq!(quad_colours(&gltf_quad(&d, 1.0, 33648, [1.0; 4])), mirrored, "MIRRORED_REPEAT");
    // The base colour factor multiplies the texture (in linear light): red × (0, 1, 1) is black.
    let tinted = quad_colours(&gltf_quad(&d, 0.0, 10497, [0.0, 1.0, 1.0, 1.0]));
    assert_eq!(tinted, vec![[0, 0, 255], [0, 255, 255], [0, 0, 0], [0, 255, 0]]);
}

/// Attributes carried slab by slab equal the direct computation
/// (`carry::reference`: every triangle over the whole grid, each piece
/// clipped to its box at once, one reduction) bit for bit, for 1 and 2
/// threads (so for different slab cuts).
fn assert_matches_reference(
    mesh: topovox::MeshRef<'_>,
    app: &topovox::attributes::Appearance,
    grid: &GridSpec,
    bits: &dyn topovox::VoxelSource,
    what: &str,
) {
    for rule in [ColourRule::Dominant, ColourRule::Blend] {
        let opts = CarryOptions { rule, normals: true };
        let want = topovox::attributes::carry::reference::carry(mesh, app, grid, bits, &opts);
        assert_eq!(want.keys.len() as u64, bits.count());
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let got = pool.install(|| carry(mesh, app, grid, bits, &opts));
            assert!(got == want, "{what}, {rule:?}, {threads} threads: attributes differ from the reference");
        }
    }
}

#[test]
fn carried_attributes_equal_the_reference_on_rotated_spot() {
    use rand::{Rng, SeedableRng};
    let loaded = topovox_io::read_mesh(&spot_path(), &topovox_io::ReadOptions::default()).unwrap();
    let mut rng = rand::rngs::SmallRng::seed_from_u64(14);
    for (n, res) in [37u64, 61, 90].into_iter().enumerate() {
        let mut mesh = loaded.mesh.clone();
        if n > 0 {
            let axis = DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)).normalize();
            let rot = glam::DQuat::from_axis_angle(axis, rng.random_range(0.0..std::f64::consts::TAU));
            mesh.transform(|p| rot * p);
        }
        let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), res).unwrap();
        for mode in [Mode::Cover, Mode::Sep26] {
            let (bits, _) = voxelize::fast(mode, mesh.as_ref(), &grid, &Options::default());
            assert_matches_reference(mesh.as_ref(), &loaded.appearance, &grid, &bits, &format!("spot {n} at {res}, {mode:?}"));
        }
    }
    // A solid: interior voxels take their colour from the nearest surface voxel.
    let grid = GridSpec::from_resolution(&loaded.report.bounds, 40).unwrap();
    let (solid, _) = topovox::voxelize::solid::parity(loaded.mesh.as_ref(), &grid).unwrap();
    assert_matches_reference(loaded.mesh.as_ref(), &loaded.appearance, &grid, &solid, "spot solid");
}

#[test]
fn carried_attributes_equal_the_reference_on_random_coloured_triangles() {
    use rand::{Rng, SeedableRng};
    use topovox::attributes::{Appearance, Material, NO_MATERIAL};
    let mut rng = rand::rngs::SmallRng::seed_from_u64(1414);
    for case in 0..12 {
        let nt = rng.random_range(1..60);
        let mut mesh = topovox::Mesh::default();
        for _ in 0..nt * 3 {
            // Coordinates on a coarse lattice now and then, so vertices and edges land on voxel faces.
            let c = |rng: &mut rand::rngs::SmallRng| {
                if rng.random_bool(0.3) {
                    rng.random_range(0..24) as f64 * 0.25
                } else {
                    rng.random_range(0.0..6.0)
                }
            };
            mesh.positions.push(DVec3::new(c(&mut rng), c(&mut rng), c(&mut rng)));
        }
        mesh.triangles = (0..nt as u32).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
        let material = |name: &str, factor: [f32; 3]| Material {
            name: name.into(),
            factor,
            texture: None,
            emission: [0.0; 3],
            roughness: 0.6,
            alpha_cutoff: None,
            alpha_texture: None,
        };
        let app = Appearance {
            materials: vec![material("red", [0.8, 0.1, 0.1]), material("blue", [0.1, 0.2, 0.9])],
            triangle_material: (0..nt).map(|_| [0, 1, NO_MATERIAL][rng.random_range(0..3)]).collect(),
            vertex_colour: if case % 2 == 0 {
                (0..nt * 3).map(|_| [rng.random(), rng.random(), rng.random()]).collect()
            } else {
                Vec::new()
            },
            ..Appearance::default()
        };
        let res = rng.random_range(4..40);
        let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), res).unwrap();
        let (bits, _) = voxelize::fast(Mode::Cover, mesh.as_ref(), &grid, &Options::default());
        assert_matches_reference(mesh.as_ref(), &app, &grid, &bits, &format!("case {case}: {nt} triangles at {res}"));
    }
}
