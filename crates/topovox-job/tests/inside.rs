//! Solids on real-world meshes (issue 66): any face orientation gives the
//! clean mesh's solid, overlapping closed shells give their union, nested
//! shells give cavities, sheets are refused by name; on every thread count
//! and on the dense (`voxelize`) and sparse (`sdf`'s sign) paths.
//!
//! The references are independent of the orientation step: ray parity of
//! each clean shell (`topovox::voxelize::solid::parity`, which ignores
//! orientation), OR-ed for unions, of the whole for nesting.

mod common;

use glam::DVec3;
use topovox::voxelize::solid;
use topovox::{DenseBits, GridSpec, Mesh};
use topovox_job::distance::{sdf, DistanceFormat, SdfRequest, Sign, Width};
use topovox_job::{JobError, Method};
use topovox_testkit::{box_mesh, random_rotation, rng, rotated, shared_mesh, sphere};

/// A small seeded generator (no `rand` in this crate's tests).
struct Lcg(u64);

impl Lcg {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `m` with a fraction `f` of its faces reversed, chosen by `seed`.
fn flipped(m: &Mesh, f: f64, seed: u64) -> Mesh {
    let mut r = Lcg(seed);
    let mut out = m.clone();
    for t in &mut out.triangles {
        if r.unit() < f {
            t.swap(1, 2);
        }
    }
    out
}

/// Every mesh of `parts` in one mesh.
fn joined(parts: &[Mesh]) -> Mesh {
    let mut out = Mesh::default();
    for p in parts {
        let base = out.positions.len() as u32;
        out.positions.extend(&p.positions);
        out.triangles.extend(p.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    out
}

fn inverted(m: &Mesh) -> Mesh {
    let mut out = m.clone();
    out.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    out
}

/// `voxelize --mode solid --method auto` of `m` on `grid` with `threads`.
fn auto_solid(m: &Mesh, grid: &GridSpec, threads: usize) -> Result<DenseBits, JobError> {
    let plan = common::plan_with("solid", Method::Auto, common::on_grid(grid), None);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| topovox_job::voxelize(&plan, m.as_ref(), "mesh", None, None)).map(|v| v.voxels.to_dense())
}

/// The inside of `sdf` (its sparse solid path) on `grid`.
fn sdf_inside(m: &Mesh, grid: &GridSpec) -> Result<DenseBits, JobError> {
    let req = SdfRequest {
        grid: common::on_grid(grid),
        width: Width::Voxels(2.0),
        unsigned: false,
        sign: Sign::Auto,
        max_memory: None,
        format: DistanceFormat::Vdb,
    };
    let s = sdf(m.as_ref(), "mesh", &req, None)?;
    let d = s.field.dense();
    let [nx, ny, nz] = grid.dims();
    let mut bits = DenseBits::new([nx, ny, nz]);
    for (n, &x) in d.iter().enumerate() {
        let n = n as u32;
        if x < 0.0 {
            bits.set(n / (ny * nz), n / nz % ny, n % nz);
        }
    }
    Ok(bits)
}

fn parity(m: &Mesh, grid: &GridSpec) -> DenseBits {
    solid::parity(m.as_ref(), grid).unwrap().0
}

fn union(shells: &[Mesh], grid: &GridSpec) -> DenseBits {
    let mut out = DenseBits::new(grid.dims());
    for s in shells {
        parity(s, grid).for_each_set(|i, j, k| out.set(i, j, k));
    }
    out
}

fn assert_same(got: &DenseBits, want: &DenseBits, what: &str) {
    assert!(want.count() > 0, "{what}: the reference is empty");
    if let Some(v) = got.first_difference(want) {
        panic!("{what}: differs at {v:?} (reference {}; {} vs {} voxels)", want.get(v[0], v[1], v[2]), got.count(), want.count());
    }
}

/// The closed shared meshes, and open ones made closed (their winding
/// solid's blocky surface), each also randomly rotated.
fn closed_meshes() -> Vec<(String, Mesh)> {
    let mut out = Vec::new();
    let mut r = rng(66);
    for name in ["cow.obj", "fandisk.obj", "rocker-arm.obj", "spot-textured.obj", "suzanne.obj", "teapot.obj"] {
        let mut m = shared_mesh(name);
        if !topovox::query::inside::watertight(&topovox::query::inside::triangles(m.as_ref())) {
            let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 20).unwrap();
            let bits = topovox::voxelize::winding::winding(m.as_ref(), &grid).unwrap().0;
            let t = topovox::surface::blocky(&bits, &grid, &topovox::voxelize::Stop::new()).unwrap();
            m = Mesh { positions: t.positions, triangles: t.triangles, segments: Vec::new() };
        }
        out.push((format!("{name} rotated"), rotated(&m, random_rotation(&mut r))));
        out.push((name.to_string(), m));
    }
    out
}

#[test]
fn flipped_faces_give_the_clean_solid_voxel_for_voxel() {
    for (n, (name, clean)) in closed_meshes().into_iter().enumerate() {
        for (res, threads) in [(17, 1), (40, 2)] {
            let grid = GridSpec::from_resolution(&clean.as_ref().bounds(), res).unwrap();
            // The clean mesh's solid: its exact winding number (the union
            // of its overlapping parts), decided again on the vertices as
            // given near the surface, so within a voxel or two of the
            // lattice's.
            let want = auto_solid(&clean, &grid, 1).unwrap();
            let lattice = solid::winding_closed(clean.as_ref(), &grid).unwrap().0;
            let mut differ = 0u64;
            want.for_each_set(|i, j, k| differ += u64::from(!lattice.get(i, j, k)));
            lattice.for_each_set(|i, j, k| differ += u64::from(!want.get(i, j, k)));
            assert!(differ <= 4, "{name} clean at {res}: {differ} voxels off the lattice's winding solid");
            for f in [0.1, 0.3, 0.5] {
                let m = flipped(&clean, f, n as u64 * 7 + res);
                let what = format!("{name}, {f} flipped, at {res}, {threads} threads");
                assert_same(&auto_solid(&m, &grid, threads).unwrap(), &want, &what);
                assert_same(&auto_solid(&inverted(&m), &grid, 3 - threads).unwrap(), &want, &format!("{what}, inverted"));
            }
        }
    }
}

#[test]
fn the_sparse_path_and_point_queries_follow_the_oriented_mesh() {
    let clean = shared_mesh("spot-textured.obj");
    let m = flipped(&clean, 0.3, 5);
    let grid = GridSpec::from_resolution(&clean.as_ref().bounds(), 24).unwrap();
    let want = parity(&clean, &grid);
    assert_same(&sdf_inside(&m, &grid).unwrap(), &want, "sdf's sign, spot 30 % flipped");
    let q = topovox::query::Query::new(m.as_ref(), topovox::query::Sign::Auto).unwrap();
    let [nx, ny, nz] = grid.dims();
    for i in 0..nx {
        for j in 0..ny {
            for k in 0..nz {
                assert_eq!(q.contains(grid.voxel_center([i, j, k])), want.get(i, j, k), "Query.contains at {i} {j} {k}");
            }
        }
    }
}

#[test]
fn a_flipped_open_mesh_stays_within_a_tenth_of_a_percent() {
    let clean = shared_mesh("stanford-bunny.obj");
    for (res, f) in [(48, 0.1), (64, 0.3), (64, 0.5)] {
        let grid = GridSpec::from_resolution(&clean.as_ref().bounds(), res).unwrap();
        let want = auto_solid(&clean, &grid, 2).unwrap();
        let got = auto_solid(&flipped(&clean, f, res), &grid, 2).unwrap();
        let mut differ = 0u64;
        want.for_each_set(|i, j, k| differ += u64::from(!got.get(i, j, k)));
        got.for_each_set(|i, j, k| differ += u64::from(!want.get(i, j, k)));
        assert!(differ as f64 <= 1e-3 * want.count() as f64, "bunny {f} flipped at {res}: {differ} of {} voxels differ", want.count());
    }
}

#[test]
fn overlapping_closed_shells_give_their_union() {
    let spot = shared_mesh("spot-textured.obj");
    let e = spot.as_ref().bounds().extent();
    let mut shifted = spot.clone();
    shifted.transform(|p| p + e * DVec3::new(0.31, 0.17, 0.05));
    let cases: Vec<(&str, Vec<Mesh>)> = vec![
        ("two spheres", vec![sphere(DVec3::ZERO, 1.0, 24), sphere(DVec3::new(0.9, 0.3, 0.1), 0.8, 20)]),
        (
            "three spheres",
            vec![sphere(DVec3::ZERO, 1.0, 24), sphere(DVec3::new(0.9, 0.3, 0.1), 0.8, 20), sphere(DVec3::new(0.2, 1.1, -0.4), 0.7, 18)],
        ),
        (
            "two boxes",
            vec![box_mesh(DVec3::ZERO, DVec3::new(2.0, 1.0, 1.0)), box_mesh(DVec3::new(0.5, 0.3, -0.4), DVec3::new(1.3, 1.7, 0.6))],
        ),
        ("spot and its shifted copy", vec![spot, shifted]),
    ];
    let mut r = rng(7);
    for (n, (name, shells)) in cases.into_iter().enumerate() {
        for turn in 0..2 {
            let shells: Vec<Mesh> = if turn == 0 {
                shells.clone()
            } else {
                let rot = random_rotation(&mut r);
                shells
                    .iter()
                    .map(|s| {
                        let mut s = s.clone();
                        s.transform(|p| rot * p);
                        s
                    })
                    .collect()
            };
            let whole = joined(&shells);
            let grid = GridSpec::from_resolution(&whole.as_ref().bounds(), 36).unwrap();
            let want = union(&shells, &grid);
            assert!(parity(&whole, &grid).count() < want.count(), "{name}: parity of the whole should cut the overlap out");
            for f in [0.0, 0.3] {
                let m = flipped(&whole, f, n as u64 + turn);
                let what = format!("{name} (turn {turn}, {f} flipped)");
                assert_same(&auto_solid(&m, &grid, 2).unwrap(), &want, &what);
                assert_same(&sdf_inside(&m, &grid).unwrap(), &want, &format!("{what}, sdf's sign"));
            }
        }
    }
}

#[test]
fn nested_shells_give_cavities_whichever_way_they_face() {
    let outer = box_mesh(DVec3::ZERO, DVec3::splat(4.0));
    let inner = box_mesh(DVec3::splat(1.0), DVec3::splat(3.0));
    let core = sphere(DVec3::splat(2.0), 0.6, 16);
    for (name, shells) in [("a box in a box", vec![outer.clone(), inner.clone()]), ("a ball in a box in a box", vec![outer, inner, core])] {
        for faces in 0..(1 << shells.len()) {
            let turned: Vec<Mesh> =
                shells.iter().enumerate().map(|(s, m)| if faces >> s & 1 == 1 { inverted(m) } else { m.clone() }).collect();
            let whole = joined(&turned);
            let grid = GridSpec::from_resolution(&whole.as_ref().bounds(), 20).unwrap();
            let want = parity(&whole, &grid);
            let got = auto_solid(&whole, &grid, 2).unwrap();
            assert_same(&got, &want, &format!("{name}, orientations {faces:b}"));
            assert!(!got.get(8, 8, 5), "{name}: the cavity between the boxes is empty");
        }
    }
}

#[test]
fn sheets_are_refused_in_one_line_naming_wrap() {
    let sheet = Mesh {
        positions: vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.2), DVec3::Y],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        segments: Vec::new(),
    };
    let mut r = Lcg(3);
    let mut p = || DVec3::new(r.unit(), r.unit(), r.unit());
    let tris: Vec<[DVec3; 3]> = (0..40).map(|_| [p(), p(), p()]).collect();
    let soup = topovox_testkit::soup(&tris);
    // Waves up to half the sheet's width: pockets on both sides.
    let wavy = height_field(40, |x, y| 0.5 * (6.0 * x).sin() * (5.0 * y).cos());
    let pockets = joined(&[wavy.clone(), {
        let mut w = wavy.clone();
        w.transform(|p| p + DVec3::new(1.5, 0.2, 0.1));
        w
    }]);
    for (name, m) in [("a sheet", sheet), ("a soup of sheets", soup), ("a wavy sheet", wavy), ("two wavy sheets", pockets)] {
        let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 16).unwrap();
        for e in [auto_solid(&m, &grid, 1).err(), sdf_inside(&m, &grid).err()] {
            let e = e.unwrap_or_else(|| panic!("{name}: not refused")).to_string();
            assert!(e.contains("encloses no volume") && e.contains("--inside wrap") && !e.contains('\n'), "{name}: {e}");
        }
    }
}

/// A sheet `z = f(x, y)` over the unit square, `n × n` vertices.
fn height_field(n: u32, f: impl Fn(f64, f64) -> f64) -> Mesh {
    let mut m = Mesh::default();
    for r in 0..n {
        for c in 0..n {
            let (x, y) = (f64::from(c) / f64::from(n - 1), f64::from(r) / f64::from(n - 1));
            m.positions.push(DVec3::new(x, y, f(x, y)));
        }
    }
    for r in 0..n - 1 {
        for c in 0..n - 1 {
            let a = r * n + c;
            m.triangles.push([a, a + 1, a + n]);
            m.triangles.push([a + 1, a + n + 1, a + n]);
        }
    }
    m
}

/// Open surfaces that wrap around some volume are not sheets: a half
/// pipe, a hemisphere and the bunny keep the generalized winding number.
#[test]
fn open_surfaces_around_a_volume_are_not_sheets() {
    let pipe = height_field(30, |_, _| 0.0);
    let mut pipe = pipe;
    pipe.transform(|p| {
        let a = p.x * std::f64::consts::PI;
        DVec3::new(a.cos(), a.sin(), 3.0 * p.y)
    });
    let mut dome = sphere(DVec3::ZERO, 1.0, 24);
    dome.triangles.retain(|t| t.iter().map(|&i| dome.positions[i as usize].z).sum::<f64>() > 0.0);
    for (name, m) in [("a half pipe", pipe), ("a hemisphere", dome), ("the bunny", shared_mesh("stanford-bunny.obj"))] {
        let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 24).unwrap();
        let solid = auto_solid(&m, &grid, 2).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(solid.count() > 0, "{name}: empty");
    }
}
