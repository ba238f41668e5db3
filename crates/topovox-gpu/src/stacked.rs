//! Many meshes in one dispatch: each mesh's lattice triangles moved by
//! whole voxels into its own z-range of one tall grid, voxelized by the
//! compute path in one upload and one dispatch per slab, and the tall
//! grid's voxels handed back to each mesh.
//!
//! **Same voxels as one call per mesh.** Every GPU mode decides each
//! voxel by the triangle and that voxel's box alone (on lattice
//! coordinates that a move by whole voxels keeps exact), so a mesh's
//! voxels inside its own grid do not depend on what else the tall grid
//! holds. Items are stacked with two empty layers between them, and an
//! item is stacked only when none of its triangles reaches below its first
//! layer or above its last by more than one layer (true of every grid
//! fitted to its mesh); the others run on their own. Voxels of the gaps,
//! and past an item's own `nx`, `ny`, are dropped.

use topovox::geom::fixed::{voxel_span, ONE};
use topovox::geom::lattice::{prepare, LatticeTriangle};
use topovox::{BrickBits, GridSpec, MeshRef};

use crate::{CoverReport, Gpu, GpuError, GpuMode, GpuPath};

/// What a stacked run did.
#[derive(Clone, Debug)]
pub struct StackedReport {
    /// Meshes voxelized in the tall grid.
    pub stacked: u64,
    /// Meshes voxelized on their own (a triangle past their grid in z).
    pub alone: u64,
    /// The tall grid's run (`None` when nothing stacked).
    pub run: Option<CoverReport>,
}

impl Gpu {
    /// `mode` by `path` of each `(mesh, grid)`: per item the voxels of
    /// [`Gpu::voxelize_with`] and its preparation counts, in one dispatch
    /// for all the items that stack (see the module doc).
    pub fn voxelize_stacked(
        &self,
        mode: GpuMode,
        path: GpuPath,
        items: &[(MeshRef<'_>, GridSpec)],
    ) -> Result<(Vec<(BrickBits, topovox::voxelize::Report)>, StackedReport), GpuError> {
        let mut out = Vec::with_capacity(items.len());
        let mut report = StackedReport { stacked: 0, alone: 0, run: None };
        let mut tall: Vec<LatticeTriangle> = Vec::new();
        let mut placed: Vec<Option<i64>> = Vec::with_capacity(items.len());
        let (nx, ny) = items.iter().fold((1, 1), |(x, y), (_, g)| (x.max(g.dims()[0]), y.max(g.dims()[1])));
        let mut next = 1i64;
        for (mesh, grid) in items {
            let (tris, prepared) = prepare(*mesh, grid);
            let dims = grid.dims();
            let mut r = topovox::voxelize::Report { prepare: prepared, voxels: 0 };
            if stacks(&tris, dims[2]) {
                tall.extend(tris.iter().map(|t| LatticeTriangle { v: t.v.map(|p| [p[0], p[1], p[2] + next * ONE]) }));
                placed.push(Some(next));
                next += dims[2] as i64 + 2;
                out.push((BrickBits::new(dims), r));
                report.stacked += 1;
            } else {
                let (bits, alone) = self.voxelize_lattice(mode, path, &tris, dims)?;
                r.voxels = alone.report.voxels;
                placed.push(None);
                out.push((bits, r));
                report.alone += 1;
            }
        }
        if report.stacked > 0 {
            let (bits, run) = self.voxelize_lattice(mode, path, &tall, [nx, ny, next as u32])?;
            let starts: Vec<(i64, usize)> = placed.iter().enumerate().filter_map(|(n, p)| p.map(|k| (k, n))).collect();
            bits.for_each_set(&mut |i, j, k| {
                // The last item starting at or below layer k.
                let at = starts.partition_point(|s| s.0 <= k as i64);
                let Some(&(k0, n)) = at.checked_sub(1).and_then(|a| starts.get(a)) else { return };
                let d = items[n].1.dims();
                let kl = k as i64 - k0;
                if i < d[0] && j < d[1] && kl < d[2] as i64 {
                    out[n].0.set(i, j, kl as u32);
                }
            });
            report.run = Some(run);
            for ((bits, r), p) in out.iter_mut().zip(&placed) {
                if p.is_some() {
                    r.voxels = bits.count();
                }
            }
        }
        Ok((out, report))
    }
}

/// Whether every triangle stays within one layer of `0..nz` in z.
fn stacks(tris: &[LatticeTriangle], nz: u32) -> bool {
    tris.iter().all(|t| {
        let (lo, hi) = (t.v.iter().map(|p| p[2]).min().unwrap_or(0), t.v.iter().map(|p| p[2]).max().unwrap_or(0));
        let (k0, k1) = voxel_span(lo, hi);
        k0 >= -1 && k1 <= nz as i64
    })
}
