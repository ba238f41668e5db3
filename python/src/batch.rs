//! Folders of meshes: the native `batch` (what `topovox batch` runs), and
//! the plan, one-mesh step and manifest the Dask and Ray helpers use.

use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::Value;
use topovox::voxelize::Stop;
use topovox_io::mesh_out::MeshOut;
use topovox_job::batch::{BatchOptions, BatchProgress, Run};
use topovox_job::distance::{DistanceFormat, SdfOptions};
use topovox_job::remesh::RemeshOptions;
use topovox_job::sample::SampleOptions;
use topovox_job::{JobError, OptionValue};

use crate::convert::to_py;
use crate::errors::{py_err, value_err};
use crate::interrupt::{interruptible_ticking, progress_tick};
use crate::options::{job_options, option_value, table_options};

/// `(input, output, done)` per mesh of a batch, and the options' fingerprint.
pub(crate) type BatchListing<'py> = (Vec<(String, String, bool)>, Bound<'py, PyAny>);

/// The options of a batch, validated (with its fingerprint), and `jobs`:
/// `run="sdf"` takes `sdf`'s options, `run="remesh"` `remesh`'s, else
/// `voxelize`'s; `format` defaults to the run's.
pub(crate) fn batch_options(
    options: Option<&Bound<'_, PyDict>>,
    format: Option<&str>,
) -> PyResult<(topovox_job::batch::BatchOptions, Option<usize>)> {
    let get = |k: &str| -> PyResult<Option<OptionValue>> {
        match options.map(|d| d.get_item(k)).transpose()?.flatten().filter(|v| !v.is_none()) {
            Some(v) => Ok(Some(option_value(k, &v)?)),
            None => Ok(None),
        }
    };
    let jobs = match get("jobs")? {
        Some(OptionValue::Int(n)) if n >= 1 => Some(n as usize),
        Some(v) => return Err(value_err(format!("jobs must be an integer of at least 1; got {}", topovox_job::table::shown(&v)))),
        None => None,
    };
    let run = match get("run")? {
        Some(v) => topovox_job::table::chosen::<Run>("run", &v).map_err(py_err)?,
        None => Run::Voxelize,
    };
    let own = ["jobs", "run"];
    let format = format.unwrap_or(run.default_format());
    let opts = match run {
        Run::Voxelize => {
            let target = <topovox_job::output::Output as topovox_job::Choice>::parse(format).map_err(|e| value_err(e.to_string()))?;
            BatchOptions::voxelize(&job_options(options, &own)?, target)
        }
        Run::Sdf => {
            let target = <DistanceFormat as topovox_job::Choice>::parse(format).map_err(|e| value_err(format!("run=\"sdf\": {e}")))?;
            BatchOptions::sdf(&table_options::<SdfOptions>(options, &own)?, target)
        }
        Run::Remesh => {
            let target = <MeshOut as topovox_job::Choice>::parse(format).map_err(|e| value_err(format!("run=\"remesh\": {e}")))?;
            BatchOptions::remesh(&table_options::<RemeshOptions>(options, &own)?, target)
        }
        Run::Sample => BatchOptions::sample(&table_options::<SampleOptions>(options, &own)?, format),
    };
    Ok((opts.map_err(py_err)?, jobs))
}

/// Meshes finished of all (skipped ones count as finished), shared by the
/// batch's threads and the caller's progress callback.
#[derive(Default)]
struct Counts {
    total: AtomicU64,
    finished: AtomicU64,
}

impl BatchProgress for Counts {
    fn start(&self, total: u64, skipped: u64) {
        self.total.store(total, Ordering::Relaxed);
        self.finished.store(skipped, Ordering::Relaxed);
    }

    fn finished(&self, _record: &Value) {
        self.finished.fetch_add(1, Ordering::Relaxed);
    }
}

/// The native batch: see `topovox.batch`. `progress(finished, total)` is
/// called on the caller's thread as meshes finish (at most every 50 ms)
/// and once at the end.
#[pyfunction]
#[pyo3(signature = (inputs, out_dir, format=None, glob=None, options=None, progress=None))]
pub(crate) fn batch<'py>(
    py: Python<'py>,
    inputs: Vec<PathBuf>,
    out_dir: PathBuf,
    format: Option<&str>,
    glob: Option<String>,
    options: Option<&Bound<'py, PyDict>>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (opts, jobs) = batch_options(options, format)?;
    if let Some(n) = jobs {
        topovox_job::check_threads(n, "jobs").map_err(py_err)?;
    }
    let stop = Arc::new(Stop::new());
    let counts = Counts::default();
    let tick = progress_tick(progress.as_ref(), || (counts.finished.load(Ordering::Relaxed), counts.total.load(Ordering::Relaxed)));
    let work = || -> Result<(topovox_job::batch::Summary, Vec<String>), JobError> {
        let (items, warnings) = topovox_job::batch::items(&inputs, glob.as_deref(), &out_dir, &opts)?;
        let pool = topovox_job::pool_for(jobs, "jobs")?;
        let summary = pool.install(|| topovox_job::batch::run(&items, &out_dir, &opts, &counts, Some(&stop)))?;
        Ok((summary, warnings))
    };
    let (summary, warnings) = interruptible_ticking(py, &stop, work, tick)?.map_err(py_err)?;
    let mut v = summary.to_json();
    v["warnings"] = serde_json::json!(warnings);
    to_py(py, &v)
}

/// The batch plan without running it: `[(input, output), ...]` and the
/// options' fingerprint (for the Dask and Ray helpers, which run
/// [`process_one`] per mesh and write the same manifest).
#[pyfunction]
#[pyo3(signature = (inputs, out_dir, format=None, glob=None, options=None))]
pub(crate) fn batch_plan<'py>(
    py: Python<'py>,
    inputs: Vec<PathBuf>,
    out_dir: PathBuf,
    format: Option<&str>,
    glob: Option<String>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<BatchListing<'py>> {
    let (opts, _) = batch_options(options, format)?;
    let (items, _) = topovox_job::batch::items(&inputs, glob.as_deref(), &out_dir, &opts).map_err(py_err)?;
    topovox_job::batch::create_out_dir(&out_dir).map_err(py_err)?;
    let manifest = topovox_job::batch::Manifest::open(&out_dir).map_err(py_err)?;
    manifest.refuse_other_options(&items, &opts.fingerprint).map_err(py_err)?;
    let listed = items
        .iter()
        .map(|i| (i.input.display().to_string(), i.output.display().to_string(), manifest.is_done(i, &opts.fingerprint)))
        .collect();
    Ok((listed, to_py(py, &opts.fingerprint)?))
}

/// One mesh of a batch: voxelizes `input`, writes `output`, returns the
/// manifest record (a dict; failures are its `error`, never exceptions).
#[pyfunction]
#[pyo3(signature = (input, output, format=None, options=None))]
pub(crate) fn process_one<'py>(
    py: Python<'py>,
    input: PathBuf,
    output: PathBuf,
    format: Option<&str>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (mut opts, _) = batch_options(options, format)?;
    opts.threads = opts.threads.or(Some(1));
    let item = topovox_job::batch::Item { input, output };
    // One mesh, run by a Dask or Ray worker (which interrupts its tasks its own way).
    let record = py.detach(move || topovox_job::batch::process_one(&item, &opts, None));
    to_py(py, &record)
}

/// Appends records (dicts or JSON strings) to `out_dir`'s manifest, one
/// line each.
#[pyfunction]
pub(crate) fn append_manifest(py: Python<'_>, out_dir: PathBuf, records: Vec<String>) -> PyResult<()> {
    py.detach(move || -> Result<(), JobError> {
        let m = topovox_job::batch::Manifest::open(&out_dir)?;
        for r in records {
            let v: Value = serde_json::from_str(&r).map_err(|e| JobError::invalid(format!("manifest record is not JSON: {e}")))?;
            m.append(&v)?;
        }
        Ok(())
    })
    .map_err(py_err)
}
