//! `topovox.remesh` and `topovox.check_mesh`: watertight meshes and the
//! mesh certificate, as `topovox remesh` and `topovox check MESH` make them
//! (`topovox_job::remesh`, `topovox_job::check`).

use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use topovox::voxelize::Stop;
use topovox_job::check::{certificate_json, mesh_certificate};
use topovox_job::remesh::{RemeshOptions, Remeshed};
use topovox_job::JobError;

use crate::convert::to_py;
use crate::errors::{py_err, value_err};
use crate::interrupt::interruptible;
use crate::meshes::Mesh;
use crate::options::table_options;

/// The native remesh: see `topovox.remesh` for the documentation. Returns
/// the mesh and the summary's facts (with the certificate when asked).
#[pyfunction]
#[pyo3(signature = (mesh, options=None))]
pub fn remesh<'py>(py: Python<'py>, mesh: &Mesh, options: Option<&Bound<'py, PyDict>>) -> PyResult<(Mesh, Bound<'py, PyAny>)> {
    let opts: RemeshOptions = table_options(options, &[])?;
    let req = opts.request(false).map_err(py_err)?;
    let pool = opts.run.threads.map(topovox_job::pool).transpose().map_err(py_err)?;
    let (inner, name) = (&mesh.inner, mesh.name());
    let stop = Stop::new();
    let run = || -> Result<Remeshed, JobError> {
        let go = || topovox_job::remesh::remesh(inner.mesh.as_ref(), &name, &req, Some(&stop));
        match &pool {
            Some(p) => p.install(go),
            None => go(),
        }
    };
    let r = interruptible(py, &stop, run)?.map_err(py_err)?;
    let mut facts = r.made.summary();
    facts["warnings"] = serde_json::json!(r.made.warnings);
    let (positions, triangles) = (r.mesh.positions, r.mesh.triangles.iter().map(|t| t.map(i64::from)).collect());
    let loaded = py.detach(|| topovox_io::validate_mesh(positions, triangles, Vec::new())).map_err(|k| value_err(k.to_string()))?;
    Ok((Mesh { inner: Arc::new(loaded), path: None }, to_py(py, &facts)?))
}

/// check_mesh(mesh) -> dict: the mesh certificate (see `topovox.check_mesh`).
#[pyfunction]
pub fn check_mesh<'py>(py: Python<'py>, mesh: &Mesh) -> PyResult<Bound<'py, PyAny>> {
    let (inner, name) = (&mesh.inner, mesh.name());
    let stop = Stop::new();
    let c = interruptible(py, &stop, || mesh_certificate(inner.mesh.as_ref(), &name, Some(&stop)))?.map_err(py_err)?;
    to_py(py, &certificate_json(&c))
}
