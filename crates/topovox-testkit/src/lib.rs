//! Test helpers for topovox (not published): shared meshes, generated
//! meshes, random rotations, proptest strategies aimed at edge cases, and
//! the [`agree`] harness that runs every path on one input and names the
//! first differing voxel.

use std::path::PathBuf;

use glam::{DMat3, DQuat, DVec3};
use rand::{Rng, SeedableRng};
use topovox::voxelize::driver::Driver;
use topovox::voxelize::{self, Mode, Options, Traversal};
use topovox::{DenseBits, GridSpec, Mesh};

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

/// `shared/meshes`: `$TOPOVOX_SHARED/meshes` or `../shared/meshes` beside the
/// repository. Panics with a clear message if missing: tests that need the
/// shared meshes must not pass silently without them.
pub fn shared_meshes_dir() -> PathBuf {
    let dir = match std::env::var_os("TOPOVOX_SHARED") {
        Some(s) => PathBuf::from(s).join("meshes"),
        None => PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/meshes"),
    };
    assert!(dir.is_dir(), "shared meshes not found at {} (set TOPOVOX_SHARED)", dir.display());
    dir
}

/// Loads a mesh from `shared/meshes`.
pub fn shared_mesh(name: &str) -> Mesh {
    let path = shared_meshes_dir().join(name);
    topovox_io::read_mesh(&path).unwrap_or_else(|e| panic!("{e}")).mesh
}

/// A uniformly random rotation.
pub fn random_rotation(rng: &mut impl Rng) -> DMat3 {
    loop {
        let q = DQuat::from_xyzw(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let len = q.length();
        if len > 0.1 && len <= 1.0 {
            return DMat3::from_quat(q / len);
        }
    }
}

/// A seeded RNG for reproducible tests.
pub fn rng(seed: u64) -> rand::rngs::SmallRng {
    rand::rngs::SmallRng::seed_from_u64(seed)
}

/// A grid of boxes fitted to `bounds`: each axis's edge a random 1 to 8
/// times `longest side / res` (so edges differ by up to 1:8, and no axis
/// has more than `res` voxels).
pub fn box_grid(bounds: &topovox::Aabb, res: u64, r: &mut impl Rng) -> GridSpec {
    let base = bounds.extent().max_element() / res as f64;
    let s = DVec3::new(base * r.random_range(1.0..8.0), base * r.random_range(1.0..8.0), base * r.random_range(1.0..8.0));
    GridSpec::from_voxel_size(bounds, s).unwrap()
}

/// `mesh` taken into index space of `grid` scaled per axis but not moved to
/// its origin: `p / s`; with [`unit_grid`] the same voxels are asked for on
/// unit cubes (the metamorphic twin of a grid of boxes).
pub fn scaled_to_unit(mesh: &Mesh, grid: &GridSpec) -> Mesh {
    let s = grid.voxel_size();
    let mut m = mesh.clone();
    m.transform(|p| p / s);
    m
}

/// `grid` with unit cubes and its origin divided by its voxel size: the grid
/// [`scaled_to_unit`]'s mesh is voxelized on.
pub fn unit_grid(grid: &GridSpec) -> GridSpec {
    GridSpec::new(grid.origin() / grid.voxel_size(), 1.0, grid.dims().map(u64::from)).unwrap()
}

/// `mesh` rotated by `rot` about the centre of its bounding box.
pub fn rotated(mesh: &Mesh, rot: DMat3) -> Mesh {
    let b = mesh.as_ref().bounds();
    let c = (b.min + b.max) * 0.5;
    let mut m = mesh.clone();
    m.transform(|p| c + rot * (p - c));
    m
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

/// Runs every `cover` path — the reference, and the fast path on 1, 2 and 8
/// threads with several slab heights and every traversal — and returns the common result, or a
/// message naming the first configuration and voxel that differ.
pub fn agree(mesh: &Mesh, grid: &GridSpec) -> Result<DenseBits, String> {
    agree_mode(Mode::Cover, mesh, grid)
}

/// [`agree`] for any surface or line mode: the mode's reference against its
/// fast path on 1, 2 and 8 threads, several slab heights and every
/// traversal, against its tiled runs (tiles of 8, 24 and 64; the scanline
/// kernel in tiles of 8 and 24 where the mode has one), and against its
/// scanline path where it has one; names the first differing voxel.
/// Returns the reference grid.
pub fn agree_mode(mode: Mode, mesh: &Mesh, grid: &GridSpec) -> Result<DenseBits, String> {
    let (reference, rep) = voxelize::reference(mode, mesh.as_ref(), grid);
    if reference.count() != rep.voxels {
        return Err(format!("reference report says {} voxels, grid has {}", rep.voxels, reference.count()));
    }
    for threads in [1, 2, 8] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
        // A deferral limit of 1 has a slab run its put-off tests before
        // each next triangle (the slab driver's; the other defers none).
        for (slab_height, traversal, driver, defer_limit) in [
            (0, Traversal::Auto, Driver::Auto, 0),
            (0, Traversal::Auto, Driver::Slabs, 1),
            (0, Traversal::Auto, Driver::Triangles, 0),
            (1, Traversal::WalkRows, Driver::Slabs, 0),
            (7, Traversal::ScanBoxes, Driver::Slabs, 1),
            (0, Traversal::WalkRows, Driver::Triangles, 0),
        ] {
            let opts = Options { slab_height, traversal, driver, defer_limit, ..Options::default() };
            let (fast, frep) = pool.install(|| voxelize::fast(mode, mesh.as_ref(), grid, &opts));
            if fast.count() != frep.voxels {
                return Err(format!("fast report says {} voxels, grid has {}", frep.voxels, fast.count()));
            }
            let fast = fast.to_dense();
            if let Some(v) = reference.first_difference(&fast) {
                return Err(format!(
                    "{} fast (threads {threads}, slab height {slab_height}, {traversal:?}, {driver:?}, deferral limit {defer_limit}) differs from reference at voxel {v:?}: reference {}, fast {}",
                    mode.name(),
                    reference.get(v[0], v[1], v[2]),
                    fast.get(v[0], v[1], v[2])
                ));
            }
            if frep.voxels != rep.voxels || frep.prepare != rep.prepare {
                return Err(format!("fast report {frep:?} differs from reference report {rep:?}"));
            }
        }
        if threads != 2 {
            use voxelize::tiled::TileKernel;
            for (tile, kernel) in [
                (8, TileKernel::Fast),
                (24, TileKernel::Fast),
                (64, TileKernel::Fast),
                (8, TileKernel::Scanline),
                (24, TileKernel::Scanline),
            ] {
                if kernel == TileKernel::Scanline && !voxelize::scanline::supports(mode) {
                    continue;
                }
                let Ok((tiled, trep)) =
                    pool.install(|| voxelize::tiled::tiled_with(mode, kernel, mesh.as_ref(), grid, tile, &Options::default()))
                else {
                    break;
                };
                if let Some(v) = reference.first_difference(&tiled.to_dense()) {
                    return Err(format!(
                        "{} tiled (threads {threads}, tile {tile}, {kernel:?} kernel) differs from reference at voxel {v:?}: reference {}, tiled {}",
                        mode.name(),
                        reference.get(v[0], v[1], v[2]),
                        tiled.get(v[0], v[1], v[2])
                    ));
                }
                if trep != rep || tiled.count() != rep.voxels {
                    return Err(format!("tiled report {trep:?} differs from reference report {rep:?}"));
                }
            }
        }
        for (slab_height, driver) in [(0, Driver::Auto), (1, Driver::Slabs), (7, Driver::Slabs), (0, Driver::Triangles)] {
            let opts = Options { slab_height, driver, ..Options::default() };
            let Some((scan, srep)) = pool.install(|| voxelize::scanline::scanline(mode, mesh.as_ref(), grid, &opts)) else { break };
            let scan = scan.to_dense();
            if let Some(v) = reference.first_difference(&scan) {
                return Err(format!(
                    "{} scanline (threads {threads}, slab height {slab_height}) differs from reference at voxel {v:?}: reference {}, scanline {}",
                    mode.name(),
                    reference.get(v[0], v[1], v[2]),
                    scan.get(v[0], v[1], v[2])
                ));
            }
            if srep.voxels != rep.voxels || srep.prepare != rep.prepare {
                return Err(format!("scanline report {srep:?} differs from reference report {rep:?}"));
            }
        }
    }
    Ok(reference)
}

/// Metamorphic check: voxelizing `mesh` moved by whole voxels `shift` on a
/// grid grown by `margin` voxels per side gives the unmoved result shifted.
/// `voxelize` is the method under test.
pub fn assert_whole_voxel_shift(
    mesh: &Mesh,
    grid: &GridSpec,
    shift: [i32; 3],
    margin: u32,
    voxelize: impl Fn(&Mesh, &GridSpec) -> DenseBits,
) {
    let s = grid.voxel_size();
    let big = GridSpec::new(grid.origin() - margin as f64 * s, s, grid.dims().map(|d| (d + 2 * margin) as u64)).unwrap();
    let a = voxelize(mesh, &big);
    let mut moved = mesh.clone();
    moved.transform(|p| p + DVec3::new(shift[0] as f64, shift[1] as f64, shift[2] as f64) * s);
    let b = voxelize(&moved, &big);
    assert!(a.count() > 0);
    assert_eq!(a.count(), b.count());
    let at = |c: u32, d: i32| (c as i64 + d as i64) as u32;
    a.for_each_set(|i, j, k| assert!(b.get(at(i, shift[0]), at(j, shift[1]), at(k, shift[2])), "{i} {j} {k}"));
}

/// A mesh of independent triangles given by their vertices.
pub fn soup(tris: &[[DVec3; 3]]) -> Mesh {
    Mesh {
        positions: tris.iter().flatten().copied().collect(),
        triangles: (0..tris.len() as u32).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
        segments: Vec::new(),
    }
}

/// Proptest strategies aimed at the edge cases of voxelization: vertices on
/// voxel faces, edges and corners, a few ulps off grid planes, axis-aligned,
/// sliver and zero-area triangles. Coordinates are in grid units of a grid
/// with origin 0 and voxel size 1.
pub mod strategies {
    use glam::DVec3;
    use proptest::prelude::*;

    /// One coordinate in `[-2, 10]`: integers, halves, values a few ulps
    /// off an integer, or arbitrary.
    pub fn coord() -> impl Strategy<Value = f64> {
        prop_oneof![
            (-2i32..=10).prop_map(|i| i as f64),
            (-4i32..=20).prop_map(|i| i as f64 * 0.5),
            ((-2i32..=10), (-3i64..=3)).prop_map(|(i, u)| {
                let x = i as f64;
                f64::from_bits((x.to_bits() as i64 + u) as u64)
            }),
            (-2.0f64..10.0),
        ]
    }

    /// A point of [`coord`]s.
    pub fn point() -> impl Strategy<Value = DVec3> {
        (coord(), coord(), coord()).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    /// A small offset in `[-3, 3]` voxels: whole and half voxels, a few
    /// ulps off them, or arbitrary.
    pub fn offset() -> impl Strategy<Value = f64> {
        prop_oneof![(-3i32..=3).prop_map(|i| i as f64), (-6i32..=6).prop_map(|i| i as f64 * 0.5), (-3.0f64..3.0), (0.0f64..0.3),]
    }

    /// A triangle spanning at most a few voxels — what the short paths for
    /// small triangles take: a vertex from [`point`] (often on a grid
    /// plane), the others offset from it by [`offset`]s, so vertices share
    /// planes, straddle them by ulps or lie exactly on them.
    pub fn small_triangle() -> impl Strategy<Value = [DVec3; 3]> {
        (point(), (offset(), offset(), offset()), (offset(), offset(), offset()))
            .prop_map(|(a, (x1, y1, z1), (x2, y2, z2))| [a, a + DVec3::new(x1, y1, z1), a + DVec3::new(x2, y2, z2)])
    }

    /// A triangle: general, axis-aligned (one coordinate shared), sliver
    /// (third vertex near an edge), zero-area (collinear or repeated), or
    /// tiny around a lattice point.
    pub fn triangle() -> impl Strategy<Value = [DVec3; 3]> {
        prop_oneof![
            3 => (point(), point(), point()).prop_map(|(a, b, c)| [a, b, c]),
            2 => (point(), point(), point(), 0usize..3, coord()).prop_map(|(mut a, mut b, mut c, axis, v)| {
                a[axis] = v;
                b[axis] = v;
                c[axis] = v;
                [a, b, c]
            }),
            1 => (point(), point(), 0.0f64..1.0, -1e-3f64..1e-3).prop_map(|(a, b, t, e)| {
                let c = a + (b - a) * t + DVec3::splat(e);
                [a, b, c]
            }),
            1 => (point(), point(), 0.0f64..1.0).prop_map(|(a, b, t)| [a, b, a + (b - a) * t]),
            1 => (point(), point()).prop_map(|(a, b)| [a, b, a]),
            1 => ((-1i32..=9), (-1i32..=9), (-1i32..=9), point(), point()).prop_map(|(i, j, k, p, q)| {
                let c = DVec3::new(i as f64, j as f64, k as f64);
                [c, c + (p - c) * 1e-3, c + (q - c) * 1e-3]
            }),
        ]
    }
}
