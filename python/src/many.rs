//! The native `voxelize_many`: many meshes in one call, assembled into one
//! sparse batch (coordinates with a batch column, per-voxel features,
//! offsets) as sparse-convolution libraries take them.
//!
//! Each mesh runs exactly what `topovox.voxelize` runs for it alone (the
//! same plan, the same job), so an item equals a single call voxel for
//! voxel (`topovox_job::many`: `method="gpu"` surface modes go to the GPU
//! in one dispatch for the batch); the work is spread over the meshes (a
//! rayon task each) and within them (the voxelizer's own threads share
//! the same pool). The GIL is released throughout; Ctrl-C stops at the
//! next mesh or slab.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Arc;

use numpy::ndarray::{Array1, Array2};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use topovox::attributes::carry::DEFAULT_COLOUR;
use topovox::attributes::{VoxelAttributes, NO_MATERIAL};
use topovox::voxelize::Stop;
use topovox_job::{Choice, JobError, Keep, Voxelized, Voxelizer};

use crate::errors::{py_err, value_err};
use crate::grids::{GridData, VoxelGrid};
use crate::interrupt::{interruptible_ticking, progress_tick};
use crate::meshes::Mesh;
use crate::options::job_options;
use crate::voxelize::carried_grid;

topovox::choice! {
    /// A per-voxel feature of a training batch (columns in the order asked).
    pub enum Feature: "feature" default Occupancy {
        /// 1 for every set voxel (one column).
        Occupancy = "occupancy",
        /// The area-weighted mean unit normal of the surface in the voxel (three columns; zero where none passes).
        Normal = "normal",
        /// sRGB colour in [0, 1] (three columns; the renderer's grey where the mesh has none).
        Colour = "colour",
        /// Surface area inside the voxel, in index space (one column).
        Coverage = "coverage",
        /// Material index, -1 for none (one column).
        Material = "material",
        /// Signed distance from the voxel centre to the mesh, world units, negative inside by the solid's rule (one column).
        Sdf = "sdf",
    }
}

impl Feature {
    /// Columns it takes.
    fn width(self) -> usize {
        match self {
            Feature::Normal | Feature::Colour => 3,
            _ => 1,
        }
    }

    /// Whether it needs the carried attributes.
    fn carried(self) -> bool {
        matches!(self, Feature::Normal | Feature::Colour | Feature::Coverage | Feature::Material)
    }
}

/// One mesh's result: its grid and its rows of features (C order).
struct Item {
    data: GridData,
    features: Vec<f32>,
}

/// The native voxelize_many: see `topovox.voxelize_many`. `meshes` holds
/// `None` where the caller could not load a mesh (an empty item); a mesh
/// that fails leaves an empty item too, its exception listed in `errors`
/// as is (the caller names the mesh and raises or keeps it).
/// `progress(finished, total)` is called on this thread, from the loop
/// that watches for Ctrl-C, whenever the count of meshes voxelized changed.
#[pyfunction]
#[pyo3(signature = (meshes, options=None, features=vec![], progress=None))]
pub(crate) fn voxelize_many<'py>(
    py: Python<'py>,
    meshes: Vec<Option<PyRef<'py, Mesh>>>,
    options: Option<&Bound<'py, PyDict>>,
    features: Vec<String>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut opts = job_options(options, &[])?;
    let features = features.iter().map(|f| Feature::parse(f).map_err(|e| value_err(e.to_string()))).collect::<PyResult<Vec<_>>>()?;
    // The normal column needs the normals carried, as `normals=True` would.
    opts.export.normals |= features.contains(&Feature::Normal);
    let voxelizer = Voxelizer::new(&opts).map_err(py_err)?;
    let plan = &voxelizer.plan;
    if plan.is_line() && features.iter().any(|f| f.carried()) {
        return Err(value_err("line modes carry no attributes: ask for occupancy or sdf only"));
    }
    let keep = Keep::Memory { also: features.iter().any(|f| f.carried()) };
    let pool = opts.run.threads.map(topovox_job::pool).transpose().map_err(py_err)?;
    let inputs: Vec<Option<(Arc<topovox_io::LoadedMesh>, String)>> =
        meshes.iter().map(|m| m.as_ref().map(|m| (m.inner.clone(), m.name()))).collect();
    let stop = Stop::new();
    let budget = topovox_job::budget(plan.request.max_memory);
    let reserve = Reserve { budget, taken: AtomicU64::new(0), stop: &stop, why: Default::default() };
    let (finished, total) = (AtomicUsize::new(0), inputs.iter().flatten().count());
    let tick = progress_tick(progress.as_ref(), || (finished.load(Ordering::Relaxed) as u64, total as u64));
    let results = interruptible_ticking(
        py,
        &stop,
        || {
            let run = || -> Vec<Option<Result<Item, JobError>>> {
                let given: Vec<(&topovox_io::LoadedMesh, &str)> = inputs.iter().flatten().map(|(m, n)| (m.as_ref(), n.as_str())).collect();
                let refs: Vec<(topovox::MeshRef<'_>, &str)> = given.iter().map(|(m, n)| (m.mesh.as_ref(), *n)).collect();
                let each = per_item(plan, budget, refs.len());
                let mut voxelized = topovox_job::many::voxelize_many(&each, &refs, &stop, &finished).into_iter();
                let paired: Vec<Option<(&topovox_io::LoadedMesh, Result<Voxelized, JobError>)>> =
                    inputs.iter().map(|i| i.as_ref().map(|(m, _)| (m.as_ref(), voxelized.next().expect("a result per mesh")))).collect();
                paired
                    .into_par_iter()
                    .map(|p| p.map(|(mesh, v)| v.and_then(|v| item(&voxelizer, mesh, v, &features, keep, &reserve))))
                    .collect()
            };
            match pool {
                Some(p) => p.install(run),
                None => run(),
            }
        },
        tick,
    )?;
    if let Some(e) = reserve.refused() {
        return Err(py_err(e));
    }
    assemble(py, results, &features, budget)
}

/// The plan each mesh runs under: the batch's budget shared by the meshes
/// that run at once (one a thread), so that their voxelizers together keep
/// to it; a single mesh gets it whole, as `voxelize` does.
fn per_item(plan: &topovox_job::Plan, budget: u64, meshes: usize) -> topovox_job::Plan {
    let at_once = rayon::current_num_threads().min(meshes).max(1) as u64;
    let mut each = plan.clone();
    if at_once > 1 && budget != u64::MAX {
        each.request.max_memory = Some((budget / at_once).max(1 << 20));
    }
    each
}

/// What the batch's items hold together after voxelizing: each reserves
/// its rows (the ordered voxels, their features, their share of the
/// arrays) and its grid's storage before allocating them, so a batch
/// whose voxels cannot fit is refused the moment one item's count shows
/// it, not after every item has run (a tetrahedron's solid at 2048 has
/// 1.4 × 10⁹ voxels: 34 GiB of ordered voxels, which aborted the
/// interpreter). Whether a batch fits is its total, whatever the order.
struct Reserve<'a> {
    budget: u64,
    taken: AtomicU64,
    stop: &'a Stop,
    /// The first refusal's message.
    why: std::sync::Mutex<Option<String>>,
}

/// Bytes a voxel's row takes: the ordered voxel (24, and a second copy
/// while counting-sorted), coordinates (16), and per column the item's
/// features and the batch's copy (4 + 4).
fn row_bytes(width: usize) -> u64 {
    48 + 16 + 8 * width as u64
}

impl Reserve<'_> {
    /// Reserves `bytes` for `data`'s item, or stops the batch.
    fn take(&self, data: &GridData, bytes: u64) -> Result<(), JobError> {
        let total = self.taken.fetch_add(bytes, Ordering::SeqCst).saturating_add(bytes);
        if total <= self.budget {
            return Ok(());
        }
        let [x, y, z] = data.grid().dims();
        let why = format!(
            "the batch's voxels need more than the {} this run may use (a {x}x{y}x{z} item alone holds {} voxels, about {}); use fewer meshes per call, a coarser grid or a surface mode, or raise max_memory",
            topovox_job::bytes(self.budget),
            data.count(),
            topovox_job::bytes(bytes)
        );
        self.why.lock().unwrap_or_else(|e| e.into_inner()).get_or_insert(why);
        self.stop.request();
        Err(JobError::Interrupted)
    }

    /// The refusal, if the batch did not fit.
    fn refused(&self) -> Option<JobError> {
        (self.taken.load(Ordering::SeqCst) > self.budget)
            .then(|| JobError::failed(self.why.lock().unwrap_or_else(|e| e.into_inner()).take().unwrap_or_default()))
    }
}

/// One mesh's grid as `voxelize` gives it, with its features measured
/// once its share of the batch's memory is reserved.
fn item(
    voxelizer: &Voxelizer,
    mesh: &topovox_io::LoadedMesh,
    v: Voxelized,
    features: &[Feature],
    keep: Keep,
    reserve: &Reserve<'_>,
) -> Result<Item, JobError> {
    let data = carried_grid(voxelizer, mesh, v, keep)?;
    let width: usize = features.iter().map(|f| f.width()).sum();
    let query = if features.contains(&Feature::Sdf) { topovox_job::query_bytes(mesh.mesh.as_ref()) } else { 0 };
    let storage = match data.voxels() {
        topovox_job::Voxels::Dense(_) => data.grid().dense_bytes(),
        _ => data.count(),
    };
    reserve.take(&data, data.count().saturating_mul(row_bytes(width)).saturating_add(query).saturating_add(storage))?;
    let features = measure(&data, mesh, features)?;
    Ok(Item { data, features })
}

/// The feature rows of `data`'s set voxels, in C order.
fn measure(data: &GridData, mesh: &topovox_io::LoadedMesh, features: &[Feature]) -> Result<Vec<f32>, JobError> {
    let order = data.ordered();
    let width: usize = features.iter().map(|f| f.width()).sum();
    let mut out = Vec::with_capacity(order.len() * width);
    let query = if features.contains(&Feature::Sdf) {
        Some(topovox::query::Query::new(mesh.mesh.as_ref(), topovox::query::Sign::Auto).map_err(|e| JobError::invalid(e.to_string()))?)
    } else {
        None
    };
    let attrs = data.attributes();
    for &(ijk, slot) in order {
        for f in features {
            push_feature(&mut out, *f, ijk, slot, attrs, data, query.as_ref());
        }
    }
    Ok(out)
}

fn push_feature(
    out: &mut Vec<f32>,
    f: Feature,
    ijk: [u32; 3],
    slot: usize,
    attrs: Option<&VoxelAttributes>,
    data: &GridData,
    query: Option<&topovox::query::Query>,
) {
    match f {
        Feature::Occupancy => out.push(1.0),
        Feature::Normal => out.extend(attrs.and_then(|a| a.normal.as_ref()).map_or([0.0; 3], |n| n[slot])),
        Feature::Colour => {
            let c = attrs.and_then(|a| a.colour.as_ref()).map_or(DEFAULT_COLOUR, |c| c[slot]);
            out.extend(c.map(|v| v as f32 / 255.0));
        }
        Feature::Coverage => out.push(attrs.and_then(|a| a.coverage.as_ref()).map_or(0.0, |c| c[slot])),
        Feature::Material => {
            let m = attrs.and_then(|a| a.material.as_ref()).map_or(NO_MATERIAL, |m| m[slot]);
            out.push(crate::convert::material_index(m) as f32);
        }
        Feature::Sdf => {
            let q = query.expect("a query when sdf is asked");
            out.push(q.signed_distance(data.grid().voxel_center(ijk)) as f32);
        }
    }
}

/// The batch's arrays and items, and each failed mesh's exception.
fn assemble<'py>(
    py: Python<'py>,
    results: Vec<Option<Result<Item, JobError>>>,
    features: &[Feature],
    budget: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let width: usize = features.iter().map(|f| f.width()).sum();
    let rows: u64 = results.iter().flatten().flatten().map(|it| it.data.ordered().len() as u64).sum();
    let need = rows.saturating_mul(16 + 4 * width as u64);
    if need > budget {
        return Err(py_err(JobError::failed(format!(
            "the batch's {rows} voxels need about {} as arrays, more than the {} this run may use; use fewer meshes per call or a coarser grid",
            topovox_job::bytes(need),
            topovox_job::bytes(budget)
        ))));
    }
    let (grids, errors) = (PyList::empty(py), PyList::empty(py));
    let mut offsets = vec![0i64];
    // Sized once: growing them page-faulted a tenth of a small batch's time.
    let (mut coords, mut feats) = (Vec::<i32>::with_capacity(rows as usize * 4), Vec::<f32>::with_capacity(rows as usize * width));
    for (b, r) in results.into_iter().enumerate() {
        match r {
            Some(Ok(it)) => {
                coords.extend(it.data.ordered().iter().flat_map(|(v, _)| [b as i32, v[0] as i32, v[1] as i32, v[2] as i32]));
                feats.extend_from_slice(&it.features);
                grids.append(Py::new(py, VoxelGrid { inner: Arc::new(it.data) })?)?;
            }
            Some(Err(JobError::Interrupted)) => return Err(py_err(JobError::Interrupted)),
            Some(Err(e)) => {
                errors.append((b, py_err(e).into_value(py)))?;
                grids.append(py.None())?;
            }
            None => grids.append(py.None())?,
        }
        offsets.push(coords.len() as i64 / 4);
    }
    let d = PyDict::new(py);
    let n = coords.len() / 4;
    d.set_item("coords", Array2::from_shape_vec((n, 4), coords).expect("rows of four").into_pyarray(py))?;
    d.set_item("features", Array2::from_shape_vec((n, width), feats).expect("rows of the features' width").into_pyarray(py))?;
    d.set_item("offsets", Array1::from(offsets).into_pyarray(py))?;
    d.set_item("grids", grids)?;
    d.set_item("errors", errors)?;
    d.set_item("columns", features.iter().flat_map(|f| columns(*f)).collect::<Vec<_>>())?;
    Ok(d)
}

/// The names of a feature's columns.
fn columns(f: Feature) -> Vec<String> {
    match f.width() {
        1 => vec![f.name().to_string()],
        _ => ["x", "y", "z"]
            .iter()
            .zip(["r", "g", "b"])
            .map(|(a, c)| format!("{}.{}", f.name(), if f == Feature::Colour { c } else { a }))
            .collect(),
    }
}

/// The features' names and help, for `topovox.FEATURES`.
#[pyfunction]
pub(crate) fn features() -> Vec<(&'static str, &'static str)> {
    Feature::ALL.iter().map(|f| (f.name(), f.help())).collect()
}
