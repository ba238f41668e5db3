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

use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use glam::DVec3;
use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{
    PyFileNotFoundError, PyIsADirectoryError, PyKeyboardInterrupt, PyOSError, PyPermissionError, PyRuntimeError, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyList, PyString};
use serde_json::Value;
use topovox::attributes::{ColourRule, VoxelAttributes, NO_MATERIAL};
use topovox::voxelize::Stop;
use topovox::{GridSpec, VoxelSize, VoxelSource};
use topovox_io::LoadedMesh;
use topovox_job::{JobError, JobOptions, OptionValue, Voxels};

mod distance;

pyo3::create_exception!(_topovox, FileFormatError, PyOSError, "A file's content does not follow its format (the message names the file).");

/// A [`JobError`] as the Python exception the package documents.
/// A message in Python's terms: the command line's `--voxel-size` is the
/// keyword `voxel_size`.
fn python_terms(msg: &str) -> String {
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    while let Some(at) = rest.find("--") {
        out.push_str(&rest[..at]);
        let flag = &rest[at + 2..];
        let end = flag.find(|c: char| !(c.is_ascii_alphanumeric() || c == '-')).unwrap_or(flag.len());
        // A flag starts a word ("give --voxel-size"); a "--" inside a word
        // (a file name such as "a--b.obj") is left as it is.
        let starts_word = out.chars().last().is_none_or(|c| !(c.is_alphanumeric() || "-_./\\".contains(c)));
        if end > 0 && flag.as_bytes()[0].is_ascii_lowercase() && starts_word {
            out.push_str(&flag[..end].replace('-', "_"));
        } else {
            out.push_str("--");
            out.push_str(&flag[..end]);
        }
        rest = &flag[end..];
    }
    out.push_str(rest);
    out
}

fn py_err(e: JobError) -> PyErr {
    match e {
        JobError::Invalid(m) => PyValueError::new_err(python_terms(&m)),
        JobError::Failed(m) => PyRuntimeError::new_err(m),
        JobError::Io(io) => io_err(io),
        JobError::Interrupted => PyKeyboardInterrupt::new_err("interrupted"),
    }
}

/// How often [`interruptible`] looks for a signal while the work runs.
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// Runs `work` on a thread of its own, without the GIL, while this thread
/// runs Python's signal handlers every [`SIGNAL_POLL`]. When one raises
/// (Ctrl-C: `KeyboardInterrupt`), `stop` is requested, the work is waited
/// for (it gives up at its next look at `stop`: a slab, tile, brick row,
/// mesh or buffered write) and the handler's exception is raised; what the
/// work made is dropped. Outside the main thread Python runs no signal
/// handlers, and this only runs the work.
fn interruptible<T: Send>(py: Python<'_>, stop: &Stop, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    std::thread::scope(|s| {
        let waiting = std::thread::current();
        // The stack of the main thread the work would otherwise run on.
        let worker = std::thread::Builder::new()
            .stack_size(8 << 20)
            .spawn_scoped(s, move || {
                let r = work();
                waiting.unpark();
                r
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start a worker thread: {e}")))?;
        while !worker.is_finished() {
            py.detach(|| std::thread::park_timeout(SIGNAL_POLL));
            if let Err(e) = py.check_signals() {
                stop.request();
                // Its result (incomplete, or an Interrupted error) is dropped.
                let _ = py.detach(|| worker.join());
                return Err(e);
            }
        }
        worker.join().map_err(|p| std::panic::resume_unwind(p))
    })
}

fn io_err(e: topovox_io::IoError) -> PyErr {
    use std::io::ErrorKind as K;
    let msg = e.to_string();
    match &e.kind {
        topovox_io::ErrorKind::Read(x) | topovox_io::ErrorKind::Write(x) => match x.kind() {
            K::NotFound => PyFileNotFoundError::new_err(msg),
            K::PermissionDenied => PyPermissionError::new_err(msg),
            K::IsADirectory => PyIsADirectoryError::new_err(msg),
            _ => PyOSError::new_err(msg),
        },
        _ => FileFormatError::new_err(msg),
    }
}

fn value_err(msg: impl Into<String>) -> PyErr {
    PyValueError::new_err(msg.into())
}

/// A triangle mesh (and polylines), as read from a file or built from arrays.
#[pyclass(module = "topovox._topovox", name = "Mesh", frozen)]
struct Mesh {
    inner: Arc<LoadedMesh>,
    path: Option<PathBuf>,
}

/// Copies an `(n, 3)` float array (float64 or float32, any strides) into
/// points.
fn points_from(name: &str, a: &Bound<'_, PyAny>) -> PyResult<Vec<DVec3>> {
    fn rows<T: numpy::Element + Copy + Into<f64>>(name: &str, a: PyReadonlyArray2<'_, T>) -> PyResult<Vec<DVec3>> {
        let v = a.as_array();
        if v.ncols() != 3 {
            return Err(value_err(format!("{name} must have shape (n, 3); got {}", shape(v.shape()))));
        }
        Ok(v.rows().into_iter().map(|r| DVec3::new(r[0].into(), r[1].into(), r[2].into())).collect())
    }
    if let Ok(x) = a.extract::<PyReadonlyArray2<'_, f64>>() {
        return rows(name, x);
    }
    if let Ok(x) = a.extract::<PyReadonlyArray2<'_, f32>>() {
        return rows(name, x);
    }
    Err(shape_or_dtype(name, a, "(n, 3) float64 or float32"))
}

/// Copies an `(n, K)` integer array (int64, int32, uint32, uint64) into index tuples.
fn indices_from<const K: usize>(name: &str, a: &Bound<'_, PyAny>) -> PyResult<Vec<[i64; K]>> {
    fn rows<T: numpy::Element + Copy + TryInto<i64>, const K: usize>(name: &str, a: PyReadonlyArray2<'_, T>) -> PyResult<Vec<[i64; K]>> {
        let v = a.as_array();
        if v.ncols() != K {
            return Err(value_err(format!("{name} must have shape (n, {K}); got {}", shape(v.shape()))));
        }
        v.rows()
            .into_iter()
            .enumerate()
            .map(|(n, r)| {
                let mut out = [0i64; K];
                for (o, x) in out.iter_mut().zip(r.iter()) {
                    *o = (*x).try_into().map_err(|_| value_err(format!("{name}: row {n} has an index beyond int64")))?;
                }
                Ok(out)
            })
            .collect()
    }
    if let Ok(x) = a.extract::<PyReadonlyArray2<'_, i64>>() {
        return rows(name, x);
    }
    if let Ok(x) = a.extract::<PyReadonlyArray2<'_, i32>>() {
        return rows(name, x);
    }
    if let Ok(x) = a.extract::<PyReadonlyArray2<'_, u32>>() {
        return rows(name, x);
    }
    if let Ok(x) = a.extract::<PyReadonlyArray2<'_, u64>>() {
        return rows(name, x);
    }
    Err(shape_or_dtype(name, a, &format!("(n, {K}) int64, int32, uint32 or uint64")))
}

/// An `(h, w, 3|4)` uint8 image as a texture.
fn texture_from(py: Python<'_>, t: &Bound<'_, PyAny>) -> PyResult<topovox::attributes::Texture> {
    let arr = py.import("numpy")?.call_method1("asarray", (t, "uint8"))?;
    let a = arr.extract::<numpy::PyReadonlyArray3<'_, u8>>().map_err(|_| value_err("texture must be an (h, w, 3) or (h, w, 4) image"))?;
    let v = a.as_array();
    let (h, w, c) = v.dim();
    if !(c == 3 || c == 4) || h == 0 || w == 0 || h > 16384 || w > 16384 {
        return Err(value_err(format!("texture must be an (h, w, 3) or (h, w, 4) image up to 16384 a side; got {}", shape(&[h, w, c]))));
    }
    let rgba = (0..h)
        .flat_map(|y| (0..w).map(move |x| (y, x)))
        .flat_map(|(y, x)| [v[[y, x, 0]], v[[y, x, 1]], v[[y, x, 2]], if c == 4 { v[[y, x, 3]] } else { 255 }])
        .collect();
    Ok(topovox::attributes::Texture {
        name: "texture".into(),
        width: w as u32,
        height: h as u32,
        rgba,
        wrap: [topovox::attributes::Wrap::Repeat; 2],
    })
}

/// One textured material over every triangle, with per-vertex UVs given
/// with `v = 0` at the image's bottom row (as trimesh, Open3D and OBJ
/// store them) turned into per-corner UVs with `v = 0` at the top.
fn textured_material(
    app: &mut topovox::attributes::Appearance,
    triangles: &[[i64; 3]],
    uv: &[[f32; 2]],
    texture: topovox::attributes::Texture,
) {
    let index = app.textures.len() as u32;
    app.textures.push(texture);
    let material = app.materials.len() as u32;
    app.materials.push(topovox::attributes::Material {
        name: "texture".into(),
        factor: [1.0; 3],
        texture: Some(index),
        emission: [0.0; 3],
        roughness: topovox::attributes::DEFAULT_ROUGHNESS,
        alpha_cutoff: None,
        alpha_texture: None,
    });
    app.triangle_material = vec![material; triangles.len()];
    app.triangle_uv = triangles.iter().map(|t| t.map(|v| [uv[v as usize][0], 1.0 - uv[v as usize][1]])).collect();
}

/// Face colours as materials: one plain material per distinct colour.
fn face_materials(app: &mut topovox::attributes::Appearance, colours: &[[u8; 3]]) {
    let mut index: std::collections::HashMap<[u8; 3], u32> = std::collections::HashMap::new();
    for c in colours {
        let next = app.materials.len() as u32;
        let id = *index.entry(*c).or_insert_with(|| {
            app.materials.push(topovox::attributes::Material {
                name: format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]),
                factor: c.map(|x| topovox::attributes::colour::to_linear(x) as f32),
                texture: None,
                emission: [0.0; 3],
                roughness: topovox::attributes::DEFAULT_ROUGHNESS,
                alpha_cutoff: None,
                alpha_texture: None,
            });
            next
        });
        app.triangle_material.push(id);
    }
}

/// A shape as Python prints it: `(3, 2)`, `(5,)`.
fn shape(s: &[usize]) -> String {
    match s {
        [one] => format!("({one},)"),
        _ => format!("({})", s.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")),
    }
}

fn shape_or_dtype(name: &str, a: &Bound<'_, PyAny>, want: &str) -> PyErr {
    match a.cast::<numpy::PyUntypedArray>() {
        Ok(arr) => value_err(format!("{name} must be a {want} array; got shape {}, dtype {}", shape(arr.shape()), arr.dtype())),
        Err(_) => value_err(format!("{name} must be a {want} NumPy array")),
    }
}

#[pymethods]
impl Mesh {
    /// Mesh(vertices, faces, segments=None, vertex_colours=None,
    /// face_colours=None): a mesh from arrays, validated like a file
    /// (finite coordinates, indices in range); colours are `(n, 3)` uint8
    /// sRGB, one per vertex or per face (`topovox.as_mesh` converts
    /// floats, RGBA and trimesh/Open3D colours).
    #[new]
    #[pyo3(signature = (vertices, faces=None, segments=None, vertex_colours=None, face_colours=None, uvs=None, texture=None))]
    #[allow(clippy::too_many_arguments)]
    fn new<'py>(
        py: Python<'py>,
        vertices: &Bound<'py, PyAny>,
        faces: Option<&Bound<'py, PyAny>>,
        segments: Option<&Bound<'py, PyAny>>,
        vertex_colours: Option<&Bound<'py, PyAny>>,
        face_colours: Option<&Bound<'py, PyAny>>,
        uvs: Option<&Bound<'py, PyAny>>,
        texture: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Mesh> {
        let positions = points_from("vertices", vertices)?;
        let triangles = faces.map(|f| indices_from::<3>("faces", f)).transpose()?.unwrap_or_default();
        let segs = segments.map(|s| indices_from::<2>("segments", s)).transpose()?.unwrap_or_default();
        let (nv, nf) = (positions.len(), triangles.len());
        let vc = vertex_colours.map(|c| rows_of::<u8, 3>("vertex_colours", &as_array(py, c, "uint8")?, nv)).transpose()?;
        let fc = face_colours.map(|c| rows_of::<u8, 3>("face_colours", &as_array(py, c, "uint8")?, nf)).transpose()?;
        let textured = match (uvs, texture) {
            (Some(u), Some(t)) => Some((rows_of::<f32, 2>("uvs", &as_array(py, u, "float32")?, nv)?, texture_from(py, t)?)),
            (None, None) => None,
            _ => return Err(value_err("uvs and texture come together: per-vertex UVs and the image they index")),
        };
        let tris_for_uv = triangles.clone();
        let mut loaded = py.detach(|| topovox_io::validate_mesh(positions, triangles, segs)).map_err(|k| value_err(k.to_string()))?;
        if let Some(vc) = vc {
            loaded.appearance.vertex_colour = vc;
        }
        if let Some(fc) = fc {
            face_materials(&mut loaded.appearance, &fc);
        }
        if let Some((uv, tex)) = textured {
            textured_material(&mut loaded.appearance, &tris_for_uv, &uv, tex);
        }
        Ok(Mesh { inner: Arc::new(loaded), path: None })
    }

    /// Vertex positions, `(n, 3)` float64 (a copy).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let p = &self.inner.mesh.positions;
        Array2::from_shape_fn((p.len(), 3), |(i, c)| p[i][c]).into_pyarray(py)
    }

    /// Triangles, `(m, 3)` int64 indices into `vertices` (polygons fan-triangulated).
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<i64>> {
        let t = &self.inner.mesh.triangles;
        Array2::from_shape_fn((t.len(), 3), |(i, c)| t[i][c] as i64).into_pyarray(py)
    }

    /// Polyline segments, `(k, 2)` int64 indices into `vertices`.
    #[getter]
    fn segments<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<i64>> {
        let s = &self.inner.mesh.segments;
        Array2::from_shape_fn((s.len(), 2), |(i, c)| s[i][c] as i64).into_pyarray(py)
    }

    /// `vertex_colours`, as trimesh and Open3D spell it.
    #[getter]
    fn vertex_colors<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<u8>>> {
        self.vertex_colours(py)
    }

    /// Per-vertex sRGB colours, `(n, 3)` uint8, or None.
    #[getter]
    fn vertex_colours<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<u8>>> {
        let c = &self.inner.appearance.vertex_colour;
        (!c.is_empty()).then(|| Array2::from_shape_fn((c.len(), 3), |(i, k)| c[i][k]).into_pyarray(py))
    }

    /// Per-triangle corner texture coordinates, `(m, 3, 2)` float32 (v = 0
    /// at the top of the image; NaN where a corner has none), or None.
    #[getter]
    fn uvs<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray3<f32>>> {
        let u = &self.inner.appearance.triangle_uv;
        (!u.is_empty()).then(|| Array3::from_shape_fn((u.len(), 3, 2), |(i, c, k)| u[i][c][k]).into_pyarray(py))
    }

    /// Per-triangle material index into `materials` (-1: none), `(m,)` int64, or None.
    #[getter]
    fn face_materials<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<i64>>> {
        let m = &self.inner.appearance.triangle_material;
        (!m.is_empty()).then(|| m.iter().map(|&x| if x == NO_MATERIAL { -1 } else { x as i64 }).collect::<Array1<i64>>().into_pyarray(py))
    }

    /// Materials: a list of dicts with `name`, `colour` (linear RGB
    /// factor) and `texture` (its name, or None).
    #[getter]
    fn materials<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let app = &self.inner.appearance;
        let list = PyList::empty(py);
        for m in &app.materials {
            let d = PyDict::new(py);
            d.set_item("name", &m.name)?;
            d.set_item("colour", m.factor.to_vec())?;
            d.set_item("texture", m.texture.and_then(|t| app.textures.get(t as usize)).map(|t| t.name.clone()))?;
            list.append(d)?;
        }
        Ok(list)
    }

    /// Warnings from reading the file (a missing material library, …).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings.clone()
    }

    /// The file it was read from, or None.
    #[getter]
    fn path(&self) -> Option<String> {
        self.path.as_ref().map(|p| p.display().to_string())
    }

    /// Bounding box of the used vertices, `(2, 3)` float64: min, max.
    #[getter]
    fn bounds<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let b = self.inner.report.bounds;
        Array2::from_shape_fn((2, 3), |(r, c)| if r == 0 { b.min[c] } else { b.max[c] }).into_pyarray(py)
    }

    fn __repr__(&self) -> String {
        let r = &self.inner.report;
        let from = self.path.as_ref().map(|p| format!(" from {:?}", p.display().to_string())).unwrap_or_default();
        format!("<topovox.Mesh {} vertices, {} triangles, {} segments{from}>", r.vertices, r.triangles, r.segments)
    }
}

/// load_mesh(path, allow_external_paths=False) -> Mesh
///
/// Reads a mesh file: OBJ (with its MTL and textures), STL, PLY, glTF/GLB,
/// or `.lines` polylines.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     The file.
/// allow_external_paths : bool
///     Read files the model names (material libraries, textures, buffers)
///     even outside its folder. Off by default.
///
/// Returns
/// -------
/// Mesh
///
/// Raises
/// ------
/// FileNotFoundError, PermissionError, FileFormatError
///     The file cannot be read, or its content is malformed.
///
/// Examples
/// --------
/// >>> mesh = topovox.load_mesh("bunny.obj")
#[pyfunction]
#[pyo3(signature = (path, allow_external_paths=false))]
fn load_mesh(py: Python<'_>, path: PathBuf, allow_external_paths: bool) -> PyResult<Mesh> {
    let p = path.clone();
    let loaded = py.detach(move || topovox_io::read_mesh_with(&p, &topovox_io::ReadOptions { allow_external_paths })).map_err(io_err)?;
    Ok(Mesh { inner: Arc::new(loaded), path: Some(path) })
}

/// A voxel grid: where the voxels are, which are set, and what they carry.
#[pyclass(module = "topovox._topovox", name = "VoxelGrid", frozen)]
struct VoxelGrid {
    inner: Arc<GridData>,
}

struct GridData {
    voxels: Voxels,
    grid: GridSpec,
    attrs: Option<VoxelAttributes>,
    facts: Value,
    /// The dense array, made on first use (read-only: every caller shares it).
    dense: OnceLock<Py<PyArray3<bool>>>,
    /// The set voxels in C order with their attribute slots, made on first use.
    order: OnceLock<Vec<([u32; 3], usize)>>,
}

/// A JSON value as Python objects.
fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64(), n.as_f64()) {
            (Some(i), _, _) => i.into_pyobject(py)?.into_any(),
            (_, Some(u), _) => u.into_pyobject(py)?.into_any(),
            (_, _, f) => f.unwrap_or(f64::NAN).into_pyobject(py)?.into_any(),
        },
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Array(a) => {
            let l = PyList::empty(py);
            for x in a {
                l.append(to_py(py, x)?)?;
            }
            l.into_any()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

impl GridData {
    fn new(voxels: Voxels, grid: GridSpec, attrs: Option<VoxelAttributes>, facts: Value) -> GridData {
        GridData { voxels, grid, attrs, facts, dense: OnceLock::new(), order: OnceLock::new() }
    }

    /// Set voxels in the order of `numpy.argwhere(occupancy)` (i, then j,
    /// then k), each with its slot in key order (the attributes' order);
    /// sorted once.
    fn ordered(&self) -> &[([u32; 3], usize)] {
        self.order.get_or_init(|| {
            let mut v = Vec::with_capacity(self.voxels.count() as usize);
            let mut slot = 0usize;
            self.voxels.for_each_set(&mut |i, j, k| {
                v.push(([i, j, k], slot));
                slot += 1;
            });
            v.sort_unstable_by_key(|e| e.0);
            v
        })
    }
}

#[pymethods]
impl VoxelGrid {
    /// Voxels along x, y, z.
    #[getter]
    fn dims(&self) -> (u32, u32, u32) {
        let d = self.inner.grid.dims();
        (d[0], d[1], d[2])
    }

    /// World position of the grid's low corner, `(3,)` float64.
    #[getter]
    fn origin<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from(self.inner.grid.origin().to_array().to_vec()).into_pyarray(py)
    }

    /// The grid's world box, `(2, 3)` float64: its low and high corners.
    #[getter]
    fn bounds<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let g = &self.inner.grid;
        let (o, s, d) = (g.origin(), g.voxel_size(), g.dims());
        Array2::from_shape_fn((2, 3), |(r, c)| o[c] + r as f64 * d[c] as f64 * s[c]).into_pyarray(py)
    }

    /// Edge length of a voxel: a float for cubes, `(sx, sy, sz)` when the
    /// grid has a size per axis (see `spacing` for the three always).
    #[getter]
    fn voxel_size<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        size_to_py(py, self.inner.grid.size())
    }

    /// A voxel's edge lengths along x, y, z, `(3,)` float64 (equal for cubes).
    #[getter]
    fn spacing<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from(self.inner.grid.voxel_size().to_array().to_vec()).into_pyarray(py)
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
        Some(order.iter().map(|o| if m[o.1] == NO_MATERIAL { -1 } else { m[o.1] as i64 }).collect::<Array1<i64>>().into_pyarray(py))
    }

    /// Per set voxel mean surface normal, `(k, 3)` float32, aligned with `indices()`; None without (`normals=True`).
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f32>>> {
        let nrm = self.inner.attrs.as_ref()?.normal.as_ref()?;
        let order = self.inner.ordered();
        Some(Array2::from_shape_fn((order.len(), 3), |(n, k)| nrm[order[n].1][k]).into_pyarray(py))
    }

    /// Per set voxel surface area inside it / voxel_size², `(k,)` float32, aligned with `indices()`; None without.
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
        let target = topovox_job::output::output_format(format.as_deref(), &path).map_err(py_err)?;
        topovox_job::output::check_output_path(&path).map_err(py_err)?;
        let job = JobOptions { dither, block_palette, up: up_of(up)?, watertight, triangulate, ..JobOptions::default() };
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
        let v = py
            .detach(move || {
                let mesh = m.as_ref().map(|m| (m.mesh.as_ref(), &inner.grid, "grid"));
                match &inner.voxels {
                    topovox_job::Voxels::Sparse(s) => {
                        let layers = topovox_job::check::window_layers(s.dims(), topovox_job::budget(None));
                        topovox_job::check::report_sparse(s, mesh, layers)
                    }
                    voxels => topovox_job::check::report(&voxels.to_dense(), mesh),
                }
            })
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
    ///     `(n, 3)` float.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     `(n, 3)` int64.
    ///
    /// Examples
    /// --------
    /// >>> grid.world_to_index([[0.0, 0.0, 0.0]])
    fn world_to_index<'py>(&self, py: Python<'py>, points: &Bound<'_, PyAny>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let p = points_from("points", points)?;
        let g = self.inner.grid;
        Ok(Array2::from_shape_fn((p.len(), 3), |(n, c)| g.to_grid_units(p[n])[c].floor() as i64).into_pyarray(py))
    }

    /// index_to_world(indices) -> numpy.ndarray
    ///
    /// The centre of each voxel.
    ///
    /// Parameters
    /// ----------
    /// indices : array_like
    ///     `(n, 3)` integers.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray
    ///     `(n, 3)` float64.
    ///
    /// Examples
    /// --------
    /// >>> centres = grid.index_to_world(grid.coords())
    fn index_to_world<'py>(&self, py: Python<'py>, indices: &Bound<'_, PyAny>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let ijk = indices_from::<3>("indices", indices)?;
        let g = self.inner.grid;
        let (o, s) = (g.origin(), g.voxel_size());
        Ok(Array2::from_shape_fn((ijk.len(), 3), |(n, c)| o[c] + (ijk[n][c] as f64 + 0.5) * s[c]).into_pyarray(py))
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
        let (o, s) = (self.inner.grid.origin(), self.inner.grid.voxel_size());
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
    #[pyo3(signature = (coords, dims, origin=None, voxel_size=SizeArg::Cube(1.0), colours=None, materials=None, normals=None, coverage=None, facts=None))]
    #[allow(clippy::too_many_arguments)]
    fn from_coords<'py>(
        py: Python<'py>,
        coords: &Bound<'py, PyAny>,
        dims: (u64, u64, u64),
        origin: Option<(f64, f64, f64)>,
        voxel_size: SizeArg,
        colours: Option<&Bound<'py, PyAny>>,
        materials: Option<&Bound<'py, PyAny>>,
        normals: Option<&Bound<'py, PyAny>>,
        coverage: Option<&Bound<'py, PyAny>>,
        facts: Option<String>,
    ) -> PyResult<VoxelGrid> {
        let o = origin.unwrap_or_default();
        let grid = GridSpec::new(DVec3::new(o.0, o.1, o.2), voxel_size.size()?, [dims.0, dims.1, dims.2])
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
    #[pyo3(signature = (array, origin=None, voxel_size=SizeArg::Cube(1.0)))]
    fn from_dense(py: Python<'_>, array: &Bound<'_, PyAny>, origin: Option<(f64, f64, f64)>, voxel_size: SizeArg) -> PyResult<VoxelGrid> {
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
        VoxelGrid::from_coords(py, &coords, (nx, ny, nz), origin, voxel_size, None, None, None, None, None)
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
            size_to_py(py, g.size())?,
            self.colours(py),
            self.materials(py),
            self.normals(py),
            self.coverage(py),
            self.inner.facts.to_string(),
        );
        Ok((ctor, args.into_pyobject(py)?.into_any()))
    }

    fn __repr__(&self) -> String {
        let [x, y, z] = self.inner.grid.dims();
        let mode = self.inner.facts.get("mode").and_then(Value::as_str).map(|m| format!(" {m}")).unwrap_or_default();
        format!("<topovox.VoxelGrid{mode} {x}x{y}x{z}, {} voxels, voxel size {}>", self.inner.voxels.count(), self.inner.grid.size())
    }
}

/// NumPy's `__array__(dtype, copy)` of a cached read-only array `a`:
/// converted to `dtype`, copied when asked, else `a` itself.
pub(crate) fn array_protocol<'py>(
    a: Bound<'py, PyAny>,
    dtype: Option<&Bound<'py, PyAny>>,
    copy: Option<bool>,
) -> PyResult<Bound<'py, PyAny>> {
    match (dtype, copy) {
        (Some(d), _) => a.call_method1("astype", (d,)),
        (None, Some(true)) => a.call_method0("copy"),
        _ => Ok(a),
    }
}

/// A voxel size as Python gives it: one number (cubes) or a sequence of
/// three (per axis).
#[derive(FromPyObject, Clone)]
pub(crate) enum SizeArg {
    /// A cube's edge.
    Cube(f64),
    /// `(sx, sy, sz)`, checked to be three by [`SizeArg::size`].
    Boxes(Vec<f64>),
}

impl SizeArg {
    /// The size, or a `ValueError` for a sequence of other than three.
    pub(crate) fn size(self) -> PyResult<VoxelSize> {
        match self {
            SizeArg::Cube(c) => Ok(c.into()),
            SizeArg::Boxes(v) => <[f64; 3]>::try_from(v.as_slice())
                .map(VoxelSize::from)
                .map_err(|_| value_err(format!("voxel_size takes one number or three (sx, sy, sz); got {} values", v.len()))),
        }
    }
}

/// A voxel size for Python: a float for cubes, `(sx, sy, sz)` for boxes.
pub(crate) fn size_to_py(py: Python<'_>, s: VoxelSize) -> PyResult<Bound<'_, PyAny>> {
    match s.cube() {
        Some(c) => Ok(c.into_pyobject(py)?.into_any()),
        None => Ok((s.0.x, s.0.y, s.0.z).into_pyobject(py)?.into_any()),
    }
}

/// `a` as a NumPy array of `dtype` (converted by NumPy, which says what it cannot convert).
fn as_array<'py>(py: Python<'py>, a: &Bound<'py, PyAny>, dtype: &str) -> PyResult<Bound<'py, PyAny>> {
    let np = py.import("numpy")?;
    let arr = np.call_method1("asarray", (a, dtype))?;
    // One attribute per voxel may come as a flat array: make it a column.
    if arr.getattr("ndim")?.extract::<usize>()? == 1 {
        return arr.call_method1("reshape", ((-1i64, 1i64),));
    }
    Ok(arr)
}

/// The rows of an `(n, K)` array of `T`, checked to number `n`.
fn rows_of<T: numpy::Element + Copy, const K: usize>(name: &str, a: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<[T; K]>> {
    let arr = a.extract::<PyReadonlyArray2<'_, T>>().map_err(|_| value_err(format!("{name} must be an (n, {K}) array")))?;
    let v = arr.as_array();
    if v.nrows() != n || v.ncols() != K {
        return Err(value_err(format!("{name} must have shape ({n}, {K}), one row per voxel; got {}", shape(v.shape()))));
    }
    Ok(v.rows().into_iter().map(|r| std::array::from_fn(|c| r[c])).collect())
}

/// Each voxel's key (`i + nx·(j + ny·k)`) with its row, sorted by key;
/// refuses voxels outside the grid and voxels given twice.
fn sorted_coords(ijk: &[[i64; 3]], dims: [u32; 3]) -> PyResult<Vec<(u64, usize)>> {
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
fn voxels_at(dims: [u32; 3], set: impl Iterator<Item = [u32; 3]>) -> Voxels {
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
fn import_trimesh<'py>(py: Python<'py>, what: &str) -> PyResult<Bound<'py, PyModule>> {
    py.import("trimesh")
        .map_err(|e| pyo3::exceptions::PyImportError::new_err(format!("VoxelGrid.{what} needs trimesh (pip install trimesh): {e}")))
}

/// Vertices, faces and optional face colours of a mesh of the voxels.
type MeshArrays<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>, Option<Bound<'py, PyArray2<u8>>>);

/// `(input, output, done)` per mesh of a batch, and the options' fingerprint.
type BatchListing<'py> = (Vec<(String, String, bool)>, Bound<'py, PyAny>);

type Triangles = (Vec<[f64; 3]>, Vec<[u32; 3]>, Option<Vec<[u8; 3]>>);

/// Greedy quads of the voxels (coloured when the grid has colours), with
/// their T-junctions split (watertight), as world-space triangles.
fn greedy_triangles(g: &GridData) -> Triangles {
    let (palette, quads) = topovox_job::output::palette_quads(&g.voxels.to_dense(), g.attrs.as_ref());
    let (o, s) = (g.grid.origin(), g.grid.voxel_size() / 2.0);
    let mut index: std::collections::HashMap<[u32; 3], u32> = std::collections::HashMap::with_capacity(quads.len() * 2);
    let mut verts = Vec::with_capacity(quads.len() * 2);
    let mut faces = Vec::with_capacity(quads.len() * 3);
    let mut colours = palette.as_ref().map(|_| Vec::with_capacity(quads.len() * 3));
    for f in topovox::export::watertight::conform(&quads) {
        let ids: Vec<u32> = f
            .vertices
            .iter()
            .map(|&c| {
                *index.entry(c).or_insert_with(|| {
                    verts.push([o.x + c[0] as f64 * s.x, o.y + c[1] as f64 * s.y, o.z + c[2] as f64 * s.z]);
                    verts.len() as u32 - 1
                })
            })
            .collect();
        for t in 1..ids.len() - 1 {
            faces.push([ids[0], ids[t], ids[t + 1]]);
            if let (Some(out), Some(p)) = (colours.as_mut(), palette.as_ref()) {
                out.push(
                    f.class.checked_sub(1).and_then(|i| p.get(i as usize)).copied().unwrap_or(topovox::attributes::carry::DEFAULT_COLOUR),
                );
            }
        }
    }
    (verts, faces, colours)
}

/// A Python keyword's value as a job option's value.
fn option_value(key: &str, v: &Bound<'_, PyAny>) -> PyResult<OptionValue> {
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

/// The job options of keyword arguments (`None` keeps a default; the
/// names in `skip` are the caller's own), checked by the job crate.
fn job_options(options: Option<&Bound<'_, PyDict>>, skip: &[&str]) -> PyResult<JobOptions> {
    let mut o = JobOptions::default();
    for (k, v) in options.into_iter().flat_map(|d| d.iter()) {
        let k: String = k.extract()?;
        if !v.is_none() && !skip.contains(&k.as_str()) {
            o.set(&k, &option_value(&k, &v)?).map_err(py_err)?;
        }
    }
    Ok(o)
}

/// Every option `voxelize` and `batch` take: `[(name, help, example)]`
/// (from the job crate's one list; the tests check both take each).
#[pyfunction]
fn options<'py>(py: Python<'py>) -> PyResult<Vec<(&'static str, &'static str, Bound<'py, PyAny>)>> {
    use topovox_job::options::Example as E;
    topovox_job::KEYWORDS
        .iter()
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
fn choices(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
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
    d.set_item("format", topovox_job::output::Output::names().split(", ").collect::<Vec<_>>())?;
    Ok(d)
}

/// The native voxelize: see `topovox.voxelize` for the documentation.
#[pyfunction]
#[pyo3(signature = (mesh, options=None))]
fn voxelize(py: Python<'_>, mesh: &Mesh, options: Option<&Bound<'_, PyDict>>) -> PyResult<VoxelGrid> {
    let opts = job_options(options, &[])?;
    let plan = opts.plan().map_err(py_err)?;
    let carry = opts.carry();
    // Attributes are carried when any is asked for (normals are one).
    let attributes = opts.attributes || opts.normals;
    let pool = opts.threads.map(topovox_job::pool).transpose().map_err(py_err)?;
    let inner = &mesh.inner;
    let name = mesh.path.as_ref().map(|p| p.display().to_string()).unwrap_or_else(|| "mesh".into());
    let stop = Stop::new();
    let data = interruptible(py, &stop, || {
        let run = || -> Result<GridData, JobError> {
            let v = topovox_job::voxelize(&plan, inner.mesh.as_ref(), &name, None, Some(&stop))?;
            let attrs = if attributes && !plan.is_line() {
                topovox_job::check_attributes_carried(&plan, &v)?;
                topovox_job::attributes(&plan, inner.mesh.as_ref(), &inner.appearance, &v, &carry)
            } else {
                None
            };
            let mut facts = v.facts(&plan);
            facts["warnings"] = serde_json::json!(v.warnings);
            Ok(GridData::new(v.voxels, v.grid, attrs, facts))
        };
        match pool {
            Some(p) => p.install(run),
            None => run(),
        }
    })?
    .map_err(py_err)?;
    Ok(VoxelGrid { inner: Arc::new(data) })
}

/// `x`, `y` or `z` as an up axis.
fn up_of(up: &str) -> PyResult<topovox_job::Up> {
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
fn load_voxels(
    py: Python<'_>,
    path: PathBuf,
    origin: Option<Vec<f64>>,
    voxel_size: Option<SizeArg>,
    up: &str,
    allow_external_paths: bool,
) -> PyResult<VoxelGrid> {
    let p = path.clone();
    let up = up_of(up)?;
    let opts = topovox_io::ReadOptions { allow_external_paths };
    let loaded = py.detach(move || topovox_io::read_voxels_opts(&p, up, &opts)).map_err(io_err)?;
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

/// The options of a batch, validated (with its fingerprint), and `jobs`.
fn batch_options(options: Option<&Bound<'_, PyDict>>, format: &str) -> PyResult<(topovox_job::batch::BatchOptions, Option<usize>)> {
    let target = topovox_job::output::Output::from_name(format)
        .ok_or_else(|| value_err(format!("unknown format {format:?} (expected one of: {})", topovox_job::output::Output::names())))?;
    let jobs = match options.map(|d| d.get_item("jobs")).transpose()?.flatten().filter(|v| !v.is_none()) {
        Some(v) => match option_value("jobs", &v)? {
            OptionValue::Int(n) if n >= 1 => Some(n as usize),
            _ => return Err(value_err(format!("jobs must be an integer of at least 1; got {}", v.repr()?))),
        },
        None => None,
    };
    let opts = job_options(options, &["jobs"])?.batch(target).map_err(py_err)?;
    Ok((opts, jobs))
}

/// The native batch: see `topovox.batch`.
#[pyfunction]
#[pyo3(signature = (inputs, out_dir, format="npy", glob=None, options=None))]
fn batch<'py>(
    py: Python<'py>,
    inputs: Vec<PathBuf>,
    out_dir: PathBuf,
    format: &str,
    glob: Option<String>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (opts, jobs) = batch_options(options, format)?;
    if let Some(n) = jobs {
        topovox_job::check_threads(n, "jobs").map_err(py_err)?;
    }
    let stop = Arc::new(Stop::new());
    let (summary, warnings) = interruptible(py, &stop, || -> Result<(topovox_job::batch::Summary, Vec<String>), JobError> {
        let (files, warnings) = topovox_job::batch::collect_inputs(&inputs, glob.as_deref(), &out_dir)?;
        let ext = opts.format.name().replace("npy-bool", "npy");
        let items = topovox_job::batch::plan_items(&files, &out_dir, &ext)?;
        let pool =
            topovox_job::pool_for(jobs.unwrap_or_else(|| std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)), "jobs")?;
        let summary = pool.install(|| topovox_job::batch::run(&items, &out_dir, &opts, &topovox_job::batch::Silent, Some(&stop)))?;
        Ok((summary, warnings))
    })?
    .map_err(py_err)?;
    let mut v = summary.to_json();
    v["warnings"] = serde_json::json!(warnings);
    to_py(py, &v)
}

/// The batch plan without running it: `[(input, output), ...]` and the
/// options' fingerprint (for the Dask and Ray helpers, which run
/// [`process_one`] per mesh and write the same manifest).
#[pyfunction]
#[pyo3(signature = (inputs, out_dir, format="npy", glob=None, options=None))]
fn batch_plan<'py>(
    py: Python<'py>,
    inputs: Vec<PathBuf>,
    out_dir: PathBuf,
    format: &str,
    glob: Option<String>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<BatchListing<'py>> {
    let (opts, _) = batch_options(options, format)?;
    let (files, _) = topovox_job::batch::collect_inputs(&inputs, glob.as_deref(), &out_dir).map_err(py_err)?;
    let ext = opts.format.name().replace("npy-bool", "npy");
    let items = topovox_job::batch::plan_items(&files, &out_dir, &ext).map_err(py_err)?;
    std::fs::create_dir_all(&out_dir).map_err(|e| io_err(topovox_io::IoError::new(&out_dir, topovox_io::ErrorKind::Write(e))))?;
    let manifest = topovox_job::batch::Manifest::open(&out_dir).map_err(py_err)?;
    let listed = items
        .iter()
        .map(|i| (i.input.display().to_string(), i.output.display().to_string(), manifest.is_done(i, &opts.fingerprint)))
        .collect();
    Ok((listed, to_py(py, &opts.fingerprint)?))
}

/// One mesh of a batch: voxelizes `input`, writes `output`, returns the
/// manifest record (a dict; failures are its `error`, never exceptions).
#[pyfunction]
#[pyo3(signature = (input, output, format="npy", options=None))]
fn process_one<'py>(
    py: Python<'py>,
    input: PathBuf,
    output: PathBuf,
    format: &str,
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
fn append_manifest(py: Python<'_>, out_dir: PathBuf, records: Vec<String>) -> PyResult<()> {
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

#[pymodule]
fn _topovox(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("FileFormatError", m.py().get_type::<FileFormatError>())?;
    m.add_class::<Mesh>()?;
    m.add_class::<VoxelGrid>()?;
    m.add_class::<distance::DistanceGrid>()?;
    m.add_function(wrap_pyfunction!(distance::sdf, m)?)?;
    m.add_function(wrap_pyfunction!(load_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(voxelize, m)?)?;
    m.add_function(wrap_pyfunction!(load_voxels, m)?)?;
    m.add_function(wrap_pyfunction!(batch, m)?)?;
    m.add_function(wrap_pyfunction!(batch_plan, m)?)?;
    m.add_function(wrap_pyfunction!(process_one, m)?)?;
    m.add_function(wrap_pyfunction!(append_manifest, m)?)?;
    m.add_function(wrap_pyfunction!(options, m)?)?;
    m.add_function(wrap_pyfunction!(choices, m)?)?;
    Ok(())
}
