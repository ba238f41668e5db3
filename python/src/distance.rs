//! `topovox.sdf` and `DistanceGrid`: distance fields, as `topovox sdf` makes
//! them (`topovox_job::distance`), with the same grid options as `voxelize`.

use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use topovox::voxelize::Stop;
use topovox_job::distance::{DistanceFormat, Sdf, SdfOptions};
use topovox_job::JobError;

use crate::convert::{array_protocol, to_py};
use crate::errors::{py_err, value_err};
use crate::interrupt::interruptible;
use crate::meshes::Mesh;
use crate::options::table_options;
use crate::placement;

mod state;

/// The band's voxels and values in C order.
type Ordered = Vec<([u32; 3], f32)>;

/// A distance field: see `topovox.sdf`.
#[pyclass(module = "topovox._topovox", name = "DistanceGrid", frozen)]
pub struct DistanceGrid {
    inner: Arc<Sdf>,
    /// The dense array, made once.
    dense: OnceLock<Py<PyArray3<f32>>>,
    /// The band in C order, sorted once for `coords` and `values`.
    order: Arc<OnceLock<Ordered>>,
}

impl DistanceGrid {
    /// The stored voxels and values in C order, sorted on first use without
    /// the GIL.
    fn ordered<'a>(&'a self, py: Python<'_>) -> &'a [([u32; 3], f32)] {
        let (inner, order) = (self.inner.clone(), self.order.clone());
        py.detach(move || {
            order.get_or_init(|| ordered(&inner));
        });
        self.order.get().expect("sorted above")
    }
}

#[pymethods]
impl DistanceGrid {
    /// Voxels along x, y, z.
    #[getter]
    fn dims(&self) -> (u32, u32, u32) {
        placement::dims(&self.inner.grid)
    }

    /// `(nx, ny, nz)`, as NumPy's `shape`.
    #[getter]
    fn shape(&self) -> (u32, u32, u32) {
        placement::dims(&self.inner.grid)
    }

    /// World position of the grid's low corner, `(3,)` float64.
    #[getter]
    fn origin<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        placement::origin(py, &self.inner.grid)
    }

    /// The grid's world box, `(2, 3)` float64: its low and high corners.
    #[getter]
    fn bounds<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        placement::bounds(py, &self.inner.grid)
    }

    /// Edge length of a voxel: a float for cubes, `(sx, sy, sz)` when the
    /// grid has a size per axis (see `spacing` for the three always).
    #[getter]
    fn voxel_size<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        placement::voxel_size(py, &self.inner.grid)
    }

    /// A voxel's edge lengths along x, y, z, `(3,)` float64 (equal for cubes).
    #[getter]
    fn spacing<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        placement::spacing(py, &self.inner.grid)
    }

    /// world_to_index(points) -> numpy.ndarray
    ///
    /// The voxel holding each point: `floor((p - origin) / voxel_size)` (may lie
    /// outside the grid).
    ///
    /// Parameters
    /// ----------
    /// points : array_like
    ///     `(n, 3)` numbers (an array of any float or integer dtype, a list,
    ///     a tuple), or one point `(3,)`.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     `(n, 3)` int64; `(3,)` for one point.
    ///
    /// Examples
    /// --------
    /// >>> field.world_to_index([[0.0, 0.0, 0.0]])
    fn world_to_index<'py>(&self, py: Python<'py>, points: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        placement::world_to_index(py, &self.inner.grid, points)
    }

    /// index_to_world(indices) -> numpy.ndarray
    ///
    /// The centre of each voxel.
    ///
    /// Parameters
    /// ----------
    /// indices : array_like
    ///     `(n, 3)` integers (an array, a list, a tuple), or one voxel `(3,)`.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     `(n, 3)` float64; `(3,)` for one voxel.
    ///
    /// Examples
    /// --------
    /// >>> centres = field.index_to_world(field.coords())
    fn index_to_world<'py>(&self, py: Python<'py>, indices: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        placement::index_to_world(py, &self.inner.grid, indices)
    }

    /// Whether values are negative inside.
    #[getter]
    fn signed(&self) -> bool {
        self.inner.signed
    }

    /// The value of the voxels outside the band (`-background` inside):
    /// the band's half width in world units, or with `band="all"` the
    /// largest distance.
    #[getter]
    fn background(&self) -> f32 {
        self.inner.field.background
    }

    /// Number of voxels stored (the band's, or every voxel's).
    #[getter]
    fn count(&self) -> u64 {
        self.inner.field.band.count()
    }

    /// What made it: band, sign rule, solid facts, counts, times.
    #[getter]
    fn facts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.inner.facts)
    }

    /// to_dense() -> numpy.ndarray
    ///
    /// Every voxel's value, `(nx, ny, nz)` float32, element `[i, j, k]` =
    /// voxel `(i, j, k)` (outside the band: `±background`); made once and
    /// shared, so read-only.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///
    /// Examples
    /// --------
    /// >>> d = field.to_dense()
    fn to_dense<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        if let Some(a) = self.dense.get() {
            return Ok(a.bind(py).clone());
        }
        let [nx, ny, nz] = self.inner.grid.dims().map(|d| d as usize);
        let bytes = (nx as u64 * ny as u64 * nz as u64).saturating_mul(4);
        let budget = topovox_job::budget(None);
        if bytes > budget {
            return Err(pyo3::exceptions::PyRuntimeError::new_err(format!(
                "the dense array needs {} (float32 per voxel), more than the {} available; use coords() and values(), or save() to .vdb or .zarr",
                topovox_job::bytes(bytes),
                topovox_job::bytes(budget)
            )));
        }
        let inner = self.inner.clone();
        let values = py.detach(move || inner.field.dense());
        let a = Array3::from_shape_vec((nx, ny, nz), values).map_err(|e| value_err(e.to_string()))?.into_pyarray(py);
        a.readwrite().make_nonwriteable();
        let _ = self.dense.set(a.clone().unbind());
        Ok(self.dense.get().map(|a| a.bind(py).clone()).unwrap_or(a))
    }

    /// `numpy.asarray(field)`: the dense values (a copy when `dtype`
    /// differs or `copy=True`).
    #[pyo3(signature = (dtype=None, copy=None))]
    fn __array__<'py>(&self, py: Python<'py>, dtype: Option<&Bound<'py, PyAny>>, copy: Option<bool>) -> PyResult<Bound<'py, PyAny>> {
        array_protocol(self.to_dense(py)?.into_any(), dtype, copy)
    }

    /// coords() -> numpy.ndarray
    ///
    /// The stored voxels (the band), `(n, 3)` int32 in C order, aligned
    /// with :meth:`values`; for grids of any size.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///
    /// Examples
    /// --------
    /// >>> ijk, d = field.coords(), field.values()
    fn coords<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<i32>> {
        let v = self.ordered(py);
        Array2::from_shape_fn((v.len(), 3), |(n, c)| v[n].0[c] as i32).into_pyarray(py)
    }

    /// values() -> numpy.ndarray
    ///
    /// The stored voxels' values, `(n,)` float32, aligned with :meth:`coords`.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///
    /// Examples
    /// --------
    /// >>> inside = field.coords()[field.values() < 0]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f32>> {
        let v = self.ordered(py);
        Array1::from_iter(v.iter().map(|e| e.1)).into_pyarray(py)
    }

    /// save(path, format=None) -> None
    ///
    /// Writes the field as `topovox sdf` does: `.vdb` (an OpenVDB level set
    /// named `surface`), `.npy` (float32, every voxel), `.zarr` or `.vti`.
    ///
    /// Parameters
    /// ----------
    /// path : str or os.PathLike
    ///     The file (or `.zarr` folder).
    /// format : {"vdb", "npy", "zarr", "vti"}, optional
    ///     Default: from the extension.
    ///
    /// Examples
    /// --------
    /// >>> field.save("bunny.vdb")
    #[pyo3(signature = (path, format=None))]
    fn save(&self, py: Python<'_>, path: PathBuf, format: Option<String>) -> PyResult<()> {
        let format = DistanceFormat::of(format.as_deref(), &path).map_err(py_err)?;
        topovox_job::output::check_output_path(&path).map_err(py_err)?;
        let stop = Stop::new();
        let inner = &self.inner;
        interruptible(py, &stop, || topovox_job::distance::write(&path, format, inner, Some(&stop)))?.map_err(py_err)
    }

    /// `a == b`: the same place, sign, background, stored voxels and
    /// values (bit for bit) and inside voxels; facts are not compared.
    fn __eq__(&self, py: Python<'_>, other: &Bound<'_, DistanceGrid>) -> bool {
        let o = other.get();
        let (a, b) = (&self.inner, &o.inner);
        if !placement::same_place(&a.grid, &b.grid) || a.signed != b.signed || a.field.background.to_bits() != b.field.background.to_bits()
        {
            return false;
        }
        let bits = |v: &[([u32; 3], f32)]| v.iter().map(|e| (e.0, e.1.to_bits())).collect::<Vec<_>>();
        if bits(self.ordered(py)) != bits(o.ordered(py)) {
            return false;
        }
        let (x, y) = (a.clone(), b.clone());
        py.detach(move || match (&x.field.inside, &y.field.inside) {
            (Some(p), Some(q)) => placement::same_voxels(p, q),
            (p, q) => p.is_none() && q.is_none(),
        })
    }

    fn __hash__(&self) -> u64 {
        placement::hash_of(&self.inner.grid, self.inner.field.band.count())
    }

    /// Pickling and `copy.deepcopy` (Dask, Ray, multiprocessing): the
    /// placement, the band's bricks and values and the inside voxels as
    /// NumPy arrays, rebuilt by `DistanceGrid._from_state`.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (Bound<'py, PyAny>,))> {
        let ctor = py.import("topovox._topovox")?.getattr("DistanceGrid")?.getattr("_from_state")?;
        Ok((ctor, (state::save(py, &self.inner)?,)))
    }

    /// The grid `__reduce__` described (not for direct use).
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyDict>) -> PyResult<DistanceGrid> {
        Ok(DistanceGrid { inner: Arc::new(state::load(state)?), dense: OnceLock::new(), order: Arc::default() })
    }

    fn __repr__(&self) -> String {
        let [x, y, z] = self.inner.grid.dims();
        let kind = if self.inner.signed { "signed" } else { "unsigned" };
        format!(
            "<topovox.DistanceGrid {kind} {x}x{y}x{z}, {} voxels stored, voxel size {}>",
            self.inner.field.band.count(),
            self.inner.grid.voxel_size()
        )
    }
}

/// The stored voxels and values in C order.
fn ordered(s: &Sdf) -> Ordered {
    let mut v = Vec::with_capacity(s.field.band.count() as usize);
    s.field.band.for_each(|i, j, k, d| v.push(([i, j, k], d)));
    v.sort_unstable_by_key(|e| e.0);
    v
}

/// The native sdf: see `topovox.sdf` for the documentation.
#[pyfunction]
#[pyo3(signature = (mesh, options=None))]
pub fn sdf(py: Python<'_>, mesh: &Mesh, options: Option<&Bound<'_, PyDict>>) -> PyResult<DistanceGrid> {
    let opts: SdfOptions = table_options(options, &[])?;
    let req = opts.request(DistanceFormat::Vdb).map_err(py_err)?;
    let pool = opts.run.threads.map(topovox_job::pool).transpose().map_err(py_err)?;
    let inner = &mesh.inner;
    let name = mesh.name();
    let stop = Stop::new();
    let run = || -> Result<Sdf, JobError> {
        let go = || topovox_job::distance::sdf(inner.mesh.as_ref(), &name, &req, Some(&stop));
        match &pool {
            Some(p) => p.install(go),
            None => go(),
        }
    };
    let s = interruptible(py, &stop, run)?.map_err(py_err)?;
    Ok(DistanceGrid { inner: Arc::new(s), dense: OnceLock::new(), order: Arc::default() })
}
