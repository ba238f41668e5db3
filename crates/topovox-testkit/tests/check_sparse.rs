//! `certify_sparse` (the check window by window, for grids past memory)
//! gives `certify`'s report exactly, for any window size: on shared meshes
//! (closed and open, rotated), on voxel sets with leaks (so witnesses,
//! tunnels and holes in columns exist), on sparse solids with runs of
//! full bricks, and on random voxel sets without a mesh.

use proptest::prelude::*;
use topovox::grid::sparse::SparseBricks;
use topovox::topology::inside::{snap_all, Parity};
use topovox::topology::{certify, certify_sparse};
use topovox::voxelize::{self, Mode, Options, Stop};
use topovox::{DenseBits, GridSpec, Mesh, VoxelSource};
use topovox_testkit::{random_rotation, rng, rotated, shared_mesh};

fn sparse_of(d: &DenseBits) -> SparseBricks {
    let mut bricks = Vec::new();
    d.for_each_brick(&mut |b, bits| bricks.push((b, *bits)));
    SparseBricks::from_bricks(d.dims(), bricks)
}

/// The dense report and the sparse one for several window sizes agree;
/// returns the report.
fn same(d: &DenseBits, sparse: &SparseBricks, mesh: Option<(&Mesh, &GridSpec)>, what: &str) -> topovox::topology::CheckReport {
    let want = certify(d, mesh.map(|(m, g)| (m.as_ref(), g))).unwrap();
    for layers in [1, 2, 3, 1000] {
        let got = certify_sparse(sparse, mesh.map(|(m, g)| (m.as_ref(), g)), layers).unwrap();
        assert_eq!(got, want, "{what}: windows of {layers} brick layers");
    }
    want
}

/// Removes every `n`-th set voxel: leaks, tunnels and holes for the checks to find.
fn thinned(d: &DenseBits, n: usize) -> DenseBits {
    let mut out = DenseBits::new(d.dims());
    let mut c = 0;
    d.for_each_set(|i, j, k| {
        c += 1;
        if c % n != 0 {
            out.set(i, j, k);
        }
    });
    out
}

/// The first pair of adjacent unset voxels of different class, by brute
/// force over every voxel and forward offset, in (k, j, offset, i) order.
fn brute_witness(bits: &DenseBits, p: &Parity, all26: bool) -> Option<[[u32; 3]; 2]> {
    let [nx, ny, nz] = bits.dims();
    let mut offsets = Vec::new();
    for dk in -1..=1i64 {
        for dj in -1..=1i64 {
            for di in -1..=1i64 {
                if (dk, dj, di) > (0, 0, 0) && (all26 || di.abs() + dj.abs() + dk.abs() == 1) {
                    offsets.push([di, dj, dk]);
                }
            }
        }
    }
    for k in 0..nz as i64 {
        for j in 0..ny as i64 {
            for d in &offsets {
                for i in 0..nx as i64 {
                    let q = [i + d[0], j + d[1], k + d[2]];
                    if q.iter().zip([nx, ny, nz]).any(|(&x, n)| x < 0 || x >= n as i64) {
                        continue;
                    }
                    let (u, v) = ([i as u32, j as u32, k as u32], q.map(|x| x as u32));
                    let (cu, cv) = (p.inside(u[0], u[1], u[2]), p.inside(v[0], v[1], v[2]));
                    if cu != cv && !bits.get(u[0], u[1], u[2]) && !bits.get(v[0], v[1], v[2]) {
                        return Some(if cu { [u, v] } else { [v, u] });
                    }
                }
            }
        }
    }
    None
}

#[test]
fn shared_meshes_every_window_size() {
    let mut r = rng(0xc4ec);
    // What the cases found, so the comparison is known to cover them.
    let (mut witnesses, mut tunnels, mut holes, mut open) = (0, 0, 0, 0);
    for (name, res) in [("cow.obj", 70), ("fandisk.obj", 45), ("stanford-bunny.obj", 60), ("spot-textured.obj", 50), ("beetle.obj", 40)] {
        let base = shared_mesh(name);
        for rot in [false, true] {
            let mesh = if rot { rotated(&base, random_rotation(&mut r)) } else { base.clone() };
            let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), res).unwrap();
            for mode in [Mode::Cover, Mode::Sep6, Mode::Sep26] {
                let d = voxelize::fast(mode, mesh.as_ref(), &grid, &Options::default()).0.to_dense();
                let what = format!("{name} rotated {rot} {} at {res}", mode.name());
                for bits in [d.clone(), thinned(&d, 7)] {
                    let f = same(&bits, &sparse_of(&bits), Some((&mesh, &grid)), &what).mesh.unwrap();
                    let s = f.separation.as_ref();
                    if let Some(s) = s {
                        let snapped = snap_all(mesh.as_ref(), &grid).unwrap();
                        let parity = Parity::classify(&snapped.crossing_triangles(), grid.dims());
                        assert_eq!(s.witness_6, brute_witness(&bits, &parity, false), "{what}: 6-witness");
                        assert_eq!(s.witness_26, brute_witness(&bits, &parity, true), "{what}: 26-witness");
                    }
                    witnesses += s.map_or(0, |s| s.witness_6.is_some() as u32 + s.witness_26.is_some() as u32);
                    tunnels += (f.tunnels_6 > 0) as u32;
                    holes += (f.columns.empty > 0) as u32;
                    open += !f.closed as u32;
                }
            }
        }
    }
    assert!(witnesses > 4 && tunnels > 4 && holes > 4 && open > 0, "{witnesses} {tunnels} {holes} {open}");
}

#[test]
fn sparse_solids_with_full_runs() {
    for (name, res) in [("cow.obj", 90), ("cheburashka.obj", 70)] {
        let mesh = shared_mesh(name);
        let grid = GridSpec::from_resolution(&mesh.as_ref().bounds(), res).unwrap();
        let snapped = snap_all(mesh.as_ref(), &grid).unwrap();
        let (solid, _) = voxelize::solid::parity_sparse(&snapped, grid.dims(), &Stop::new());
        assert!(solid.full_bricks() > 0, "{name}: no full bricks to test");
        same(&solid.to_dense(), &solid, Some((&mesh, &grid)), &format!("{name} solid"));
        same(&solid.to_dense(), &solid, None, &format!("{name} solid, no mesh"));
    }
}

/// Windows far wider than their voxels look bricks up in a hash map
/// rather than a table of the whole window (800 MB for a few voxels in a
/// 65536² window): the same report as the voxels moved to a small grid,
/// mesh moved with them.
#[test]
fn few_voxels_in_a_wide_grid() {
    // In voxel units on a fixed lattice of 2^-20, so that moving by whole
    // voxels is exact.
    let mut mesh = shared_mesh("cow.obj");
    let fit = GridSpec::from_resolution(&mesh.as_ref().bounds(), 60).unwrap();
    let q = (1u64 << 20) as f64;
    mesh.positions.iter_mut().for_each(|p| *p = (((*p - fit.origin()) / fit.voxel_size().0 + 1.0) * q).round() / q);
    let small = GridSpec::new(glam::DVec3::ZERO, 1.0, fit.dims().map(|d| d as u64 + 2)).unwrap();
    let wide = GridSpec::new(glam::DVec3::ZERO, 1.0, [8192, 8192, small.dims()[2] as u64]).unwrap();
    let mut moved = mesh.clone();
    moved.positions.iter_mut().for_each(|p| *p += glam::DVec3::new(2000.0, 3000.0, 0.0));
    for (mode, name) in [(Mode::Cover, "cover"), (Mode::Sep6, "sep6")] {
        let near = voxelize::tiled::tiled(mode, mesh.as_ref(), &small, 64, &Options::default()).unwrap().0;
        let far = voxelize::tiled::tiled(mode, moved.as_ref(), &wide, 512, &Options::default()).unwrap().0;
        assert_eq!(far.count(), near.count(), "{name}");
        let a = certify_sparse(&near, Some((mesh.as_ref(), &small)), 2).unwrap();
        let mut b = certify_sparse(&far, Some((moved.as_ref(), &wide)), 2).unwrap();
        // Witnesses are voxels: moved back.
        if let Some(sep) = b.mesh.as_mut().and_then(|m| m.separation.as_mut()) {
            for w in [&mut sep.witness_6, &mut sep.witness_26].into_iter().flatten() {
                w.iter_mut().for_each(|v| *v = [v[0] - 2000, v[1] - 3000, v[2]]);
            }
        }
        assert_eq!(a, b, "{name}");
        assert_eq!(certify_sparse(&near, None, 3).unwrap(), certify_sparse(&far, None, 3).unwrap(), "{name}, no mesh");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn random_voxel_sets(nx in 1u32..40, ny in 1u32..30, nz in 1u32..40, density in 0.05f64..0.7, seed in any::<u64>()) {
        use rand::Rng;
        let mut r = rng(seed);
        let mut d = DenseBits::new([nx, ny, nz]);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    if r.random_bool(density) {
                        d.set(i, j, k);
                    }
                }
            }
        }
        same(&d, &sparse_of(&d), None, &format!("random {nx}x{ny}x{nz}"));
    }
}
