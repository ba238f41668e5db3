//! `topovox check VOXELS [--mesh MESH]`: certify a voxel file's topology.

use std::time::Instant;

use anyhow::{bail, Result};
use serde_json::{json, Value};

use crate::args::CheckArgs;

pub fn run(a: &CheckArgs) -> Result<()> {
    let t0 = Instant::now();
    let pool = topovox_job::pool_for(a.threads, "--threads")?;
    if a.mesh.is_none() && topovox_io::is_mesh_file(&a.voxels) {
        return pool.install(|| check_mesh_file(a, t0));
    }
    if !a.require.is_empty() {
        bail!("--require applies to a mesh file checked alone; {} is read as voxels", a.voxels.display());
    }
    let up = a.up.unwrap_or_default();
    let sparse_format = topovox_io::VoxelFormat::from_path(&a.voxels).is_some_and(topovox_io::VoxelFormat::reads_sparsely);
    if a.sparse && !sparse_format {
        bail!("{}: --sparse reads only .vdb, .zarr and .npz files", a.voxels.display());
    }
    let voxels = if a.sparse {
        Voxels::Sparse(topovox_io::read_voxels_sparse(
            &a.voxels,
            &topovox_io::ReadOptions { attributes: false, allow_external_paths: a.allow_external_paths, ..Default::default() },
        )?)
    } else {
        match topovox_io::read_voxels(
            &a.voxels,
            &topovox_io::ReadOptions { up, allow_external_paths: a.allow_external_paths, ..Default::default() },
        ) {
            Ok(l) => Voxels::Dense(l),
            // Past memory: checked window by window.
            Err(e) if matches!(e.kind, topovox_io::ErrorKind::TooLarge { .. }) && sparse_format => {
                Voxels::Sparse(topovox_io::read_voxels_sparse(
                    &a.voxels,
                    &topovox_io::ReadOptions { attributes: false, allow_external_paths: a.allow_external_paths, ..Default::default() },
                )?)
            }
            Err(e) if matches!(e.kind, topovox_io::ErrorKind::TooLarge { .. }) => {
                bail!("{e}; grids past memory are checked from .vdb, .zarr or .npz files (window by window)")
            }
            Err(e) => return Err(e.into()),
        }
    };
    let (dims, placement) = match &voxels {
        Voxels::Dense(l) => (l.bits.dims(), l.placement),
        Voxels::Sparse(s) => (s.bits.dims(), s.placement),
    };
    let mesh = match &a.mesh {
        Some(path) => {
            let m = topovox_io::read_mesh(
                path,
                &topovox_io::ReadOptions { allow_external_paths: a.allow_external_paths, ..Default::default() },
            )?;
            for w in &m.warnings {
                crate::console::warn(&format!("{}: {w}", path.display()));
            }
            let (grid, source) = topovox_job::check::check_grid(
                dims,
                placement,
                &a.grid.options,
                &m.report.bounds,
                &a.voxels.display().to_string(),
                &path.display().to_string(),
            )?;
            Some((m, grid, source))
        }
        None => None,
    };
    let mesh = mesh.as_ref().map(|(m, g, s)| (m.mesh.as_ref(), g, *s));
    let mut v = pool.install(|| match &voxels {
        Voxels::Dense(l) => topovox_job::check::report(&l.bits, mesh),
        Voxels::Sparse(s) => {
            let layers = topovox_job::check::window_layers(dims, topovox_job::budget(None));
            topovox_job::check::report_sparse(&s.bits, mesh, layers)
        }
    })?;
    v["check_s"] = json!(t0.elapsed().as_secs_f64());
    if a.json {
        return crate::console::print_stdout(&v.to_string());
    }
    crate::console::print_stdout(&text(&v, a))
}

/// `topovox check MESH`: the mesh's certificate; exit status 1 when a
/// required property fails.
fn check_mesh_file(a: &CheckArgs, t0: Instant) -> Result<()> {
    use topovox_job::check::{certificate_json, mesh_certificate, MeshProperty};
    use topovox_job::Choice;
    let opts = topovox_io::ReadOptions { allow_external_paths: a.allow_external_paths, ..Default::default() };
    let loaded = topovox_io::read_mesh(&a.voxels, &opts)?;
    for w in &loaded.warnings {
        crate::console::warn(&format!("{}: {w}", a.voxels.display()));
    }
    let name = a.voxels.display().to_string();
    let c = mesh_certificate(loaded.mesh.as_ref(), &name, None)?;
    let required = if a.require.is_empty() { vec![MeshProperty::Watertight] } else { a.require.clone() };
    let failed: Vec<&str> = required.iter().filter(|p| !p.holds(&c)).map(|p| p.name()).collect();
    let mut v = certificate_json(&c);
    v["input"] = json!(name);
    v["required"] = json!(required.iter().map(|p| p.name()).collect::<Vec<_>>());
    v["failed"] = json!(failed);
    v["check_s"] = json!(t0.elapsed().as_secs_f64());
    if a.json {
        crate::console::print_stdout(&v.to_string())?;
    } else {
        crate::console::print_stdout(&mesh_text(&name, &c))?;
    }
    if !failed.is_empty() {
        eprintln!("topovox: {name}: not {}", failed.join(", not "));
        std::process::exit(1);
    }
    Ok(())
}

fn mesh_text(name: &str, c: &topovox::mesh_check::MeshCheck) -> String {
    let yes = |b: bool| if b { "yes" } else { "NO" };
    let genus = c.genus.map_or("n/a".to_string(), |g| g.to_string());
    let first = if c.self_intersections > 0 { format!(" (first: {:?})", c.intersecting_pairs) } else { String::new() };
    format!(
        "{name}: {} faces, {} vertices, {} edges, {} component(s), genus {genus}, volume {}\n  closed: {} ({} boundary edges, {} edges with more than two faces)\n  manifold: {} ({} non-manifold vertices)\n  oriented: {} ({} inconsistent edges)\n  self-intersecting face pairs: {}{first}\n  degenerate faces: {}\n  watertight: {}",
        c.faces, c.vertices, c.edges, c.components, c.volume,
        yes(c.closed()), c.boundary_edges, c.non_manifold_edges,
        yes(c.manifold()), c.non_manifold_vertices,
        yes(c.oriented()), c.inconsistent_edges,
        c.self_intersections, c.degenerate_faces,
        yes(c.watertight()),
    )
}

/// The voxels, read densely or (past memory, or with `--sparse`) as bricks.
enum Voxels {
    Dense(topovox_io::LoadedVoxels),
    Sparse(topovox_io::SparseVoxels),
}

fn text(v: &Value, a: &CheckArgs) -> String {
    let yes_no = |b: &Value| match b.as_bool() {
        Some(true) => "yes",
        Some(false) => "NO",
        None => "n/a",
    };
    let mut s = format!(
        "{}: {} voxels on {}; components: {} (6-connected), {} (26-connected); thick voxels: {}",
        a.voxels.display(),
        v["voxels"],
        v["dims"],
        v["components_6"],
        v["components_26"],
        v["thick_voxels"]
    );
    if let Some(mesh) = &a.mesh {
        s += &format!("\nmesh {}: grid from {}", mesh.display(), v["grid"]["source"].as_str().unwrap_or("?"));
        if v["closed"].as_bool() == Some(true) {
            s += &format!(
                "\n  closed surface; {} voxel centres inside\n  6-separating: {}\n  26-separating: {}\n  removable keeping 6-separation: {}",
                v["inside_voxels"],
                yes_no(&v["separating_6"]),
                yes_no(&v["separating_26"]),
                v["thin_removable"]
            );
            for c in ["6", "26"] {
                if let Some(w) = v[format!("witness_{c}")].as_object() {
                    s += &format!("\n  {c}-leak: unset {c}-neighbours {} (inside) and {} (outside)", w["inside"], w["outside"]);
                }
            }
        } else {
            s += &format!("\n  not a closed surface ({} boundary edges, or no triangles): separation needs one", v["boundary_edges"]);
        }
        let c = &v["columns"];
        s += &format!(
            "\n  runs along each triangle's dominant axis at its columns: {} x1, {} x2, {} x3+ (max {}), {} holes",
            c["one"], c["two"], c["three_or_more"], c["max"], c["empty"]
        );
        s += &format!(
            "\n  6-tunnel-free: {} ({} tunnels)\n  18-tunnel-free: {} ({} tunnels)\n  26-tunnel-free: {} ({} tunnels)",
            yes_no(&v["tunnel_free_6"]),
            v["tunnels_6"],
            yes_no(&v["tunnel_free_18"]),
            v["tunnels_18"],
            yes_no(&v["tunnel_free_26"]),
            v["tunnels_26"]
        );
    }
    let how = match v["windows"].as_u64() {
        Some(n) => format!(" without a dense grid, in {n} window{}", if n == 1 { "" } else { "s" }),
        None => String::new(),
    };
    s + &format!("\nchecked{how} in {:.2} s", v["check_s"].as_f64().unwrap_or(0.0))
}
