//! `voxkit scene`: writes a bundled, deterministic test scene as OBJ + MTL.

use anyhow::{bail, Result};

use crate::args::SceneArgs;

pub fn run(a: &SceneArgs) -> Result<()> {
    let (mesh, app) = match a.name.as_str() {
        "cornell" => voxkit_view::scenes::cornell(),
        "city" => voxkit_view::scenes::city(),
        other => bail!("unknown scene {other:?} (known: cornell, city)"),
    };
    if a.output.extension().and_then(|e| e.to_str()).map(|e| e.eq_ignore_ascii_case("obj")) != Some(true) {
        bail!("{}: scenes are written as OBJ; give a .obj file name", a.output.display());
    }
    voxkit_job::output::check_output_path(&a.output)?;
    let mtl_path = a.output.with_extension("mtl");
    let mtl_name = mtl_path.file_name().and_then(|n| n.to_str()).unwrap_or("scene.mtl").to_string();
    let (obj, mtl) = voxkit_view::scenes::to_obj(&mesh, &app, &mtl_name);
    voxkit_io::atomic::write_atomically(&mtl_path, |w| w.write_all(mtl.as_bytes()))?;
    voxkit_io::atomic::write_atomically(&a.output, |w| w.write_all(obj.as_bytes()))?;
    crate::print_stdout(&format!(
        "scene {}: {} triangles, {} materials -> {} and {}",
        a.name,
        mesh.triangles.len(),
        app.materials.len(),
        a.output.display(),
        mtl_path.display()
    ))
}
