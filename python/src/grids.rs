//! `VoxelGrid`: set voxels, their placement and attributes, as NumPy
//! arrays (dense, coordinates), meshes (greedy quads, trimesh) and files
//! (`save`, `load_voxels`); the placement getters are shared with
//! `DistanceGrid` through [`crate::placement`].

use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use glam::DVec3;
use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::Value;
use topovox::attributes::{VoxelAttributes, NO_MATERIAL};
use topovox::voxelize::Stop;
use topovox::{GridSpec, VoxelSource};
use topovox_job::output::Output;
use topovox_job::{ExportOptions, Voxels};

use crate::convert::{array_protocol, as_array, indices_from, rows_of, shape, size_to_py, to_py, triple_f64, triple_u64, SizeArg};
use crate::errors::{io_err, py_err, value_err};
use crate::interrupt::interruptible;
use crate::meshes::Mesh;
use crate::placement;

/// A voxel grid: where the voxels are, which are set, and what they carry.
#[pyclass(module = "topovox._topovox", name = "VoxelGrid", frozen)]
pub(crate) struct VoxelGrid {
    pub(crate) inner: Arc<GridData>,
}

pub(crate) struct GridData {
    voxels: Voxels,
    grid: GridSpec,
    attrs: Option<VoxelAttributes>,
    facts: Value,
    /// The dense array, made on first use (read-only: every caller shares it).
    dense: OnceLock<Py<PyArray3<bool>>>,
    /// The set voxels in C order with their attribute slots, made on first use.
    order: OnceLock<Vec<([u32; 3], usize)>>,
}

impl GridData {
    /// The grid the voxels lie on.
    pub(crate) fn grid(&self) -> &GridSpec {
        &self.grid
    }

    /// The carried attributes, if any (in key order: see [`GridData::ordered`]).
    pub(crate) fn attributes(&self) -> Option<&VoxelAttributes> {
        self.attrs.as_ref()
    }

    /// The voxels as stored.
    pub(crate) fn voxels(&self) -> &Voxels {
        &self.voxels
    }

    /// How many voxels are set.
    pub(crate) fn count(&self) -> u64 {
        self.voxels.count()
    }

    pub(crate) fn new(voxels: Voxels, grid: GridSpec, attrs: Option<VoxelAttributes>, facts: Value) -> GridData {
        GridData { voxels, grid, attrs, facts, dense: OnceLock::new(), order: OnceLock::new() }
    }

    /// Set voxels in the order of `numpy.argwhere(occupancy)` (i, then j,
    /// then k), each with its slot in key order (the attributes' order);
    /// sorted once.
    pub(crate) fn ordered(&self) -> &[([u32; 3], usize)] {
        self.order.get_or_init(|| {
            let mut v = Vec::with_capacity(self.voxels.count() as usize);
            let mut slot = 0usize;
            self.voxels.for_each_set(&mut |i, j, k| {
                v.push(([i, j, k], slot));
                slot += 1;
            });
            let dims = self.grid.dims();
            if v.len() > 1 << 24 {
                // In place: the passes below hold a second copy.
                v.sort_unstable_by_key(|e| e.0);
                return v;
            }
            // C order by three stable counting passes (k, then j, then i):
            // linear in the voxels, where a comparison sort was a quarter
            // of a small batch's time.
            for axis in [2, 1, 0] {
                v = counting_sort(v, dims[axis] as usize, |e| e.0[axis] as usize);
            }
            v
        })
    }
}

/// `items` stably sorted by `key` (below `buckets`).
fn counting_sort<T: Copy>(items: Vec<T>, buckets: usize, key: impl Fn(&T) -> usize) -> Vec<T> {
    let mut start = vec![0usize; buckets + 1];
    for e in &items {
        start[key(e) + 1] += 1;
    }
    for b in 0..buckets {
        start[b + 1] += start[b];
    }
    let mut out = items.clone();
    for e in items {
        let k = key(&e);
        out[start[k]] = e;
        start[k] += 1;
    }
    out
}

#[pymethods]
impl VoxelGrid {
    /// Voxels along x, y, z.
    #[getter]
    fn dims(&self) -> (u32, u32, u32) {
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

    /// Number of set voxels.
    #[getter]
    fn count(&self) -> u64 {
        self.inner.voxels.count()
    }

    /// `len(grid)`: the first axis, as NumPy's (`grid.count` counts the set voxels).
    fn __len__(&self) -> usize {
        self.inner.grid.dims()[0] as usize
    }

    /// `(nx, ny, nz)`, as NumPy's `shape`.
    #[getter]
    fn shape(&self) -> (u32, u32, u32) {
        self.dims()
    }

    /// What made it: mode, method, grid, counts, times, solid and GPU facts.
    #[getter]
    fn facts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_py(py, &self.inner.facts)
    }

    /// Dense occupancy, `(nx, ny, nz)` bool, element `[i, j, k]` = voxel
    /// `(i, j, k)`: made once and shared, so read-only (`.copy()` to edit).
    #[getter]
    fn occupancy<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<bool>>> {
        if let Some(a) = self.inner.dense.get() {
            return Ok(a.bind(py).clone());
        }
        let [nx, ny, nz] = self.inner.grid.dims().map(|d| d as usize);
        let bytes = nx.checked_mul(ny).and_then(|n| n.checked_mul(nz)).ok_or_else(|| value_err("grid too large to densify"))?;
        if topovox_job::available_memory().is_some_and(|m| bytes as u64 > m / 2) {
            return Err(PyRuntimeError::new_err(format!(
                "a dense {nx}x{ny}x{nz} occupancy needs {}; use .coords() for the set voxels",
                topovox_job::bytes(bytes as u64)
            )));
        }
        let inner = self.inner.clone();
        let dense = py.detach(move || {
            let mut a = vec![false; bytes];
            inner.voxels.for_each_set(&mut |i, j, k| a[(i as usize * ny + j as usize) * nz + k as usize] = true);
            a
        });
        let arr = Array3::from_shape_vec((nx, ny, nz), dense).map_err(|e| PyRuntimeError::new_err(e.to_string()))?.into_pyarray(py);
        let kwargs = PyDict::new(py);
        kwargs.set_item("write", false)?;
        arr.call_method("setflags", (), Some(&kwargs))?;
        Ok(self.inner.dense.get_or_init(|| arr.clone().unbind()).bind(py).clone())
    }

    /// to_dense() -> numpy.ndarray
    ///
    /// The dense occupancy (`occupancy`), made once and shared, so read-only.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     `(nx, ny, nz)` bool, element `[i, j, k]` = voxel `(i, j, k)`.
    ///
    /// Raises
    /// ------
    /// RuntimeError
    ///     The dense array would not fit in memory (use `coords()`).
    ///
    /// Examples
    /// --------
    /// >>> occ = grid.to_dense().copy()
    fn to_dense<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<bool>>> {
        self.occupancy(py)
    }

    /// `numpy.asarray(grid)`: the dense occupancy (a copy when `dtype`
    /// differs or `copy=True`).
    #[pyo3(signature = (dtype=None, copy=None))]
    fn __array__<'py>(&self, py: Python<'py>, dtype: Option<&Bound<'py, PyAny>>, copy: Option<bool>) -> PyResult<Bound<'py, PyAny>> {
        array_protocol(self.occupancy(py)?.into_any(), dtype, copy)
    }

    /// coords() -> numpy.ndarray
    ///
    /// The set voxels sorted in C order (as `numpy.argwhere(occupancy)`),
    /// aligned with `colours`, `normals`, `coverage` and `materials`; sparse,
    /// for grids of any size, made once.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     `(n, 3)` int32.
    ///
    /// Examples
    /// --------
    /// >>> xyz = grid.index_to_world(grid.coords())
    fn coords<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<i32>> {
        let inner = self.inner.clone();
        let v = py.detach(move || inner.ordered().iter().map(|e| e.0).collect::<Vec<_>>());
        Array2::from_shape_fn((v.len(), 3), |(n, c)| v[n][c] as i32).into_pyarray(py)
    }

    /// indices() -> numpy.ndarray
    ///
    /// The set voxels in C order (as `numpy.argwhere(occupancy)`), aligned with
    /// the attributes; for grids of any size.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     `(n, 3)` int64.
    ///
    /// Examples
    /// --------
    /// >>> ijk = grid.indices()
    fn indices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<i64>> {
        let inner = self.inner.clone();
        let v = py.detach(move || inner.ordered().to_vec());
        Array2::from_shape_fn((v.len(), 3), |(n, c)| v[n].0[c] as i64).into_pyarray(py)
    }

    /// `colours`, as NumPy/trimesh users spell it.
    #[getter]
    fn colors<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<u8>>> {
        self.colours(py)
    }

    /// Per set voxel sRGB colour, `(k, 3)` uint8, aligned with `indices()`; None without attributes.
    #[getter]
    fn colours<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<u8>>> {
        let c = self.inner.attrs.as_ref()?.colour.as_ref()?;
        let order = self.inner.ordered();
        Some(Array2::from_shape_fn((order.len(), 3), |(n, k)| c[order[n].1][k]).into_pyarray(py))
    }

    /// Per set voxel material index (-1: none), `(k,)` int64, aligned with `indices()`; None without.
    #[getter]
    fn materials<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<i64>>> {
        let m = self.inner.attrs.as_ref()?.material.as_ref()?;
        let order = self.inner.ordered();
        Some(order.iter().map(|o| crate::convert::material_index(m[o.1])).collect::<Array1<i64>>().into_pyarray(py))
    }

    /// Per set voxel mean surface normal, `(k, 3)` float32, aligned with `indices()`; None without (`normals=True`).
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f32>>> {
        let nrm = self.inner.attrs.as_ref()?.normal.as_ref()?;
        let order = self.inner.ordered();
        Some(Array2::from_shape_fn((order.len(), 3), |(n, k)| nrm[order[n].1][k]).into_pyarray(py))
    }

    /// Per set voxel surface area inside it, in index space (a piece spanning the voxel parallel to a face: 1; cubes: area / s²), `(k,)` float32, aligned with `indices()`; None without.
    #[getter]
    fn coverage<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f32>>> {
        let c = self.inner.attrs.as_ref()?.coverage.as_ref()?;
        let order = self.inner.ordered();
        Some(order.iter().map(|o| c[o.1]).collect::<Array1<f32>>().into_pyarray(py))
    }

    /// save(path, format=None, dither=False, block_palette=None, up="y", watertight=True, triangulate=False)
    ///
    /// Writes the grid in any format the CLI writes, atomically (a temporary
    /// file renamed into place).
    ///
    /// Parameters
    /// ----------
    /// path : str or os.PathLike
    ///     The output; the format comes from the extension unless `format` is given.
    /// format : str, optional
    ///     One of `topovox.FORMATS`.
    /// dither : bool
    ///     `.vox`: dither colours onto the palette.
    /// block_palette : str or os.PathLike, optional
    ///     `.schem`: a colour -> block table.
    /// up : {"x", "y", "z"}
    ///     `.vox` and `.schem`: the data's up axis.
    /// watertight, triangulate : bool
    ///     `.obj` and `.glb`: split T-junctions; triangles only.
    ///
    /// Raises
    /// ------
    /// ValueError
    ///     A format that cannot hold this grid (too large to be dense, unknown).
    /// FileNotFoundError, IsADirectoryError, PermissionError
    ///     The output's folder is missing, or the path is a folder.
    ///
    /// Examples
    /// --------
    /// >>> grid.save("bunny.vdb")
    #[pyo3(signature = (path, format=None, dither=false, block_palette=None, up="y", watertight=true, triangulate=false))]
    #[allow(clippy::too_many_arguments)]
    fn save(
        &self,
        py: Python<'_>,
        path: PathBuf,
        format: Option<String>,
        dither: bool,
        block_palette: Option<PathBuf>,
        up: &str,
        watertight: bool,
        triangulate: bool,
    ) -> PyResult<()> {
        let format = format.map(|f| <Output as topovox_job::Choice>::parse(&f)).transpose().map_err(|e| value_err(e.to_string()))?;
        let target = topovox_job::output::output_format(format, &path).map_err(py_err)?;
        topovox_job::output::check_output_path(&path).map_err(py_err)?;
        let job = ExportOptions { dither, block_palette, up: up_of(up)?, watertight, triangulate, ..ExportOptions::default() };
        let stop = Arc::new(Stop::new());
        let opts = topovox_io::WriteOptions { stop: Some(stop.clone()), ..job.write_options().map_err(py_err)? };
        let inner = &self.inner;
        interruptible(py, &stop, || topovox_job::output::write(&path, target, &inner.voxels, &inner.grid, inner.attrs.as_ref(), &opts))?
            .map_err(py_err)?;
        Ok(())
    }

    /// check(mesh=None) -> dict
    ///
    /// The `topovox check` report: components, thick voxels; with the mesh
    /// (anything `voxelize` takes): closedness, separation with witnesses,
    /// thinness, tunnels. A grid past memory is checked window by window.
    ///
    /// Parameters
    /// ----------
    /// mesh : optional
    ///     The source mesh.
    ///
    /// Returns
    /// -------
    /// dict
    ///     The report (`separating_6`, `components_26`, `tunnels_6`, ...).
    ///
    /// Examples
    /// --------
    /// >>> grid.check(mesh)["separating_6"]
    #[pyo3(signature = (mesh=None))]
    fn check<'py>(&self, py: Python<'py>, mesh: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyAny>> {
        let inner = self.inner.clone();
        // Any mesh `voxelize` takes (trimesh, Open3D, arrays, a path).
        let m = match mesh {
            Some(m) => Some(py.import("topovox")?.getattr("as_mesh")?.call1((m,))?.cast_into::<Mesh>()?.get().inner.clone()),
            None => None,
        };
        // Ctrl-C returns at once; the check, left to finish, is dropped.
        let v = crate::interrupt::interruptible_read(py, move || {
            let mesh = m.as_ref().map(|m| (m.mesh.as_ref(), &inner.grid, "grid"));
            match &inner.voxels {
                topovox_job::Voxels::Sparse(s) => {
                    let layers = topovox_job::check::window_layers(s.dims(), topovox_job::budget(None));
                    topovox_job::check::report_sparse(s, mesh, layers)
                }
                voxels => topovox_job::check::report(&voxels.to_dense(), mesh),
            }
        })?
        .map_err(py_err)?;
        to_py(py, &v)
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
    /// >>> grid.world_to_index([[0.0, 0.0, 0.0]])
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
    /// >>> centres = grid.index_to_world(grid.coords())
    fn index_to_world<'py>(&self, py: Python<'py>, indices: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        placement::index_to_world(py, &self.inner.grid, indices)
    }

    /// greedy_mesh() -> (vertices, faces, face_colours)
    ///
    /// The mesh of the voxels: boundary faces merged into greedy quads,
    /// T-junctions split so it is watertight, as triangles with shared vertices.
    ///
    /// Returns
    /// -------
    /// tuple
    ///     `vertices (n, 3) float64, faces (m, 3) int64, face_colours (m, 3)
    ///     uint8 or None`.
    ///
    /// Raises
    /// ------
    /// RuntimeError
    ///     The grid does not fit densely in memory.
    ///
    /// Examples
    /// --------
    /// >>> v, f, c = grid.greedy_mesh()
    fn greedy_mesh<'py>(&self, py: Python<'py>) -> PyResult<MeshArrays<'py>> {
        let g = &self.inner.grid;
        topovox_job::check_memory(g, topovox_job::budget(None), "a mesh of the voxels").map_err(py_err)?;
        let inner = self.inner.clone();
        let (verts, faces, colours) = py.detach(move || greedy_triangles(&inner));
        let v = Array2::from_shape_fn((verts.len(), 3), |(n, c)| verts[n][c]).into_pyarray(py);
        let f = Array2::from_shape_fn((faces.len(), 3), |(n, c)| faces[n][c] as i64).into_pyarray(py);
        let c = colours.map(|c| Array2::from_shape_fn((c.len(), 3), |(n, k)| c[n][k]).into_pyarray(py));
        Ok((v, f, c))
    }

    /// to_trimesh() -> trimesh.voxel.VoxelGrid
    ///
    /// The voxels as trimesh holds them, placed where they are (voxel
    /// `(i, j, k)`'s centre at `transform @ (i, j, k, 1)`).
    ///
    /// Returns
    /// -------
    /// trimesh.voxel.VoxelGrid
    ///
    /// Raises
    /// ------
    /// ImportError
    ///     trimesh is not installed.
    ///
    /// Examples
    /// --------
    /// >>> grid.to_trimesh().points
    fn to_trimesh<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let trimesh = import_trimesh(py, "to_trimesh")?;
        let (o, s) = (self.inner.grid.origin(), self.inner.grid.voxel_size().0);
        let t = Array2::from_shape_fn((4, 4), |(r, c)| match (r, c) {
            (r, c) if r == c && r < 3 => s[r],
            (3, 3) => 1.0,
            (r, 3) => o[r] + 0.5 * s[r],
            _ => 0.0,
        });
        let kwargs = PyDict::new(py);
        kwargs.set_item("transform", t.into_pyarray(py))?;
        let dense = self.occupancy(py)?.call_method0("copy")?;
        trimesh.getattr("voxel")?.getattr("VoxelGrid")?.call((dense,), Some(&kwargs))
    }

    /// to_trimesh_mesh() -> trimesh.Trimesh
    ///
    /// The mesh of the voxels (`greedy_mesh()`), coloured per face when the grid
    /// carries colours.
    ///
    /// Returns
    /// -------
    /// trimesh.Trimesh
    ///
    /// Raises
    /// ------
    /// ImportError
    ///     trimesh is not installed.
    ///
    /// Examples
    /// --------
    /// >>> grid.to_trimesh_mesh().export("voxels.stl")
    fn to_trimesh_mesh<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let trimesh = import_trimesh(py, "to_trimesh_mesh")?;
        let (v, f, c) = self.greedy_mesh(py)?;
        let kwargs = PyDict::new(py);
        kwargs.set_item("vertices", v)?;
        kwargs.set_item("faces", f)?;
        kwargs.set_item("process", false)?;
        if let Some(c) = c {
            let rgba = c.readonly().as_array().map(|&x| x);
            let n = rgba.nrows();
            let with_alpha = Array2::from_shape_fn((n, 4), |(i, k)| if k < 3 { rgba[[i, k]] } else { 255u8 });
            kwargs.set_item("face_colors", with_alpha.into_pyarray(py))?;
        }
        trimesh.getattr("Trimesh")?.call((), Some(&kwargs))
    }

    /// VoxelGrid.from_coords(coords, dims, origin=(0, 0, 0), voxel_size=1.0, colours=None, materials=None, normals=None, coverage=None)
    ///
    /// A grid whose set voxels are the rows of `coords`, with attributes aligned
    /// with those rows (any row order).
    ///
    /// Parameters
    /// ----------
    /// coords : array_like
    ///     `(n, 3)` integers inside `dims`, each voxel once.
    /// dims : tuple of int
    ///     `(nx, ny, nz)`.
    /// origin : tuple of float, optional
    ///     The grid's low corner.
    /// voxel_size : float or tuple of float
    ///     A voxel's edge, or `(sx, sy, sz)` per axis.
    /// colours, materials, normals, coverage : array_like, optional
    ///     `(n, 3)` uint8, `(n,)` int (-1: none), `(n, 3)` float, `(n,)` float.
    ///
    /// Returns
    /// -------
    /// VoxelGrid
    ///
    /// Raises
    /// ------
    /// ValueError
    ///     A voxel outside the grid or given twice, or arrays of the wrong shape.
    ///
    /// Examples
    /// --------
    /// >>> g = topovox.VoxelGrid.from_coords([[0, 0, 0], [1, 2, 3]], (4, 4, 4))
    #[staticmethod]
    #[pyo3(
        signature = (coords, dims, origin=None, voxel_size=SizeArg::Cube(1.0), colours=None, materials=None, normals=None, coverage=None, facts=None),
        text_signature = "(coords, dims, origin=None, voxel_size=1.0, colours=None, materials=None, normals=None, coverage=None, facts=None)"
    )]
    #[allow(clippy::too_many_arguments)]
    fn from_coords<'py>(
        py: Python<'py>,
        coords: &Bound<'py, PyAny>,
        dims: &Bound<'py, PyAny>,
        origin: Option<&Bound<'py, PyAny>>,
        voxel_size: SizeArg,
        colours: Option<&Bound<'py, PyAny>>,
        materials: Option<&Bound<'py, PyAny>>,
        normals: Option<&Bound<'py, PyAny>>,
        coverage: Option<&Bound<'py, PyAny>>,
        facts: Option<String>,
    ) -> PyResult<VoxelGrid> {
        let o = origin.map(|o| triple_f64(py, "origin", o)).transpose()?.unwrap_or_default();
        let grid = GridSpec::new(DVec3::from_array(o), voxel_size.size()?, triple_u64(py, "dims", dims)?)
            .map_err(|e| value_err(format!("invalid grid: {e}")))?;
        let ijk = indices_from::<3>("coords", &as_array(py, coords, "int64")?)?;
        let order = sorted_coords(&ijk, grid.dims())?;
        let n = ijk.len();
        let attr = |a: Option<&Bound<'py, PyAny>>, dtype: &str| a.map(|a| as_array(py, a, dtype)).transpose();
        let (colours, materials, normals, coverage) =
            (attr(colours, "uint8")?, attr(materials, "int64")?, attr(normals, "float32")?, attr(coverage, "float32")?);
        let attrs = if colours.is_some() || materials.is_some() || normals.is_some() || coverage.is_some() {
            fn perm<T: Copy>(v: Vec<T>, order: &[(u64, usize)]) -> Vec<T> {
                order.iter().map(|&(_, r)| v[r]).collect()
            }
            Some(VoxelAttributes {
                dims: grid.dims(),
                keys: order.iter().map(|e| e.0).collect(),
                colour: colours.map(|c| rows_of::<u8, 3>("colours", &c, n)).transpose()?.map(|c| perm(c, &order)),
                material: materials
                    .map(|m| rows_of::<i64, 1>("materials", &m, n))
                    .transpose()?
                    .map(|m| perm(m, &order).into_iter().map(|[x]| u32::try_from(x).unwrap_or(NO_MATERIAL)).collect()),
                normal: normals.map(|c| rows_of::<f32, 3>("normals", &c, n)).transpose()?.map(|c| perm(c, &order)),
                coverage: coverage
                    .map(|c| rows_of::<f32, 1>("coverage", &c, n))
                    .transpose()?
                    .map(|c| perm(c, &order).into_iter().map(|[x]| x).collect()),
            })
        } else {
            None
        };
        let voxels = voxels_at(grid.dims(), order.iter().map(|&(_, r)| ijk[r].map(|c| c as u32)));
        let facts = match facts {
            Some(f) => serde_json::from_str(&f).map_err(|e| value_err(format!("facts: not JSON ({e})")))?,
            None => serde_json::json!({"source": "coords", "voxels": n}),
        };
        Ok(VoxelGrid { inner: Arc::new(GridData::new(voxels, grid, attrs, facts)) })
    }

    /// VoxelGrid.from_dense(array, origin=(0, 0, 0), voxel_size=1.0)
    ///
    /// A grid whose set voxels are the non-zero elements of a 3-D array.
    ///
    /// Parameters
    /// ----------
    /// array : array_like
    ///     `(nx, ny, nz)`, element `[i, j, k]` = voxel `(i, j, k)`.
    /// origin : tuple of float, optional
    ///     The grid's low corner.
    /// voxel_size : float or tuple of float
    ///     A voxel's edge, or `(sx, sy, sz)` per axis.
    ///
    /// Returns
    /// -------
    /// VoxelGrid
    ///
    /// Raises
    /// ------
    /// ValueError
    ///     The array is not 3-D.
    ///
    /// Examples
    /// --------
    /// >>> g = topovox.VoxelGrid.from_dense(np.ones((2, 2, 2), bool))
    #[staticmethod]
    #[pyo3(signature = (array, origin=None, voxel_size=SizeArg::Cube(1.0)), text_signature = "(array, origin=None, voxel_size=1.0)")]
    fn from_dense<'py>(
        py: Python<'py>,
        array: &Bound<'py, PyAny>,
        origin: Option<&Bound<'py, PyAny>>,
        voxel_size: SizeArg,
    ) -> PyResult<VoxelGrid> {
        let np = py.import("numpy")?;
        let a = np.call_method1("asarray", (array,))?;
        let shape: Vec<u64> = a.getattr("shape")?.extract()?;
        let [nx, ny, nz] = shape[..] else {
            return Err(value_err(format!(
                "from_dense takes a 3-D array; got shape {}",
                self::shape(&shape.iter().map(|&d| d as usize).collect::<Vec<_>>())
            )));
        };
        let coords = np.call_method1("argwhere", (a,))?;
        let dims = (nx, ny, nz).into_pyobject(py)?.into_any();
        VoxelGrid::from_coords(py, &coords, &dims, origin, voxel_size, None, None, None, None, None)
    }

    /// Pickling and `copy.deepcopy`: the grid, its set voxels and attributes.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        let ctor = py.import("topovox._topovox")?.getattr("VoxelGrid")?.getattr("from_coords")?;
        let g = &self.inner.grid;
        let args = (
            self.coords(py),
            self.dims(),
            {
                let o = g.origin();
                (o.x, o.y, o.z)
            },
            size_to_py(py, g.voxel_size())?,
            self.colours(py),
            self.materials(py),
            self.normals(py),
            self.coverage(py),
            self.inner.facts.to_string(),
        );
        Ok((ctor, args.into_pyobject(py)?.into_any()))
    }

    /// `a == b`: the same set voxels at the same place (origin, voxel size,
    /// dims); attributes and facts are not compared. Grids are immutable,
    /// so they hash (equal grids alike) and can be set members and keys.
    fn __eq__(&self, py: Python<'_>, other: &Bound<'_, VoxelGrid>) -> bool {
        let (a, b) = (self.inner.clone(), other.get().inner.clone());
        placement::same_place(&a.grid, &b.grid) && py.detach(move || placement::same_voxels(&a.voxels, &b.voxels))
    }

    fn __hash__(&self) -> u64 {
        placement::hash_of(&self.inner.grid, self.inner.voxels.count())
    }

    fn __repr__(&self) -> String {
        let [x, y, z] = self.inner.grid.dims();
        let mode = self.inner.facts.get("mode").and_then(Value::as_str).map(|m| format!(" {m}")).unwrap_or_default();
        format!("<topovox.VoxelGrid{mode} {x}x{y}x{z}, {} voxels, voxel size {}>", self.inner.voxels.count(), self.inner.grid.voxel_size())
    }
}

/// Each voxel's key (`i + nx·(j + ny·k)`) with its row, sorted by key;
/// refuses voxels outside the grid and voxels given twice.
pub(crate) fn sorted_coords(ijk: &[[i64; 3]], dims: [u32; 3]) -> PyResult<Vec<(u64, usize)>> {
    let [nx, ny, _] = dims.map(u64::from);
    let mut keyed = Vec::with_capacity(ijk.len());
    for (row, c) in ijk.iter().enumerate() {
        if (0..3).any(|a| c[a] < 0 || c[a] >= dims[a] as i64) {
            return Err(value_err(format!("coords row {row} {c:?} lies outside the grid {dims:?}")));
        }
        keyed.push((c[0] as u64 + nx * (c[1] as u64 + ny * c[2] as u64), row));
    }
    keyed.sort_unstable();
    if let Some(w) = keyed.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(value_err(format!("coords rows {} and {} are the same voxel {:?}", w[0].1, w[1].1, ijk[w[0].1])));
    }
    Ok(keyed)
}

/// Voxels with the given set voxels: dense bits for grids up to 2^31
/// voxels, sparse bricks past that.
pub(crate) fn voxels_at(dims: [u32; 3], set: impl Iterator<Item = [u32; 3]>) -> Voxels {
    if dims.iter().map(|&d| d as u64).product::<u64>() <= 1 << 31 {
        let mut d = topovox::DenseBits::new(dims);
        set.for_each(|[i, j, k]| d.set(i, j, k));
        return Voxels::Dense(d);
    }
    let bricks = set.map(|[i, j, k]| {
        let mut b = [0u64; 8];
        topovox::grid::brick::set_in_brick(&mut b, i, j, k);
        ([i / 8, j / 8, k / 8], b)
    });
    Voxels::Sparse(topovox::grid::sparse::SparseBricks::from_bricks(dims, bricks))
}

/// `trimesh`, or an ImportError saying which method needs it.
pub(crate) fn import_trimesh<'py>(py: Python<'py>, what: &str) -> PyResult<Bound<'py, PyModule>> {
    py.import("trimesh")
        .map_err(|e| pyo3::exceptions::PyImportError::new_err(format!("VoxelGrid.{what} needs trimesh (pip install trimesh): {e}")))
}

/// Vertices, faces and optional face colours of a mesh of the voxels.
pub(crate) type MeshArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>, Option<Bound<'py, PyArray2<u8>>>);

pub(crate) use topovox_io::voxel_mesh::Triangles;

/// Greedy quads of the voxels (coloured when the grid has colours), with
/// their T-junctions split (watertight), as world-space triangles.
pub(crate) fn greedy_triangles(g: &GridData) -> Triangles {
    let (palette, quads) = topovox_job::output::palette_quads(&g.voxels.to_dense(), g.attrs.as_ref());
    topovox_io::voxel_mesh::triangles(&quads, &g.grid, palette.as_deref())
}

/// `x`, `y` or `z` as an up axis.
pub(crate) fn up_of(up: &str) -> PyResult<topovox_job::Up> {
    <topovox_job::Up as topovox_job::Choice>::parse(up).map_err(|e| value_err(format!("up: {e}")))
}

/// load_voxels(path, origin=None, voxel_size=None, up="y", allow_external_paths=False) -> VoxelGrid
///
/// Reads any voxel file topovox writes, with its placement where the file
/// records it.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     The file (.npy, .npz, .binvox, .vox, .txt, .schem, .vti, .ply, .vdb, .zarr).
/// origin, voxel_size
///     The placement, when the file does not record it (default 0 and 1);
///     `voxel_size` is one number or `(sx, sy, sz)`.
/// up : {"x", "y", "z"}
///     The up axis `.vox` and `.schem` files were written with.
/// allow_external_paths : bool
///     Follow links out of a `.zarr` folder.
///
/// Returns
/// -------
/// VoxelGrid
///
/// Raises
/// ------
/// FileNotFoundError, FileFormatError
///     The file cannot be read, or its content is malformed.
///
/// Examples
/// --------
/// >>> grid = topovox.load_voxels("bunny.vdb")
#[pyfunction]
#[pyo3(signature = (path, origin=None, voxel_size=None, up="y", allow_external_paths=false))]
pub(crate) fn load_voxels(
    py: Python<'_>,
    path: PathBuf,
    origin: Option<Vec<f64>>,
    voxel_size: Option<SizeArg>,
    up: &str,
    allow_external_paths: bool,
) -> PyResult<VoxelGrid> {
    let p = path.clone();
    let up = up_of(up)?;
    let opts = topovox_io::ReadOptions { allow_external_paths, ..Default::default() };
    let loaded = crate::interrupt::interruptible_read(py, move || topovox_io::read_voxels(&p, &topovox_io::ReadOptions { up, ..opts }))?
        .map_err(io_err)?;
    let dims = loaded.bits.dims();
    let o = match origin {
        Some(o) if o.len() == 3 => DVec3::new(o[0], o[1], o[2]),
        Some(o) => return Err(value_err(format!("origin must have 3 values; got {}", o.len()))),
        None => loaded.placement.map(|p| p.0).unwrap_or(DVec3::ZERO),
    };
    let s = voxel_size.map(SizeArg::size).transpose()?.map(|s| s.0).or(loaded.placement.map(|p| p.1)).unwrap_or(DVec3::ONE);
    let grid = GridSpec::new(o, s, dims.map(u64::from)).map_err(|e| value_err(format!("invalid grid: {e}")))?;
    let facts = serde_json::json!({"input": path.display().to_string(), "voxels": loaded.bits.count(), "placement_from_file": loaded.placement.is_some()});
    Ok(VoxelGrid { inner: Arc::new(GridData::new(Voxels::Dense(loaded.bits), grid, loaded.attributes, facts)) })
}
