//! Mesh files by format: which reader a file's extension picks, and the
//! readers run inside the panic fence; SVG outlines likewise.

use std::path::Path;

use crate::error::{ErrorKind, IoError};
use crate::fence::fence;
use crate::mesh_report::LoadedMesh;
use crate::resources::{self, ReadOptions};
use crate::{gltf, obj, off, ply, polyline, stl, svg};

/// Mesh file formats topovox reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (+ MTL).
    Obj,
    /// STL, ASCII or binary.
    Stl,
    /// PLY, ASCII or binary.
    Ply,
    /// glTF 2.0, JSON (`.gltf`) or binary (`.glb`).
    Gltf,
    /// Plain text polylines (`.lines`).
    Polyline,
    /// Object File Format (`.off`, ModelNet's), text.
    Off,
}

impl MeshFormat {
    /// The format for a file extension (case-insensitive), if known.
    pub fn from_extension(ext: &str) -> Option<MeshFormat> {
        match ext.to_ascii_lowercase().as_str() {
            "obj" => Some(MeshFormat::Obj),
            "stl" => Some(MeshFormat::Stl),
            "ply" => Some(MeshFormat::Ply),
            "gltf" | "glb" => Some(MeshFormat::Gltf),
            "lines" => Some(MeshFormat::Polyline),
            "off" => Some(MeshFormat::Off),
            _ => None,
        }
    }
}

/// Reads a mesh file, choosing the format from its extension; external
/// files it names are read only from inside its folder unless
/// `opts.allow_external_paths`. The result's `sources` lists the mesh file
/// and every file it led to.
pub fn read_mesh(path: &Path, opts: &ReadOptions) -> Result<LoadedMesh, IoError> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let format = MeshFormat::from_extension(ext).ok_or_else(|| {
        IoError::new(path, ErrorKind::UnknownFormat { ext: ext.to_string(), expected: "obj, stl, ply, gltf, glb, off, lines" })
    })?;
    let bytes = resources::read_regular_within(path, opts).map_err(|kind| IoError::new(path, kind))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let res = resources::Resources::new(Some(base), opts);
    crate::load_estimate::check(counted(format), &bytes, || res.read_limit()).map_err(|kind| IoError::new(path, kind))?;
    let mut loaded = read_with(&bytes, format, &res).map_err(|kind| IoError::new(path, kind))?;
    loaded.sources.push(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()));
    loaded.sources.extend(res.used());
    Ok(loaded)
}

/// Parses a mesh from memory. `base_dir` resolves relative references
/// (OBJ material libraries and textures, glTF external buffers and images),
/// inside that folder only; `None` disables them.
pub fn read_mesh_bytes(bytes: &[u8], format: MeshFormat, base_dir: Option<&Path>) -> Result<LoadedMesh, ErrorKind> {
    read_with(bytes, format, &resources::Resources::new(base_dir, &ReadOptions::default()))
}

/// How reading `format` is counted before parsing.
fn counted(format: MeshFormat) -> crate::load_estimate::Counted {
    use crate::load_estimate::Counted;
    match format {
        MeshFormat::Stl => Counted::Stl,
        MeshFormat::Ply => Counted::Ply,
        MeshFormat::Gltf => Counted::Gltf,
        MeshFormat::Obj | MeshFormat::Off | MeshFormat::Polyline => Counted::Lines,
    }
}

fn read_with(bytes: &[u8], format: MeshFormat, res: &resources::Resources) -> Result<LoadedMesh, ErrorKind> {
    let name = match format {
        MeshFormat::Obj => "OBJ",
        MeshFormat::Stl => "STL",
        MeshFormat::Ply => "PLY",
        MeshFormat::Gltf => "glTF",
        MeshFormat::Polyline => "polyline",
        MeshFormat::Off => "OFF",
    };
    fence(name, || match format {
        MeshFormat::Obj => obj::read(bytes, res),
        MeshFormat::Stl => stl::read(bytes),
        MeshFormat::Ply => ply::read(bytes),
        MeshFormat::Gltf => gltf::read(bytes, res),
        MeshFormat::Polyline => polyline::read(bytes),
        MeshFormat::Off => off::read(bytes),
    })
}
/// Reads an SVG file's outlines (see [`svg`]).
pub fn read_svg(path: &Path, opts: &svg::SvgOptions) -> Result<svg::LoadedSvg, IoError> {
    let bytes = resources::read_regular(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
    fence("SVG", || svg::read(&bytes, opts)).map_err(|k| IoError::new(path, k))
}

/// Whether `path` holds a triangle mesh rather than voxels: an OBJ, STL,
/// OFF or glTF file, or a PLY whose header declares faces (topovox writes
/// voxels as PLY points without faces). Reads at most the PLY's first 64 KiB.
pub fn is_mesh_file(path: &Path) -> bool {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    match MeshFormat::from_extension(&ext) {
        Some(MeshFormat::Ply) => ply_declares_faces(path),
        Some(MeshFormat::Polyline) | None => false,
        Some(_) => true,
    }
}

fn ply_declares_faces(path: &Path) -> bool {
    use std::io::Read;
    let mut head = Vec::new();
    let read = resources::open_regular(path).and_then(|(f, _)| f.take(64 << 10).read_to_end(&mut head));
    if read.is_err() {
        return false;
    }
    let text = String::from_utf8_lossy(&head);
    let header = text.split("end_header").next().unwrap_or("");
    header.lines().any(|l| {
        let w: Vec<&str> = l.split_whitespace().collect();
        matches!(w.as_slice(), ["element", "face" | "tristrips", n] if n.parse::<u64>().is_ok_and(|n| n > 0))
    })
}
