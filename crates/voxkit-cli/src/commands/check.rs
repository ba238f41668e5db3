//! `voxkit check VOXELS [--mesh MESH]`: certify a voxel file's topology.

use std::time::Instant;

use anyhow::{bail, Context, Result};
use serde_json::{json, Value};
use voxkit::topology::certify;
use voxkit::GridSpec;

use crate::args::CheckArgs;
use crate::plan::GridRequest;

pub fn run(a: &CheckArgs) -> Result<()> {
    let t0 = Instant::now();
    let pool = crate::thread_pool(a.threads)?;
    let loaded = voxkit_io::read_voxels(&a.voxels)?;
    let dims = loaded.bits.dims();
    let g = &a.grid;
    let grid_given = g.resolution.is_some() || g.voxel_size.is_some() || g.origin.is_some() || g.dims.is_some() || g.pad.is_some();
    let mesh = match &a.mesh {
        Some(path) => {
            let m = voxkit_io::read_mesh(path)?;
            for w in &m.warnings {
                eprintln!("voxkit: warning: {}: {w}", path.display());
            }
            let bounds = m.report.bounds;
            let (grid, source) = if grid_given {
                (GridRequest::from_args(&a.grid)?.fit(&bounds)?, "options")
            } else if let Some((origin, s)) = loaded.placement {
                (GridSpec::new(origin, s, dims.map(u64::from)).context("invalid grid in the voxel file")?, "file")
            } else {
                let n = *dims.iter().max().unwrap_or(&1) as u64;
                (GridSpec::from_resolution(&bounds, n).context("invalid grid")?, "inferred")
            };
            if grid.dims() != dims {
                let [x, y, z] = grid.dims();
                bail!(
                    "{}: holds a {}x{}x{} grid but the {} grid for {} is {x}x{y}x{z}; pass the grid options used to voxelize it",
                    a.voxels.display(),
                    dims[0],
                    dims[1],
                    dims[2],
                    if source == "inferred" { "fitted" } else { source },
                    path.display()
                );
            }
            Some((m, grid, source))
        }
        None => None,
    };
    let report = pool.install(|| certify(&loaded.bits, mesh.as_ref().map(|(m, g, _)| (m.mesh.as_ref(), g))))?;
    let check_s = t0.elapsed().as_secs_f64();

    let facts = report.mesh.as_ref();
    let sep = facts.and_then(|f| f.separation.as_ref());
    let witness = |w: Option<[[u32; 3]; 2]>| w.map(|p| json!({"inside": p[0], "outside": p[1]}));
    let v = json!({
        "voxels": report.voxels,
        "dims": dims,
        "components_6": report.components_6,
        "components_26": report.components_26,
        "thick_voxels": report.thick_voxels,
        "closed": facts.map(|f| f.closed),
        "boundary_edges": facts.map(|f| f.boundary_edges),
        "separating_6": sep.map(|s| s.witness_6.is_none()),
        "separating_26": sep.map(|s| s.witness_26.is_none()),
        "witness_6": sep.and_then(|s| witness(s.witness_6)),
        "witness_26": sep.and_then(|s| witness(s.witness_26)),
        "inside_voxels": sep.map(|s| s.inside_voxels),
        "thin_removable": sep.map(|s| s.thin_removable),
        "tunnels_6": facts.map(|f| f.tunnels_6),
        "tunnels_26": facts.map(|f| f.tunnels_26),
        "tunnel_free_6": facts.map(|f| f.tunnels_6 == 0),
        "tunnel_free_26": facts.map(|f| f.tunnels_26 == 0),
        "columns": facts.map(|f| {
            let c = f.columns;
            json!({"samples": c.samples, "empty": c.empty, "one": c.one, "two": c.two, "three_or_more": c.more, "max": c.max})
        }),
        "grid": mesh.as_ref().map(|(_, g, source)| {
            let o = g.origin();
            json!({"origin": [o.x, o.y, o.z], "voxel_size": g.voxel_size(), "dims": g.dims(), "source": source})
        }),
        "check_s": check_s,
    });
    if a.json {
        return crate::print_stdout(&v.to_string());
    }
    crate::print_stdout(&text(&v, a))
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
            "\n  6-tunnel-free: {} ({} tunnels)\n  26-tunnel-free: {} ({} tunnels)",
            yes_no(&v["tunnel_free_6"]),
            v["tunnels_6"],
            yes_no(&v["tunnel_free_26"]),
            v["tunnels_26"]
        );
    }
    s + &format!("\nchecked in {:.2} s", v["check_s"].as_f64().unwrap_or(0.0))
}
