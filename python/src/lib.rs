//! `topovox._topovox`: the native half of the topovox Python package.
//!
//! Everything here runs what the `topovox` command line runs (the
//! `topovox-job` crate), so a Python call and a CLI call with the same
//! options give the same voxels, bit for bit. The Python half
//! (`python/topovox/__init__.py`) accepts mesh-like objects, documents the
//! API and adds `to_trimesh`, Dask and Ray.
//!
//! - Arrays in are copied once, into the voxelizer's own types; arrays out
//!   are new NumPy arrays.
//! - The GIL is released while meshes load, voxelize, carry colours, write
//!   and check (`Python::detach`).
//! - Ctrl-C stops `voxelize`, `VoxelGrid.save` and `batch` within about a
//!   second, with `KeyboardInterrupt` and no output (see `interruptible`).
//! - Errors are Python exceptions with the CLI's one-line messages:
//!   `ValueError` for bad arguments and bad arrays, `OSError` subclasses
//!   for files (`FileNotFoundError`, `PermissionError`, or
//!   `topovox.FileFormatError` for malformed content), `RuntimeError` for
//!   failures while running (no GPU, not enough memory).
//!
//! Rooms: `meshes` (Mesh, load_mesh), `grids` (VoxelGrid, load_voxels),
//! `distance` (DistanceGrid, sdf), `query` (Query, sample), `placement` (the getters both grids
//! share), `voxelize`, `many` (voxelize_many: sparse training batches), `batch`, `options` (keywords → job options),
//! `convert` (arrays and values in and out), `errors`, `interrupt`.

mod batch;
mod convert;
mod distance;
mod errors;
mod grids;
mod interrupt;
mod many;
mod meshes;
mod options;
mod placement;
mod query;
mod remesh;
mod voxelize;

use pyo3::prelude::*;

#[pymodule]
fn _topovox(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("FileFormatError", m.py().get_type::<errors::FileFormatError>())?;
    m.add_class::<meshes::Mesh>()?;
    m.add_class::<grids::VoxelGrid>()?;
    m.add_class::<distance::DistanceGrid>()?;
    m.add_class::<query::Query>()?;
    m.add_function(wrap_pyfunction!(query::sample, m)?)?;
    m.add_function(wrap_pyfunction!(distance::sdf, m)?)?;
    m.add_function(wrap_pyfunction!(remesh::remesh, m)?)?;
    m.add_function(wrap_pyfunction!(remesh::check_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(meshes::load_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(meshes::load_meshes, m)?)?;
    m.add_function(wrap_pyfunction!(voxelize::voxelize, m)?)?;
    m.add_function(wrap_pyfunction!(many::voxelize_many, m)?)?;
    m.add_function(wrap_pyfunction!(many::features, m)?)?;
    m.add_function(wrap_pyfunction!(grids::load_voxels, m)?)?;
    m.add_function(wrap_pyfunction!(batch::batch, m)?)?;
    m.add_function(wrap_pyfunction!(batch::batch_plan, m)?)?;
    m.add_function(wrap_pyfunction!(batch::process_one, m)?)?;
    m.add_function(wrap_pyfunction!(batch::append_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(options::options, m)?)?;
    m.add_function(wrap_pyfunction!(options::choices, m)?)?;
    Ok(())
}
