//! `Mesh`: a triangle mesh (and polylines) from a file or from arrays, with
//! its colours, UVs, texture and materials; `load_mesh`.

use std::path::PathBuf;
use std::sync::Arc;

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use topovox_io::LoadedMesh;

use crate::convert::{as_array, indices_from, points_from, rows_of, shape};
use crate::errors::{io_err, value_err};

/// A triangle mesh (and polylines), as read from a file or built from arrays.
#[pyclass(module = "topovox._topovox", name = "Mesh", frozen)]
pub(crate) struct Mesh {
    pub(crate) inner: Arc<LoadedMesh>,
    pub(crate) path: Option<PathBuf>,
}

impl Mesh {
    /// How messages name it: its file, or `mesh`.
    pub(crate) fn name(&self) -> String {
        self.path.as_ref().map(|p| p.display().to_string()).unwrap_or_else(|| "mesh".into())
    }
}

/// An `(h, w, 3|4)` uint8 image as a texture.
pub(crate) fn texture_from(py: Python<'_>, t: &Bound<'_, PyAny>) -> PyResult<topovox::attributes::Texture> {
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
pub(crate) fn textured_material(
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
pub(crate) fn face_materials(app: &mut topovox::attributes::Appearance, colours: &[[u8; 3]]) {
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
        (!m.is_empty()).then(|| m.iter().map(|&x| crate::convert::material_index(x)).collect::<Array1<i64>>().into_pyarray(py))
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

    /// save(path, format=None): writes the triangles as OBJ or PLY (exact
    /// coordinates), STL or GLB (float32), by `format` or the extension;
    /// the file is replaced all or nothing.
    #[pyo3(signature = (path, format=None))]
    fn save(&self, py: Python<'_>, path: PathBuf, format: Option<&str>) -> PyResult<()> {
        let format = topovox_job::remesh::format_of(format, &path).map_err(crate::errors::py_err)?;
        let m = &self.inner.mesh;
        py.detach(|| topovox_io::mesh_out::write_mesh(&path, &m.positions, &m.triangles, format, None)).map_err(io_err)
    }

    /// to_trimesh(): a `trimesh.Trimesh` of the vertices and faces
    /// (`process=False`: nothing merged or reordered); imports trimesh.
    fn to_trimesh<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let kw = PyDict::new(py);
        kw.set_item("vertices", self.vertices(py))?;
        kw.set_item("faces", self.faces(py))?;
        kw.set_item("process", false)?;
        py.import("trimesh")?.getattr("Trimesh")?.call((), Some(&kw))
    }

    fn __repr__(&self) -> String {
        let r = &self.inner.report;
        let from = self.path.as_ref().map(|p| format!(" from {:?}", p.display().to_string())).unwrap_or_default();
        format!("<topovox.Mesh {} vertices, {} triangles, {} segments{from}>", r.vertices, r.triangles, r.segments)
    }
}

/// load_mesh(path, allow_external_paths=False, max_memory=None) -> Mesh
///
/// Reads a mesh file: OBJ (with its MTL and textures), STL, PLY, glTF/GLB,
/// OFF (ModelNet's),
/// or `.lines` polylines.
///
/// Parameters
/// ----------
/// path : str or os.PathLike
///     The file.
/// allow_external_paths : bool
///     Read files the model names (material libraries, textures, buffers)
///     even outside its folder. Off by default.
/// max_memory : int or str, optional
///     The memory the read may take, in bytes or as ``"2G"``: a file
///     whose reading would hold more is refused before it is parsed.
///     Default: nine tenths of the available memory.
///
/// Returns
/// -------
/// Mesh
///
/// Raises
/// ------
/// FileNotFoundError, PermissionError, FileFormatError
///     The file cannot be read, or its content is malformed.
/// MemoryError
///     Reading it would hold more than ``max_memory``.
///
/// Examples
/// --------
/// >>> mesh = topovox.load_mesh("bunny.obj")
#[pyfunction]
#[pyo3(signature = (path, allow_external_paths=false, max_memory=None))]
pub(crate) fn load_mesh(
    py: Python<'_>,
    path: PathBuf,
    allow_external_paths: bool,
    max_memory: Option<&Bound<'_, PyAny>>,
) -> PyResult<Mesh> {
    // The job's own option parses max_memory, as for every other call.
    let mut run = topovox_job::RunOptions { allow_external_paths, ..Default::default() };
    if let Some(m) = max_memory.filter(|m| !m.is_none()) {
        topovox_job::table::Table::set_named(&mut run, "max_memory", &crate::options::option_value("max_memory", m)?)
            .map_err(crate::errors::py_err)?;
    }
    let (p, opts) = (path.clone(), run.read_options());
    let read = move || topovox_io::read_mesh(&p, &opts);
    let loaded = crate::interrupt::interruptible_read(py, read)?.map_err(io_err)?;
    Ok(Mesh { inner: Arc::new(loaded), path: Some(path) })
}

/// load_meshes(paths, allow_external_paths=False, threads=None) -> list
///
/// Reads many mesh files at once, on all threads (or ``threads``): for
/// each path, in order, its :class:`Mesh` or the exception
/// :func:`load_mesh` would raise for it (returned, not raised). Each read
/// is what ``load_mesh(path, allow_external_paths)`` does; the native
/// half of ``voxelize_many(paths)``.
#[pyfunction]
#[pyo3(signature = (paths, allow_external_paths=false, threads=None))]
pub(crate) fn load_meshes(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    allow_external_paths: bool,
    threads: Option<usize>,
) -> PyResult<Vec<Py<PyAny>>> {
    use rayon::prelude::*;
    let opts = topovox_job::RunOptions { allow_external_paths, ..Default::default() }.read_options();
    let pool = threads.map(topovox_job::pool).transpose().map_err(crate::errors::py_err)?;
    let given = paths.clone();
    let read = move || {
        let all = || given.par_iter().map(|p| topovox_io::read_mesh(p, &opts)).collect::<Vec<_>>();
        match pool {
            Some(p) => p.install(all),
            None => all(),
        }
    };
    let loaded = crate::interrupt::interruptible_read(py, read)?;
    loaded
        .into_iter()
        .zip(paths)
        .map(|(r, path)| match r {
            Ok(m) => Ok(Py::new(py, Mesh { inner: Arc::new(m), path: Some(path) })?.into_any()),
            Err(e) => Ok(io_err(e).into_value(py).into_any()),
        })
        .collect()
}
