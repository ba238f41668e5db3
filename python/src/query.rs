//! `topovox.Query` and `topovox.sample`: exact point queries and training
//! samples (`topovox::query`). Points are copied once (any float dtype and
//! strides), the work runs without the GIL, on `threads` threads.

use std::sync::Arc;

use glam::DVec3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use topovox::query::{Ask, Closest, Query as Core, Sign};

use topovox_job::sample::SampleOptions;

use crate::convert::{points_from, to_py};
use crate::errors::{py_err, value_err};
use crate::interrupt::interruptible_read;
use crate::meshes::Mesh;
use crate::options::table_options;

fn sign_of(s: &str) -> PyResult<Sign> {
    <topovox_job::distance::Sign as topovox_job::Choice>::parse(s).map(Sign::from).map_err(|e| value_err(e.to_string()))
}

fn sign_name(s: Sign) -> &'static str {
    topovox_job::Choice::name(topovox_job::distance::Sign::from(s))
}

/// A mesh prepared for point queries: see `topovox.Query`.
#[pyclass(module = "topovox._topovox", name = "Query", frozen)]
pub struct Query {
    inner: Arc<Core>,
    pool: Option<Arc<rayon::ThreadPool>>,
}

impl Query {
    /// Runs `f` without the GIL on the query's threads; Ctrl-C returns at
    /// once (`KeyboardInterrupt`), the answers, which change nothing, are
    /// dropped when they come.
    fn run<T: Send + 'static>(&self, py: Python<'_>, f: impl FnOnce(&Core) -> T + Send + 'static) -> PyResult<T> {
        let (inner, pool) = (self.inner.clone(), self.pool.clone());
        interruptible_read(py, move || match pool {
            Some(p) => p.install(|| f(&inner)),
            None => f(&inner),
        })
    }

    fn values<'py>(&self, py: Python<'py>, points: &Bound<'py, PyAny>, ask: Ask) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let pts = points_from("points", points)?;
        let out = self.run(py, move |q| {
            let mut out = vec![0.0; pts.len()];
            q.batch(&pts, ask, &mut out);
            out
        })?;
        Ok(Array1::from(out).into_pyarray(py))
    }
}

fn pool(threads: Option<usize>) -> PyResult<Option<Arc<rayon::ThreadPool>>> {
    Ok(threads.map(topovox_job::pool).transpose().map_err(py_err)?.map(Arc::new))
}

#[pymethods]
impl Query {
    #[new]
    #[pyo3(signature = (mesh, sign="auto", threads=None))]
    fn new(py: Python<'_>, mesh: &Mesh, sign: &str, threads: Option<usize>) -> PyResult<Query> {
        let (sign, pool) = (sign_of(sign)?, pool(threads)?);
        let (inner, name) = (mesh.inner.clone(), mesh.name());
        let q = py.detach(|| Core::new(inner.mesh.as_ref(), sign)).map_err(|e| value_err(format!("{name}: {e}")))?;
        Ok(Query { inner: Arc::new(q), pool })
    }

    /// distances(points, signed) -> (n,) float64
    fn distance<'py>(&self, py: Python<'py>, points: &Bound<'py, PyAny>, signed: bool) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.values(py, points, if signed { Ask::SignedDistance } else { Ask::Distance })
    }

    /// contains(points) -> (n,) float64 of 0 and 1 (the Python side makes bools)
    fn contains<'py>(&self, py: Python<'py>, points: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.values(py, points, Ask::Contains)
    }

    /// winding_number(points) -> (n,) float64
    fn winding_number<'py>(&self, py: Python<'py>, points: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.values(py, points, Ask::WindingNumber)
    }

    /// closest(points) -> (points (n, 3), distances (n,), elements (n,) int64, weights (n, 3))
    #[allow(clippy::type_complexity)]
    fn closest<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<i64>>, Bound<'py, PyArray2<f64>>)> {
        let pts = points_from("points", points)?;
        let got = self.run(py, move |q| {
            let mut out = vec![Closest { point: DVec3::NAN, distance: f64::NAN, element: u32::MAX, weights: [f64::NAN; 3] }; pts.len()];
            q.closest_batch(&pts, &mut out);
            out
        })?;
        let n = got.len();
        let at = Array2::from_shape_fn((n, 3), |(i, a)| got[i].point[a]);
        let w = Array2::from_shape_fn((n, 3), |(i, a)| got[i].weights[a]);
        let d = Array1::from_iter(got.iter().map(|c| c.distance));
        let e = Array1::from_iter(got.iter().map(|c| if c.element == u32::MAX { -1 } else { i64::from(c.element) }));
        Ok((at.into_pyarray(py), d.into_pyarray(py), e.into_pyarray(py), w.into_pyarray(py)))
    }

    /// What the query knows of its mesh: a dict.
    #[getter]
    fn facts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let f = self.inner.facts();
        let d = PyDict::new(py);
        d.set_item("elements", f.elements)?;
        d.set_item("skipped", f.skipped)?;
        d.set_item("watertight", f.watertight)?;
        d.set_item("boundary_cycles", f.cycles)?;
        d.set_item("sign", sign_name(f.sign))?;
        if let Some(o) = f.orientation {
            // The keys of the JSON summaries, from the same serialization.
            let facts = serde_json::to_value(topovox_job::facts::OrientFacts::from(o)).map_err(|e| value_err(e.to_string()))?;
            d.set_item("orientation", to_py(py, &facts)?)?;
        }
        Ok(d)
    }
}

/// The native `topovox.sample`: see its documentation. Returns a dict of arrays.
#[pyfunction]
#[pyo3(signature = (mesh, options=None))]
pub fn sample<'py>(py: Python<'py>, mesh: &Mesh, options: Option<&Bound<'py, PyDict>>) -> PyResult<Bound<'py, PyDict>> {
    let opts: SampleOptions = table_options(options, &[])?;
    let pool = pool(opts.run.threads)?;
    let (inner, name) = (mesh.inner.clone(), mesh.name());
    let job = opts.clone();
    // Ctrl-C returns at once; the samples, which change nothing, are dropped.
    let s = interruptible_read(py, move || {
        let work = || topovox_job::sample::sample(&inner, &name, &job);
        match &pool {
            Some(p) => p.install(work),
            None => work(),
        }
    })?
    .map_err(py_err)?;
    let (samples, n) = (&s.samples, s.samples.points.len());
    let d = PyDict::new(py);
    d.set_item("points", Array2::from_shape_fn((n, 3), |(i, a)| samples.points[i][a]).into_pyarray(py))?;
    d.set_item("sdf", Array1::from(samples.sdf.clone()).into_pyarray(py))?;
    d.set_item("occupancy", Array1::from_iter(samples.occupancy.iter().map(|&o| u8::from(o))).into_pyarray(py))?;
    d.set_item("normals", Array2::from_shape_fn((n, 3), |(i, a)| samples.normals[i][a]).into_pyarray(py))?;
    d.set_item("kind", Array1::from_iter(samples.kind.iter().map(|&k| k as u8)).into_pyarray(py))?;
    if let Some(c) = &s.colours {
        d.set_item("colours", Array2::from_shape_fn((n, 3), |(i, a)| c[i][a]).into_pyarray(py))?;
    }
    d.set_item("offset", Array1::from(s.offset.to_array().to_vec()).into_pyarray(py))?;
    d.set_item("scale", s.scale)?;
    d.set_item("bounds", Array2::from_shape_fn((2, 3), |(r, a)| if r == 0 { s.bounds.0[a] } else { s.bounds.1[a] }).into_pyarray(py))?;
    d.set_item("info", to_py(py, &s.summary())?)?;
    Ok(d)
}
