//! `topovox info MESH`.

use anyhow::Result;
use serde_json::json;

use crate::args::InfoArgs;

pub fn run(a: &InfoArgs) -> Result<()> {
    let loaded =
        topovox_io::read_mesh(&a.mesh, &topovox_io::ReadOptions { allow_external_paths: a.allow_external_paths, ..Default::default() })?;
    let r = &loaded.report;
    let (mn, mx) = (r.bounds.min, r.bounds.max);
    let app = &loaded.appearance;
    let with_uv = app.triangle_uv.iter().filter(|t| t.iter().flatten().all(|c| c.is_finite())).count();
    let materials: Vec<serde_json::Value> = app
        .materials
        .iter()
        .map(|m| {
            let tex = m.texture.and_then(|t| app.textures.get(t as usize));
            json!({"name": m.name, "factor": m.factor, "texture": tex.map(|t| json!({"name": t.name, "width": t.width, "height": t.height}))})
        })
        .collect();
    if a.json {
        let v = json!({
            "path": a.mesh.display().to_string(),
            "vertices": r.vertices,
            "triangles": r.triangles,
            "degenerate": r.degenerate,
            "bounds": { "min": [mn.x, mn.y, mn.z], "max": [mx.x, mx.y, mx.z] },
            "warnings": loaded.warnings,
            "appearance": {
                "materials": materials,
                "textures": app.textures.len(),
                "triangles_with_uv": with_uv,
                "vertex_colours": !app.vertex_colour.is_empty(),
            },
        });
        crate::console::print_stdout(&v.to_string())?;
    } else {
        for w in &loaded.warnings {
            crate::console::warn(&format!("{}: {w}", a.mesh.display()));
        }
        let e = r.bounds.extent();
        crate::console::print_stdout(&format!(
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
        let colour = if app.has_colour() { "carried into voxels" } else { "none" };
        crate::console::print_stdout(&format!(
            "  colour:     {colour} ({} materials, {} textures, {with_uv} triangles with UVs, vertex colours: {})",
            app.materials.len(),
            app.textures.len(),
            if app.vertex_colour.is_empty() { "no" } else { "yes" }
        ))?;
    }
    Ok(())
}
