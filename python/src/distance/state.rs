//! A `DistanceGrid` as plain values for pickling: the placement, the
//! band's bricks (coordinates, masks, where their values start), its
//! values, and the inside voxels as bricks and runs of full bricks. The
//! state is checked when rebuilt (counts, order, bounds), so a damaged one
//! is a `ValueError`, never a panic.

use glam::DVec3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use topovox::distance::band::{Band, BandBrick};
use topovox::distance::field::Field;
use topovox::grid::sparse::SparseBricks;
use topovox::GridSpec;
use topovox_job::distance::Sdf;

use crate::errors::value_err;

/// The state of `s`.
pub(crate) fn save<'py>(py: Python<'py>, s: &Sdf) -> PyResult<Bound<'py, PyAny>> {
    let d = PyDict::new(py);
    let g = &s.grid;
    d.set_item("origin", g.origin().to_array().to_vec())?;
    d.set_item("spacing", g.voxel_size().0.to_array().to_vec())?;
    d.set_item("dims", g.dims().to_vec())?;
    d.set_item("signed", s.signed)?;
    d.set_item("background", s.field.background)?;
    let b = &s.field.band;
    d.set_item("radius", b.radius)?;
    let n = b.bricks.len();
    d.set_item("band_at", Array2::from_shape_fn((n, 3), |(r, c)| b.bricks[r].at[c]).into_pyarray(py))?;
    d.set_item("band_mask", Array2::from_shape_fn((n, 8), |(r, c)| b.bricks[r].mask[c]).into_pyarray(py))?;
    d.set_item("band_first", b.bricks.iter().map(|x| x.first as u64).collect::<Array1<u64>>().into_pyarray(py))?;
    d.set_item("values", Array1::from(b.values.clone()).into_pyarray(py))?;
    if let Some(ins) = &s.field.inside {
        let mut rows: Vec<([u32; 3], [u64; 8], u32)> = Vec::new();
        ins.for_each_brick_run(|at, bits, run| rows.push((at, *bits, run)));
        let k = rows.len();
        d.set_item("inside_at", Array2::from_shape_fn((k, 3), |(r, c)| rows[r].0[c]).into_pyarray(py))?;
        d.set_item("inside_bits", Array2::from_shape_fn((k, 8), |(r, c)| rows[r].1[c]).into_pyarray(py))?;
        d.set_item("inside_run", rows.iter().map(|r| r.2).collect::<Array1<u32>>().into_pyarray(py))?;
    }
    d.set_item("facts", s.facts.to_string())?;
    d.set_item("warnings", s.warnings.clone())?;
    Ok(d.into_any())
}

fn bad(what: &str) -> PyErr {
    value_err(format!("not a DistanceGrid state: {what}"))
}

fn get<'py, T>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<T>
where
    T: for<'a> FromPyObject<'a, 'py>,
{
    d.get_item(key)?.ok_or_else(|| bad(&format!("no {key}")))?.extract().map_err(|_| bad(&format!("{key} of the wrong type")))
}

/// The grid a state describes, checked.
pub(crate) fn load(d: &Bound<'_, PyDict>) -> PyResult<Sdf> {
    let three = |v: Vec<f64>| <[f64; 3]>::try_from(v).map_err(|_| bad("not three numbers"));
    let dims = <[u64; 3]>::try_from(get::<Vec<u64>>(d, "dims")?).map_err(|_| bad("dims"))?;
    let grid = GridSpec::new(DVec3::from_array(three(get(d, "origin")?)?), DVec3::from_array(three(get(d, "spacing")?)?), dims)
        .map_err(|e| bad(&e.to_string()))?;
    let at: PyReadonlyArray2<'_, u32> = get(d, "band_at")?;
    let mask: PyReadonlyArray2<'_, u64> = get(d, "band_mask")?;
    let first: PyReadonlyArray1<'_, u64> = get(d, "band_first")?;
    let values: PyReadonlyArray1<'_, f32> = get(d, "values")?;
    let (at, mask, first, values) = (at.as_array(), mask.as_array(), first.as_array(), values.as_array());
    let n = at.nrows();
    if at.ncols() != 3 || mask.dim() != (n, 8) || first.len() != n {
        return Err(bad("band arrays of unequal lengths"));
    }
    let nb = grid.dims().map(|d| d.div_ceil(8));
    let mut bricks = Vec::with_capacity(n);
    let mut next = 0u64;
    for r in 0..n {
        let b =
            BandBrick { at: [at[[r, 0]], at[[r, 1]], at[[r, 2]]], mask: std::array::from_fn(|c| mask[[r, c]]), first: first[r] as usize };
        if first[r] != next || (0..3).any(|a| b.at[a] >= nb[a]) {
            return Err(bad("band bricks out of order or outside the grid"));
        }
        next += b.mask.iter().map(|w| w.count_ones() as u64).sum::<u64>();
        bricks.push(b);
    }
    if next != values.len() as u64 {
        return Err(bad("band masks and values disagree"));
    }
    let band = Band { dims: grid.dims(), radius: get(d, "radius")?, bricks, values: values.to_vec() };
    let inside = match d.get_item("inside_at")? {
        Some(_) => Some(inside(d, grid.dims(), nb)?),
        None => None,
    };
    let facts: serde_json::Value = serde_json::from_str(&get::<String>(d, "facts")?).map_err(|_| bad("facts"))?;
    let field = Field { band, inside, background: get(d, "background")? };
    // What the facts record of the sign and the time, typed again.
    let (sign, distance_s) = (facts["sign"].as_str().map(String::from), facts["distance_s"].as_f64().unwrap_or(0.0));
    Ok(Sdf { field, grid, signed: get(d, "signed")?, sign, distance_s, facts, warnings: get(d, "warnings")? })
}

/// The inside voxels: bricks (`run` 1) and runs of full bricks along x.
fn inside(d: &Bound<'_, PyDict>, dims: [u32; 3], nb: [u32; 3]) -> PyResult<SparseBricks> {
    let at: PyReadonlyArray2<'_, u32> = get(d, "inside_at")?;
    let bits: PyReadonlyArray2<'_, u64> = get(d, "inside_bits")?;
    let run: PyReadonlyArray1<'_, u32> = get(d, "inside_run")?;
    let (at, bits, run) = (at.as_array(), bits.as_array(), run.as_array());
    let k = at.nrows();
    if at.ncols() != 3 || bits.dim() != (k, 8) || run.len() != k {
        return Err(bad("inside arrays of unequal lengths"));
    }
    let (mut bricks, mut runs) = (Vec::new(), Vec::new());
    for r in 0..k {
        let b = [at[[r, 0]], at[[r, 1]], at[[r, 2]]];
        let n = run[r];
        if n == 0 || b[0].checked_add(n).is_none_or(|end| end > nb[0]) || b[1] >= nb[1] || b[2] >= nb[2] {
            return Err(bad("inside bricks outside the grid"));
        }
        let brick: [u64; 8] = std::array::from_fn(|c| bits[[r, c]]);
        // Bits past the grid's edge must be clear (SparseBricks requires it).
        if (0..n).any(|x| !within(&brick, [b[0] + x, b[1], b[2]], dims)) {
            return Err(bad("inside voxels outside the grid"));
        }
        if n == 1 {
            bricks.push((b, brick));
        } else if brick == [u64::MAX; 8] {
            runs.push((b, n));
        } else {
            return Err(bad("a run of bricks that are not full"));
        }
    }
    Ok(SparseBricks::from_parts(dims, bricks, runs))
}

/// Whether every set bit of the brick at `b` is a voxel of the grid.
fn within(brick: &[u64; 8], b: [u32; 3], dims: [u32; 3]) -> bool {
    let room = |a: usize| dims[a].saturating_sub(b[a] * 8).min(8);
    let (nx, ny, nz) = (room(0), room(1), room(2));
    let row: u64 = (0..ny).fold(0, |m, y| m | (((1u64 << nx) - 1) << (y * 8)));
    brick.iter().enumerate().all(|(z, &w)| if (z as u32) < nz { w & !row == 0 } else { w == 0 })
}
