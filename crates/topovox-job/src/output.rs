//! Outputs: which format a path names, and writing voxels with their
//! attributes in it — every voxel format, and the mesh of the voxels
//! (`.obj`, `.glb`).

use std::path::Path;

use serde_json::{json, Value};
use topovox::attributes::{quantize, VoxelAttributes};
use topovox::export::greedy::{greedy_quads_by_class, Quad};
use topovox::{DenseBits, GridSpec, VoxelSource};
use topovox_io::{VoxelFormat, WriteOptions};

use crate::error::{JobError, Result};
use topovox::choice::Choice;

/// What an output file holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// A voxel format.
    Voxels(VoxelFormat),
    /// A mesh of the voxels (greedy quads).
    Mesh(MeshKind),
}

/// Mesh formats for the voxels' boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshKind {
    /// Wavefront OBJ (+ MTL with colours).
    Obj,
    /// Binary glTF.
    Glb,
}

impl Output {
    /// The `--format` name.
    pub fn name(self) -> &'static str {
        match self {
            Output::Voxels(f) => f.name(),
            Output::Mesh(MeshKind::Obj) => "obj",
            Output::Mesh(MeshKind::Glb) => "glb",
        }
    }

    /// True when the output stores colours.
    pub fn has_colour(self) -> bool {
        match self {
            Output::Voxels(f) => f.has_colour(),
            Output::Mesh(_) => true,
        }
    }

    /// The format called `name` (a voxel format, `obj` or `glb`).
    pub fn from_name(name: &str) -> Option<Output> {
        match name.to_ascii_lowercase().as_str() {
            "obj" => Some(Output::Mesh(MeshKind::Obj)),
            "glb" => Some(Output::Mesh(MeshKind::Glb)),
            n => VoxelFormat::from_name(n).map(Output::Voxels),
        }
    }

    /// Every output format name, for messages.
    pub fn names() -> String {
        <Output as Choice>::names().join(", ")
    }
}

/// `--format` and Python's `format=` are this choice: clap lists each
/// format with its line of help, Python's `topovox.FORMATS` is its names.
impl Choice for Output {
    const WHAT: &'static str = "format";
    const ALL: &'static [Output] = &[
        Output::Voxels(VoxelFormat::Npy),
        Output::Voxels(VoxelFormat::NpyBool),
        Output::Voxels(VoxelFormat::Npz),
        Output::Voxels(VoxelFormat::Binvox),
        Output::Voxels(VoxelFormat::Vox),
        Output::Voxels(VoxelFormat::Text),
        Output::Voxels(VoxelFormat::Schem),
        Output::Voxels(VoxelFormat::Vti),
        Output::Voxels(VoxelFormat::Ply),
        Output::Voxels(VoxelFormat::Vdb),
        Output::Voxels(VoxelFormat::Zarr),
        Output::Mesh(MeshKind::Obj),
        Output::Mesh(MeshKind::Glb),
    ];

    fn name(self) -> &'static str {
        Output::name(self)
    }

    fn help(self) -> &'static str {
        match self {
            Output::Voxels(VoxelFormat::Npy) => "NumPy array, uint8, (nx, ny, nz)",
            Output::Voxels(VoxelFormat::NpyBool) => "NumPy array, bool, (nx, ny, nz)",
            Output::Voxels(VoxelFormat::Npz) => "NumPy archive: the set voxels' indices and the grid (any size)",
            Output::Voxels(VoxelFormat::Binvox) => "binvox (cubes only)",
            Output::Voxels(VoxelFormat::Vox) => "MagicaVoxel, with colours (cubes only)",
            Output::Voxels(VoxelFormat::Text) => "text, one `i j k` line per set voxel",
            Output::Voxels(VoxelFormat::Schem) => "Minecraft Sponge schematic, with blocks by colour (cubes only)",
            Output::Voxels(VoxelFormat::Vti) => "VTK ImageData, with attribute arrays",
            Output::Voxels(VoxelFormat::Ply) => "PLY point cloud of voxel centres, with colours",
            Output::Voxels(VoxelFormat::Vdb) => "OpenVDB bool grid (sparse; --attributes adds attribute grids)",
            Output::Voxels(VoxelFormat::Zarr) => "Zarr v3 array, sharded (sparse; --attributes makes a group)",
            Output::Mesh(MeshKind::Obj) => "Wavefront OBJ mesh of the voxels (+ MTL with colours)",
            Output::Mesh(MeshKind::Glb) => "binary glTF mesh of the voxels",
        }
    }
}

/// The output format: `format` if given, else the extension of `output`.
pub fn output_format(format: Option<Output>, output: &Path) -> Result<Output> {
    match format {
        Some(f) => Ok(f),
        None => output.extension().and_then(|e| e.to_str()).and_then(Output::from_name).ok_or_else(|| {
            JobError::invalid(format!(
                "{}: cannot tell the output format from the extension (use one of: {}, or --format)",
                output.display(),
                Output::names()
            ))
        }),
    }
}

/// True for the formats written from the set voxels alone (no dense
/// buffer of the grid): `.vdb`, `.zarr` (only chunks holding voxels),
/// `.npz` (the voxels' indices), `.txt`, `.ply`.
pub fn is_sparse(target: Output) -> bool {
    matches!(target, Output::Voxels(VoxelFormat::Vdb | VoxelFormat::Zarr | VoxelFormat::Npz | VoxelFormat::Text | VoxelFormat::Ply))
}

/// Bytes the writer of `target` holds per non-empty 8³ brick while it
/// writes: `.vdb` gathers them into its tree (origin and mask, 76 bytes,
/// and its lower nodes: 80 measured on the bunny at 8192), `.zarr` into
/// shards (key and brick: 72); the others stream.
pub fn writer_bytes_per_brick(target: Output) -> u64 {
    match target {
        Output::Voxels(VoxelFormat::Vdb) => 80,
        Output::Voxels(VoxelFormat::Zarr) => 72,
        _ => 0,
    }
}

/// Refuses a target that cannot hold `grid`, before any work: a format
/// that only knows cubes for a grid of boxes, and a dense format for a grid
/// that cannot be dense in the memory the run may use (`max_memory`, else
/// nine tenths of what is available).
pub fn check_fits(target: Output, grid: &GridSpec, max_memory: Option<u64>) -> Result<()> {
    if let Some(why) = refuses(target, grid.voxel_size()) {
        return Err(JobError::invalid(why));
    }
    if let Some(why) = match target {
        Output::Voxels(f) => f.refuses_dims(grid.dims()),
        Output::Mesh(_) => None,
    } {
        return Err(JobError::invalid(why));
    }
    let budget = crate::memory::budget(max_memory);
    if is_sparse(target) || crate::memory::dense_fits(grid, budget) {
        return Ok(());
    }
    let [x, y, z] = grid.dims();
    Err(JobError::invalid(format!(
        "grid {x}x{y}x{z} cannot be held densely ({} at 1 bit per voxel, more than the {} this run may use) and .{} is a dense format; write .vdb (OpenVDB), .zarr (Zarr v3), .npz (NumPy indices), .txt or .ply, which hold only the set voxels",
        crate::memory::bytes(grid.dense_bytes()),
        crate::memory::bytes(budget),
        target.name()
    )))
}

/// Why `target` cannot store voxels of `size` (a cubes-only format and
/// boxes); `None` when it can.
pub fn refuses(target: Output, size: topovox::VoxelSize) -> Option<String> {
    match target {
        Output::Voxels(f) => f.refuses(size),
        Output::Mesh(_) => None,
    }
}

/// Every file writing `out` as `target` creates: the output, and for an
/// `.obj` the `.mtl` beside it (named after the output's stem).
pub fn files_written(out: &Path, target: Output) -> Vec<std::path::PathBuf> {
    let mut v = vec![out.to_path_buf()];
    if target == Output::Mesh(MeshKind::Obj) && out.as_os_str() != "-" {
        v.push(out.with_extension("mtl"));
    }
    v
}

/// Refuses, before anything is written, an output (or a file written beside
/// it) that is one of `inputs` by identity — the same file by any name,
/// link or hard link: one line naming both.
pub fn refuse_overwriting(out: &Path, target: Output, inputs: &[std::path::PathBuf]) -> Result<()> {
    refuse_overwriting_any(&files_written(out, target), inputs)
}

/// Refuses, before any work, when any of `outputs` is one of `inputs`.
pub fn refuse_overwriting_any(outputs: &[std::path::PathBuf], inputs: &[std::path::PathBuf]) -> Result<()> {
    for f in outputs {
        topovox_io::atomic::refuse_overwriting_inputs(f, inputs)?;
    }
    Ok(())
}

/// Checks, before any work, that `out` can be created: its folder exists
/// and it is not a folder itself (`-` is standard output).
pub fn check_output_path(out: &Path) -> Result<()> {
    if out.as_os_str() == "-" {
        return Ok(());
    }
    let dir = match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    // File errors, of the kinds the OS gives (Python: FileNotFoundError,
    // IsADirectoryError), not bad arguments.
    let cannot =
        |kind, why: String| JobError::Io(topovox_io::IoError::new(out, topovox_io::ErrorKind::Write(std::io::Error::new(kind, why))));
    if !dir.is_dir() {
        return Err(cannot(std::io::ErrorKind::NotFound, format!("directory {} does not exist", dir.display())));
    }
    let zarr = out.extension().is_some_and(|e| e.eq_ignore_ascii_case("zarr"));
    if out.is_dir() && !(zarr && out.join("zarr.json").is_file()) {
        return Err(cannot(std::io::ErrorKind::IsADirectory, "it is a directory".into()));
    }
    Ok(())
}

/// The greedy quads of `dense`, one class per palette entry when `attrs`
/// has colours (up to 255, quantized), with that palette: what a mesh of
/// the voxels is drawn from (`.obj`, `.glb`, Python's `greedy_mesh`).
pub fn palette_quads(dense: &DenseBits, attrs: Option<&VoxelAttributes>) -> (Option<Vec<[u8; 3]>>, Vec<Quad>) {
    match attrs.and_then(|a| a.colour.as_ref().map(|c| (a, c))) {
        Some((a, colours)) => {
            let palette = quantize::palette(colours, 255);
            let index = quantize::map_to_palette(colours, &palette);
            let class = move |i: u32, j: u32, k: u32| a.slot(i, j, k).map(|s| index[s] as u32 + 1).unwrap_or(0);
            (Some(palette), greedy_quads_by_class(dense, &class))
        }
        None => (None, topovox::export::greedy::greedy_quads(dense)),
    }
}

/// Writes `bits` (with `attrs`) to `out` as `target`; returns facts for
/// the summaries. A dense format (or a mesh of the voxels) for a grid that
/// cannot be held densely is refused before anything is written
/// ([`check_fits`]), whichever front end asks. Once `opts.stop` is
/// requested the result is [`JobError::Interrupted`] and `out` is left as
/// it was.
pub fn write(
    out: &Path,
    target: Output,
    bits: &dyn VoxelSource,
    grid: &GridSpec,
    attrs: Option<&VoxelAttributes>,
    opts: &WriteOptions,
) -> Result<Value> {
    let stopped = || opts.stop.as_ref().is_some_and(|s| s.requested());
    let written = (|| -> Result<Value> {
        check_fits(target, grid, None)?;
        match target {
            Output::Voxels(f) => {
                topovox_io::write_voxels_with(out, f, bits, grid, attrs, opts)?;
                Ok(json!({"colours": attrs.and_then(|a| a.colour.as_ref()).is_some() && f.has_colour()}))
            }
            Output::Mesh(kind) => {
                let mut dense = DenseBits::new(bits.dims());
                bits.for_each_set(&mut |i, j, k| dense.set(i, j, k));
                let (palette, quads) = palette_quads(&dense, attrs);
                if stopped() {
                    return Err(JobError::Interrupted);
                }
                let vertices = match kind {
                    MeshKind::Obj => topovox_io::voxel_mesh::write_quads_obj(out, &quads, grid, palette.as_deref(), &opts.mesh)?,
                    MeshKind::Glb => topovox_io::voxel_mesh::write_quads_glb(out, &quads, grid, palette.as_deref(), &opts.mesh)?,
                };
                Ok(json!({"quads": quads.len(), "vertices": vertices, "colours": palette.as_ref().map(|p| p.len()),
                "watertight": opts.mesh.watertight, "triangulated": opts.mesh.triangulate}))
            }
        }
    })();
    // A write that failed because the stop was requested is an interruption.
    match written {
        Err(_) if stopped() => Err(JobError::Interrupted),
        r => r,
    }
}
