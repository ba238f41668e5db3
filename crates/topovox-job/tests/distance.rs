//! Distance fields (issue 42): every stored value within 1e-5 voxel (plus
//! float32 rounding) of the brute-force reference on the shared meshes,
//! randomly rotated meshes and random soups; the sign equal to
//! `voxelize --mode solid` voxel for voxel on open and closed meshes for
//! every sign rule; the band and `--band all` paths equal where both
//! store; every thread count byte-identical; bad input refused.

mod common;

use glam::DVec3;
use proptest::prelude::*;
use topovox::distance::reference;
use topovox::Mesh;
use topovox_job::distance::{sdf, write, DistanceFormat, Sdf, SdfRequest, Sign, Width};
use topovox_job::{GridOptions, GridRequest, JobError, Method};
use topovox_testkit::{box_grid, random_rotation, rng, rotated, shared_mesh, soup, sphere};

fn request(resolution: u64, width: Width, sign: Sign, unsigned: bool) -> SdfRequest {
    let grid = GridRequest::new(&GridOptions { resolution: Some(resolution), pad: Some(2), ..GridOptions::default() }).unwrap();
    SdfRequest { grid, width, unsigned, sign, max_memory: None, format: DistanceFormat::Vdb }
}

fn run(mesh: &Mesh, req: &SdfRequest, threads: usize) -> Sdf {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| sdf(mesh.as_ref(), "mesh", req, None)).unwrap()
}

/// Every value of `s` within 1e-5 voxel plus f32 rounding of the reference
/// (outside the band: the reference is at least the radius, and the value
/// is ±background).
fn assert_exact(mesh: &Mesh, s: &Sdf, what: &str) {
    assert_close(&reference::distances(mesh.as_ref(), &s.grid).unwrap(), s, what)
}

/// [`assert_exact`] against reference distances `want` of the same grid.
fn assert_close(want: &[f64], s: &Sdf, what: &str) {
    let got = s.field.dense();
    let h = s.grid.voxel_size().0.max_element();
    let bg = s.field.background as f64;
    for (n, (&g, &w)) in got.iter().zip(want).enumerate() {
        let g = g.abs() as f64;
        let ok = if g == bg && s.field.band.count() < want.len() as u64 {
            w >= bg * (1.0 - 1e-6)
        } else {
            (g - w).abs() <= 1e-5 * h + w * f32::EPSILON as f64
        };
        assert!(ok, "{what}: voxel {n}: stored {g}, reference {w} (voxel size {h})");
    }
}

/// `sdf < 0` exactly on the voxels `--mode solid --method M` sets; how many.
fn assert_sign_is_solid(mesh: &Mesh, s: &Sdf, method: Method, what: &str) -> usize {
    let solid = common::plan_with("solid", method, common::on_grid(&s.grid), None);
    let v = topovox_job::voxelize(&solid, mesh.as_ref(), "mesh", None, None).unwrap().voxels.to_dense();
    let d = s.field.dense();
    let [_, ny, nz] = s.grid.dims().map(|x| x as usize);
    let mut inside = 0;
    for (n, &x) in d.iter().enumerate() {
        let (i, j, k) = (n / (ny * nz), n / nz % ny, n % nz);
        let set = v.get(i as u32, j as u32, k as u32);
        inside += set as usize;
        assert_eq!(x < 0.0, set, "{what}: voxel {:?} holds {x}, solid says {set}", [i, j, k]);
    }
    inside
}

#[test]
fn shared_meshes_match_the_reference_and_the_solid() {
    let mut r = rng(42);
    let mut inside = 0;
    for (name, res) in [("suzanne.obj", 20), ("beetle.obj", 18), ("cow.obj", 14), ("teapot.obj", 14), ("stanford-bunny.obj", 8)] {
        let base = shared_mesh(name);
        for turn in 0..2 {
            let mesh = if turn == 0 { base.clone() } else { rotated(&base, random_rotation(&mut r)) };
            // The three requests fit the same grid: one reference.
            let mut want = None;
            for (sign, method) in [(Sign::Auto, Method::Auto), (Sign::Winding, Method::Winding)] {
                let what = format!("{name} (turn {turn}, sign {sign})");
                let band = run(&mesh, &request(res, Width::Voxels(2.5), sign, false), 2);
                let want = want.get_or_insert_with(|| reference::distances(mesh.as_ref(), &band.grid).unwrap());
                assert_close(want, &band, &what);
                inside += assert_sign_is_solid(&mesh, &band, method, &what);
            }
            let all = run(&mesh, &request(res, Width::All, Sign::Auto, false), 2);
            assert_close(want.as_ref().expect("computed above"), &all, &format!("{name} (turn {turn}, all)"));
        }
    }
    assert!(inside > 1000, "the signs were tested on {inside} inside voxels only");
}

/// Grids of boxes: distances in world units from each box's centre, the
/// band at least `W` voxels deep along every axis, the sign the solid's,
/// and the written files read back on the same grid.
#[test]
fn grids_of_boxes_keep_world_distances_and_the_solid_sign() {
    let mut r = rng(43);
    for name in ["suzanne.obj", "cow.obj"] {
        let mesh = rotated(&shared_mesh(name), random_rotation(&mut r));
        let sizes = box_grid(&mesh.as_ref().bounds(), 40, &mut r).voxel_size().0.to_array();
        let grid = GridRequest::new(&GridOptions { voxel_size: Some(sizes.into()), pad: Some(2), ..GridOptions::default() }).unwrap();
        let what = format!("{name} on sizes {sizes:?}");
        let req = SdfRequest {
            grid,
            width: Width::Voxels(2.0),
            unsigned: false,
            sign: Sign::Winding,
            max_memory: None,
            format: DistanceFormat::Vdb,
        };
        let s = run(&mesh, &req, 2);
        assert_eq!(s.grid.voxel_size().0.to_array(), sizes);
        assert_exact(&mesh, &s, &what);
        let largest = sizes.iter().fold(0f64, |a, &b| a.max(b));
        assert_eq!(s.field.background, (2.0 * largest) as f32, "{what}: the band is measured in the largest edge");
        assert!(assert_sign_is_solid(&mesh, &s, Method::Winding, &what) > 0, "{what}");
        let all = run(&mesh, &SdfRequest { width: Width::All, ..req }, 2);
        assert_exact(&mesh, &all, &format!("{what}, all"));
    }
}

#[test]
fn parity_sign_is_the_parity_solid() {
    let mesh = sphere(DVec3::new(0.3, -0.2, 0.1), 1.0, 10);
    let s = run(&mesh, &request(24, Width::Voxels(3.0), Sign::Parity, false), 2);
    assert_eq!(s.facts["sign"], "parity");
    assert!(assert_sign_is_solid(&mesh, &s, Method::Parity, "sphere") > 1000);
}

#[test]
fn band_and_all_agree_and_threads_change_nothing() {
    let mesh = rotated(&shared_mesh("cow.obj"), random_rotation(&mut rng(7)));
    let band = run(&mesh, &request(40, Width::Voxels(3.0), Sign::Auto, false), 1);
    let all = run(&mesh, &request(40, Width::All, Sign::Auto, false), 1);
    let dense = all.field.dense();
    let [_, ny, nz] = band.grid.dims().map(|x| x as usize);
    band.field.band.for_each(|i, j, k, v| {
        let n = (i as usize * ny + j as usize) * nz + k as usize;
        assert_eq!(v.to_bits(), dense[n].to_bits(), "voxel {:?}", [i, j, k]);
    });
    let dir = std::env::temp_dir().join(format!("topovox-sdf-threads-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for format in [DistanceFormat::Vdb, DistanceFormat::Npy, DistanceFormat::Vti] {
        let bytes = |threads: usize, req: &SdfRequest| {
            let s = run(&mesh, req, threads);
            let out = dir.join(format!("f-{threads}.{format}"));
            write(&out, format, &s, None).unwrap();
            std::fs::read(&out).unwrap()
        };
        for req in [request(40, Width::Voxels(3.0), Sign::Auto, false), request(24, Width::All, Sign::Auto, true)] {
            let one = bytes(1, &req);
            for t in [2, 3] {
                assert!(one == bytes(t, &req), "{format}: {t} threads wrote other bytes");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn unsigned_fields_have_no_sign() {
    let mesh = shared_mesh("suzanne.obj");
    let s = run(&mesh, &request(20, Width::Voxels(2.0), Sign::Auto, true), 2);
    assert!(s.field.inside.is_none() && !s.signed);
    assert!(s.field.dense().iter().all(|&v| v >= 0.0));
    assert_exact(&mesh, &s, "suzanne unsigned");
}

#[test]
fn bad_input_is_refused() {
    let mut m = shared_mesh("suzanne.obj");
    m.positions[3].y = f64::NAN;
    let e = sdf(m.as_ref(), "m.obj", &request(16, Width::Voxels(3.0), Sign::Auto, false), None).err().unwrap();
    assert!(matches!(&e, JobError::Invalid(s) if s.contains("m.obj") && s.contains("non-finite")), "{e}");
    let e = sdf(Mesh::default().as_ref(), "e.obj", &request(16, Width::Voxels(3.0), Sign::Auto, false), None).err().unwrap();
    assert!(matches!(&e, JobError::Invalid(_)), "{e}");
    for bad in ["0", "-1", "nan", "inf", "x", ""] {
        assert!(Width::parse(bad).is_err(), "{bad}");
    }
    // A dense format past --max-memory is refused before any work.
    let mut req = request(512, Width::Voxels(3.0), Sign::Auto, false);
    req.max_memory = Some(1 << 20);
    req.format = DistanceFormat::Npy;
    let e = sdf(shared_mesh("cow.obj").as_ref(), "cow.obj", &req, None).err().unwrap();
    assert!(matches!(&e, JobError::Failed(s) if s.contains("max-memory")), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Random soups (degenerate triangles included) at random resolutions:
    /// exact on both paths; the sign is the solid's (generalized winding).
    #[test]
    fn random_soups(tris in prop::collection::vec(topovox_testkit::strategies::triangle(), 1..12), res in 6u64..16) {
        let mesh = soup(&tris);
        prop_assume!(!mesh.as_ref().bounds().is_empty());
        for width in [Width::Voxels(2.0), Width::All] {
            let req = request(res, width, Sign::Auto, false);
            let Ok(s) = sdf(mesh.as_ref(), "soup", &req, None) else { continue };
            assert_exact(&mesh, &s, "soup");
        }
    }
}

/// `convert`, `render` and `check` read a written field in any format as
/// its inside: exactly the negative voxels (the solid), with the
/// placement where the format keeps it; an unsigned field as the voxels
/// within half a voxel diagonal of the surface (not in `.npy`, which keeps
/// no voxel size).
#[test]
fn written_fields_read_back_as_their_inside() {
    let dir = std::env::temp_dir().join(format!("topovox-sdf-read-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = rotated(&shared_mesh("cow.obj"), random_rotation(&mut rng(3)));
    for (req, what) in [
        (request(64, Width::Voxels(3.0), Sign::Auto, false), "band"),
        (request(40, Width::All, Sign::Auto, false), "all"),
        (request(48, Width::Voxels(2.0), Sign::Auto, true), "unsigned"),
    ] {
        let s = run(&mesh, &req, 2);
        let d = s.field.dense();
        let near = (0.5 * s.grid.voxel_size().0.length()) as f32;
        let want: Vec<bool> = d.iter().map(|&v| if s.signed { v < 0.0 } else { v <= near }).collect();
        assert!(want.iter().filter(|&&w| w).count() > 100, "{what}");
        for format in [DistanceFormat::Vdb, DistanceFormat::Npy, DistanceFormat::Zarr, DistanceFormat::Vti] {
            if format == DistanceFormat::Npy && !s.signed {
                continue; // .npy records no voxel size: an unsigned field has no inside
            }
            let out = dir.join(format!("{what}.{format}"));
            write(&out, format, &s, None).unwrap();
            let back = topovox_io::read_voxels(&out, &topovox_io::ReadOptions::default()).unwrap();
            assert_eq!(back.bits.dims(), s.grid.dims(), "{what} {format}");
            let [_, ny, nz] = s.grid.dims().map(|x| x as usize);
            for (n, &w) in want.iter().enumerate() {
                let (i, j, k) = ((n / (ny * nz)) as u32, (n / nz % ny) as u32, (n % nz) as u32);
                assert_eq!(back.bits.get(i, j, k), w, "{what} {format}: voxel {:?}", [i, j, k]);
            }
            if format != DistanceFormat::Npy {
                let (o, size) = back.placement.unwrap();
                assert_eq!((o, size), (s.grid.origin(), s.grid.voxel_size().0), "{what} {format}");
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
