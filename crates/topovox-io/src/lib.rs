//! # topovox-io
//!
//! Readers for triangle meshes (OBJ with MTL and textures, STL, PLY,
//! glTF/GLB), polylines (`.lines`, OBJ `l`) and SVG outlines, and writers
//! and readers for voxel grids: NumPy `.npy` and `.npz`, binvox,
//! MagicaVoxel `.vox`, Minecraft `.schem`, text, VTK `.vti`, PLY point
//! clouds, OpenVDB `.vdb`, Zarr v3, and meshes of the voxels (`.obj`,
//! `.glb`); PNG pictures. One file per format. Every failure is an [`IoError`] naming the file and
//! the problem; no reader panics on malformed input (the third-party
//! parsers are additionally fenced with `catch_unwind`).
//!
//! **Architecture Invariant:** outputs are written to a temporary file in the
//! destination directory and renamed into place, so a failure never leaves a
//! half-written file ([`atomic::write_atomically`]).

pub mod atomic;
pub mod binvox;
pub mod error;
mod former_name;
pub mod gltf;
pub mod mesh_report;
pub mod npy;
pub mod npz;
pub mod obj;
pub mod off;
pub mod orient;
pub mod pixels;
pub mod ply;
pub mod png;
pub mod points;
pub mod polyline;
mod resources;
pub mod schem;
pub mod spray_cloud;
pub mod stl;
pub mod svg;
pub mod text;
pub mod texture;
pub mod vdb;
pub mod vox;
pub mod voxel_mesh;
pub mod vti;
pub mod zarr;

use std::path::Path;

pub use error::{ErrorKind, IoError};
pub use mesh_report::{validate_mesh, LoadedMesh, MeshReport};
pub use png::{write_png, write_png_rgba};
pub use resources::ReadOptions;
use topovox::attributes::VoxelAttributes;
use topovox::{DenseBits, GridSpec, VoxelSource};

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
/// files it names are read only from inside its folder.
pub fn read_mesh(path: &Path) -> Result<LoadedMesh, IoError> {
    read_mesh_with(path, &ReadOptions::default())
}

/// [`read_mesh`] with options (external paths allowed or not). The
/// result's `sources` lists the mesh file and every file it led to.
pub fn read_mesh_with(path: &Path, opts: &ReadOptions) -> Result<LoadedMesh, IoError> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    let format = MeshFormat::from_extension(ext).ok_or_else(|| {
        IoError::new(path, ErrorKind::UnknownFormat { ext: ext.to_string(), expected: "obj, stl, ply, gltf, glb, off, lines" })
    })?;
    let bytes = std::fs::read(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let res = resources::Resources::new(Some(base), opts);
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

thread_local! {
    static FENCED: std::cell::Cell<u32> = const { std::cell::Cell::new(0) };
}

/// True while this thread runs a third-party parser inside the panic fence: a
/// panic hook can stay silent, since the panic becomes an ordinary error.
pub fn panic_is_fenced() -> bool {
    FENCED.with(|f| f.get() > 0)
}

/// Runs a third-party parser so that a panic inside it (a bug in that
/// crate, triggered by malformed input) becomes an error naming the format
/// instead of aborting the program.
fn fence<T>(format: &'static str, f: impl FnOnce() -> Result<T, ErrorKind>) -> Result<T, ErrorKind> {
    fenced(f).unwrap_or_else(|msg| Err(ErrorKind::malformed(format, format!("the parser crashed on it ({msg})"))))
}

/// Runs `f` (a parser outside topovox-io, such as the spray cloud's) inside
/// the panic fence: a panic becomes `Err` with its message, and the panic
/// hook stays silent ([`panic_is_fenced`]).
pub fn fenced<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    FENCED.with(|c| c.set(c.get() + 1));
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    FENCED.with(|c| c.set(c.get() - 1));
    r.map_err(|p| {
        p.downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown cause".into())
    })
}

/// Voxel file formats topovox writes and reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VoxelFormat {
    /// NumPy `.npy`, dtype uint8, shape (nx, ny, nz).
    Npy,
    /// NumPy `.npy`, dtype bool, shape (nx, ny, nz).
    NpyBool,
    /// binvox (cube of side max(dims), run-length encoded).
    Binvox,
    /// MagicaVoxel `.vox`, split into models of at most 256³.
    Vox,
    /// Plain text: one `i j k` line per set voxel.
    Text,
    /// Minecraft Sponge schematic (version 2).
    Schem,
    /// VTK ImageData (XML, appended, zlib).
    Vti,
    /// PLY point cloud of voxel centres.
    Ply,
    /// OpenVDB bool grid (sparse; see [`vdb`]).
    Vdb,
    /// Zarr v3 array, a directory of gzip chunks (see [`zarr`]).
    Zarr,
    /// NumPy `.npz`: the set voxels' `(k, 3)` indices and the grid (see [`npz`]).
    Npz,
}

impl VoxelFormat {
    /// Whether [`read_voxels_sparse`] reads this format without a dense
    /// grid (`.vdb`, `.zarr`, `.npz`).
    pub fn reads_sparsely(self) -> bool {
        matches!(self, VoxelFormat::Vdb | VoxelFormat::Zarr | VoxelFormat::Npz)
    }

    /// Names accepted by `--format`.
    pub const NAMES: &'static str = "npy, npy-bool, npz, binvox, vox, txt, schem, vti, ply, vdb, zarr";

    /// The format for a `--format` name or a file extension.
    pub fn from_name(name: &str) -> Option<VoxelFormat> {
        match name.to_ascii_lowercase().as_str() {
            "npy" => Some(VoxelFormat::Npy),
            "npy-bool" | "npy_bool" => Some(VoxelFormat::NpyBool),
            "binvox" => Some(VoxelFormat::Binvox),
            "vox" => Some(VoxelFormat::Vox),
            "txt" | "text" | "xyz" => Some(VoxelFormat::Text),
            "schem" => Some(VoxelFormat::Schem),
            "vti" => Some(VoxelFormat::Vti),
            "ply" => Some(VoxelFormat::Ply),
            "vdb" => Some(VoxelFormat::Vdb),
            "zarr" => Some(VoxelFormat::Zarr),
            "npz" => Some(VoxelFormat::Npz),
            _ => None,
        }
    }

    /// The `--format` name of this format.
    pub fn name(self) -> &'static str {
        match self {
            VoxelFormat::Npy => "npy",
            VoxelFormat::NpyBool => "npy-bool",
            VoxelFormat::Binvox => "binvox",
            VoxelFormat::Vox => "vox",
            VoxelFormat::Text => "txt",
            VoxelFormat::Schem => "schem",
            VoxelFormat::Vti => "vti",
            VoxelFormat::Ply => "ply",
            VoxelFormat::Vdb => "vdb",
            VoxelFormat::Zarr => "zarr",
            VoxelFormat::Npz => "npz",
        }
    }

    /// True when the format only knows cubic voxels (`.binvox`, `.vox`,
    /// `.schem`): it refuses a grid of boxes.
    pub fn cubes_only(self) -> bool {
        matches!(self, VoxelFormat::Binvox | VoxelFormat::Vox | VoxelFormat::Schem)
    }

    /// The refusal of a grid of boxes by a [cubes-only](Self::cubes_only)
    /// format, naming the formats that keep a voxel size per axis; `None`
    /// when the format takes `size`.
    pub fn refuses(self, size: topovox::VoxelSize) -> Option<String> {
        (self.cubes_only() && size.cube().is_none()).then(|| {
            format!(
                ".{} stores cubic voxels only, and the voxel size {size} is not cubic; write .vti, .vdb, .zarr, .npz, .ply, .txt or .npy, which keep a voxel size per axis",
                self.name()
            )
        })
    }

    /// True when the format stores voxel colours.
    pub fn has_colour(self) -> bool {
        matches!(self, VoxelFormat::Vox | VoxelFormat::Schem | VoxelFormat::Vti | VoxelFormat::Ply)
    }

    /// The format for a path's extension.
    pub fn from_path(path: &Path) -> Option<VoxelFormat> {
        VoxelFormat::from_name(path.extension()?.to_str()?)
    }
}

/// Writes `bits` on `grid` to `path` atomically (temporary file + rename).
pub fn write_voxels(path: &Path, format: VoxelFormat, bits: &dyn VoxelSource, grid: &GridSpec) -> Result<(), IoError> {
    write_voxels_with(path, format, bits, grid, None, &WriteOptions::default())
}

/// Options of the coloured writers.
#[derive(Clone, Debug, Default)]
pub struct WriteOptions {
    /// `.vox`: error-diffusion dithering onto the palette (off: nearest entry).
    pub dither: bool,
    /// `.schem`: the colour → block table (default: the built-in one).
    pub blocks: Option<schem::BlockPalette>,
    /// `.vox` and `.schem`: the data's up axis, rotated to point up in
    /// MagicaVoxel and Minecraft (default y; see [`orient`]).
    pub up: orient::Up,
    /// `.obj` and `.glb` meshes of the voxels: watertight, triangles.
    pub mesh: voxel_mesh::MeshOptions,
    /// Once requested, the write fails and nothing is put in place (see
    /// [`atomic::write_atomically_until`]). Default: none.
    pub stop: Option<std::sync::Arc<topovox::voxelize::Stop>>,
}

/// [`write_voxels`] with per-voxel attributes (colours for `.vox`,
/// `.schem`, `.ply`; every array for `.vti`; ignored by the other formats).
pub fn write_voxels_with(
    path: &Path,
    format: VoxelFormat,
    bits: &dyn VoxelSource,
    grid: &GridSpec,
    attrs: Option<&VoxelAttributes>,
    opts: &WriteOptions,
) -> Result<(), IoError> {
    if let Some(why) = format.refuses(grid.size()) {
        return Err(IoError::new(path, ErrorKind::Unsupported(why)));
    }
    if format == VoxelFormat::Zarr {
        // A directory: built under a temporary name and renamed (see [`zarr`]).
        if matches!(atomic::target(path), atomic::Target::Stdout | atomic::Target::Special(_)) {
            return Err(IoError::new(
                path,
                ErrorKind::Write(std::io::Error::other("a Zarr array is a directory; give a path ending in .zarr")),
            ));
        }
        return zarr::write(path, bits, grid, attrs, opts.stop.as_deref());
    }
    atomic::write_atomically_until(path, opts.stop.as_deref(), |w| match format {
        VoxelFormat::Npy => npy::write(w, bits, npy::Dtype::U8),
        VoxelFormat::NpyBool => npy::write(w, bits, npy::Dtype::Bool),
        VoxelFormat::Binvox => binvox::write(w, bits, grid),
        VoxelFormat::Vox => vox::write(w, bits, attrs, opts.dither, opts.up),
        VoxelFormat::Text => text::write(w, bits, grid),
        VoxelFormat::Schem => schem::write(w, bits, attrs, opts.blocks.as_ref().unwrap_or(&schem::BlockPalette::default()), opts.up),
        VoxelFormat::Vti => vti::write(w, bits, grid, attrs),
        VoxelFormat::Ply => points::write(w, bits, grid, attrs),
        VoxelFormat::Vdb => vdb::write(w, bits, grid, attrs),
        VoxelFormat::Npz => npz::write(w, bits, grid),
        VoxelFormat::Zarr => unreachable!("Zarr arrays are written above"),
    })
}

/// A voxel size in JSON: one number for cubes (what files and scripts
/// written before boxes hold), `[sx, sy, sz]` for boxes.
pub fn size_json(size: topovox::VoxelSize) -> serde_json::Value {
    match size.cube() {
        Some(s) => serde_json::json!(s),
        None => serde_json::json!(size.to_array()),
    }
}

/// Reads [`size_json`]'s form back: a positive finite number, or three.
pub fn size_from_json(v: &serde_json::Value) -> Option<glam::DVec3> {
    let s = match v {
        serde_json::Value::Array(a) if a.len() == 3 => glam::DVec3::new(a[0].as_f64()?, a[1].as_f64()?, a[2].as_f64()?),
        v => glam::DVec3::splat(v.as_f64()?),
    };
    (s.is_finite() && s.min_element() > 0.0).then_some(s)
}

/// Half the diagonal of a voxel of `size`: an unsigned distance field
/// (`.vdb`, `.vti`, `.zarr`) is read back as the voxels whose value is at
/// most this, those whose centre lies in reach of a surface crossing them.
pub(crate) fn half_diagonal(size: glam::DVec3) -> f64 {
    0.5 * size.length()
}

/// A voxel grid read back from a file, with the grid placement when the
/// format stores it.
#[derive(Clone, Debug)]
pub struct LoadedVoxels {
    /// The voxels.
    pub bits: DenseBits,
    /// Origin and voxel size per axis, when the format carries them (binvox,
    /// text, vti, ply, npz, vdb, zarr).
    pub placement: Option<(glam::DVec3, glam::DVec3)>,
    /// Per-voxel attributes, when the format carries them (colours of
    /// `.vox`, `.schem` and `.ply`; every array of `.vti`).
    pub attributes: Option<VoxelAttributes>,
}

/// True when `path` names a voxel file (by extension; a `.ply` only when
/// it is a topovox point cloud — other PLY files are meshes).
pub fn is_voxel_file(path: &Path) -> bool {
    match VoxelFormat::from_path(path) {
        Some(VoxelFormat::Ply) => {
            let mut head = vec![0u8; 4096];
            let n = std::fs::File::open(path).and_then(|mut f| std::io::Read::read(&mut f, &mut head)).unwrap_or(0);
            points::is_voxel_cloud(&head[..n])
        }
        Some(_) => true,
        None => false,
    }
}

/// Reads any voxel file topovox writes, choosing the format from the extension.
pub fn read_voxels(path: &Path) -> Result<LoadedVoxels, IoError> {
    read_voxels_with(path, orient::Up::default())
}

/// [`read_voxels`], `.vox` and `.schem` files without a recorded up axis
/// being rotated back by `up` (see [`orient`]).
pub fn read_voxels_with(path: &Path, up: orient::Up) -> Result<LoadedVoxels, IoError> {
    read_voxels_opts(path, up, &ReadOptions::default())
}

/// [`read_voxels_with`]; `opts` says whether a voxel folder (`.zarr`) may
/// be read through links that lead outside it.
pub fn read_voxels_opts(path: &Path, up: orient::Up, opts: &ReadOptions) -> Result<LoadedVoxels, IoError> {
    let format = VoxelFormat::from_path(path).ok_or_else(|| {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_string();
        IoError::new(path, ErrorKind::UnknownFormat { ext, expected: VoxelFormat::NAMES })
    })?;
    if format == VoxelFormat::Zarr {
        return zarr::read(path, opts);
    }
    if matches!(format, VoxelFormat::Npy | VoxelFormat::NpyBool) {
        let file = std::fs::File::open(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
        let total = file.metadata().map_err(|e| IoError::new(path, ErrorKind::Read(e)))?.len();
        let mut r = std::io::BufReader::new(file);
        return npy::read_stream(&mut r, total).map_err(|k| IoError::new(path, k));
    }
    if format == VoxelFormat::Npz {
        // Streamed from the file: the index array is never held whole.
        let file = std::fs::File::open(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
        let total = file.metadata().map_err(|e| IoError::new(path, ErrorKind::Read(e)))?.len();
        return fence("voxel", || npz::read_from(std::io::BufReader::new(file), total)).map_err(|k| IoError::new(path, k));
    }
    let bytes = std::fs::read(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
    read_voxels_bytes_with(&bytes, format, up).map_err(|k| IoError::new(path, k))
}

/// Voxels read without a dense grid.
#[derive(Clone, Debug)]
pub struct SparseVoxels {
    /// The voxels, as sparse bricks (full regions as runs of full bricks).
    pub bits: topovox::grid::sparse::SparseBricks,
    /// Origin and voxel size per axis, when the file records them.
    pub placement: Option<(glam::DVec3, glam::DVec3)>,
    /// The file holds attributes that were not read (not asked for).
    pub attributes_left: bool,
    /// The attributes of the set voxels, when asked for and present.
    pub attributes: Option<VoxelAttributes>,
}

/// Reads a `.vdb` file, a `.zarr` array or a `.npz` of indices without a dense grid, for grids
/// that do not fit in memory densely ([`read_voxels`] refuses those with
/// [`ErrorKind::TooLarge`]): memory follows the set voxels. Other formats
/// are refused by name.
///
/// With `attributes`, the attribute grids or arrays of a `.vdb` or `.zarr`
/// written with `--attributes` are read too (about 32 bytes per set voxel).
pub fn read_voxels_sparse(path: &Path, attributes: bool) -> Result<SparseVoxels, IoError> {
    read_voxels_sparse_opts(path, attributes, &ReadOptions::default())
}

/// [`read_voxels_sparse`]; `opts` as for [`read_voxels_opts`].
pub fn read_voxels_sparse_opts(path: &Path, attributes: bool, opts: &ReadOptions) -> Result<SparseVoxels, IoError> {
    match VoxelFormat::from_path(path) {
        Some(VoxelFormat::Vdb) => {
            let bytes = std::fs::read(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
            fence("VDB", || vdb::read_sparse(&bytes, attributes)).map_err(|k| IoError::new(path, k))
        }
        Some(VoxelFormat::Zarr) => zarr::read_sparse(path, attributes, opts),
        Some(VoxelFormat::Npz) => {
            let file = std::fs::File::open(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
            let total = file.metadata().map_err(|e| IoError::new(path, ErrorKind::Read(e)))?.len();
            fence("NumPy .npz", || npz::read_sparse_from(std::io::BufReader::new(file), total)).map_err(|k| IoError::new(path, k))
        }
        _ => Err(IoError::new(path, ErrorKind::Unsupported("only .vdb, .zarr and .npz are read without a dense grid".into()))),
    }
}

/// Parses a voxel file from memory.
pub fn read_voxels_bytes(bytes: &[u8], format: VoxelFormat) -> Result<LoadedVoxels, ErrorKind> {
    read_voxels_bytes_with(bytes, format, orient::Up::default())
}

/// [`read_voxels_bytes`] with the up axis of `.vox` and `.schem` files that
/// do not record one.
pub fn read_voxels_bytes_with(bytes: &[u8], format: VoxelFormat, up: orient::Up) -> Result<LoadedVoxels, ErrorKind> {
    fence("voxel", || match format {
        VoxelFormat::Npy | VoxelFormat::NpyBool => npy::read(bytes),
        VoxelFormat::Binvox => binvox::read(bytes),
        VoxelFormat::Vox => vox::read(bytes, up),
        VoxelFormat::Text => text::read(bytes),
        VoxelFormat::Schem => schem::read(bytes, up),
        VoxelFormat::Vti => vti::read(bytes),
        VoxelFormat::Ply => points::read(bytes),
        VoxelFormat::Vdb => vdb::read(bytes),
        VoxelFormat::Npz => npz::read(bytes),
        VoxelFormat::Zarr => Err(ErrorKind::malformed("Zarr", "a Zarr array is a directory; read it by path")),
    })
}

/// Memory available to this process, from `/proc/meminfo` (None if unknown).
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Human-readable byte count.
pub fn bytes(n: u64) -> String {
    const U: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = n as f64;
    let mut u = 0;
    while v >= 1024.0 && u < U.len() - 1 {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{n} B")
    } else {
        format!("{v:.1} {}", U[u])
    }
}

/// The most memory a dense read may take, set by [`set_dense_read_budget`]
/// (0: nine tenths of the available memory).
static DENSE_READ_BUDGET: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// Caps the memory the readers may give a dense grid (the CLI's
/// `--max-memory`; a fuzzer's memory limit): a file claiming a larger
/// grid is refused with [`ErrorKind::TooLarge`], and callers that can
/// read it sparsely ([`read_voxels_sparse`]) do. `0` restores the default,
/// nine tenths of the available memory.
pub fn set_dense_read_budget(bytes: u64) {
    DENSE_READ_BUDGET.store(bytes, std::sync::atomic::Ordering::Relaxed);
}

/// A dense grid for a reader, refused when the file claims one that would
/// not fit in the memory a read may take (a hostile file of a few bytes
/// can claim billions of voxels; allocating them would abort the process).
pub(crate) fn dense_grid(dims: [u32; 3]) -> Result<topovox::DenseBits, ErrorKind> {
    // In u128: three u32 extents overflow u64.
    let need = u64::try_from((dims[0] as u128).div_ceil(64) * 8 * dims[1] as u128 * dims[2] as u128).unwrap_or(u64::MAX);
    let budget = DENSE_READ_BUDGET.load(std::sync::atomic::Ordering::Relaxed);
    // Small grids are never refused: reading /proc per file costs more.
    if need > 64 << 20 || (budget != 0 && need > budget) {
        let limit = read_limit();
        if need > limit {
            return Err(ErrorKind::TooLarge { dims, need: bytes(need), available: bytes(limit) });
        }
    }
    Ok(topovox::DenseBits::new(dims))
}

/// The memory one read may take: the budget [`set_dense_read_budget`] set
/// (`--max-memory`), at most nine tenths of the available memory (where
/// that cannot be read, 1 TiB stands for it).
pub(crate) fn read_limit() -> u64 {
    let budget = DENSE_READ_BUDGET.load(std::sync::atomic::Ordering::Relaxed);
    let avail = available_memory().unwrap_or(1 << 40) / 10 * 9;
    if budget == 0 {
        avail
    } else {
        budget.min(avail)
    }
}

/// Reads an SVG file's outlines (see [`svg`]).
pub fn read_svg(path: &Path, opts: &svg::SvgOptions) -> Result<svg::LoadedSvg, IoError> {
    let bytes = std::fs::read(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
    fence("SVG", || svg::read(&bytes, opts)).map_err(|k| IoError::new(path, k))
}

/// Consecutive runs of `items` with the same `key`.
pub(crate) fn runs<T, K: PartialEq>(items: &[T], key: impl Fn(&T) -> K) -> Vec<std::ops::Range<usize>> {
    let mut out = Vec::new();
    let mut s = 0;
    while s < items.len() {
        let k = key(&items[s]);
        let e = s + items[s..].iter().take_while(|x| key(x) == k).count();
        out.push(s..e);
        s = e;
    }
    out
}
