//! Meshes for tests: the shared meshes, boxes, spheres and triangle soups.

use std::path::PathBuf;

use glam::DVec3;
use topovox::Mesh;

/// Every mesh in `shared/meshes`.
pub const SHARED_MESHES: &[&str] = &[
    "alligator.obj",
    "beetle.obj",
    "cheburashka.obj",
    "cow.obj",
    "fandisk.obj",
    "homer.obj",
    "rocker-arm.obj",
    "spot-textured.obj",
    "stanford-bunny.obj",
    "suzanne.obj",
    "teapot.obj",
    "woody.obj",
];

/// `shared/meshes`: `$TOPOVOX_SHARED/meshes`, else `../shared/meshes`
/// beside the repository, else `target/test-meshes/meshes` (what
/// `scripts/test-meshes.sh` fetches). Panics with a clear message if none
/// is there: tests that need the shared meshes must not pass silently
/// without them.
pub fn shared_meshes_dir() -> PathBuf {
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = match std::env::var_os("TOPOVOX_SHARED") {
        Some(s) => PathBuf::from(s).join("meshes"),
        None => [repo.join("../shared/meshes"), repo.join("target/test-meshes/meshes")]
            .into_iter()
            .find(|d| d.is_dir())
            .unwrap_or_else(|| repo.join("../shared/meshes")),
    };
    assert!(dir.is_dir(), "shared meshes not found at {} (set TOPOVOX_SHARED, or fetch them: bash scripts/test-meshes.sh)", dir.display());
    dir
}

/// Loads a mesh from `shared/meshes`.
pub fn shared_mesh(name: &str) -> Mesh {
    let path = shared_meshes_dir().join(name);
    topovox_io::read_mesh(&path, &topovox_io::ReadOptions::default()).unwrap_or_else(|e| panic!("{e}")).mesh
}

/// An axis-aligned box `[lo, hi]` as 12 outward-facing triangles.
pub fn box_mesh(lo: DVec3, hi: DVec3) -> Mesh {
    let positions: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(if i & 1 == 0 { lo.x } else { hi.x }, if i & 2 == 0 { lo.y } else { hi.y }, if i & 4 == 0 { lo.z } else { hi.z })
        })
        .collect();
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut triangles = Vec::new();
    for q in quads {
        triangles.push([q[0], q[1], q[2]]);
        triangles.push([q[0], q[2], q[3]]);
    }
    Mesh { positions, triangles, segments: Vec::new() }
}

/// A UV sphere of `n` rings (closed, about `2n²` triangles).
pub fn sphere(center: DVec3, radius: f64, n: u32) -> Mesh {
    let n = n.max(3);
    let mut positions = vec![center + DVec3::Z * radius, center - DVec3::Z * radius];
    for r in 1..n {
        let th = std::f64::consts::PI * r as f64 / n as f64;
        for s in 0..2 * n {
            let ph = std::f64::consts::PI * s as f64 / n as f64;
            positions.push(center + radius * DVec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
        }
    }
    let ring = |r: u32, s: u32| 2 + (r - 1) * 2 * n + (s % (2 * n));
    let mut triangles = Vec::new();
    for s in 0..2 * n {
        triangles.push([0, ring(1, s), ring(1, s + 1)]);
        triangles.push([1, ring(n - 1, s + 1), ring(n - 1, s)]);
        for r in 1..n - 1 {
            triangles.push([ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)]);
            triangles.push([ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)]);
        }
    }
    Mesh { positions, triangles, segments: Vec::new() }
}

/// A mesh of independent triangles given by their vertices.
pub fn soup(tris: &[[DVec3; 3]]) -> Mesh {
    Mesh {
        positions: tris.iter().flatten().copied().collect(),
        triangles: (0..tris.len() as u32).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
        segments: Vec::new(),
    }
}
