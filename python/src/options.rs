//! Keyword arguments as the job's options, checked by `topovox-job`'s one
//! list ([`topovox_job::KEYWORDS`]), and that list and every named choice
//! for Python to document and test.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyList, PyString};
use topovox::attributes::ColourRule;
use topovox_job::{JobOptions, OptionValue, Table};

use crate::errors::{py_err, value_err};

/// A Python keyword's value as a job option's value.
pub(crate) fn option_value(key: &str, v: &Bound<'_, PyAny>) -> PyResult<OptionValue> {
    if v.is_instance_of::<PyBool>() || v.get_type().name()?.to_cow()? == "bool_" {
        return Ok(OptionValue::Bool(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(OptionValue::Text(v.extract()?));
    }
    if !v.is_instance_of::<PyFloat>() {
        if let Ok(i) = v.extract::<i64>() {
            return Ok(OptionValue::Int(i));
        }
    }
    if let Ok(f) = v.extract::<f64>() {
        return Ok(OptionValue::Float(f));
    }
    if let Ok(p) = v.extract::<PathBuf>() {
        return Ok(OptionValue::Text(p.to_string_lossy().into_owned()));
    }
    if let Ok(n) = v.extract::<Vec<f64>>() {
        return Ok(OptionValue::Numbers(n));
    }
    Err(value_err(format!("{key} does not take {}", v.repr()?)))
}

/// The options of a table (`JobOptions`, `SdfOptions`) from keyword
/// arguments (`None` keeps a default; the names in `skip` are the caller's
/// own), checked by the job crate.
pub(crate) fn table_options<T: Table>(options: Option<&Bound<'_, PyDict>>, skip: &[&str]) -> PyResult<T> {
    let mut o = T::default();
    for (k, v) in options.into_iter().flat_map(|d| d.iter()) {
        let k: String = k.extract()?;
        if !v.is_none() && !skip.contains(&k.as_str()) {
            o.set_named(&k, &option_value(&k, &v)?).map_err(py_err)?;
        }
    }
    Ok(o)
}

/// [`table_options`] of a voxelization job.
pub(crate) fn job_options(options: Option<&Bound<'_, PyDict>>, skip: &[&str]) -> PyResult<JobOptions> {
    table_options(options, skip)
}

/// Every option `voxelize` and `batch` take (`command="sdf"`: every
/// option `sdf` takes): `[(name, help, example)]`, from the job crate's
/// tables; the tests check each front end takes each.
#[pyfunction]
#[pyo3(signature = (command="voxelize"))]
pub(crate) fn options<'py>(py: Python<'py>, command: &str) -> PyResult<Vec<(&'static str, &'static str, Bound<'py, PyAny>)>> {
    use topovox_job::table::Example as E;
    let rows: Vec<&'static topovox_job::Keyword> = match command {
        "voxelize" | "batch" => JobOptions::keywords().collect(),
        "sdf" => topovox_job::distance::SdfOptions::keywords().collect(),
        "remesh" => topovox_job::remesh::RemeshOptions::keywords().collect(),
        "sample" => topovox_job::sample::SampleOptions::keywords().collect(),
        _ => {
            return Err(crate::errors::value_err(format!(
                "options: no command {command:?} (expected voxelize, batch, sdf, remesh or sample)"
            )))
        }
    };
    rows.into_iter()
        .map(|k| {
            let example = match k.example {
                E::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
                E::Int(i) => i.into_pyobject(py)?.into_any(),
                E::Float(f) => f.into_pyobject(py)?.into_any(),
                E::Text(t) => t.into_pyobject(py)?.into_any(),
                E::Numbers(n) => PyList::new(py, n)?.into_any(),
            };
            Ok((k.name, k.help, example))
        })
        .collect()
}

/// Every name of every named choice: `{"mode": [...], "method": [...], ...}`.
#[pyfunction]
pub(crate) fn choices(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    use topovox_job::Choice;
    fn names<T: Choice>() -> Vec<&'static str> {
        T::names()
    }
    let d = PyDict::new(py);
    d.set_item("mode", names::<topovox_job::Mode>())?;
    d.set_item("method", names::<topovox_job::Method>())?;
    d.set_item("fill", names::<topovox_job::Fill>())?;
    d.set_item("hollow", names::<topovox_job::Hollow>())?;
    d.set_item("gpu_path", names::<topovox_job::GpuPath>())?;
    d.set_item("colour_rule", names::<ColourRule>())?;
    d.set_item("up", names::<topovox_job::Up>())?;
    d.set_item("format", names::<topovox_job::output::Output>())?;
    d.set_item("inside", names::<topovox_job::remesh::Inside>())?;
    d.set_item("surface_kind", names::<topovox_job::remesh::SurfaceKind>())?;
    Ok(d)
}
