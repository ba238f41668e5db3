//! What the GPU commands (`render --gpu`, `view`, `spray`) draw: meshes with
//! their materials and voxel files as greedy quads, spray clouds, cameras.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use topovox::glam::Vec3;
use topovox_view::{Camera, Scene};

use crate::values::CameraSpec;

/// Voxel quads' material: light grey, rough.
const VOXEL_COLOUR: [f32; 3] = [0.72, 0.72, 0.70];

/// Adds a voxel file's greedy quads, placed where the file says (else
/// voxel `(i, j, k)` at `(i, j, k)`), moved by `offset`.
pub fn add_voxel_file(scene: &mut Scene, path: &Path, up: Option<topovox_io::orient::Up>, offset: Vec3) -> Result<()> {
    let upname = up.unwrap_or_default();
    let loaded = topovox_io::read_voxels(path, &topovox_io::ReadOptions { up: upname, ..Default::default() })?;
    let (origin, size) = loaded.placement.map(|(o, s)| (o.as_vec3(), s.as_vec3())).unwrap_or((Vec3::ZERO, Vec3::ONE));
    add_voxels(scene, &loaded.bits, origin + offset, size);
    Ok(())
}

/// Adds voxels as greedy quads of one clay material.
pub fn add_voxels(scene: &mut Scene, bits: &topovox::grid::dense::DenseBits, origin: Vec3, size: Vec3) {
    let quads = topovox::export::greedy::greedy_quads(bits);
    let m = scene.add_material(topovox_view::scene::ShadeMaterial::new(VOXEL_COLOUR, [0.0; 3], 0.7));
    scene.add_quads(&quads, origin, size, m);
}

/// Loads a mesh with its materials, or a voxel file's greedy quads, as a
/// scene; the kind loaded ("mesh" or "voxel file"). None of `outputs` may
/// be a file the mesh reads.
pub fn load_scene(
    input: &Path,
    up: Option<topovox_io::orient::Up>,
    allow_external_paths: bool,
    outputs: &[PathBuf],
) -> Result<(Scene, &'static str)> {
    let mut scene = Scene::default();
    if topovox_io::is_voxel_file(input) {
        add_voxel_file(&mut scene, input, up, Vec3::ZERO)?;
        return Ok((scene, "voxel file"));
    }
    let loaded = topovox_io::read_mesh(input, &topovox_io::ReadOptions { allow_external_paths, ..Default::default() })?;
    for out in outputs {
        topovox_io::atomic::refuse_overwriting_inputs(out, &loaded.sources)?;
    }
    for w in &loaded.warnings {
        crate::console::warn(&format!("{}: {w}", input.display()));
    }
    scene.add_mesh(loaded.mesh.as_ref(), &loaded.appearance);
    Ok((scene, "mesh"))
}

/// Reads a spray cloud (`topovox spray`'s PLY).
pub fn read_points(path: &Path) -> Result<Vec<topovox_view::spray::SprayPoint>> {
    let bytes = topovox_io::read_regular(path).with_context(|| format!("{}: cannot read", path.display()))?;
    topovox_io::fenced(|| topovox_io::spray_cloud::read_ply(&bytes))
        .unwrap_or_else(|msg| Err(format!("the PLY parser crashed on it ({msg})")))
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// The renderer's camera of `--camera`, with the `--up` direction.
pub fn camera(c: CameraSpec, up: Vec3) -> Camera {
    Camera { eye: c.eye, target: c.target, up, fov_deg: c.fov_deg }
}

/// Checks that a spray cloud may be written to `path`: a `.ply` name in a
/// folder that exists.
pub fn check_cloud_path(path: &Path) -> Result<()> {
    if path.extension().and_then(|e| e.to_str()).map(|e| e.eq_ignore_ascii_case("ply")) != Some(true) {
        bail!("{}: spray clouds are written as PLY; give a .ply file name", path.display());
    }
    Ok(topovox_job::output::check_output_path(path)?)
}
