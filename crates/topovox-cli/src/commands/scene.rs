//! `topovox scene`: writes a bundled, deterministic test scene as OBJ + MTL.

use anyhow::{bail, Result};

use crate::args::{SceneArgs, SceneName};

pub fn run(a: &SceneArgs) -> Result<()> {
    let (mesh, app) = match a.name {
        SceneName::Cornell => topovox_view::scenes::cornell(),
        SceneName::City => topovox_view::scenes::city(),
        SceneName::CutOuts => topovox_view::scenes::cut_outs(),
    };
    if a.output.extension().and_then(|e| e.to_str()).map(|e| e.eq_ignore_ascii_case("obj")) != Some(true) {
        bail!("{}: scenes are written as OBJ; give a .obj file name", a.output.display());
    }
    topovox_job::output::check_output_path(&a.output)?;
    let mtl_path = a.output.with_extension("mtl");
    let mtl_name = mtl_path.file_name().and_then(|n| n.to_str()).unwrap_or("scene.mtl").to_string();
    // Textures as PNG beside the OBJ, named after it: STEM-NAME.png.
    let stem = a.output.file_stem().and_then(|s| s.to_str()).unwrap_or("scene").to_string();
    let texture_files: Vec<String> = app.textures.iter().map(|t| format!("{stem}-{}.png", t.name)).collect();
    let (obj, mtl) = topovox_view::scenes::to_obj(&mesh, &app, &mtl_name, &texture_files);
    for (t, file) in app.textures.iter().zip(&texture_files) {
        topovox_io::write_png_rgba(&a.output.with_file_name(file), t.width, t.height, &t.rgba)?;
    }
    // Both complete before either is in place, the .mtl first (see
    // topovox_io::atomic::Staged).
    let staged_mtl = topovox_io::atomic::stage(&mtl_path, |w| w.write_all(mtl.as_bytes()))?;
    let staged_obj = topovox_io::atomic::stage(&a.output, |w| w.write_all(obj.as_bytes()))?;
    staged_mtl.commit()?;
    staged_obj.commit()?;
    crate::console::print_stdout(&format!(
        "scene {}: {} triangles, {} materials, {} textures -> {} and {}",
        a.name,
        mesh.triangles.len(),
        app.materials.len(),
        texture_files.len(),
        a.output.display(),
        mtl_path.display()
    ))
}
