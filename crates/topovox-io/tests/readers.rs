//! Each reader on small files built here, with known answers.

use std::path::{Path, PathBuf};

use glam::DVec3;
use topovox_io::read_mesh;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("topovox-io-readers-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn write(name: &str, bytes: &[u8]) -> PathBuf {
    let p = tmp(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

fn shared(name: &str) -> PathBuf {
    // As topovox-testkit's `shared_meshes_dir` (which depends on this crate).
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = match std::env::var_os("TOPOVOX_SHARED") {
        Some(s) => PathBuf::from(s).join("meshes"),
        None => {
            [repo.join("../shared/meshes"), repo.join("target/test-meshes/meshes")].into_iter().find(|d| d.is_dir()).unwrap_or_default()
        }
    };
    let p = dir.join(name);
    assert!(p.exists(), "shared mesh {} missing (set TOPOVOX_SHARED, or fetch them: bash scripts/test-meshes.sh)", p.display());
    p
}

#[test]
fn obj_polygons_are_fanned_and_negative_indices_resolved() {
    let p = write("quad.obj", b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf -5 -4 -3 -2\nf 1 2 5\n");
    let m = read_mesh(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!(m.report.triangles, 3);
    assert_eq!(m.mesh.triangles[0], [0, 1, 2]);
    assert_eq!(m.mesh.triangles[1], [0, 2, 3]);
    assert_eq!(m.mesh.triangles[2], [0, 1, 4]);
    assert_eq!(m.report.bounds.max, DVec3::ONE);
}

#[test]
fn obj_with_missing_mtl_warns() {
    let m = read_mesh(&shared("beetle.obj"), &topovox_io::ReadOptions::default()).unwrap();
    assert!(m.report.triangles >= 2053, "{}", m.report.triangles);
    assert!(m.warnings.iter().any(|w| w.contains(".mtl")), "{:?}", m.warnings);
}

#[test]
fn suzanne_quads_become_triangles() {
    let m = read_mesh(&shared("suzanne.obj"), &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!(m.report.vertices, 507);
    assert!(m.report.triangles > 500, "{}", m.report.triangles);
}

fn cube_tris() -> Vec<[[f32; 3]; 3]> {
    let c = |i: u32| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32];
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    quads.iter().flat_map(|q| [[c(q[0]), c(q[1]), c(q[2])], [c(q[0]), c(q[2]), c(q[3])]]).collect()
}

#[test]
fn stl_ascii_and_binary_agree() {
    let tris = cube_tris();
    let mut ascii = String::from("solid cube\n");
    let mut bin = vec![b' '; 80];
    bin.extend((tris.len() as u32).to_le_bytes());
    for t in &tris {
        ascii += "facet normal 0 0 0\nouter loop\n";
        bin.extend([0u8; 12]);
        for v in t {
            ascii += &format!("vertex {} {} {}\n", v[0], v[1], v[2]);
            for c in v {
                bin.extend(c.to_le_bytes());
            }
        }
        ascii += "endloop\nendfacet\n";
        bin.extend([0u8; 2]);
    }
    ascii += "endsolid cube\n";
    let a = read_mesh(&write("cube_ascii.stl", ascii.as_bytes()), &topovox_io::ReadOptions::default()).unwrap();
    let b = read_mesh(&write("cube_bin.stl", &bin), &topovox_io::ReadOptions::default()).unwrap();
    for m in [&a, &b] {
        assert_eq!(m.report.triangles, 12);
        assert_eq!(m.report.vertices, 8);
        assert_eq!(m.report.bounds.min, DVec3::ZERO);
    }
}

#[test]
fn ply_ascii_and_binary_with_polygons() {
    let header = |fmt: &str| {
        format!("ply\nformat {fmt} 1.0\ncomment test\nelement vertex 4\nproperty float x\nproperty float y\nproperty double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n")
    };
    let pts = [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.5]];
    let mut ascii = header("ascii");
    for p in pts {
        ascii += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    ascii += "4 0 1 2 3\n";
    let mut le = header("binary_little_endian").into_bytes();
    let mut be = header("binary_big_endian").into_bytes();
    for p in pts {
        le.extend(p[0].to_le_bytes());
        le.extend(p[1].to_le_bytes());
        le.extend((p[2] as f64).to_le_bytes());
        be.extend(p[0].to_be_bytes());
        be.extend(p[1].to_be_bytes());
        be.extend((p[2] as f64).to_be_bytes());
    }
    le.push(4);
    be.push(4);
    for i in 0..4i32 {
        le.extend(i.to_le_bytes());
        be.extend(i.to_be_bytes());
    }
    for (name, bytes) in [("a.ply", ascii.into_bytes()), ("le.ply", le), ("be.ply", be)] {
        let m = read_mesh(&write(name, &bytes), &topovox_io::ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.mesh.triangles, vec![[0, 1, 2], [0, 2, 3]], "{name}");
        assert_eq!(m.report.bounds.max, DVec3::new(1.0, 1.0, 0.5), "{name}");
    }
}

/// Issue 45, item 6: a PLY of triangle strips (`tristrips`, `-1` starting
/// a strip, as older scans store them) reads as the triangles of the same
/// surface listed as faces, each strip's turned triangles oriented alike,
/// the degenerate ones that join strips left out.
#[test]
fn ply_triangle_strips_read_as_their_triangles() {
    let verts: String = (0..8).map(|v| format!("{} {} {}\n", v & 1, (v >> 1) & 1, (v >> 2) & 1)).collect();
    // The cube's faces as counter-clockwise quads seen from outside.
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let header = |el: &str, n: usize| {
        format!("ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\nelement {el} {n}\nproperty list uchar int vertex_indices\nend_header\n{verts}")
    };
    let faces = header("face", 6) + &quads.iter().map(|q| format!("4 {} {} {} {}\n", q[0], q[1], q[2], q[3])).collect::<String>();
    // A quad a b c d as the strip a b d c; three faces in one strip list
    // joined by a repeated vertex (degenerate triangles), three by -1.
    let strip = |q: &[i64; 4]| vec![q[0], q[1], q[3], q[2]];
    let mut first: Vec<i64> = strip(&quads[0]);
    for q in &quads[1..3] {
        first.extend([*first.last().unwrap(), q[0], q[0]]);
        // Keep the parity of the next strip's first triangle even.
        if first.len() % 2 == 1 {
            first.push(q[0]);
        }
        first.extend(strip(q));
    }
    let mut second: Vec<i64> = Vec::new();
    for q in &quads[3..] {
        second.extend(strip(q));
        second.push(-1);
    }
    let list = |v: &[i64]| format!("{} {}\n", v.len(), v.iter().map(i64::to_string).collect::<Vec<_>>().join(" "));
    let strips = header("tristrips", 2) + &list(&first) + &list(&second);
    // The same closed, outward surface (the quads' diagonals may differ):
    // 12 triangles, every edge used once each way, volume +1.
    for (name, text) in [("faces.ply", faces), ("strips.ply", strips)] {
        let m = read_mesh(&write(name, text.as_bytes()), &topovox_io::ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        let t = &m.mesh.triangles;
        assert_eq!(t.len(), 12, "{name}");
        let edges: std::collections::HashSet<(u32, u32)> = t.iter().flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]).collect();
        assert!(edges.len() == 36 && edges.iter().all(|&(a, b)| edges.contains(&(b, a))), "{name}: not closed and consistent");
        let p = &m.mesh.positions;
        let volume: f64 = t.iter().map(|t| p[t[0] as usize].dot(p[t[1] as usize].cross(p[t[2] as usize])) / 6.0).sum();
        assert!((volume - 1.0).abs() < 1e-12, "{name}: volume {volume}");
    }
}

/// A glTF document with one triangle (mesh 0) instanced by a parent node
/// (translation 10,0,0) and its child (scale 2): the triangle appears twice.
fn gltf_json(uri: Option<&str>, byte_len: usize) -> String {
    let buffer = match uri {
        Some(u) => format!(r#"{{"byteLength": {byte_len}, "uri": "{u}"}}"#),
        None => format!(r#"{{"byteLength": {byte_len}}}"#),
    };
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
        "nodes": [{{"mesh": 0, "translation": [10, 0, 0], "children": [1]}}, {{"mesh": 0, "scale": [2, 2, 2]}}],
        "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
        "accessors": [
          {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
          {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}}],
        "bufferViews": [{{"buffer": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 6}}],
        "buffers": [{buffer}]}}"#
    )
}

fn gltf_bin() -> Vec<u8> {
    let mut b = Vec::new();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        b.extend(v.to_le_bytes());
    }
    for i in [0u16, 1, 2] {
        b.extend(i.to_le_bytes());
    }
    b
}

fn check_gltf(path: &Path) {
    let m = read_mesh(path, &topovox_io::ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(m.report.triangles, 2);
    let b = m.report.bounds;
    // Parent at x = 10; child scaled by 2 inside the parent: x in [10, 12].
    assert_eq!(b.min, DVec3::new(10.0, 0.0, 0.0));
    assert_eq!(b.max, DVec3::new(12.0, 2.0, 0.0));
}

#[test]
fn gltf_with_external_buffer_and_node_transforms() {
    let bin = gltf_bin();
    write("tri.bin", &bin);
    check_gltf(&write("tri.gltf", gltf_json(Some("tri.bin"), bin.len()).as_bytes()));
}

#[test]
fn glb_with_binary_chunk() {
    let mut bin = gltf_bin();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let mut json = gltf_json(None, bin.len()).into_bytes();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    check_gltf(&write("tri.glb", &glb));
}

#[test]
fn obj_polylines_become_segments_next_to_faces() {
    // A triangle, a 3-point polyline (tobj alone would read it as a
    // triangle) with a relative index and a v/vt form, and a 2-point line.
    let p = write("lines.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 2 2 2\nl 1 4 -3/1\nvt 0 0\nl 2 3\n");
    let m = topovox_io::read_mesh(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!((m.report.triangles, m.report.segments), (1, 3));
    let seg = |s: [u32; 2]| [m.mesh.positions[s[0] as usize], m.mesh.positions[s[1] as usize]];
    let v = |x: f64, y: f64, z: f64| glam::DVec3::new(x, y, z);
    assert_eq!(seg(m.mesh.segments[0]), [v(0., 0., 0.), v(2., 2., 2.)]);
    assert_eq!(seg(m.mesh.segments[1]), [v(2., 2., 2.), v(1., 0., 0.)]);
    assert_eq!(seg(m.mesh.segments[2]), [v(1., 0., 0.), v(0., 1., 0.)]);
    assert_eq!(m.report.bounds.max, v(2., 2., 2.));
}

#[test]
fn text_polylines() {
    let p = write("poly.lines", b"# two polylines\n0 0 0 1 1 1 2 0 0\n\n5,5,5, 6,6,6\n");
    let m = topovox_io::read_mesh(&p, &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!((m.report.triangles, m.report.segments, m.report.vertices), (0, 3, 5));
}

#[test]
fn gltf_alpha_modes_become_cutoffs() {
    // Three materials: MASK with a cutoff, MASK with glTF's default (0.5),
    // BLEND (drawn opaque); the triangle uses the first.
    let bin = gltf_bin();
    write("alpha.bin", &bin);
    let json = gltf_json(Some("alpha.bin"), bin.len()).replace(r#""indices": 1}"#, r#""indices": 1, "material": 0}"#).replace(
        r#""buffers":"#,
        r#""materials": [{"alphaMode": "MASK", "alphaCutoff": 0.3}, {"alphaMode": "MASK"}, {"alphaMode": "BLEND"}], "buffers":"#,
    );
    let m = read_mesh(&write("alpha.gltf", json.as_bytes()), &topovox_io::ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let cut: Vec<Option<f32>> = m.appearance.materials.iter().map(|m| m.alpha_cutoff).collect();
    assert_eq!(cut, [Some(0.3), Some(0.5), None, None], "the last is glTF's default material");
}

#[test]
fn gltf_instancing_past_memory_is_refused_before_expanding() {
    // Issue 54: root → 1000 × n1 → 1000 × n2 → 1000 × a one-triangle mesh,
    // 10⁹ instances in about 9.5 KB, grew past 1.5 GB in 4 s.
    let bin = gltf_bin();
    write("inst.bin", &bin);
    let many = |child: usize| format!("[{}]", vec![child.to_string(); 1000].join(","));
    let json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}],
        "nodes": [{{"children": {}}}, {{"children": {}}}, {{"children": {}}}, {{"mesh": 0}}],
        "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
        "accessors": [
          {{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}},
          {{"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}}],
        "bufferViews": [{{"buffer": 0, "byteLength": 36}}, {{"buffer": 0, "byteOffset": 36, "byteLength": 6}}],
        "buffers": [{{"byteLength": {}, "uri": "inst.bin"}}]}}"#,
        many(1),
        many(2),
        many(3),
        bin.len()
    );
    assert!(json.len() < 16_000);
    let t = std::time::Instant::now();
    let e = read_mesh(&write("inst.gltf", json.as_bytes()), &topovox_io::ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("places its meshes 1000000000 times") && e.contains("more than"), "{e}");
    assert!(t.elapsed().as_secs() < 5, "counted, not expanded: {:?}", t.elapsed());
    // A thousand instances are read (and are every one of them).
    let few = json.replacen(&many(1), "[1]", 1).replacen(&many(2), "[2]", 1);
    assert_eq!(read_mesh(&write("few.gltf", few.as_bytes()), &topovox_io::ReadOptions::default()).unwrap().report.triangles, 1000);
    // The same chain whose leaves hold no mesh: 10⁹ node visits place
    // nothing, and are refused as quickly (the mesh is placed once, by the root).
    let empty = json.replacen(r#"{"mesh": 0}]"#, "{}]", 1).replacen(r#"[{"children""#, r#"[{"mesh": 0, "children""#, 1);
    assert_ne!(empty, json);
    let t = std::time::Instant::now();
    let e = read_mesh(&write("empty.gltf", empty.as_bytes()), &topovox_io::ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("visits 1001001001 nodes"), "{e}");
    assert!(t.elapsed().as_secs() < 5, "counted, not walked: {:?}", t.elapsed());
}
