//! `voxkit info MESH`.

use anyhow::Result;
use serde_json::json;

use crate::args::InfoArgs;

pub fn run(a: &InfoArgs) -> Result<()> {
    let loaded = voxkit_io::read_mesh(&a.mesh)?;
    let r = &loaded.report;
    let (mn, mx) = (r.bounds.min, r.bounds.max);
    if a.json {
        let v = json!({
            "path": a.mesh.display().to_string(),
            "vertices": r.vertices,
            "triangles": r.triangles,
            "degenerate": r.degenerate,
            "bounds": { "min": [mn.x, mn.y, mn.z], "max": [mx.x, mx.y, mx.z] },
            "warnings": loaded.warnings,
        });
        crate::print_stdout(&v.to_string())?;
    } else {
        for w in &loaded.warnings {
            eprintln!("voxkit: warning: {}: {w}", a.mesh.display());
        }
        let e = r.bounds.extent();
        crate::print_stdout(&format!(
            "{}\n  vertices:   {}\n  triangles:  {}\n  degenerate: {} (skipped when voxelizing)\n  bounds:     [{}, {}, {}] .. [{}, {}, {}]\n  extent:     {} x {} x {}",
            a.mesh.display(),
            r.vertices,
            r.triangles,
            r.degenerate,
            mn.x,
            mn.y,
            mn.z,
            mx.x,
            mx.y,
            mx.z,
            e.x,
            e.y,
            e.z
        ))?;
    }
    Ok(())
}
