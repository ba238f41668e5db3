//! Where a grid lies in the world, once for `VoxelGrid` and `DistanceGrid`:
//! dims, origin, bounds, voxel size, spacing, and the maps between world
//! points and voxel indices. Each grid class's getters are one-line calls
//! of these (PyO3 gives a frozen class no shared method block), and the
//! tests (`test_distance_grids_have_the_voxel_grids_placement`) check both
//! classes expose the same placement.
//!
//! The maps take what NumPy users pass: arrays of any dtype NumPy converts
//! safely, lists, tuples, and one point (which gives one row back, `(3,)`).

use glam::DVec3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;
use topovox::{GridSpec, VoxelSource};

use crate::convert::{indices_from, points_from, shape, size_to_py};
use crate::errors::value_err;

/// Voxels along x, y, z.
pub(crate) fn dims(g: &GridSpec) -> (u32, u32, u32) {
    let d = g.dims();
    (d[0], d[1], d[2])
}

/// The low corner, `(3,)` float64.
pub(crate) fn origin<'py>(py: Python<'py>, g: &GridSpec) -> Bound<'py, PyArray1<f64>> {
    Array1::from(g.origin().to_array().to_vec()).into_pyarray(py)
}

/// The world box, `(2, 3)` float64: low and high corners.
pub(crate) fn bounds<'py>(py: Python<'py>, g: &GridSpec) -> Bound<'py, PyArray2<f64>> {
    let (o, s, d) = (g.origin(), g.voxel_size().0, g.dims());
    Array2::from_shape_fn((2, 3), |(r, c)| o[c] + r as f64 * d[c] as f64 * s[c]).into_pyarray(py)
}

/// A float for cubes, `(sx, sy, sz)` for boxes.
pub(crate) fn voxel_size<'py>(py: Python<'py>, g: &GridSpec) -> PyResult<Bound<'py, PyAny>> {
    size_to_py(py, g.voxel_size())
}

/// The three edge lengths, `(3,)` float64.
pub(crate) fn spacing<'py>(py: Python<'py>, g: &GridSpec) -> Bound<'py, PyArray1<f64>> {
    Array1::from(g.voxel_size().0.to_array().to_vec()).into_pyarray(py)
}

/// `a` as a 2-D `(n, 3)` NumPy array of `dtype` (NumPy's `safe` casting),
/// and whether it was one point `(3,)`.
fn rows<'py>(py: Python<'py>, name: &str, a: &Bound<'py, PyAny>, dtype: &str, what: &str) -> PyResult<(Bound<'py, PyAny>, bool)> {
    let np = py.import("numpy")?;
    let arr = np
        .call_method1("asarray", (a,))
        .and_then(|x| {
            let kw = pyo3::types::PyDict::new(py);
            kw.set_item("casting", "safe")?;
            x.call_method("astype", (dtype,), Some(&kw))
        })
        .map_err(|e| value_err(format!("{name} must be {what}: {}", first_line(&e.to_string()))))?;
    let dims: Vec<usize> = arr.getattr("shape")?.extract()?;
    match dims[..] {
        [3] => Ok((arr.call_method1("reshape", ((1i64, 3i64),))?, true)),
        [_, 3] => Ok((arr, false)),
        _ => Err(value_err(format!("{name} must have shape (n, 3) or (3,); got {}", shape(&dims)))),
    }
}

fn first_line(s: &str) -> &str {
    let s = s.lines().next().unwrap_or(s);
    &s[..s.char_indices().nth(120).map_or(s.len(), |(i, _)| i)]
}

/// One row back for one point in.
fn shaped<'py, T: numpy::Element>(a: Array2<T>, one: bool, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
    let a = a.into_pyarray(py).into_any();
    if one {
        a.call_method1("reshape", (3i64,))
    } else {
        Ok(a)
    }
}

/// The voxel holding each point, `floor((p - origin) / voxel_size)`, int64.
pub(crate) fn world_to_index<'py>(py: Python<'py>, g: &GridSpec, points: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let (arr, one) = rows(py, "points", points, "float64", "numbers")?;
    let p: Vec<DVec3> = points_from("points", &arr)?;
    shaped(Array2::from_shape_fn((p.len(), 3), |(n, c)| g.to_grid_units(p[n])[c].floor() as i64), one, py)
}

/// The centre of each voxel, float64.
pub(crate) fn index_to_world<'py>(py: Python<'py>, g: &GridSpec, indices: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    let (arr, one) = rows(py, "indices", indices, "int64", "integers")?;
    let ijk = indices_from::<3>("indices", &arr)?;
    let (o, s) = (g.origin(), g.voxel_size().0);
    shaped(Array2::from_shape_fn((ijk.len(), 3), |(n, c)| o[c] + (ijk[n][c] as f64 + 0.5) * s[c]), one, py)
}

/// The same place: origin, voxel size and dims, exactly (`==` on grids).
pub(crate) fn same_place(a: &GridSpec, b: &GridSpec) -> bool {
    a.origin() == b.origin() && a.voxel_size().0 == b.voxel_size().0 && a.dims() == b.dims()
}

/// The same set voxels, whatever holds them (dense bits, sparse bricks):
/// `for_each_set` visits them in one order for every holder.
pub(crate) fn same_voxels(a: &dyn VoxelSource, b: &dyn VoxelSource) -> bool {
    if a.dims() != b.dims() || a.count() != b.count() {
        return false;
    }
    let mut first = Vec::with_capacity(a.count() as usize);
    a.for_each_set(&mut |i, j, k| first.push([i, j, k]));
    let (mut n, mut same) = (0usize, true);
    b.for_each_set(&mut |i, j, k| {
        same &= first.get(n) == Some(&[i, j, k]);
        n += 1;
    });
    same && n == first.len()
}

/// A hash that equal grids share: the place and the count.
pub(crate) fn hash_of(g: &GridSpec, count: u64) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (g.dims(), g.origin().to_array().map(f64::to_bits), g.voxel_size().0.to_array().map(f64::to_bits), count).hash(&mut h);
    h.finish()
}
