//! Distance fields (`topovox sdf`, `topovox.sdf`): the grid fitted as for
//! `voxelize`, the exact distances of [`topovox::distance`], and the sign
//! of the solid: a voxel is negative exactly when `voxelize --mode solid`
//! with the same method sets it, because the sign *is* that solid (the
//! sparse solid path, the same voxels as the dense one).

use std::path::Path;
use std::time::Instant;

use serde_json::{json, Value};
use topovox::choice::Choice;
use topovox::distance::band::{band, Band};
use topovox::distance::field::Field;
use topovox::distance::{nearest, DistanceError, Pieces};
use topovox::voxelize::{Options, Stop};
use topovox::{GridSpec, MeshRef};

use crate::error::{JobError, Result};
use crate::grid::{GridOptions, GridRequest};
use crate::memory::{budget, bytes};
use crate::options::RunOptions;
use crate::plan::{SolidMethod, SolidPlan};
use crate::table::{choice, chosen, flag, number, shown, value, Example, OptionValue, Shape};

topovox::choice! {
    /// How the sign (inside or outside) of a distance is decided.
    pub enum Sign: "sign" default Auto {
        /// As `--mode solid --method auto`: the winding number of the mesh
        /// oriented by parts and nesting (nonzero where closed, the
        /// generalized `|w| ≥ ½` otherwise); meshes of sheets are refused.
        Auto = "auto",
        /// Ray parity (right for closed meshes; streaks through holes).
        Parity = "parity",
        /// The winding number (generalized on open meshes: ≥ ½ is inside).
        Winding = "winding",
    }
}

impl From<Sign> for topovox::query::Sign {
    fn from(s: Sign) -> Self {
        match s {
            Sign::Auto => topovox::query::Sign::Auto,
            Sign::Parity => topovox::query::Sign::Parity,
            Sign::Winding => topovox::query::Sign::Winding,
        }
    }
}

impl From<topovox::query::Sign> for Sign {
    fn from(s: topovox::query::Sign) -> Self {
        match s {
            topovox::query::Sign::Auto => Sign::Auto,
            topovox::query::Sign::Parity => Sign::Parity,
            topovox::query::Sign::Winding => Sign::Winding,
        }
    }
}

topovox::choice! {
    /// File formats of distance fields.
    pub enum DistanceFormat: "format" {
        /// OpenVDB: a float grid of class level set named `surface`, the band active.
        Vdb = "vdb",
        /// NumPy: float32 of shape (nx, ny, nz), every voxel.
        Npy = "npy",
        /// Zarr v3: a float32 array, sharded; chunks of background left out.
        Zarr = "zarr",
        /// VTK ImageData: a Float32 cell array `distance`, every voxel.
        Vti = "vti",
    }
}

impl DistanceFormat {
    /// The format `format` names, else the one of `out`'s extension.
    pub fn of(format: Option<&str>, out: &Path) -> Result<DistanceFormat> {
        if let Some(f) = format {
            return DistanceFormat::parse(f).map_err(|e| JobError::invalid(format!("--format: {e}")));
        }
        let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
        DistanceFormat::parse(&ext).map_err(|_| {
            JobError::invalid(format!(
                "{}: cannot tell the format from the extension; distance fields are written as .vdb, .npy, .zarr or .vti (or give --format)",
                out.display()
            ))
        })
    }

    /// Whether the file holds every voxel (so the grid must fit in memory).
    pub fn is_dense(self) -> bool {
        matches!(self, DistanceFormat::Npy | DistanceFormat::Vti)
    }
}

/// How far the stored band reaches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Width {
    /// Voxels whose distance is below this many voxel sizes.
    Voxels(f64),
    /// Every voxel of the grid.
    All,
}

/// As the user writes it: `3`, `2.5`, `all`.
impl std::fmt::Display for Width {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Width::Voxels(w) => write!(f, "{w}"),
            Width::All => f.write_str("all"),
        }
    }
}

impl Width {
    /// What a band may be, for messages.
    pub const EXPECTED: &'static str = "a number of voxels above 0 (at most 1e6) or `all`";

    /// `all`, or a positive number of voxels.
    pub fn parse(s: &str) -> Result<Width> {
        if s.trim().eq_ignore_ascii_case("all") {
            return Ok(Width::All);
        }
        match s.trim().parse::<f64>() {
            Ok(w) if w.is_finite() && w > 0.0 && w <= 1e6 => Ok(Width::Voxels(w)),
            _ => Err(JobError::invalid(format!("band: expected {}, got {s:?}", Width::EXPECTED))),
        }
    }

    /// As the user writes it.
    pub fn label(self) -> Value {
        match self {
            Width::Voxels(w) => json!(w),
            Width::All => json!("all"),
        }
    }
}

/// A band given by name: a number of voxels, or `all` (a number's text too).
fn width(key: &str, v: &OptionValue) -> Result<Width> {
    match v {
        OptionValue::Text(t) => Width::parse(t),
        OptionValue::Int(_) | OptionValue::Float(_) => Width::parse(&number(key, v)?.to_string()),
        v => Err(JobError::invalid(format!("band: expected {}, got {}", Width::EXPECTED, shown(v)))),
    }
}

crate::option_table! {
    /// What a distance field stores: the band, the sign.
    pub struct FieldOptions {
        band: Width = Width::Voxels(3.0),
            parse width,
            example Example::Float(2.5),
            print |o| Some(o.band.label()),
            cli value("W|all"),
            "half width of the stored band in voxels: voxels nearer than W voxel sizes to the mesh get their distance, the others ±W voxel sizes (OpenVDB's level-set background); all: every voxel gets its distance";
        unsigned: bool = false,
            parse flag,
            example Example::Bool(true),
            print |o| Some(json!(o.unsigned)),
            cli Shape::Flag,
            "unsigned distances (no inside): for open meshes, polylines and point-like data";
        sign: Sign = Sign::Auto,
            parse chosen,
            example Example::Text("winding"),
            print |o| Some(json!(o.sign.name())),
            cli choice::<Sign>("RULE"),
            "how inside is decided (the same rule, and the same voxels, as voxelize --mode solid --method)";
    }
}

crate::option_table! {
    /// Every option of a distance-field job (`topovox sdf`, `topovox.sdf`,
    /// `topovox batch --run sdf`).
    pub struct SdfOptions {
        [group field: FieldOptions, "The band and the sign."]
        [group grid: GridOptions, "The grid."]
        [group run: RunOptions, "Threads, memory, paths."]
    }
}

impl SdfOptions {
    /// The validated request for a field written as `format`.
    pub fn request(&self, format: DistanceFormat) -> Result<SdfRequest> {
        Ok(SdfRequest {
            grid: GridRequest::new(&self.grid)?,
            width: self.field.band,
            unsigned: self.field.unsigned,
            sign: self.field.sign,
            max_memory: self.run.max_memory,
            format,
        })
    }
}

/// A distance-field job.
#[derive(Clone, Debug)]
pub struct SdfRequest {
    /// The grid.
    pub grid: GridRequest,
    /// The band.
    pub width: Width,
    /// No sign: the unsigned distance.
    pub unsigned: bool,
    /// How the sign is decided.
    pub sign: Sign,
    /// `--max-memory`.
    pub max_memory: Option<u64>,
    /// The format it will be written in (dense formats need the grid in memory).
    pub format: DistanceFormat,
}

/// A distance field and what was done to get it.
pub struct Sdf {
    /// The values.
    pub field: Field,
    /// Where the voxels are.
    pub grid: GridSpec,
    /// Negative inside.
    pub signed: bool,
    /// How inside was decided (`parity`, `winding`); `None` when unsigned.
    pub sign: Option<String>,
    /// Seconds computing the distances.
    pub distance_s: f64,
    /// Facts for the JSON summary.
    pub facts: Value,
    /// Things the user should know (an open mesh under parity).
    pub warnings: Vec<String>,
}

fn distance_error(name: &str, e: DistanceError) -> JobError {
    JobError::invalid(format!("{name}: {e}"))
}

fn stopped() -> JobError {
    JobError::Interrupted
}

/// About the bytes the band and its bins take: 4 per band voxel, twice
/// for bricks the band fills in part, and 8 per (piece, brick) pair. The
/// band's voxels: its volume, the surface area times twice the radius,
/// over a voxel's volume (on the cow within 1 % of the stored count, cubes
/// and 1:1:8 boxes alike), plus `(2w+1)³` a piece for rims and slivers.
fn band_estimate(pieces: &Pieces, grid: &GridSpec, w: f64) -> u64 {
    let h = grid.voxel_size().0;
    let radius = w * h.max_element();
    let mut area = 0.0;
    let mut pairs = 0.0;
    for p in &pieces.items {
        let [a, b, c] = p.p;
        area += 0.5 * (b - a).cross(c - a).length();
        let ext = (p.hi - p.lo + 2.0 * radius) / h;
        pairs += ext.to_array().iter().map(|e| (e / 8.0).floor() + 2.0).product::<f64>();
    }
    let voxels = area * 2.0 * radius / (h.x * h.y * h.z) + pieces.items.len() as f64 * (2.0 * w + 1.0).powi(3);
    (voxels * 8.0 + pairs * 8.0) as u64
}

/// Refuses a job that would not fit in the memory it may use.
fn check_fits(name: &str, req: &SdfRequest, pieces: &Pieces, mesh: MeshRef<'_>, grid: &GridSpec) -> Result<()> {
    let limit = budget(req.max_memory);
    let cells = grid.voxel_count();
    let mut need = match req.width {
        // The values, their bricks, and the dense copy a dense file needs.
        Width::All => cells.saturating_mul(12),
        // A band holds at most every voxel: never more than `all` needs.
        Width::Voxels(w) => band_estimate(pieces, grid, w).min(cells.saturating_mul(12)),
    };
    if req.format.is_dense() && req.width != Width::All {
        need = need.saturating_add(cells.saturating_mul(4));
    }
    if !req.unsigned {
        need = need.saturating_add(crate::memory::sparse_solid_estimate(mesh, grid, false).bytes);
    }
    if need > limit {
        let [x, y, z] = grid.dims();
        let hint = if req.format.is_dense() { "; .vdb and .zarr keep only the band" } else { "" };
        return Err(JobError::failed(format!(
            "{name}: the distance field on the {x}x{y}x{z} grid needs about {}, more than the {} this run may use; raise --max-memory, narrow the band or lower the resolution{hint}",
            bytes(need),
            bytes(limit)
        )));
    }
    Ok(())
}

/// The distance field of `mesh` (named `name` in messages).
pub fn sdf(mesh: MeshRef<'_>, name: &str, req: &SdfRequest, stop: Option<&Stop>) -> Result<Sdf> {
    let never = Stop::new();
    let stop = stop.unwrap_or(&never);
    let pieces = Pieces::of(mesh).map_err(|e| distance_error(name, e))?;
    let grid = req.grid.fit(&mesh.bounds())?;
    check_fits(name, req, &pieces, mesh, &grid)?;
    // The band's unit: the largest voxel edge (see `topovox::distance::band`).
    let h = grid.voxel_size().0.max_element();
    let mut warnings = Vec::new();
    let mut facts = json!({"band": req.width.label(), "signed": !req.unsigned, "skipped": pieces.skipped});
    // The sign first: the solid of `--mode solid` with the same method.
    let t = Instant::now();
    let mut sign = None;
    let inside = if req.unsigned {
        None
    } else {
        let method = match req.sign {
            Sign::Auto => SolidMethod::Auto,
            Sign::Parity => SolidMethod::Parity,
            Sign::Winding => SolidMethod::Winding,
        };
        let plan = SolidPlan { method, surface: None, hollow: None };
        let opts = Options { stop: Some(stop), ..Default::default() };
        // No surface is united, so the tile size is never used.
        let out = crate::solid::run_sparse(&plan, mesh, name, &grid, topovox::voxelize::tiled::DEFAULT_TILE, &opts)?;
        if stop.requested() {
            return Err(stopped());
        }
        warnings.extend(out.warnings);
        facts["sign"] = json!(out.method);
        sign = Some(out.method.to_string());
        facts["solid"] = json!(out.facts);
        facts["inside_voxels"] = json!(out.bits.count());
        Some(out.bits)
    };
    facts["sign_s"] = json!(t.elapsed().as_secs_f64());
    let t = Instant::now();
    let (values, background) = match req.width {
        Width::Voxels(w) => (band(&pieces, &grid, w, stop).ok_or_else(stopped)?, (w * h) as f32),
        Width::All => {
            let dense = nearest::dense(&pieces, &grid, stop).ok_or_else(stopped)?;
            let far = dense.iter().fold(0f32, |a, &b| a.max(b));
            let bg = if far > 0.0 { far } else { h as f32 };
            (Band::from_dense(grid.dims(), bg as f64, &dense), bg)
        }
    };
    let distance_s = t.elapsed().as_secs_f64();
    facts["distance_s"] = json!(distance_s);
    facts["stored_voxels"] = json!(values.count());
    facts["background"] = json!(background);
    let field = Field::signed(values, inside, background);
    Ok(Sdf { field, grid, signed: !req.unsigned, sign, distance_s, facts, warnings })
}

/// Writes `sdf` to `out` in `format`: to a temporary beside it, renamed
/// into place (a Zarr folder replaces only a Zarr array topovox wrote).
///
/// `.npy` and `.vti` hold every voxel: a field whose dense copy would not
/// fit in memory is refused before anything is made (Python's
/// `DistanceGrid.save` reaches here with any field it holds).
pub fn write(out: &Path, format: DistanceFormat, sdf: &Sdf, stop: Option<&Stop>) -> Result<()> {
    let (field, grid) = (&sdf.field, &sdf.grid);
    if format.is_dense() {
        let (need, limit) = (grid.voxel_count().saturating_mul(4), budget(None));
        if need > limit {
            let [x, y, z] = grid.dims();
            return Err(JobError::failed(format!(
                "{}: a dense {x}x{y}x{z} field needs {} (float32 per voxel), more than the {} available; .vdb and .zarr keep only the band",
                out.display(),
                bytes(need),
                bytes(limit)
            )));
        }
    }
    let io = |e: topovox_io::IoError| JobError::Io(e);
    match format {
        DistanceFormat::Zarr => topovox_io::zarr::write_distance(out, field, grid, sdf.signed, stop).map_err(io),
        DistanceFormat::Vdb => {
            topovox_io::atomic::write_atomically_until(out, stop, |w| topovox_io::vdb::write_level_set(w, field, grid, sdf.signed))
                .map_err(io)
        }
        DistanceFormat::Npy => {
            let values = field.dense();
            topovox_io::atomic::write_atomically_until(out, stop, |w| topovox_io::npy::write_f32(w, grid.dims(), &values)).map_err(io)
        }
        DistanceFormat::Vti => {
            let values = field.dense();
            topovox_io::atomic::write_atomically_until(out, stop, |w| topovox_io::vti::write_distance(w, &values, grid)).map_err(io)
        }
    }
}
