//! Watertight meshes (`topovox remesh`, `topovox.remesh`): the inside
//! voxels by the rule of `voxelize --mode solid` (or wrap's shells), the
//! surface around them by [`topovox::surface`], the certificate by
//! [`topovox::mesh_check`].
//!
//! The topology is the voxels': closed, 2-manifold, oriented,
//! self-intersection-free and separating every inside voxel centre from
//! every other by construction (see `topovox::surface::tets`). Debug builds
//! and `--check` certify the result exactly before it is written.
//!
//! A file output past what one slab may hold (1 GiB, or what the budget
//! leaves) is made and written slab by slab ([`surface::Part`],
//! `topovox_io::mesh_out::PartWriter`) unless something needs the whole
//! mesh (the certificate, `--simplify`, wrap's two-sided distance): memory
//! is then the solid's bits and one slab, not the mesh (the bunny at 2048:
//! 1.3 GiB for a 92 M-triangle surface, 0.9 GiB under `--max-memory 2G`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::DVec3;
use serde_json::{json, Value};

use crate::facts::SolidFacts;
use topovox::choice::Choice;
use topovox::distance::nearest::Hierarchy;
use topovox::distance::Pieces;
use topovox::grid::dense::DenseBits;
use topovox::mesh_check::{check_mesh, MeshCheck};
use topovox::surface::{self, TriMesh};
use topovox::voxelize::{self, Options, Progress, Stop};
use topovox::{GridSpec, MeshRef};
use topovox_io::mesh_out::MeshOut;
use topovox_io::LoadedMesh;

use crate::check::certificate_json;
use crate::error::{JobError, Result};
use crate::grid::{GridOptions, GridRequest};
use crate::memory::{budget, bytes};
use crate::options::RunOptions;
use crate::plan::{SolidMethod, SolidPlan};
use crate::table::{choice, chosen, flag, int, number, value, Example, Shape};

topovox::choice! {
    /// Which voxels the surface closes around.
    pub enum Inside: "inside" default Auto {
        /// As `--mode solid --method auto`: the winding number of the mesh
        /// oriented by parts and nesting (nonzero where closed, the
        /// generalized `|w| ≥ ½` otherwise); meshes of sheets are refused.
        Auto = "auto",
        /// Ray parity (right for closed meshes; streaks through holes).
        Parity = "parity",
        /// The winding number (generalized on open meshes: ≥ ½ is inside).
        Winding = "winding",
        /// The solid, the cover grown by one voxel and every cavity they
        /// enclose: closed shells around sheets, open surfaces, thin walls
        /// and loose parts, containing the whole input surface.
        Wrap = "wrap",
    }
}

topovox::choice! {
    /// Where the surface's vertices go.
    pub enum SurfaceKind: "surface" default Smooth {
        /// On the zero of the exact signed distance along the lattice edges
        /// between inside and outside voxel centres (marching tetrahedra).
        Smooth = "smooth",
        /// On the faces of the inside voxels (a quarter voxel off where
        /// voxels meet only along an edge or at a corner).
        Blocky = "blocky",
    }
}

crate::option_table! {
    /// What `remesh` closes and how (`topovox remesh`, `topovox.remesh`).
    pub struct ShellOptions {
        inside: Inside = Inside::Auto,
            parse chosen,
            example Example::Text("wrap"),
            print |o| Some(json!(o.inside.name())),
            cli choice::<Inside>("RULE"),
            "which voxels the surface closes around: auto, parity or winding (the voxels of voxelize --mode solid with that method) or wrap (shells around any input)";
        surface: SurfaceKind = SurfaceKind::Smooth,
            parse chosen,
            example Example::Text("blocky"),
            print |o| Some(json!(o.surface.name())),
            cli choice::<SurfaceKind>("KIND"),
            "smooth (vertices where the exact signed distance crosses zero) or blocky (the inside voxels' faces)";
        min_part: u64 = 0,
            parse |k, v| int(k, v, 0),
            example Example::Int(8),
            print |o| Some(json!(o.min_part)),
            cli value("VOXELS"),
            "drop inside parts (26-connected voxels) of fewer voxels than this (default 0: every part is kept)";
        simplify: f64 = 0.0,
            parse |k, v| {
                let e = number(k, v)?;
                if !(0.0..=2.0).contains(&e) {
                    return Err(JobError::invalid(format!("{k} must be between 0 and 2 (voxels); got {e}")));
                }
                Ok(e)
            },
            example Example::Float(0.5),
            print |o| (o.simplify > 0.0).then(|| json!(o.simplify)),
            cli value("VOXELS"),
            "merge faces while each kept vertex stays within this many voxels of the planes merged into it (0 to 2; default 0: none); a collapse that would break a guarantee is refused, and the result is certified again";
        check: bool = false,
            parse flag,
            example Example::Bool(true),
            print |_| None,
            cli Shape::Flag,
            "certify the result exactly before writing it (closed, manifold, oriented, no self-intersection, no zero-area face) and report the certificate";
    }
}

crate::option_table! {
    /// Every option of a remesh job.
    pub struct RemeshOptions {
        [group shell: ShellOptions, "What is closed and how."]
        [group grid: GridOptions, "The grid."]
        [group run: RunOptions, "Threads, memory, paths."]
    }
}

/// A validated remesh request.
#[derive(Clone, Debug)]
pub struct RemeshRequest {
    /// The grid.
    pub grid: GridRequest,
    /// The inside rule.
    pub inside: Inside,
    /// The surface.
    pub surface: SurfaceKind,
    /// Smallest part kept, in voxels.
    pub min_part: u64,
    /// The simplification's bound in voxels (0: none).
    pub simplify: f64,
    /// Certify before returning.
    pub check: bool,
    /// Round vertices to f32 (the output stores floats).
    pub single: bool,
    /// `--max-memory`.
    pub max_memory: Option<u64>,
}

impl RemeshRequest {
    /// Whether a file output is made and written slab by slab, never held
    /// whole: unless something needs the whole mesh — the certificate
    /// (`check`, debug builds), `simplify`, and wrap's two-sided distance
    /// (measured part by part, it held half the pieces of the bunny's
    /// shell at 560 and took seven times as long).
    pub fn streams(&self) -> bool {
        !self.check && self.simplify <= 0.0 && self.inside != Inside::Wrap && !cfg!(debug_assertions)
    }
}

impl RemeshOptions {
    /// The validated request; `single`: the output stores f32.
    pub fn request(&self, single: bool) -> Result<RemeshRequest> {
        let mut grid = self.grid.clone();
        // Wrap grows the cover by a voxel: a fitted grid keeps room for it.
        if self.shell.inside == Inside::Wrap && grid.pad.is_none() && grid.origin.is_none() && grid.dims.is_none() {
            grid.pad = Some(1);
        }
        Ok(RemeshRequest {
            grid: GridRequest::new(&grid)?,
            inside: self.shell.inside,
            surface: self.shell.surface,
            min_part: self.shell.min_part,
            simplify: self.shell.simplify,
            check: self.shell.check,
            single,
            max_memory: self.run.max_memory,
        })
    }
}

/// What [`remesh`] found on the way, for the summary.
#[derive(Clone, Debug, PartialEq)]
pub struct RemeshFacts {
    /// How inside was decided (`parity`, `winding`, and `+wrap`).
    pub inside: String,
    /// Inside voxels the surface closes around.
    pub inside_voxels: u64,
    /// Faces between inside and outside voxels: the surface has at most
    /// [`TRIANGLES_PER_BOUNDARY_FACE`] triangles for each.
    pub boundary_voxel_faces: u64,
    /// Parts (26-connected) kept and dropped by `min_part`.
    pub parts: u64,
    /// Parts dropped.
    pub dropped_parts: u64,
    /// Seconds deciding the inside, and making the surface.
    pub inside_s: f64,
    /// Seconds making the surface.
    pub surface_s: f64,
    /// Largest and mean distance (voxels) from the output's vertices to
    /// the input, and from the input's vertices and face centres to the
    /// output (wrap and `check` only).
    pub distance: Option<[f64; 4]>,
    /// Facts of the solid.
    pub solid: SolidFacts,
    /// What `simplify` did, `None` when not asked.
    pub simplify: Option<SimplifyFacts>,
}

impl RemeshFacts {
    /// As the JSON summary writes it.
    pub fn to_json(&self) -> Value {
        let d = self.distance.map(|d| {
            json!({"output_to_input_max": d[0], "output_to_input_mean": d[1], "input_to_output_max": d[2], "input_to_output_mean": d[3]})
        });
        json!({
            "inside": self.inside, "inside_voxels": self.inside_voxels, "boundary_voxel_faces": self.boundary_voxel_faces, "parts": self.parts,
            "dropped_parts": self.dropped_parts, "inside_s": self.inside_s, "surface_s": self.surface_s,
            "distance_voxels": d, "solid": self.solid, "simplify": self.simplify,
        })
    }
}

/// What `--simplify` did.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SimplifyFacts {
    /// The bound asked for, in voxels.
    pub error_voxels: f64,
    /// Faces before.
    pub faces_before: usize,
    /// Faces after (before, when the result was not kept).
    pub faces: usize,
    /// The simplified surface passed its certificate and separation check.
    pub kept: bool,
    /// Seconds simplifying and checking.
    pub seconds: f64,
}

/// How a watertight mesh was made: what the summary reports.
pub struct RemeshMade {
    /// The grid of its voxels.
    pub grid: GridSpec,
    /// Facts for the summary.
    pub facts: RemeshFacts,
    /// The certificate (with `check`, and in debug builds).
    pub certificate: Option<MeshCheck>,
    /// Things the user should know (an open mesh under parity).
    pub warnings: Vec<String>,
    /// The mesh's vertices.
    pub vertices: u64,
    /// The mesh's triangles.
    pub triangles: u64,
}

/// A watertight mesh and how it was made.
pub struct Remeshed {
    /// The mesh.
    pub mesh: TriMesh,
    /// How.
    pub made: RemeshMade,
}

/// The most triangles the smooth surface has per boundary voxel face
/// ([`RemeshFacts::boundary_voxel_faces`]): each of Kuhn's six tetrahedra
/// in a lattice cube gives at most two triangles, a cube gives any only
/// when one of its twelve axis edges joins an inside centre to an outside
/// one, and each such edge — a boundary voxel face — lies in four cubes:
/// 6 · 2 · 4. The blocky surface, on half voxels, has at most four times
/// as many. Measured at 128 (smooth, blocky): 6.2–6.9 and 28–30 on the
/// bunny, cow, homer and fandisk; 8.0 and 32 on a box with walls 0.6 voxel
/// thin, 4.9 and 25 on it rotated.
pub const TRIANGLES_PER_BOUNDARY_FACE: u64 = 48;

/// Triangles per boundary voxel face the memory estimate counts once the
/// inside is known (smooth, blocky): the largest measured (see
/// [`TRIANGLES_PER_BOUNDARY_FACE`]), a tenth more.
const MEASURED_PER_BOUNDARY_FACE: (f64, f64) = (8.8, 35.0);

/// The most one slab of a streamed surface may hold (estimated): enough
/// that a surface of up to about 10 M triangles is made in one slab, as
/// fast as a whole one, and a larger one costs at most this much.
const SLAB_BYTES: u64 = 1 << 30;

/// Refuses a grid whose voxels and surface would not fit in memory, and
/// says how many lattice layers a slab of the surface holds.
///
/// The estimate: one bit per voxel for the solid (wrap: three grids),
/// eight for the blocky surface's half voxels, and per triangle held —
/// estimated as ten per voxel face of the input's area for the smooth
/// surface, 44 for the blocky one (the bunny: 9.3 and 41.8), and once the
/// inside is known (`boundary`: its boundary voxel faces), before the
/// surface is made, as [`MEASURED_PER_BOUNDARY_FACE`] per boundary face
/// where that is half again more than the area said — 90 bytes
/// (smooth: its vertices, the edge table, the distances at the lattice
/// ends) or 60 (blocky), plus the output's distance pieces and their copy
/// in the hierarchy where the two-sided distance is measured (wrap,
/// `check`: 2 × 328 + 128 bytes) and the certificate's sorts where it
/// runs; plus the input's pieces and hierarchies (1000 bytes a piece) and
/// 24 MiB for the process. A streamed surface ([`RemeshRequest::streams`])
/// holds one slab: the whole surface when it fits within [`SLAB_BYTES`]
/// and what the budget leaves, else as many layers as keep twice their
/// share of the triangles (surfaces crowd into some layers) within that,
/// at least 8, plus the writer's two scratch sections in memory; and a
/// fifth more for the allocator's heap. A caller that keeps the output
/// (`held`: [`remesh`], Python's `topovox.remesh`) holds it whole, with
/// its copy handed on (48 bytes a triangle). Measured peaks on the bunny are
/// 0.5–0.9 of the estimate from 128 to 2048 (see BENCHMARKS.md; the 2048
/// run once peaked at 8.4 GiB where it claimed 5.2, before the surface
/// was streamed and triangles counted as now).
fn check_fits(name: &str, req: &RemeshRequest, pieces: &Pieces, grid: &GridSpec, held: bool, boundary: Option<u64>) -> Result<u32> {
    let cells = grid.voxel_count();
    let blocky = req.surface == SurfaceKind::Blocky;
    let grids = if req.inside == Inside::Wrap { 3 } else { 1 } + if blocky { 8 } else { 0 };
    let h = grid.voxel_size().0;
    let area: f64 = pieces.items.iter().map(|p| 0.5 * (p.p[1] - p.p[0]).cross(p.p[2] - p.p[0]).length()).sum();
    let (per_face, bytes_each) = if blocky { (44.0, 60) } else { (10.0, 90) };
    let per_boundary = if blocky { MEASURED_PER_BOUNDARY_FACE.1 } else { MEASURED_PER_BOUNDARY_FACE.0 };
    // Before the inside is known, from the input's area; after, from the
    // inside's boundary where that is half again more (thin walls and
    // loose parts have more boundary than area), so a run the first
    // estimate admitted at its stated need is not refused by the second.
    let by_area = area / (h.x * h.y).min(h.y * h.z).min(h.x * h.z) * per_face;
    let faces = boundary.unwrap_or(0);
    let triangles = if faces as f64 * per_boundary > 1.5 * by_area { faces as f64 * per_boundary } else { by_area };
    let measured = req.inside == Inside::Wrap || req.check;
    let certified = req.check || cfg!(debug_assertions) || req.simplify > 0.0;
    let per_triangle = bytes_each
        + if measured { 2 * std::mem::size_of::<topovox::distance::Piece>() + 128 } else { 0 }
        + if certified { 150 } else { 0 }
        + if held { 48 } else { 0 };
    let surface = triangles * per_triangle as f64;
    let fixed = (cells / 8).saturating_mul(grids + 1).saturating_add(pieces.items.len() as u64 * 1000 + crate::memory::PROCESS_BYTES);
    let limit = budget(req.max_memory);
    let layers = if blocky { 2 * grid.dims()[2] } else { grid.dims()[2] };
    // What the allocator's heap keeps beside what is live: a fifth (see
    // `memory::sparse_solid_estimate`; a 384 run peaked at 182 MiB where
    // this estimate said 181 without it). Plans are made against the rest.
    let usable = limit / 6 * 5;
    let with_heap = |b: u64| b.saturating_add(b / 5);
    // The whole surface at once, when it fits in a slab and the budget.
    let whole = fixed.saturating_add(surface as u64);
    if held || !req.streams() || (surface <= SLAB_BYTES as f64 && whole <= usable) {
        refuse_past(name, grid, with_heap(whole), limit)?;
        return Ok(u32::MAX);
    }
    // Else slabs as thick as the budget allows, plus the writer's two
    // scratch sections, held in memory up to a limit.
    let scratch = 2 * topovox_io::atomic::Spool::SPILL as u64;
    let slab = SLAB_BYTES.min(usable.saturating_sub(fixed + scratch)) as f64;
    // A slab of t layers holds about 2·t/layers of the surface.
    let thickness = ((slab / (2.0 * surface).max(1.0)) * layers as f64).clamp(8.0, layers.max(8) as f64) as u32;
    let held = surface * (2.0 * thickness as f64 / layers as f64).min(1.0);
    let streamed = fixed + scratch + held as u64;
    if streamed > usable && whole <= usable {
        return Ok(u32::MAX);
    }
    refuse_past(name, grid, with_heap(whole.min(streamed)), limit)?;
    Ok(thickness)
}

/// Refuses, before any work, a grid whose surface the output's numbers
/// cannot hold ([`surface::check_precision`]).
fn check_precision(name: &str, req: &RemeshRequest, grid: &GridSpec) -> Result<()> {
    surface::check_precision(grid, req.single)
        .map_err(|why| JobError::invalid(format!("{name}: {why}{}", if req.single { ", or write .obj or .ply (f64)" } else { "" })))
}

/// The refusal of a run that needs `need` bytes where `limit` is allowed.
fn refuse_past(name: &str, grid: &GridSpec, need: u64, limit: u64) -> Result<()> {
    if need > limit {
        let [x, y, z] = grid.dims();
        return Err(JobError::failed(format!(
            "{name}: remeshing on the {x}x{y}x{z} grid needs about {}, more than the {} this run may use; raise --max-memory or lower the resolution",
            bytes(need),
            bytes(limit)
        )));
    }
    Ok(())
}

/// The inside voxels by `req`'s rule, with the method's name, the solid's
/// facts and warnings.
fn inside(
    mesh: MeshRef<'_>,
    name: &str,
    req: &RemeshRequest,
    grid: &GridSpec,
    stop: &Stop,
) -> Result<(DenseBits, String, SolidFacts, Vec<String>)> {
    let method = match req.inside {
        Inside::Auto | Inside::Wrap => SolidMethod::Auto,
        Inside::Parity => SolidMethod::Parity,
        Inside::Winding => SolidMethod::Winding,
    };
    let plan = SolidPlan { method, surface: None, hollow: None };
    let opts = Options { stop: Some(stop), ..Default::default() };
    if req.inside == Inside::Wrap {
        if let Some(wrapped) = wrap_sheets(mesh, grid, &opts) {
            return Ok(wrapped);
        }
    }
    let solid = crate::solid::run(&plan, mesh, name, grid, &opts)?;
    if stop.requested() {
        return Err(JobError::Interrupted);
    }
    if req.inside != Inside::Wrap {
        return Ok((solid.bits, solid.method.to_string(), solid.facts, solid.warnings));
    }
    let cover = voxelize::fast(voxelize::Mode::Cover, mesh, grid, &opts).0.to_dense();
    // Wrap closes open meshes on purpose: parity's warning does not apply.
    Ok((surface::wrap(&solid.bits, &cover), format!("{}+wrap", solid.method), solid.facts, Vec::new()))
}

/// Wrap on a mesh whose every part is a sheet: no inside (the winding
/// number's blobs beside a sheet are not volume), so the shell closes
/// around the grown cover alone; `None` when some part encloses volume.
fn wrap_sheets(mesh: MeshRef<'_>, grid: &GridSpec, opts: &Options<'_>) -> Option<(DenseBits, String, SolidFacts, Vec<String>)> {
    let report = topovox::query::orient::orient(mesh).report;
    if !report.only_sheets() {
        return None;
    }
    let cover = voxelize::fast(voxelize::Mode::Cover, mesh, grid, opts).0.to_dense();
    let nothing = DenseBits::new(grid.dims());
    let exact = crate::facts::ExactFacts { checked_voxels: 0, changed_voxels: 0 };
    let mut facts = SolidFacts::new(crate::facts::SolidMade::mesh(&Default::default(), None, exact));
    facts.inside_rule = Some("none (sheets)");
    facts.orientation = Some(report.into());
    Some((surface::wrap(&nothing, &cover), "wrap".to_string(), facts, Vec::new()))
}

/// The inside voxels a surface closes around, on their grid.
struct Closed {
    bits: DenseBits,
    grid: GridSpec,
    /// Lattice layers per slab of the surface.
    thickness: u32,
    method: String,
    solid: SolidFacts,
    warnings: Vec<String>,
    parts: u64,
    dropped_parts: u64,
    inside_voxels: u64,
    boundary_voxel_faces: u64,
    inside_s: f64,
}

/// The inside voxels of `mesh` by `req`'s rule, small parts dropped; an
/// error when the grid does not fit or nothing is inside.
/// `held`: the caller keeps the whole output in memory (no streaming).
fn close(mesh: MeshRef<'_>, name: &str, req: &RemeshRequest, pieces: &Pieces, held: bool, stop: &Stop) -> Result<Closed> {
    let grid = req.grid.fit(&mesh.bounds())?;
    check_precision(name, req, &grid)?;
    check_fits(name, req, pieces, &grid, held, None)?;
    let t = Instant::now();
    let (bits, method, solid, warnings) = inside(mesh, name, req, &grid, stop)?;
    let (bits, parts, dropped_parts) = surface::drop_small_parts(bits, req.min_part);
    let inside_voxels = bits.count();
    if inside_voxels == 0 {
        let why = if req.inside == Inside::Wrap {
            "it has no triangle of positive area in the grid (polylines are not wrapped)"
        } else {
            "no voxel centre is inside; --inside wrap closes open surfaces, sheets and loose parts"
        };
        return Err(JobError::invalid(format!("{name}: nothing to close on this grid: {why}")));
    }
    let inside_s = t.elapsed().as_secs_f64();
    let boundary_voxel_faces = bits.boundary_faces();
    // Counted again from the surface's own size, before it is made.
    let thickness = check_fits(name, req, pieces, &grid, held, Some(boundary_voxel_faces))?;
    Ok(Closed { bits, grid, thickness, method, solid, warnings, parts, dropped_parts, inside_voxels, boundary_voxel_faces, inside_s })
}

/// The surface around `c`, handed to `each` slab by slab ([`surface::Part`]);
/// `tree` gives the input's hierarchy (built when first needed).
fn surface_parts<'t, E>(
    c: &Closed,
    req: &RemeshRequest,
    pieces: &Pieces,
    tree: &dyn Fn() -> &'t Hierarchy,
    stop: &Stop,
    each: surface::Parts<'_, E>,
) -> std::result::Result<Option<()>, E> {
    match req.surface {
        SurfaceKind::Blocky => surface::blocky_parts(&c.bits, &c.grid, c.thickness, stop, each),
        SurfaceKind::Smooth => {
            // Wrap's outside centres lie at least 1.5 voxels from the input
            // (no 26-neighbour's box meets it): its shell sits there.
            let offset = (req.inside == Inside::Wrap).then(|| 1.5 * c.grid.voxel_size().0.max_element());
            surface::smooth_parts(&c.bits, &c.grid, surface::Smooth { pieces, tree: tree(), offset }, c.thickness, stop, each)
        }
    }
}

impl Closed {
    /// The summary's facts and the rest of what was made, once the surface is.
    fn made(
        self,
        surface_s: f64,
        extra: (Option<[f64; 4]>, Option<SimplifyFacts>),
        certificate: Option<MeshCheck>,
        counts: [u64; 2],
    ) -> RemeshMade {
        let Closed { grid, method, solid, warnings, parts, dropped_parts, inside_voxels, boundary_voxel_faces, inside_s, .. } = self;
        let (distance, simplify) = extra;
        let facts = RemeshFacts {
            inside: method,
            inside_voxels,
            boundary_voxel_faces,
            parts,
            dropped_parts,
            inside_s,
            surface_s,
            distance,
            solid,
            simplify,
        };
        RemeshMade { grid, facts, certificate, warnings, vertices: counts[0], triangles: counts[1] }
    }
}

/// The watertight mesh of `mesh` (named `name` in messages).
pub fn remesh(mesh: MeshRef<'_>, name: &str, req: &RemeshRequest, stop: Option<&Stop>) -> Result<Remeshed> {
    let never = Stop::new();
    let stop = stop.unwrap_or(&never);
    let pieces = Pieces::of(mesh).map_err(|e| JobError::invalid(format!("{name}: {e}")))?;
    // The input's hierarchy, built once when the smooth surface or the
    // two-sided distance first needs it.
    let tree = std::cell::OnceCell::new();
    let input_tree = || tree.get_or_init(|| Hierarchy::new(&pieces));
    let mut c = close(mesh, name, req, &pieces, true, stop)?;
    let t = Instant::now();
    let mut out = TriMesh::default();
    let made = surface_parts(&c, req, &pieces, &input_tree, stop, &mut |p: surface::Part| {
        out.positions.extend(p.positions);
        out.triangles.extend(p.triangles);
        Ok::<(), std::convert::Infallible>(())
    });
    if !matches!(made, Ok(Some(()))) {
        return Err(JobError::Interrupted);
    }
    if req.single {
        out.positions.iter_mut().for_each(|p| *p = p.as_vec3().as_dvec3());
    }
    let (out, simplify, certified) = simplified(out, &c.bits, &c.grid, req.simplify, stop, &mut c.warnings)?;
    let surface_s = t.elapsed().as_secs_f64();
    let distance = (req.check || req.inside == Inside::Wrap).then(|| two_sided(mesh, &pieces, input_tree(), &out, &c.grid));
    let certificate = match certified {
        Some(c) => Some(c),
        None if req.check || cfg!(debug_assertions) => Some(certify(name, &out, stop)?),
        None => None,
    };
    let counts = [out.positions.len() as u64, out.triangles.len() as u64];
    Ok(Remeshed { made: c.made(surface_s, (distance, simplify), certificate, counts), mesh: out })
}

/// The watertight mesh of `mesh`, made and written to `out` as `format`
/// slab by slab, never whole ([`RemeshRequest::streams`]); the made facts
/// and the seconds spent putting the file together at the end.
fn remesh_streamed(
    mesh: MeshRef<'_>,
    name: &str,
    req: &RemeshRequest,
    out: &Path,
    format: MeshOut,
    stop: &Stop,
) -> Result<(RemeshMade, f64)> {
    let pieces = Pieces::of(mesh).map_err(|e| JobError::invalid(format!("{name}: {e}")))?;
    let c = close(mesh, name, req, &pieces, false, stop)?;
    let tree = std::cell::OnceCell::new();
    let input_tree = || tree.get_or_init(|| Hierarchy::new(&pieces));
    let t = Instant::now();
    let mut writer = topovox_io::mesh_out::PartWriter::new(out, format);
    let made = surface_parts(&c, req, &pieces, &input_tree, stop, &mut |mut p: surface::Part| {
        if req.single {
            p.positions.iter_mut().for_each(|p| *p = p.as_vec3().as_dvec3());
        }
        writer.part(p.positions, p.triangles)
    });
    if made?.is_none() {
        return Err(JobError::Interrupted);
    }
    let surface_s = t.elapsed().as_secs_f64();
    let counts = [writer.vertices(), writer.triangles()];
    let t = Instant::now();
    writer.finish(Some(stop))?;
    Ok((c.made(surface_s, (None, None), None, counts), t.elapsed().as_secs_f64()))
}

/// `out` simplified within `error` voxels ([`surface::simplify`]; 0: as
/// it is), with its facts and its certificate. The simplified surface is
/// certified again, exactly, and must still separate `bits` (its parity
/// solid on `grid` is `bits`); otherwise `out` is kept with a warning.
fn simplified(
    out: TriMesh,
    bits: &DenseBits,
    grid: &GridSpec,
    error: f64,
    stop: &Stop,
    warnings: &mut Vec<String>,
) -> Result<(TriMesh, Option<SimplifyFacts>, Option<MeshCheck>)> {
    if error <= 0.0 {
        return Ok((out, None, None));
    }
    let t = Instant::now();
    let h = grid.voxel_size().0.max_element();
    let fewer = surface::simplify::simplify(&out, grid, error * h, stop).ok_or(JobError::Interrupted)?;
    let certificate = match check_mesh(&fewer.positions, &fewer.triangles, stop) {
        Ok(c) => Some(c).filter(|c| c.watertight()),
        Err(topovox::mesh_check::MeshCheckError::Stopped) => return Err(JobError::Interrupted),
        Err(_) => None,
    };
    let separates = certificate.is_some() && {
        let r = MeshRef { positions: &fewer.positions, triangles: &fewer.triangles, segments: &[] };
        topovox::voxelize::solid::parity(r, grid).is_ok_and(|(solid, _)| solid == *bits)
    };
    let faces_before = out.triangles.len();
    let facts = |kept: &TriMesh, ok: bool| SimplifyFacts {
        error_voxels: error,
        faces_before,
        faces: kept.triangles.len(),
        kept: ok,
        seconds: t.elapsed().as_secs_f64(),
    };
    if !separates {
        warnings.push(format!(
            "--simplify {error}: the simplified surface failed its certificate or its separation check; the surface is left unsimplified (please report this mesh)"
        ));
        let f = facts(&out, false);
        return Ok((out, Some(f), None));
    }
    let f = facts(&fewer, true);
    Ok((fewer, Some(f), certificate))
}

impl RemeshMade {
    /// The summary's facts and the certificate (`null` when none ran), as
    /// JSON.
    pub fn summary(&self) -> Value {
        let mut facts = self.facts.to_json();
        facts["certificate"] = self.certificate.as_ref().map(certificate_json).unwrap_or_default();
        facts
    }
}

/// The certificate of `out`; an error (nothing is written) if it fails.
fn certify(name: &str, out: &TriMesh, stop: &Stop) -> Result<MeshCheck> {
    let c = check_mesh(&out.positions, &out.triangles, stop).map_err(|e| match e {
        topovox::mesh_check::MeshCheckError::Stopped => JobError::Interrupted,
        e => JobError::failed(format!("{name}: the surface could not be certified: {e}")),
    })?;
    if !c.watertight() {
        return Err(JobError::failed(format!(
            "{name}: internal error: the surface failed its certificate ({}); nothing was written; please report this mesh",
            certificate_json(&c)
        )));
    }
    Ok(c)
}

/// Largest and mean distances (voxels, the largest edge): output vertices
/// to the input, input vertices and face centres to the output.
fn two_sided(mesh: MeshRef<'_>, pieces: &Pieces, tree: &Hierarchy, out: &TriMesh, grid: &GridSpec) -> [f64; 4] {
    use rayon::prelude::*;
    let h = grid.voxel_size().0.max_element();
    let stats = |tree: &Hierarchy, points: &[DVec3]| -> (f64, f64) {
        let d: Vec<f64> = points.par_iter().map(|&p| tree.nearest(p, (f64::INFINITY, u32::MAX)).0.sqrt() / h).collect();
        (d.iter().fold(0.0, |a: f64, &b| a.max(b)), d.iter().sum::<f64>() / d.len().max(1) as f64)
    };
    let to_input = stats(tree, &out.positions);
    let out_ref = MeshRef { positions: &out.positions, triangles: &out.triangles, segments: &[] };
    let out_pieces = Pieces::of(out_ref).expect("a surface has triangles and finite vertices");
    // The hierarchy keeps its own copy of the pieces.
    let out_tree = Hierarchy::new(&out_pieces);
    drop(out_pieces);
    let mut samples: Vec<DVec3> = pieces.items.iter().flat_map(|p| [p.p[0], (p.p[0] + p.p[1] + p.p[2]) / 3.0]).collect();
    samples.extend(mesh.positions.iter().filter(|p| p.is_finite()));
    let to_output = stats(&out_tree, &samples);
    [to_input.0, to_input.1, to_output.0, to_output.1]
}

/// A remesh job's two steps.
#[derive(Clone, Debug)]
pub struct RemeshJob {
    /// The validated request.
    pub request: RemeshRequest,
    /// The output format.
    pub format: MeshOut,
}

/// What [`RemeshJob::run`] made and wrote.
pub struct RemeshDone {
    /// The facts of the mesh's making.
    pub made: RemeshMade,
    /// Seconds writing.
    pub write_s: f64,
}

/// The format `format` names, else the one of `out`'s extension.
pub fn format_of(format: Option<&str>, out: &Path) -> Result<MeshOut> {
    if let Some(f) = format {
        return MeshOut::parse(f).map_err(|e| JobError::invalid(format!("--format: {e}")));
    }
    MeshOut::of_path(out).ok_or_else(|| {
        JobError::invalid(format!(
            "{}: cannot tell the format from the extension; remesh writes .obj, .ply, .stl or .glb (or give --format)",
            out.display()
        ))
    })
}

impl RemeshJob {
    /// Checks everything that needs no mesh: the options, the format, the
    /// output's folder, and that the output is none of `inputs`.
    pub fn prepare(options: &RemeshOptions, out: &Path, format: MeshOut, inputs: &[PathBuf]) -> Result<RemeshJob> {
        let request = options.request(format.single())?;
        crate::output::check_output_path(out)?;
        topovox_io::atomic::refuse_overwriting_inputs(out, inputs)?;
        Ok(RemeshJob { request, format })
    }

    /// The watertight mesh of `loaded`, written to `out`; `stop` ends it
    /// early (nothing is written).
    pub fn run(
        &self,
        out: &Path,
        loaded: &LoadedMesh,
        name: &str,
        progress: Option<&dyn Progress>,
        stop: Option<&Stop>,
    ) -> Result<RemeshDone> {
        topovox_io::atomic::refuse_overwriting_inputs(out, &loaded.sources)?;
        progress.inspect(|p| p.phase("remeshing"));
        if self.request.streams() {
            let never = Stop::new();
            let (made, write_s) = remesh_streamed(loaded.mesh.as_ref(), name, &self.request, out, self.format, stop.unwrap_or(&never))?;
            return Ok(RemeshDone { made, write_s });
        }
        let remeshed = remesh(loaded.mesh.as_ref(), name, &self.request, stop)?;
        progress.inspect(|p| p.phase("writing"));
        let t = Instant::now();
        topovox_io::mesh_out::write_mesh(out, &remeshed.mesh.positions, &remeshed.mesh.triangles, self.format, stop)?;
        Ok(RemeshDone { made: remeshed.made, write_s: t.elapsed().as_secs_f64() })
    }
}
