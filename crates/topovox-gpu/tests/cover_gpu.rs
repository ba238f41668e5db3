//! The GPU `cover`, `sep26` and `sep6` equal the CPU references voxel for voxel: every shared
//! mesh, random rotations, random triangles (small, large enough to go to
//! the CPU share, and on lattice planes), and grids cut into many slabs.
//!
//! Needs a GPU adapter with 64-bit shader integers (CI: Mesa's lavapipe).
//! Without one the tests say so and pass, unless `TOPOVOX_REQUIRE_GPU=1`
//! (set by `.ci/run`), where a missing adapter fails them.

use glam::DVec3;
use proptest::prelude::*;
use topovox::voxelize::{self, Mode};
use topovox::{GridSpec, Mesh};
use topovox_gpu::{Gpu, GpuMode};
use topovox_testkit::{random_rotation, rng, rotated, shared_mesh, soup};

fn gpu() -> Option<Gpu> {
    match Gpu::new() {
        Ok(g) => Some(g),
        Err(e) if std::env::var("TOPOVOX_REQUIRE_GPU").as_deref() == Ok("1") => panic!("TOPOVOX_REQUIRE_GPU=1 but {e}"),
        Err(e) => {
            eprintln!("skipping GPU test: {e}");
            None
        }
    }
}

const MODES: [Mode; 3] = [Mode::Cover, Mode::Sep26, Mode::Sep6];

/// Every GPU mode against its CPU reference; returns the cover run's (GPU, CPU) triangle counts.
fn check(g: &Gpu, mesh: &Mesh, grid: &GridSpec, what: &str) -> (u64, u64) {
    let mut counts = (0, 0);
    for mode in MODES {
        let (bits, rep) = g.voxelize(GpuMode::of(mode).unwrap(), mesh.as_ref(), grid).unwrap();
        let (want, _) = voxelize::reference(mode, mesh.as_ref(), grid);
        if let Some(v) = bits.to_dense().first_difference(&want) {
            panic!("{what}, {mode:?}: GPU and CPU reference differ at voxel {v:?} (GPU {} voxels, CPU {})", bits.count(), want.count());
        }
        if mode == Mode::Cover {
            counts = (rep.gpu_triangles, rep.cpu_triangles);
        }
    }
    counts
}

#[test]
fn every_shared_mesh_equals_the_reference() {
    let Some(g) = gpu() else { return };
    eprintln!("adapter: {}", g.adapter());
    for name in topovox_testkit::SHARED_MESHES {
        let mesh = shared_mesh(name);
        let bounds = mesh.as_ref().bounds();
        for res in [37, 128] {
            let grid = GridSpec::from_resolution(&bounds, res).unwrap();
            let (on_gpu, _) = check(&g, &mesh, &grid, &format!("{name} at {res}"));
            assert!(on_gpu > 0);
        }
    }
}

#[test]
fn rotated_meshes_and_many_slabs_equal_the_reference() {
    let Some(mut g) = gpu() else { return };
    let mut r = rng(7);
    for name in ["stanford-bunny.obj", "fandisk.obj", "suzanne.obj"] {
        let mesh = rotated(&shared_mesh(name), random_rotation(&mut r));
        let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), 96).unwrap();
        check(&g, &mesh, &grid, &format!("rotated {name}"));
    }
    // Slabs of 3 layers (and a last partial one).
    let mesh = shared_mesh("cow.obj");
    let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), 64).unwrap();
    let layer = grid.dims()[0].div_ceil(32) as u64 * grid.dims()[1] as u64 * 4;
    g.set_max_slab_bytes(3 * layer);
    check(&g, &mesh, &grid, "cow in 3-layer slabs");
}

#[test]
fn large_triangles_go_to_the_cpu_and_still_agree() {
    let Some(g) = gpu() else { return };
    // A box at 300: faces span 300 voxels, past the shader's i64 bound.
    let mesh = topovox_testkit::box_mesh(DVec3::new(0.1, 0.2, 0.3), DVec3::new(7.3, 5.1, 6.2));
    let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), 300).unwrap();
    let (on_gpu, on_cpu) = check(&g, &mesh, &grid, "box at 300");
    assert!(on_cpu > 0 && on_gpu == 0, "gpu {on_gpu}, cpu {on_cpu}");
    let rot = rotated(&mesh, random_rotation(&mut rng(3)));
    let grid = GridSpec::from_resolution(&rot.as_ref().bounds(), 100).unwrap();
    check(&g, &rot, &grid, "rotated box at 100");
}

#[test]
fn grids_of_boxes_equal_the_reference_on_every_path() {
    use topovox_gpu::GpuPath;
    let Some(g) = gpu() else { return };
    let mut r = rng(43);
    for name in ["suzanne.obj", "cow.obj", "fandisk.obj"] {
        let mesh = rotated(&shared_mesh(name), random_rotation(&mut r));
        let grid = topovox_testkit::box_grid(&mesh.as_ref().bounds(), 64, &mut r);
        let what = format!("rotated {name} on sizes {}", grid.voxel_size());
        check(&g, &mesh, &grid, &what);
        for mode in MODES {
            let (want, _) = voxelize::reference(mode, mesh.as_ref(), &grid);
            let (bits, _) = g.voxelize_with(GpuMode::of(mode).unwrap(), GpuPath::Raster, mesh.as_ref(), &grid).unwrap();
            if let Some(v) = bits.to_dense().first_difference(&want) {
                panic!("{what}, {mode:?}, rasterizer: differs from the reference at {v:?}");
            }
        }
        if name != "suzanne.obj" {
            check_solid(&g, &mesh, &grid, &what);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn random_triangles_equal_the_reference(tris in proptest::collection::vec(topovox_testkit::strategies::triangle(), 1..12)) {
        let Some(g) = gpu() else { return Ok(()) };
        let mesh = soup(&tris);
        let grid = GridSpec::new(DVec3::splat(-2.0), 0.25, [48, 48, 48]).unwrap();
        check(&g, &mesh, &grid, "random soup");
    }
}

fn check_solid(g: &Gpu, mesh: &Mesh, grid: &GridSpec, what: &str) -> (u64, u64) {
    let (bits, rep) = g.solid_parity(mesh.as_ref(), grid).unwrap();
    let (want, cpu_rep) = topovox::voxelize::solid::parity(mesh.as_ref(), grid).unwrap();
    if let Some(v) = bits.first_difference(&want) {
        panic!("{what}, solid: GPU and CPU parity differ at voxel {v:?} (GPU {} voxels, CPU {})", bits.count(), want.count());
    }
    assert_eq!(rep.solid.boundary_edges, cpu_rep.boundary_edges);
    (rep.gpu_triangles, rep.cpu_triangles)
}

#[test]
fn solid_parity_equals_the_cpu_parity() {
    let Some(mut g) = gpu() else { return };
    for name in ["stanford-bunny.obj", "cow.obj", "fandisk.obj", "suzanne.obj", "rocker-arm.obj", "spot-textured.obj", "teapot.obj"] {
        let mesh = shared_mesh(name);
        for res in [33, 100] {
            let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), res).unwrap();
            check_solid(&g, &mesh, &grid, &format!("{name} at {res}"));
        }
    }
    let mut r = rng(11);
    let mesh = rotated(&shared_mesh("stanford-bunny.obj"), random_rotation(&mut r));
    let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), 90).unwrap();
    check_solid(&g, &mesh, &grid, "rotated bunny");
    // A box whose faces pass exactly through voxel centres (ties), and one too large for i64 on the GPU.
    let cube = topovox_testkit::box_mesh(DVec3::splat(0.5), DVec3::splat(6.5));
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [8, 8, 8]).unwrap();
    check_solid(&g, &cube, &grid, "cube through centres");
    let big = topovox_testkit::box_mesh(DVec3::new(0.1, 0.2, 0.3), DVec3::new(7.3, 5.1, 6.2));
    let grid = GridSpec::from_resolution(&big.as_ref().bounds(), 200).unwrap();
    let (on_gpu, on_cpu) = check_solid(&g, &big, &grid, "box at 200");
    assert!(on_cpu > 0 && on_gpu == 0);
    // Many slabs.
    let cow = shared_mesh("cow.obj");
    let grid = GridSpec::from_resolution(&cow.as_ref().bounds(), 64).unwrap();
    let layer = grid.dims()[0].div_ceil(32) as u64 * grid.dims()[1] as u64 * 4;
    g.set_max_slab_bytes(5 * layer);
    check_solid(&g, &cow, &grid, "cow in 5-layer slabs");
    // CPU flips (oversized triangles) routed to one-layer slabs in small chunks.
    let grid = GridSpec::from_resolution(&big.as_ref().bounds(), 200).unwrap();
    g.set_max_slab_bytes(grid.dims()[0].div_ceil(32) as u64 * grid.dims()[1] as u64 * 4);
    check_solid(&g, &big, &grid, "box at 200 in one-layer slabs");
}

#[test]
fn the_rasterizer_path_equals_the_reference_and_msaa_only_misses() {
    use topovox_gpu::GpuPath;
    let Some(g) = gpu() else { return };
    eprintln!("hardware conservative rasterization: {}", g.hardware_conservative());
    let mut r = rng(5);
    let meshes = [
        ("bunny", shared_mesh("stanford-bunny.obj"), 100),
        ("fandisk", shared_mesh("fandisk.obj"), 64),
        ("rotated suzanne", rotated(&shared_mesh("suzanne.obj"), random_rotation(&mut r)), 80),
        ("rotated cow", rotated(&shared_mesh("cow.obj"), random_rotation(&mut r)), 57),
        ("alligator", shared_mesh("alligator.obj"), 64),
    ];
    let mut missed_total = 0;
    for (name, mesh, res) in &meshes {
        let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), *res).unwrap();
        for mode in MODES {
            let gm = GpuMode::of(mode).unwrap();
            let (want, _) = voxelize::reference(mode, mesh.as_ref(), &grid);
            let (bits, _) = g.voxelize_with(gm, GpuPath::Raster, mesh.as_ref(), &grid).unwrap();
            if let Some(v) = bits.to_dense().first_difference(&want) {
                panic!("{name}, {mode:?}, rasterizer: differs from the reference at {v:?} ({} vs {})", bits.count(), want.count());
            }
            let (msaa, _) = g.voxelize_with(gm, GpuPath::MsaaApprox, mesh.as_ref(), &grid).unwrap();
            let msaa = msaa.to_dense();
            let mut extra = 0;
            let mut missed = 0;
            want.for_each_set(|i, j, k| missed += !msaa.get(i, j, k) as u64);
            msaa.for_each_set(|i, j, k| extra += !want.get(i, j, k) as u64);
            assert_eq!(extra, 0, "{name}, {mode:?}: MSAA set voxels the reference does not");
            eprintln!("{name} at {res}, {mode:?}: MSAA misses {missed} of {} voxels", want.count());
            missed_total += missed;
        }
    }
    assert!(missed_total > 0, "MSAA is an approximation; it should miss some voxels on these meshes");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    #[test]
    fn random_triangles_rasterized_equal_the_reference(tris in proptest::collection::vec(topovox_testkit::strategies::triangle(), 1..10)) {
        let Some(g) = gpu() else { return Ok(()) };
        let mesh = soup(&tris);
        let grid = GridSpec::new(DVec3::splat(-2.0), 0.25, [48, 48, 48]).unwrap();
        for mode in MODES {
            let (bits, _) = g.voxelize_with(GpuMode::of(mode).unwrap(), topovox_gpu::GpuPath::Raster, mesh.as_ref(), &grid).unwrap();
            let (want, _) = voxelize::reference(mode, mesh.as_ref(), &grid);
            prop_assert!(bits.to_dense().first_difference(&want).is_none(), "{:?}: {} vs {}", mode, bits.count(), want.count());
        }
    }
}

#[test]
fn many_meshes_in_one_dispatch_equal_one_call_each() {
    let Some(g) = gpu() else { return };
    let mut r = rng(57);
    let mut meshes = Vec::new();
    for name in ["stanford-bunny.obj", "fandisk.obj", "suzanne.obj", "teapot.obj", "cow.obj"] {
        meshes.push(rotated(&shared_mesh(name), random_rotation(&mut r)));
    }
    let mut items: Vec<(topovox::MeshRef<'_>, GridSpec)> = Vec::new();
    for (n, m) in meshes.iter().enumerate() {
        let b = m.as_ref().bounds();
        items.push((m.as_ref(), GridSpec::from_resolution(&b, [24, 40, 33, 64, 17][n]).unwrap()));
    }
    // A rotated box in a grid of its middle layers: its faces reach past
    // the grid in z, so it runs on its own.
    let boxed = rotated(&topovox_testkit::box_mesh(DVec3::ZERO, DVec3::new(4.0, 3.0, 5.0)), random_rotation(&mut r));
    let b = boxed.as_ref().bounds();
    let h = (b.max - b.min).max_element() / 30.0;
    let centre = (b.min + b.max) / 2.0;
    let cut = GridSpec::new(centre - DVec3::new(15.0, 15.0, 5.0) * h, h, [30, 30, 10]).unwrap();
    items.insert(2, (boxed.as_ref(), cut));
    for mode in MODES {
        let gm = GpuMode::of(mode).unwrap();
        let (out, rep) = g.voxelize_stacked(gm, topovox_gpu::GpuPath::Compute, &items).unwrap();
        assert_eq!((rep.stacked, rep.alone), (5, 1), "{mode:?}");
        for (n, ((bits, report), (mesh, grid))) in out.iter().zip(&items).enumerate() {
            let (one, one_rep) = g.voxelize(gm, *mesh, grid).unwrap();
            if let Some(v) = bits.to_dense().first_difference(&one.to_dense()) {
                panic!("{mode:?}, item {n}: stacked and alone differ at voxel {v:?} ({} and {} voxels)", bits.count(), one.count());
            }
            assert_eq!(report.voxels, one.count());
            assert_eq!(report.prepare, one_rep.report.prepare, "{mode:?}, item {n}");
        }
    }
}
