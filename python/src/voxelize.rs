//! The native `voxelize`: what `topovox voxelize` runs, on a `Mesh`.

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use topovox::voxelize::Stop;
use topovox_io::LoadedMesh;
use topovox_job::{JobError, Keep, Voxelized, Voxelizer};

use crate::errors::py_err;
use crate::grids::{GridData, VoxelGrid};
use crate::interrupt::interruptible;
use crate::meshes::Mesh;
use crate::options::job_options;

/// The native voxelize: see `topovox.voxelize` for the documentation. It
/// takes the job's two steps, as `topovox voxelize` does, and keeps the
/// grid in memory.
#[pyfunction]
#[pyo3(signature = (mesh, options=None))]
pub(crate) fn voxelize(py: Python<'_>, mesh: &Mesh, options: Option<&Bound<'_, PyDict>>) -> PyResult<VoxelGrid> {
    let opts = job_options(options, &[])?;
    let voxelizer = Voxelizer::new(&opts).map_err(py_err)?;
    let pool = opts.run.threads.map(topovox_job::pool).transpose().map_err(py_err)?;
    let inner = &mesh.inner;
    let name = mesh.name();
    let stop = Stop::new();
    let data = interruptible(py, &stop, || {
        let run = || -> Result<GridData, JobError> {
            let made = voxelizer.make(inner, &name, Keep::Memory { also: false }, None, Some(&stop))?;
            Ok(grid_data(&voxelizer, made.voxels, made.attributes))
        };
        match pool {
            Some(p) => p.install(run),
            None => run(),
        }
    })?
    .map_err(py_err)?;
    Ok(VoxelGrid { inner: Arc::new(data) })
}

/// A job's voxels and attributes as a grid, with the job's facts.
pub(crate) fn grid_data(voxelizer: &Voxelizer, v: Voxelized, attributes: Option<topovox::attributes::VoxelAttributes>) -> GridData {
    let mut facts = v.facts(&voxelizer.plan);
    facts["warnings"] = serde_json::json!(v.warnings);
    GridData::new(v.voxels, v.grid, attributes, facts)
}

/// The grid of `v`, made of `mesh`, with the attributes `keep` wants.
pub(crate) fn carried_grid(voxelizer: &Voxelizer, mesh: &LoadedMesh, v: Voxelized, keep: Keep) -> Result<GridData, JobError> {
    let attributes = voxelizer.carried(mesh, &v, keep)?;
    Ok(grid_data(voxelizer, v, attributes))
}
