//! Python values in and out: arrays of points and indices (any dtype NumPy
//! converts, any strides), shapes as Python prints them, NumPy's
//! `__array__` protocol, voxel sizes, material indices, and JSON facts as
//! Python objects.

use glam::DVec3;
use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use serde_json::Value;
use topovox::VoxelSize;

use crate::errors::value_err;

/// A material index as Python sees it: -1 for none.
pub(crate) fn material_index(m: u32) -> i64 {
    if m == topovox::attributes::NO_MATERIAL {
        -1
    } else {
        i64::from(m)
    }
}

/// Copies an `(n, 3)` float array (float64 or float32, any strides) into
/// points.
pub(crate) fn points_from(name: &str, a: &Bound<'_, PyAny>) -> PyResult<Vec<DVec3>> {
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
pub(crate) fn indices_from<const K: usize>(name: &str, a: &Bound<'_, PyAny>) -> PyResult<Vec<[i64; K]>> {
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

/// A shape as Python prints it: `(3, 2)`, `(5,)`.
pub(crate) fn shape(s: &[usize]) -> String {
    match s {
        [one] => format!("({one},)"),
        _ => format!("({})", s.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")),
    }
}

pub(crate) fn shape_or_dtype(name: &str, a: &Bound<'_, PyAny>, want: &str) -> PyErr {
    match a.cast::<numpy::PyUntypedArray>() {
        Ok(arr) => value_err(format!("{name} must be a {want} array; got shape {}, dtype {}", shape(arr.shape()), arr.dtype())),
        Err(_) => value_err(format!("{name} must be a {want} NumPy array")),
    }
}

/// A JSON value as Python objects.
pub(crate) fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
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
pub(crate) fn as_array<'py>(py: Python<'py>, a: &Bound<'py, PyAny>, dtype: &str) -> PyResult<Bound<'py, PyAny>> {
    let np = py.import("numpy")?;
    let arr = np.call_method1("asarray", (a, dtype))?;
    // One attribute per voxel may come as a flat array: make it a column.
    if arr.getattr("ndim")?.extract::<usize>()? == 1 {
        return arr.call_method1("reshape", ((-1i64, 1i64),));
    }
    Ok(arr)
}

/// The rows of an `(n, K)` array of `T`, checked to number `n`.
pub(crate) fn rows_of<T: numpy::Element + Copy, const K: usize>(name: &str, a: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<[T; K]>> {
    let arr = a.extract::<PyReadonlyArray2<'_, T>>().map_err(|_| value_err(format!("{name} must be an (n, {K}) array")))?;
    let v = arr.as_array();
    if v.nrows() != n || v.ncols() != K {
        return Err(value_err(format!("{name} must have shape ({n}, {K}), one row per voxel; got {}", shape(v.shape()))));
    }
    Ok(v.rows().into_iter().map(|r| std::array::from_fn(|c| r[c])).collect())
}

/// Three numbers from anything NumPy reads as three (a tuple, a list, an
/// array such as a grid's `origin`).
pub(crate) fn triple_f64(py: Python<'_>, name: &str, a: &Bound<'_, PyAny>) -> PyResult<[f64; 3]> {
    let v = triple(py, name, a, "float64", "3 numbers")?;
    let v: Vec<f64> = v.extract()?;
    if v.iter().any(|x| !x.is_finite()) {
        return Err(value_err(format!("{name} must be 3 finite numbers; got {v:?}")));
    }
    Ok([v[0], v[1], v[2]])
}

/// Three whole numbers of at least 1 (a grid's dims), from a tuple, a list
/// or an integer array.
pub(crate) fn triple_u64(py: Python<'_>, name: &str, a: &Bound<'_, PyAny>) -> PyResult<[u64; 3]> {
    let v: Vec<i64> = triple(py, name, a, "int64", "3 integers")?.extract()?;
    if v.iter().any(|&x| x < 1) {
        return Err(value_err(format!("{name} must be 3 integers of at least 1; got {v:?}")));
    }
    Ok([v[0] as u64, v[1] as u64, v[2] as u64])
}

/// `a` as a `(3,)` NumPy array of `dtype` (NumPy's `safe` casting: no
/// float becomes an integer), or a one-line `ValueError` saying `what`.
fn triple<'py>(py: Python<'py>, name: &str, a: &Bound<'py, PyAny>, dtype: &str, what: &str) -> PyResult<Bound<'py, PyAny>> {
    let kw = PyDict::new(py);
    kw.set_item("casting", "safe")?;
    let arr = py
        .import("numpy")?
        .call_method1("asarray", (a,))
        .and_then(|x| x.call_method("astype", (dtype,), Some(&kw)))
        .map_err(|_| value_err(format!("{name} must be {what}; got {}", short_repr(a))))?;
    let dims: Vec<usize> = arr.getattr("shape")?.extract()?;
    if dims != [3] {
        return Err(value_err(format!("{name} must be {what}; got {}", short_repr(a))));
    }
    arr.call_method0("tolist")
}

/// `repr(a)`, at most 60 characters.
pub(crate) fn short_repr(a: &Bound<'_, PyAny>) -> String {
    let r = a.repr().map(|r| r.to_string()).unwrap_or_else(|_| "?".into());
    match r.char_indices().nth(60) {
        Some((i, _)) => format!("{}…", &r[..i]),
        None => r,
    }
}
