//! Many meshes under one plan: what [`crate::voxelize`] gives for each,
//! with `--method gpu` surface modes in one upload and one dispatch for
//! all of them ([`topovox_gpu::Gpu::voxelize_stacked`]) instead of one
//! device and one dispatch per mesh.

use std::sync::atomic::{AtomicUsize, Ordering};

use topovox::voxelize::Stop;
use topovox::MeshRef;

use crate::error::Result;
use crate::plan::Plan;
use crate::run::Voxelized;

/// Each mesh (with its name for messages) voxelized by `plan`: item for
/// item what [`crate::voxelize`] gives, voxel for voxel. Runs on the
/// current rayon pool; the GPU batch runs on this thread. `finished`
/// counts the meshes done as they finish (the GPU batch's all at once), for
/// a caller's progress.
pub fn voxelize_many(plan: &Plan, meshes: &[(MeshRef<'_>, &str)], stop: &Stop, finished: &AtomicUsize) -> Vec<Result<Voxelized>> {
    use rayon::prelude::*;
    if let Some(done) = gpu_batch(plan, meshes, stop) {
        finished.fetch_add(meshes.len(), Ordering::Relaxed);
        return done;
    }
    let one = |(m, name): &(MeshRef<'_>, &str)| {
        let v = crate::voxelize(plan, *m, name, None, Some(stop));
        finished.fetch_add(1, Ordering::Relaxed);
        v
    };
    if plan.request.method == crate::plan::Method::Gpu {
        // One device at a time.
        meshes.iter().map(one).collect()
    } else {
        meshes.par_iter().map(one).collect()
    }
}

#[cfg(feature = "gpu")]
/// Whether `plan` runs as one GPU batch: a surface mode the GPU has, by
/// the compute or raster path, not tiled on request.
fn batches_on_gpu(plan: &Plan) -> bool {
    plan.request.method == crate::plan::Method::Gpu
        && plan.solid.is_none()
        && !plan.is_line()
        && plan.request.tile.is_none()
        && plan.request.gpu_path != crate::plan::GpuPath::MsaaApprox
}

#[cfg(not(feature = "gpu"))]
fn gpu_batch(_: &Plan, _: &[(MeshRef<'_>, &str)], _: &Stop) -> Option<Vec<Result<Voxelized>>> {
    None
}

/// The GPU batch, or `None` when `plan` does not run as one. Meshes whose
/// grid would run tiled, or that fail before voxelizing, go their own way.
#[cfg(feature = "gpu")]
fn gpu_batch(plan: &Plan, meshes: &[(MeshRef<'_>, &str)], stop: &Stop) -> Option<Vec<Result<Voxelized>>> {
    use crate::error::JobError;
    use crate::run::{input_warnings, output_warnings, Voxels};
    if !batches_on_gpu(plan) {
        return None;
    }
    let t = std::time::Instant::now();
    let budget = crate::memory::budget(plan.request.max_memory);
    let mut out: Vec<Option<Result<Voxelized>>> = Vec::with_capacity(meshes.len());
    let mut batch = Vec::new();
    for (n, (mesh, name)) in meshes.iter().enumerate() {
        let prepared = input_warnings(plan, *mesh, name).and_then(|w| Ok((w, plan.request.grid.fit(&mesh.bounds())?)));
        match prepared {
            Ok((_, grid)) if crate::run::tile_for(plan, &grid, budget).is_some() => {
                out.push(Some(crate::voxelize(plan, *mesh, name, None, Some(stop))))
            }
            Ok((warnings, grid)) => {
                batch.push((n, grid, warnings));
                out.push(None);
            }
            Err(e) => out.push(Some(Err(e))),
        }
    }
    if stop.requested() {
        return Some(meshes.iter().map(|_| Err(JobError::Interrupted)).collect());
    }
    let items: Vec<(MeshRef<'_>, topovox::GridSpec)> = batch.iter().map(|(n, g, _)| (meshes[*n].0, *g)).collect();
    let run = crate::run::gpu_setup(plan.core, plan.request.gpu_path).and_then(|(gpu, gm, gp)| {
        let (bits, rep) = gpu.voxelize_stacked(gm, gp, &items).map_err(crate::run::gpu_failed)?;
        Ok((bits, rep, gpu.adapter(), gpu.is_software()))
    });
    let (done, rep, adapter, software) = match run {
        Ok(r) => r,
        Err(e) => {
            let msg = e.to_string();
            return Some(out.into_iter().map(|o| o.unwrap_or_else(|| Err(JobError::failed(msg.clone())))).collect());
        }
    };
    let seconds = t.elapsed().as_secs_f64();
    let facts = crate::facts::GpuFacts {
        path: plan.request.gpu_path.to_string(),
        adapter,
        software,
        run: crate::facts::GpuRun::Batch {
            batch: crate::facts::GpuBatch { meshes: items.len(), stacked: rep.stacked, alone: rep.alone, seconds },
        },
    };
    for ((n, grid, mut warnings), (bits, report)) in batch.into_iter().zip(done) {
        output_warnings(plan, meshes[n].1, &report, &mut warnings);
        out[n] = Some(Ok(Voxelized {
            voxels: Voxels::Bricks(bits),
            grid,
            method: "gpu",
            report,
            solid: None,
            gpu: Some(facts.clone()),
            warnings,
            voxelize_s: seconds,
            tile: None,
            tile_kernel: None,
        }));
    }
    Some(out.into_iter().map(|o| o.expect("every mesh has a result")).collect())
}
