//! The solid modes: choosing the method, running it, and the
//! `solid+surface`, `fill flood` and `hollow` variants.

use topovox::grid::dense::DenseBits;
use topovox::grid::sparse::SparseBricks;
use topovox::voxelize::{self, fill, solid, winding, Options, Stop};
use topovox::{GridSpec, MeshRef};

use topovox::query::orient::{orient, OrientReport, Oriented};
use topovox::query::{Inside, Sign};

use crate::error::{JobError, Result};
use crate::facts::{ExactFacts, SolidFacts, SolidMade, WindingFacts};
use crate::plan::{SolidMethod, SolidPlan};

/// A solid and what was done to get it.
pub struct Outcome {
    /// The voxels.
    pub bits: DenseBits,
    /// The method that ran.
    pub method: &'static str,
    /// Facts for the summary and JSON.
    pub facts: SolidFacts,
    /// Things the user should know (an open mesh under parity, a leaking shell).
    pub warnings: Vec<String>,
}

/// Parity on the GPU (the same voxels as `--method parity`).
#[cfg(feature = "gpu")]
fn gpu_parity(mesh: MeshRef<'_>, grid: &GridSpec) -> Result<(DenseBits, solid::SolidReport)> {
    let gpu = topovox_gpu::Gpu::new().map_err(|e| JobError::failed(format!("--method gpu: {e}")))?;
    let (bits, r) = gpu.solid_parity(mesh, grid).map_err(|e| JobError::failed(format!("--method gpu: {e}")))?;
    Ok((bits, r.solid))
}

#[cfg(not(feature = "gpu"))]
fn gpu_parity(_mesh: MeshRef<'_>, _grid: &GridSpec) -> Result<(DenseBits, solid::SolidReport)> {
    Err(JobError::invalid("--method gpu: this topovox was built without the `gpu` feature"))
}

/// Makes the solid `plan` asks for; `name` names the mesh in warnings.
pub fn run(plan: &SolidPlan, mesh: MeshRef<'_>, name: &str, grid: &GridSpec, opts: &Options<'_>) -> Result<Outcome> {
    let never = Stop::new();
    let stop = opts.stop.unwrap_or(&never);
    let mut warnings = Vec::new();
    let (mut bits, method, mut facts) = if plan.method == SolidMethod::Flood {
        let surface = plan.surface.unwrap_or(voxelize::Mode::Cover);
        let shell = voxelize::fast(surface, mesh, grid, opts).0.to_dense();
        let (bits, rep) = fill::flood_fill(&shell);
        if rep.enclosed == 0 {
            warnings.push(flood_leak_warning(surface));
        }
        (bits, "flood", SolidFacts::new(SolidMade::Flood { shell: surface.name(), shell_voxels: rep.shell, enclosed_voxels: rep.enclosed }))
    } else {
        mesh_solid(plan.method, mesh, name, grid, stop, &mut warnings)?
    };
    if plan.surface.is_some() && plan.method != SolidMethod::Flood {
        let surface = plan.surface.unwrap_or(voxelize::Mode::Cover);
        let (shell, _) = voxelize::fast(surface, mesh, grid, opts);
        topovox::VoxelSource::for_each_set(&shell, &mut |i, j, k| bits.set(i, j, k));
        facts.surface = Some(surface.name());
    }
    if let Some(conn) = plan.hollow {
        bits = fill::hollow(&bits, conn);
        facts.hollow = Some(connectivity(conn));
    }
    Ok(Outcome { bits, method, facts, warnings })
}

/// The mesh the winding rules decide on: `mesh` turned by
/// [`topovox::query::orient`] (`None` for parity and flood fills, which do
/// not depend on orientation); refused, in one line naming `--inside
/// wrap`, when every part of it is a sheet.
pub fn oriented(method: SolidMethod, mesh: MeshRef<'_>, name: &str) -> Result<Option<Oriented>> {
    if matches!(method, SolidMethod::Parity | SolidMethod::GpuParity | SolidMethod::Flood) {
        return Ok(None);
    }
    let o = orient(mesh);
    has_volume(name, Some(o.report))?;
    Ok(Some(o))
}

/// Refuses, in one line naming `--inside wrap`, a mesh whose every part
/// is a sheet (`report` of [`orient`]; `None`: parity, no test).
pub fn has_volume(name: &str, report: Option<OrientReport>) -> Result<()> {
    match report {
        Some(r) if r.only_sheets() => {
            let s = if r.sheets == 1 { "" } else { "s" };
            Err(JobError::invalid(format!(
                "{name}: encloses no volume ({} open sheet{s}, no closed or nearly closed part), so it has no inside: \
                 `remesh --inside wrap` closes a shell around it (surface modes and unsigned distances need no inside)",
                r.sheets
            )))
        }
        _ => Ok(()),
    }
}

/// The rule a mesh method decided by, as the JSON names it.
fn inside_rule(method: &str, watertight: bool) -> &'static str {
    match (method, watertight) {
        ("parity" | "gpu-parity", _) => "parity",
        (_, true) => "nonzero winding",
        (_, false) => "generalized winding",
    }
}

/// A dense solid by a mesh test (every method but flood fills), on the
/// mesh as [`oriented`] turns it, decided again exactly near the surface.
fn mesh_solid(
    method: SolidMethod,
    mesh: MeshRef<'_>,
    name: &str,
    grid: &GridSpec,
    stop: &Stop,
    warnings: &mut Vec<String>,
) -> Result<(DenseBits, &'static str, SolidFacts)> {
    let oriented = oriented(method, mesh, name)?;
    let mesh = oriented.as_ref().map_or(mesh, |o| o.mesh(mesh));
    // Snapped once: the closedness test and whichever method runs share it.
    let snapped = topovox::topology::inside::snap_all(mesh, grid).map_err(|e| JobError::invalid(format!("{name}: {e}")))?;
    let inspect = solid::inspect(&snapped);
    let dims = grid.dims();
    // Closed by the vertices as given: the rule the point queries use.
    let watertight = topovox::query::inside::watertight(&topovox::query::inside::triangles(mesh));
    let streaks = || {
        format!(
            "{name}: not closed and consistently oriented ({} boundary edges, {} inconsistently oriented edges): ray parity may streak through holes",
            inspect.boundary_edges, inspect.unbalanced_edges
        )
    };
    let mut near_half = Vec::new();
    let mut gwn = None;
    let (mut bits, rep, label) = match method {
        SolidMethod::Parity | SolidMethod::GpuParity => {
            if !watertight {
                warnings.push(streaks());
            }
            if method == SolidMethod::GpuParity {
                let (b, r) = gpu_parity(mesh, grid)?;
                (b, r, "gpu-parity")
            } else {
                let (b, r) = solid::parity_snapped(&snapped, dims, stop);
                (b, r, "parity")
            }
        }
        SolidMethod::Auto | SolidMethod::Winding if watertight => {
            let (b, r) = solid::winding_closed_snapped(&snapped, dims, stop);
            (b, r, "winding")
        }
        SolidMethod::Auto | SolidMethod::Winding => {
            let (b, r) = winding::winding_snapped(&snapped, dims, stop);
            gwn = Some(WindingFacts::from(&r));
            near_half = r.near_half;
            (b, r.solid, "winding")
        }
        SolidMethod::Reference if watertight => {
            let (b, r) = solid::reference::solid(mesh, grid).map_err(|e| JobError::invalid(format!("{name}: {e}")))?;
            (b, r, "reference")
        }
        SolidMethod::Reference => {
            let b = winding::reference::winding(mesh, grid).map_err(|e| JobError::invalid(format!("{name}: {e}")))?;
            let mut r = inspect;
            r.voxels = b.count();
            (b, r, "reference")
        }
        SolidMethod::Flood => unreachable!("flood fills are not mesh tests"),
    };
    drop(snapped);
    // The references decide by the winding number (the definition).
    let rule = if label == "parity" || label == "gpu-parity" { Sign::Parity } else { Sign::Winding };
    let (checked, fixes) = exact_fixes(mesh, grid, (rule, watertight), &near_half, stop, |[i, j, k]| bits.get(i, j, k));
    let changed = apply(&mut bits, &fixes);
    let exact = ExactFacts { checked_voxels: checked, changed_voxels: changed as u64 };
    let mut facts = SolidFacts::new(SolidMade::mesh(&rep, gwn, exact));
    facts.inside_rule = Some(inside_rule(label, watertight));
    facts.orientation = oriented.map(|o| o.report.into());
    Ok((bits, label, facts))
}

/// A sparse solid and what was done to get it (see [`run_sparse`]).
pub struct SparseOutcome {
    /// The voxels: sparse bricks, the interior as runs of full bricks.
    pub bits: SparseBricks,
    /// The method that ran.
    pub method: &'static str,
    /// Facts for the summary and JSON.
    pub facts: SolidFacts,
    /// Things the user should know.
    pub warnings: Vec<String>,
}

/// Makes the solid `plan` asks for without a dense grid: rows of crossings
/// turned brick row by brick row into sparse bricks and full runs, united
/// with the tiled surface (tiles of `tile`) for `solid+surface`. Parity,
/// the closed winding number and, for open meshes, the generalized one;
/// flood fills fill a tiled shell plane by plane.
pub fn run_sparse(
    plan: &SolidPlan,
    mesh: MeshRef<'_>,
    name: &str,
    grid: &GridSpec,
    tile: u32,
    opts: &Options<'_>,
) -> Result<SparseOutcome> {
    if !plan.has_sparse_path() {
        return Err(JobError::invalid(format!(
            "{name}: this solid (reference or gpu) has no sparse path yet; parity, the winding numbers and flood fills do"
        )));
    }
    let never = Stop::new();
    let stop = opts.stop.unwrap_or(&never);
    if plan.method == SolidMethod::Flood {
        let surface = plan.surface.unwrap_or(voxelize::Mode::Cover);
        let (shell, _) = voxelize::tiled::tiled(surface, mesh, grid, tile, opts).map_err(|e| JobError::invalid(e.to_string()))?;
        let (bits, rep) = fill::flood_fill_sparse(&shell, stop);
        drop(shell);
        let mut warnings = Vec::new();
        if rep.enclosed == 0 {
            warnings.push(flood_leak_warning(surface));
        }
        let mut facts = SolidFacts::new(SolidMade::Flood { shell: surface.name(), shell_voxels: rep.shell, enclosed_voxels: rep.enclosed });
        facts.full_bricks = Some(bits.full_bricks());
        let bits = hollow_sparse(plan, bits, &mut facts);
        return Ok(SparseOutcome { bits, method: "flood", facts, warnings });
    }
    let oriented = oriented(plan.method, mesh, name)?;
    let shape = mesh;
    let mesh = oriented.as_ref().map_or(mesh, |o| o.mesh(mesh));
    let snapped = topovox::topology::inside::snap_all(mesh, grid).map_err(|e| JobError::invalid(format!("{name}: {e}")))?;
    let inspect = solid::inspect(&snapped);
    let mut warnings = Vec::new();
    let open = format!(
        "{name}: not closed and consistently oriented ({} boundary edges, {} inconsistently oriented edges)",
        inspect.boundary_edges, inspect.unbalanced_edges
    );
    let dims = grid.dims();
    let mut gwn = None;
    let watertight = topovox::query::inside::watertight(&topovox::query::inside::triangles(mesh));
    let mut near_half = Vec::new();
    let (bits, rep, method) = match plan.method {
        SolidMethod::Parity => {
            if !watertight {
                warnings.push(format!("{open}: ray parity may streak through holes"));
            }
            let (b, r) = solid::parity_sparse(&snapped, dims, stop);
            (b, r, "parity")
        }
        _ if !watertight => {
            let (b, r) = winding::winding_sparse(&snapped, dims, stop);
            gwn = Some(WindingFacts::from(&r));
            near_half = r.near_half;
            (b, r.solid, "winding")
        }
        _ => {
            let (b, r) = solid::winding_closed_sparse(&snapped, dims, stop);
            (b, r, "winding")
        }
    };
    drop(snapped);
    let rule = if method == "parity" { Sign::Parity } else { Sign::Winding };
    let (checked, fixes) = exact_fixes(mesh, grid, (rule, watertight), &near_half, stop, |[i, j, k]| bits.get(i, j, k));
    let changed = fixes.len();
    let bits = if fixes.is_empty() { bits } else { bits.with_changes(&fixes) };
    let exact = ExactFacts { checked_voxels: checked, changed_voxels: changed as u64 };
    let mut facts = SolidFacts::new(SolidMade::mesh(&rep, gwn, exact));
    facts.full_bricks = Some(bits.full_bricks());
    facts.inside_rule = Some(inside_rule(method, watertight));
    facts.orientation = oriented.map(|o| o.report.into());
    let bits = match plan.surface {
        Some(surface) => {
            let (shell, _) = voxelize::tiled::tiled(surface, shape, grid, tile, opts).map_err(|e| JobError::invalid(e.to_string()))?;
            facts.surface = Some(surface.name());
            bits.union(&shell)
        }
        None => bits,
    };
    let bits = hollow_sparse(plan, bits, &mut facts);
    Ok(SparseOutcome { bits, method, facts, warnings })
}

/// `--hollow` on a sparse solid, if the plan asks.
fn hollow_sparse(plan: &SolidPlan, bits: SparseBricks, facts: &mut SolidFacts) -> SparseBricks {
    match plan.hollow {
        Some(conn) => {
            facts.hollow = Some(connectivity(conn));
            fill::hollow_sparse(&bits, conn)
        }
        None => bits,
    }
}

/// The warning of a flood fill that enclosed nothing.
fn flood_leak_warning(surface: voxelize::Mode) -> String {
    format!(
        "the {} shell encloses no voxel: it leaks through a hole wider than the shell, or the mesh is too thin for this grid",
        surface.name()
    )
}

/// The voxels whose decision snapping to the lattice could change (those
/// near the surface, and `near_half` of the generalized winding number),
/// decided again by `rule` on the mesh as given
/// ([`topovox::query::grid`]): how many decisions, and those that differ
/// from `is_set` (the lattice solid). So the solid is what
/// `topovox.Query(mesh).contains` says at every voxel centre. Nothing once
/// `stop` is requested. Prepared after the solid, and keeping only the
/// changes, so its memory and the solid's do not add up.
fn exact_fixes(
    mesh: MeshRef<'_>,
    grid: &GridSpec,
    (rule, watertight): (Sign, bool),
    near_half: &[[u32; 3]],
    stop: &Stop,
    is_set: impl Fn([u32; 3]) -> bool + Sync,
) -> (u64, Vec<([u32; 3], bool)>) {
    if stop.requested() {
        return (0, Vec::new());
    }
    // A mesh found closed needs no second look for its boundary.
    let tris = topovox::query::inside::triangles(mesh);
    let exact = if watertight { Inside::closed(tris, rule) } else { Inside::of_triangles(tris, rule) };
    topovox::query::grid::changes(mesh, &exact, grid, near_half, is_set)
}

/// Sets `bits` as `fixes` say; how many changed.
fn apply(bits: &mut DenseBits, fixes: &[([u32; 3], bool)]) -> usize {
    let mut changed = 0;
    for &([i, j, k], inside) in fixes {
        if bits.get(i, j, k) != inside {
            changed += 1;
            if inside {
                bits.set(i, j, k);
            } else {
                bits.clear(i, j, k);
            }
        }
    }
    changed
}

/// The connectivity `--hollow` kept, as the summary says it.
fn connectivity(conn: topovox::topology::runs::Connectivity) -> u8 {
    if conn == topovox::topology::runs::Connectivity::Six {
        6
    } else {
        26
    }
}
