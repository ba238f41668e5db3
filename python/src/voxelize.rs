//! The native `voxelize`: what `topovox voxelize` runs, on a `Mesh`.

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use topovox::attributes::carry::CarryOptions;
use topovox::voxelize::Stop;
use topovox_io::LoadedMesh;
use topovox_job::{JobError, Plan, Voxelized};

use crate::errors::py_err;
use crate::grids::{GridData, VoxelGrid};
use crate::interrupt::interruptible;
use crate::meshes::Mesh;
use crate::options::job_options;

/// The native voxelize: see `topovox.voxelize` for the documentation.
#[pyfunction]
#[pyo3(signature = (mesh, options=None))]
pub(crate) fn voxelize(py: Python<'_>, mesh: &Mesh, options: Option<&Bound<'_, PyDict>>) -> PyResult<VoxelGrid> {
    let opts = job_options(options, &[])?;
    let plan = opts.plan().map_err(py_err)?;
    let carry = opts.export.carry();
    let attributes = opts.export.carries();
    let pool = opts.run.threads.map(topovox_job::pool).transpose().map_err(py_err)?;
    let inner = &mesh.inner;
    let name = mesh.name();
    let stop = Stop::new();
    let data = interruptible(py, &stop, || {
        let run = || -> Result<GridData, JobError> {
            let v = topovox_job::voxelize(&plan, inner.mesh.as_ref(), &name, None, Some(&stop))?;
            grid_data(&plan, inner, v, attributes.then_some(&carry))
        };
        match pool {
            Some(p) => p.install(run),
            None => run(),
        }
    })?
    .map_err(py_err)?;
    Ok(VoxelGrid { inner: Arc::new(data) })
}

/// A job's voxels as a grid: with the attributes carried from `mesh` when
/// `carry` asks (refused when they would not fit), and the job's facts.
pub(crate) fn grid_data(plan: &Plan, mesh: &LoadedMesh, v: Voxelized, carry: Option<&CarryOptions>) -> Result<GridData, JobError> {
    let attrs = match carry {
        Some(carry) if !plan.is_line() => {
            topovox_job::check_attributes_carried(plan, &v)?;
            topovox_job::attributes(plan, mesh.mesh.as_ref(), &mesh.appearance, &v, carry)
        }
        _ => None,
    };
    let mut facts = v.facts(plan);
    facts["warnings"] = serde_json::json!(v.warnings);
    Ok(GridData::new(v.voxels, v.grid, attrs, facts))
}
