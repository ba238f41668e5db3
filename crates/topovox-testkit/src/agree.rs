//! The [`agree`] harness: every path on one input, the first differing
//! voxel named; and the whole-voxel shift law.

use glam::DVec3;
use topovox::voxelize::driver::Driver;
use topovox::voxelize::{self, Mode, Options, Traversal};
use topovox::{DenseBits, GridSpec, Mesh};

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
    let s = grid.voxel_size().0;
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
