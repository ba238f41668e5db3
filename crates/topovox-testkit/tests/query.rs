//! Point queries against the grids: `Query::contains` at every voxel centre
//! equals the solid voxelization with the same rule, and `Query::distance`
//! the dense distance field, bit for bit.
//!
//! The grids decide on vertices snapped to their 1/4096-voxel lattice, the
//! queries on the vertices as given. On meshes whose vertices lie on the
//! lattice (a power-of-two voxel size, vertices rounded to it) the two are
//! the same mesh and must agree exactly, ties included; on any mesh they
//! may differ only at centres within the snapping's reach of the surface.

use glam::DVec3;
use topovox::distance::{nearest, Pieces};
use topovox::query::{Query, Sign};
use topovox::stop::Stop;
use topovox::voxelize::{solid, winding};
use topovox::{DenseBits, GridSpec, Mesh};
use topovox_testkit::{box_mesh, random_rotation, rng, rotated, shared_mesh, sphere};

/// A grid over `m` with a power-of-two voxel size about `extent / res`
/// and an origin on a multiple of it, so lattice points are exact floats.
fn dyadic_grid(m: &Mesh, res: f64) -> GridSpec {
    let b = m.as_ref().bounds();
    let h = 2f64.powf((b.extent().max_element() / res).log2().floor());
    let origin = (b.min / h).floor() * h - DVec3::splat(h);
    let dims = ((b.max - origin) / h).ceil() + 1.0;
    GridSpec::new(origin, h, dims.to_array().map(|d| d as u64)).unwrap()
}

/// `m` with every vertex moved to the nearest point of `grid`'s lattice.
fn on_lattice(m: &Mesh, grid: &GridSpec) -> Mesh {
    let (o, h) = (grid.origin(), grid.voxel_size().0 / 4096.0);
    let mut out = m.clone();
    out.transform(|p| o + ((p - o) / h).round() * h);
    out
}

/// The grid solid by `q`'s rule, as `voxelize --mode solid` picks it:
/// the winding rules on the mesh as `orient` turns it.
fn grid_solid(m: &Mesh, grid: &GridSpec, sign: Sign, watertight: bool) -> DenseBits {
    let oriented = topovox::query::orient::orient(m.as_ref());
    let o = oriented.mesh(m.as_ref());
    match (sign, watertight) {
        (Sign::Parity, _) => solid::parity(m.as_ref(), grid).unwrap().0,
        (_, true) => solid::winding_closed(o, grid).unwrap().0,
        (_, false) => winding::winding(o, grid).unwrap().0,
    }
}

/// Voxels where `contains` and the grid solid differ, with their distance
/// to the surface in voxels and their winding number.
fn differences(m: &Mesh, grid: &GridSpec, sign: Sign) -> Vec<([u32; 3], f64, f64)> {
    let q = Query::new(m.as_ref(), sign).unwrap();
    let bits = grid_solid(m, grid, sign, q.facts().watertight);
    let [nx, ny, nz] = grid.dims();
    let h = grid.voxel_size().0.max_element();
    let mut out = Vec::new();
    for i in 0..nx {
        for j in 0..ny {
            for k in 0..nz {
                let c = grid.voxel_center([i, j, k]);
                if q.contains(c) != bits.get(i, j, k) {
                    out.push(([i, j, k], q.distance(c) / h, q.winding_number(c)));
                }
            }
        }
    }
    out
}

fn meshes() -> Vec<(String, Mesh)> {
    let mut out: Vec<(String, Mesh)> =
        ["stanford-bunny.obj", "teapot.obj", "suzanne.obj", "fandisk.obj"].iter().map(|n| (n.to_string(), shared_mesh(n))).collect();
    out.push(("sphere".into(), sphere(DVec3::new(0.3, -0.2, 0.1), 1.7, 12)));
    for (n, m) in out.clone() {
        out.push((format!("{n} rotated"), rotated(&m, random_rotation(&mut rng(n.len() as u64 + 3)))));
    }
    out
}

#[test]
fn contains_equals_the_grid_solid_on_lattice_meshes() {
    for (name, m) in meshes() {
        for sign in [Sign::Auto, Sign::Winding, Sign::Parity] {
            let grid = dyadic_grid(&m, 28.0);
            let m = on_lattice(&m, &grid);
            let d = differences(&m, &grid, sign);
            assert!(d.is_empty(), "{name} {sign:?}: {} voxels differ, first {:?}", d.len(), &d[..d.len().min(5)]);
        }
    }
}

#[test]
fn boxes_through_voxel_centres_tie_alike() {
    // Faces, edges and corners exactly through centres: the tie rule decides.
    let m = box_mesh(DVec3::new(1.5, 2.5, 0.5), DVec3::new(6.5, 5.5, 7.5));
    let grid = GridSpec::new(DVec3::ZERO, 1.0, [9, 9, 9]).unwrap();
    for sign in [Sign::Auto, Sign::Winding, Sign::Parity] {
        assert!(differences(&m, &grid, sign).is_empty(), "{sign:?}");
    }
    // Open: the box without its top.
    let mut open = m.clone();
    open.triangles.truncate(10);
    assert!(differences(&open, &grid, Sign::Auto).is_empty());
}

#[test]
fn off_the_lattice_contains_differs_only_within_the_snapping() {
    for (name, m) in meshes() {
        let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 24).unwrap();
        for (at, d, w) in differences(&m, &grid, Sign::Auto) {
            // Snapping moves each vertex by at most √3/8192 voxel.
            assert!(d < 1e-3 || (w.abs() - 0.5).abs() < 1e-2, "{name}: voxel {at:?} differs {d} voxels from the surface, w = {w}");
        }
    }
}

#[test]
fn distances_equal_the_dense_field_bit_for_bit() {
    for (name, m) in meshes() {
        let grid = GridSpec::from_resolution(&m.as_ref().bounds(), 20).unwrap();
        let field = nearest::dense(&Pieces::of(m.as_ref()).unwrap(), &grid, &Stop::new()).unwrap();
        let q = Query::new(m.as_ref(), Sign::Auto).unwrap();
        let [nx, ny, nz] = grid.dims();
        let mut centres = Vec::new();
        for i in 0..nx {
            for j in 0..ny {
                for k in 0..nz {
                    centres.push(grid.voxel_center([i, j, k]));
                }
            }
        }
        let mut got = vec![0.0; centres.len()];
        q.batch(&centres, topovox::query::Ask::Distance, &mut got);
        let bad = got.iter().zip(&field).filter(|(g, f)| (**g as f32).to_bits() != f.to_bits()).count();
        assert_eq!(bad, 0, "{name}: {bad} values differ");
    }
}
