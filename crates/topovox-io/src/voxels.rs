//! Voxel files by format: which writer or reader a file's extension
//! picks, dense and sparse reads, and the writers' options.

use std::path::Path;

use topovox::attributes::VoxelAttributes;
use topovox::{DenseBits, GridSpec, VoxelSource};

use crate::error::{ErrorKind, IoError};
use crate::fence::fence;
use crate::resources::{open_regular, read_regular, ReadOptions};
use crate::{atomic, binvox, npy, npz, orient, points, schem, text, vdb, vox, voxel_mesh, vti, zarr};

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

    /// Why the format cannot hold a grid of `dims`, whatever its voxels
    /// (a schematic's sides and block count); `None` when it can.
    pub fn refuses_dims(self, dims: [u32; 3]) -> Option<String> {
        match self {
            VoxelFormat::Schem => crate::schem::too_large(dims),
            _ => None,
        }
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
    if let Some(why) = format.refuses(grid.voxel_size()) {
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
            let n = open_regular(path).and_then(|(mut f, _)| std::io::Read::read(&mut f, &mut head)).unwrap_or(0);
            points::is_voxel_cloud(&head[..n])
        }
        Some(_) => true,
        None => false,
    }
}

/// Reads any voxel file topovox writes, choosing the format from the
/// extension. `opts.up`: the data's up axis, by which `.vox` and `.schem`
/// files that record none are rotated back (see [`orient`]);
/// `opts.allow_external_paths`: whether a voxel folder (`.zarr`) may be
/// read through links that lead outside it.
pub fn read_voxels(path: &Path, opts: &ReadOptions) -> Result<LoadedVoxels, IoError> {
    let format = VoxelFormat::from_path(path).ok_or_else(|| {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_string();
        IoError::new(path, ErrorKind::UnknownFormat { ext, expected: VoxelFormat::NAMES })
    })?;
    if format == VoxelFormat::Zarr {
        return zarr::read(path, opts);
    }
    if matches!(format, VoxelFormat::Npy | VoxelFormat::NpyBool) {
        let (file, total) = open_regular(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
        let mut r = std::io::BufReader::new(file);
        return npy::read_stream(&mut r, total).map_err(|k| IoError::new(path, k));
    }
    if format == VoxelFormat::Npz {
        // Streamed from the file: the index array is never held whole.
        let (file, total) = open_regular(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
        return fence("voxel", || npz::read_from(std::io::BufReader::new(file), total)).map_err(|k| IoError::new(path, k));
    }
    let bytes = read_regular(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
    read_voxels_bytes(&bytes, format, opts).map_err(|k| IoError::new(path, k))
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
/// With `opts.attributes`, the attribute grids or arrays of a `.vdb` or
/// `.zarr` written with `--attributes` are read too (about 32 bytes per set
/// voxel); `opts.allow_external_paths` as for [`read_voxels`].
pub fn read_voxels_sparse(path: &Path, opts: &ReadOptions) -> Result<SparseVoxels, IoError> {
    let attributes = opts.attributes;
    match VoxelFormat::from_path(path) {
        Some(VoxelFormat::Vdb) => {
            let bytes = read_regular(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
            fence("VDB", || vdb::read_sparse(&bytes, attributes)).map_err(|k| IoError::new(path, k))
        }
        Some(VoxelFormat::Zarr) => zarr::read_sparse(path, attributes, opts),
        Some(VoxelFormat::Npz) => {
            let (file, total) = open_regular(path).map_err(|e| IoError::new(path, ErrorKind::Read(e)))?;
            fence("NumPy .npz", || npz::read_sparse_from(std::io::BufReader::new(file), total)).map_err(|k| IoError::new(path, k))
        }
        _ => Err(IoError::new(path, ErrorKind::Unsupported("only .vdb, .zarr and .npz are read without a dense grid".into()))),
    }
}

/// Parses a voxel file from memory (`opts.up` as for [`read_voxels`]).
pub fn read_voxels_bytes(bytes: &[u8], format: VoxelFormat, opts: &ReadOptions) -> Result<LoadedVoxels, ErrorKind> {
    let up = opts.up;
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
