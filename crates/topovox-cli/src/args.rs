//! Raw command-line arguments (stage one of two: see `plan.rs`).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use topovox::raster::{RasterMethod, RasterMode};
use topovox_io::mesh_out::MeshOut;
use topovox_job::batch::Run;
use topovox_job::check::MeshProperty;
use topovox_job::distance::{DistanceFormat, SdfOptions};
use topovox_job::output::Output;
use topovox_job::remesh::RemeshOptions;
use topovox_job::sample::SampleOptions;
use topovox_job::{ColourRule, ExportOptions, GridOptions, JobOptions, Mode, Switch, Up};

use topovox::render::raycast::View;

use crate::choice::choice;
use crate::flags::{Flags, RunFlags, RunTable, Runs};
use crate::values::{self, CameraSpec, Size};

/// topovox: voxelize triangle meshes with guaranteed topology.
#[derive(Parser, Debug)]
#[command(name = "topovox", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Voxelize a mesh into a voxel file (.npy, .npz, .vdb, .zarr, .vox, .binvox, .schem, .vti, .ply, .txt) or a mesh of the voxels.
    Voxelize(VoxelizeArgs),
    /// Distance field of a mesh: the exact distance from each voxel centre to the
    /// mesh in a narrow band (or on every voxel), negative exactly where
    /// `voxelize --mode solid` sets voxels; to .vdb (an OpenVDB level set), .npy, .zarr or .vti.
    Sdf(SdfArgs),
    /// Watertight mesh of a mesh: closed, 2-manifold, oriented, without
    /// self-intersections, every part kept, around the voxels `voxelize --mode
    /// solid` sets (or, with --inside wrap, shells around any input); to .obj,
    /// .ply, .stl or .glb.
    Remesh(RemeshArgs),
    /// Training samples of a mesh: points on, near and around it with their
    /// exact signed distance (negative where `voxelize --mode solid` would
    /// call them inside) and occupancy, surface normals; to .npz.
    Sample(SampleArgs),
    /// Print a report of a mesh file: vertices, triangles, degenerate triangles, bounds.
    Info(InfoArgs),
    /// Benchmark voxelization (medians over repeats) on a mesh at several resolutions.
    Bench(BenchArgs),
    /// Certify a voxel file's topology: components, and with the source mesh
    /// separation (with a witness), thinness and tunnels.
    Check(CheckArgs),
    /// Compare a mode's voxels with reference modes on meshes: voxels
    /// missing and extra, and whether `check` certifies 6-separation (the
    /// gap table of the published `pos` algorithm).
    Gaps(GapsArgs),
    /// Render a voxel file or a mesh to a PNG picture (CPU ray casting; with
    /// --gpu, the GPU renderer: clusters, one multi-draw-indirect call, GPU
    /// frustum culling, light grid, Blinn–Phong).
    Render(RenderArgs),
    /// Open a window on a mesh (and its voxels) with the GPU renderer:
    /// orbit and fly camera, keys switching culling, prepass and gamma.
    View(ViewArgs),
    /// Write a bundled test scene (OBJ + MTL, textures as PNG beside): the
    /// Cornell box, a city of about a million triangles with 169 emissive
    /// street lamps and cut-out foliage, or the alpha test's three quads.
    Scene(SceneArgs),
    /// Spray rays from a camera into a mesh: each hit becomes a point with
    /// its albedo, emission and light term (Lambert term and attenuation
    /// towards light samples on the emissive triangles, shadow rays), saved
    /// as PLY and drawn by render --gpu --points and view --points.
    Spray(SprayArgs),
    /// Convert a voxel file to another voxel format, or to a mesh of the voxels (.obj, greedy quads).
    Convert(ConvertArgs),
    /// Voxelize whole datasets: one output per input mesh, a manifest of
    /// JSON lines, resumable, a bad mesh recorded without stopping the rest.
    Batch(BatchArgs),
    /// Rasterize an SVG's outlines in 2D with a connectivity guarantee
    /// (curve4, curve8, diamond) or fill them (nonzero rule).
    Raster(RasterArgs),
}

topovox::choice! {
    /// Extra baselines of `topovox bench`.
    pub enum Baseline: "baseline" {
        /// The brute-force loop: bounding box × f64 triangle/box test, one thread.
        Brute = "brute",
    }
}

#[derive(Args, Debug)]
pub struct VoxelizeArgs {
    /// Input mesh (.obj, .stl, .ply, .gltf, .glb, .off).
    pub mesh: PathBuf,
    /// Output file: .npy, .npz, .binvox, .vox, .txt, .schem, .vti, .ply,
    /// .vdb, .zarr (voxels), or .obj / .glb (a mesh of the voxels); the format comes from the
    /// extension unless --format is given. `-` writes to standard output
    /// (with --format).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    #[command(flatten)]
    pub job: Flags<JobOptions>,
    /// Output format (default: from the extension).
    #[arg(long, value_name = "FORMAT", value_parser = choice::<Output>())]
    pub format: Option<Output>,
    /// Also render the result to this PNG (see `topovox render` for --view, --size, --up, --outline).
    #[arg(long, value_name = "PNG")]
    pub preview: Option<PathBuf>,
    #[command(flatten)]
    pub picture: PictureArgs,
    /// Print one JSON object on stdout instead of the summary line.
    #[arg(long)]
    pub json: bool,
    /// No progress bar and no summary line.
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(Args, Debug)]
pub struct SdfArgs {
    /// Input mesh (.obj, .stl, .ply, .gltf, .glb, .off).
    pub mesh: PathBuf,
    /// Output file: .vdb (a float level set named `surface`, the band active), .npy
    /// (float32, every voxel), .zarr (float32, sharded) or .vti (a `distance` cell array).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    #[command(flatten)]
    pub sdf: Flags<SdfOptions>,
    /// Output format: vdb, npy, zarr or vti (default: from the extension).
    #[arg(long, value_name = "FORMAT", value_parser = choice::<DistanceFormat>())]
    pub format: Option<DistanceFormat>,
    /// Print one JSON object on stdout instead of the summary line.
    #[arg(long)]
    pub json: bool,
    /// No progress bar and no summary line.
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(Args, Debug)]
pub struct RemeshArgs {
    /// Input mesh (.obj, .stl, .ply, .gltf, .glb, .off).
    pub mesh: PathBuf,
    /// Output mesh: .obj or .ply (coordinates exact), .stl or .glb (float).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    #[command(flatten)]
    pub remesh: Flags<RemeshOptions>,
    /// Output format: obj, ply, stl or glb (default: from the extension).
    #[arg(long, value_name = "FORMAT", value_parser = choice::<MeshOut>())]
    pub format: Option<MeshOut>,
    /// Print one JSON object on stdout instead of the summary line.
    #[arg(long)]
    pub json: bool,
    /// No progress bar and no summary line.
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(Args, Debug)]
pub struct SampleArgs {
    /// Input mesh (.obj, .stl, .ply, .gltf, .glb, .off).
    pub mesh: PathBuf,
    /// Output: an .npz archive (points, sdf, occupancy, normals, kind, offset, scale, bounds).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    #[command(flatten)]
    pub sample: Flags<SampleOptions>,
    /// Print one JSON object on stdout instead of the summary line.
    #[arg(long)]
    pub json: bool,
    /// No progress bar and no summary line.
    #[arg(long, short)]
    pub quiet: bool,
}

/// How a picture is taken.
#[derive(Args, Debug, Clone)]
pub struct PictureArgs {
    /// Camera: iso, x, y, z (from that axis's positive side), or AZIMUTH,ELEVATION in degrees.
    #[arg(long, default_value = "iso", value_name = "VIEW", allow_hyphen_values = true, value_parser = values::view)]
    pub view: View,
    /// Picture size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768", value_name = "WxH", value_parser = values::size)]
    pub size: Size,
    /// Draw the outline of the source mesh's silhouette over the voxels (mesh inputs and --preview).
    #[arg(long)]
    pub outline: bool,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Read files the model names (OBJ material libraries and textures,
    /// glTF buffers and images) even outside its folder: absolute paths,
    /// `../`, links leading out. Off by default.
    #[arg(long)]
    pub allow_external_paths: bool,
    /// A voxel file (any format topovox writes) or a mesh (voxelized first, with --mode and the grid options).
    pub input: PathBuf,
    /// Output picture (.png).
    #[arg(short, long, value_name = "PNG")]
    pub output: PathBuf,
    #[command(flatten)]
    pub picture: PictureArgs,
    /// The axis drawn pointing up: x, y or z (default y: OBJ and glTF
    /// models are usually y-up). For .vox and .schem inputs, also the axis
    /// they were written with (`--up` of voxelize), unless they record it.
    #[arg(long, value_name = "x|y|z", value_parser = choice::<Up>())]
    pub up: Option<Up>,
    /// For a mesh: the surface mode to voxelize with.
    #[arg(long, value_parser = choice::<Mode>(), default_value = "cover")]
    pub mode: Mode,
    #[command(flatten)]
    pub grid: Flags<GridOptions>,
    /// For a mesh: how surface colours combine in a voxel (dominant or blend).
    #[arg(long, visible_alias = "color-rule", value_parser = choice::<ColourRule>(), default_value = "dominant", value_name = "RULE")]
    pub colour_rule: ColourRule,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Print one JSON object on stdout instead of the summary line.
    #[arg(long)]
    pub json: bool,
    /// No summary line.
    #[arg(long, short)]
    pub quiet: bool,
    #[command(flatten)]
    pub gpu: GpuRenderArgs,
}

/// The GPU renderer's options (`render --gpu`).
#[derive(Args, Debug)]
pub struct GpuRenderArgs {
    /// Draw the input itself (a mesh with its materials, or a voxel file's
    /// greedy quads) with the GPU renderer instead of ray casting voxels.
    #[arg(long)]
    pub gpu: bool,
    /// --gpu: camera eye, target and vertical field of view in degrees
    /// (default: the whole scene from above-front-right, 45°).
    #[arg(long, value_name = "EX,EY,EZ,TX,TY,TZ[,FOV]", allow_hyphen_values = true, value_parser = values::camera)]
    pub camera: Option<CameraSpec>,
    /// --gpu: cluster culling: none, frustum, occlusion (frustum, then
    /// Hi-Z occlusion against the depth of the frustum survivors), or
    /// occlusion-two-pass (the depth of the previous frame's clusters).
    #[arg(long, default_value = "occlusion", value_parser = choice::<topovox::render::Culling>())]
    pub culling: topovox::render::Culling,
    /// --gpu: a depth-only pass before shading.
    #[arg(long, default_value = "off", value_name = "on|off", value_parser = choice::<Switch>())]
    pub prepass: Switch,
    /// --gpu: colour surfaces by their light-grid cell's list length (blue:
    /// no light, red: the longest list) instead of shading them.
    #[arg(long, default_value = "off", value_name = "on|off", value_parser = choice::<Switch>())]
    pub light_grid: Switch,
    /// --gpu: linear to sRGB on output.
    #[arg(long, default_value = "on", value_name = "on|off", value_parser = choice::<Switch>())]
    pub gamma: Switch,
    /// --gpu: a camera path, one camera per line as for --camera (`#`
    /// starts a comment); frame N is written to OUT with `-NNNN` before
    /// the extension.
    #[arg(long, value_name = "FILE", conflicts_with = "camera")]
    pub frames: Option<PathBuf>,
    /// --gpu: render every frame this many times and report the median
    /// times (for measuring).
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub repeat: u32,
    /// --gpu: write the frame's statistics (clusters kept, triangles
    /// drawn, lights, light grid, the draw call, frame times) as JSON.
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,
    /// --gpu: also draw this point cloud of `topovox spray` (its stored
    /// light term, lit towards the viewer each frame).
    #[arg(long, value_name = "PLY")]
    pub points: Option<PathBuf>,
    /// --gpu: draw every cluster's box over the picture, green where the
    /// cluster was drawn, red where culling dropped it.
    #[arg(long, default_value = "off", value_name = "on|off", value_parser = choice::<Switch>())]
    pub boxes: Switch,
    /// --gpu: draw the scene's triangles (off: only the --points cloud).
    #[arg(long, default_value = "on", value_name = "on|off", value_parser = choice::<Switch>())]
    pub mesh: Switch,
}

/// `topovox spray`: rays from a camera into a scene, hits as a point cloud.
#[derive(Args, Debug)]
pub struct SprayArgs {
    /// Read files the model names (OBJ material libraries and textures,
    /// glTF buffers and images) even outside its folder. Off by default.
    #[arg(long)]
    pub allow_external_paths: bool,
    /// A mesh (with its materials; emissive ones are the lights) or a voxel file (its greedy quads).
    pub input: PathBuf,
    /// Output point cloud (.ply).
    #[arg(short, long, value_name = "PLY")]
    pub output: PathBuf,
    /// Rays cast (each hit is a point).
    #[arg(long, default_value_t = 1_000_000, value_name = "N")]
    pub rays: usize,
    /// Light samples per point, drawn uniformly over the emissive triangles.
    #[arg(long, default_value_t = 16, value_name = "K")]
    pub light_samples: u32,
    /// Shadow rays towards the light samples.
    #[arg(long, default_value = "on", value_name = "on|off", value_parser = choice::<Switch>())]
    pub shadows: Switch,
    /// Seed of the random rays and samples (the cloud is the same for a seed, whatever the thread count).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Camera eye, target and vertical field of view in degrees (default:
    /// the whole scene from above-front-right, 45°, as render --gpu).
    #[arg(long, value_name = "EX,EY,EZ,TX,TY,TZ[,FOV]", allow_hyphen_values = true, value_parser = values::camera)]
    pub camera: Option<CameraSpec>,
    /// The camera's picture, WIDTHxHEIGHT: rays fill its aspect.
    #[arg(long, default_value = "1280x720", value_name = "WxH", value_parser = values::size)]
    pub size: Size,
    /// The axis pointing up: x, y or z (default y).
    #[arg(long, value_name = "x|y|z", value_parser = choice::<Up>())]
    pub up: Option<Up>,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Print one JSON object on stdout instead of the summary line.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug)]
pub struct ViewArgs {
    /// Read files the model names (OBJ material libraries and textures,
    /// glTF buffers and images) even outside its folder. Off by default.
    #[arg(long)]
    pub allow_external_paths: bool,
    /// A mesh (drawn with its materials) or a voxel file (drawn as quads).
    pub input: PathBuf,
    /// Also draw this voxel file beside the mesh (or over it: --layout).
    #[arg(long, value_name = "FILE", conflicts_with = "mode")]
    pub voxels: Option<PathBuf>,
    /// Also voxelize the mesh with this surface mode (and the grid
    /// options) and draw the voxels beside it.
    #[arg(long, value_parser = choice::<Mode>())]
    pub mode: Option<Mode>,
    #[command(flatten)]
    pub grid: Flags<GridOptions>,
    /// Voxels beside the mesh (side) or in its place (overlay).
    #[arg(long, default_value = "side", value_parser = choice::<Layout>())]
    pub layout: Layout,
    /// Window size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_name = "WxH", value_parser = values::size)]
    pub size: Size,
    /// The axis pointing up: x, y or z (default y).
    #[arg(long, value_name = "x|y|z", value_parser = choice::<Up>())]
    pub up: Option<Up>,
    /// Starting camera: eye, target, vertical field of view in degrees.
    #[arg(long, value_name = "EX,EY,EZ,TX,TY,TZ[,FOV]", allow_hyphen_values = true, value_parser = values::camera)]
    pub camera: Option<CameraSpec>,
    /// Starting culling: none, frustum, occlusion or occlusion-two-pass (key C cycles).
    #[arg(long, default_value = "occlusion", value_parser = choice::<topovox::render::Culling>())]
    pub culling: topovox::render::Culling,
    /// Starting Z-prepass (key Z toggles).
    #[arg(long, default_value = "off", value_name = "on|off", value_parser = choice::<Switch>())]
    pub prepass: Switch,
    /// Starting gamma correction (key G toggles).
    #[arg(long, default_value = "on", value_name = "on|off", value_parser = choice::<Switch>())]
    pub gamma: Switch,
    /// Scripted run: close after N frames (with --screenshot, save the last).
    #[arg(long, value_name = "N")]
    pub frames: Option<u32>,
    /// With --frames: the last frame as PNG.
    #[arg(long, value_name = "PNG", requires = "frames")]
    pub screenshot: Option<PathBuf>,
    /// A point cloud of `topovox spray` to draw (key P adds to it).
    #[arg(long, value_name = "PLY")]
    pub points: Option<PathBuf>,
    /// On closing, write every point (given and sprayed) to this PLY.
    #[arg(long, value_name = "PLY")]
    pub save_points: Option<PathBuf>,
    /// Rays per spray at the cursor (key P, middle button).
    #[arg(long, default_value_t = 20_000, value_name = "N")]
    pub spray_rays: usize,
    /// Half-angle of the spray's cone in degrees.
    #[arg(long, default_value_t = 2.0, value_name = "DEG")]
    pub spray_degrees: f32,
    /// Print one JSON object on stdout when the window closes.
    #[arg(long)]
    pub json: bool,
    /// No summary line when the window closes.
    #[arg(long, short)]
    pub quiet: bool,
}

topovox::choice! {
    /// The bundled scenes of `topovox scene`.
    pub enum SceneName: "scene" {
        /// The Cornell box.
        Cornell = "cornell",
        /// A city of about a million triangles with 169 emissive street
        /// lamps and cut-out foliage.
        City = "city",
        /// Three quads, the front one cut out in a checkerboard: the alpha
        /// test's scene.
        CutOuts = "cut-outs",
    }
}

topovox::choice! {
    /// Where `view` draws the voxels.
    pub enum Layout: "layout" {
        /// Beside the mesh.
        Side = "side",
        /// In the mesh's place.
        Overlay = "overlay",
    }
}

#[derive(Args, Debug)]
pub struct SceneArgs {
    /// Which scene: cornell, city, or cut-outs (three quads, the front one
    /// cut out in a checkerboard: the alpha test's scene).
    #[arg(value_parser = choice::<SceneName>())]
    pub name: SceneName,
    /// Output OBJ; its MTL is written beside it with the same stem.
    #[arg(short, long, value_name = "OBJ")]
    pub output: PathBuf,
}

#[derive(Args, Debug)]
pub struct CheckArgs {
    /// Read files the model names (OBJ material libraries and textures,
    /// glTF buffers and images) even outside its folder: absolute paths,
    /// `../`, links leading out. Off by default.
    #[arg(long)]
    pub allow_external_paths: bool,
    /// Voxel file (any format topovox reads: .npy, .binvox, .vox, .vti,
    /// .vdb, .zarr, .npz, ...), or a mesh file alone (.obj, .stl, .off,
    /// .gltf, .glb, a .ply with faces): its certificate (closed, manifold,
    /// oriented, self-intersections, degenerate faces, components, genus,
    /// volume), each decided exactly.
    pub voxels: PathBuf,
    /// A mesh file: the properties it must have, else the exit status is 1
    /// (default: watertight, which is all of them).
    #[arg(long, value_name = "PROPS", value_delimiter = ',', value_parser = choice::<MeshProperty>())]
    pub require: Vec<MeshProperty>,
    /// The source mesh (a closed surface for the separation checks).
    #[arg(long)]
    pub mesh: Option<PathBuf>,
    /// The grid the voxels were made on, when the file does not carry it
    /// (npy, vox); without these the grid is inferred as the mesh's fitted
    /// grid at resolution = the largest dimension.
    #[command(flatten)]
    pub grid: Flags<GridOptions>,
    /// .vox and .schem files: the up axis they were written with (`--up` of
    /// voxelize; default y), when the file does not record it.
    #[arg(long, value_name = "x|y|z", value_parser = choice::<Up>())]
    pub up: Option<Up>,
    /// Check without a dense grid, window by window (.vdb, .zarr and .npz
    /// only; chosen by itself when the grid does not fit in memory densely).
    /// Same report.
    #[arg(long)]
    pub sparse: bool,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Read files the model names (OBJ material libraries and textures,
    /// glTF buffers and images) even outside its folder: absolute paths,
    /// `../`, links leading out. Off by default.
    #[arg(long)]
    pub allow_external_paths: bool,
    /// Input mesh.
    pub mesh: PathBuf,
    /// Print one JSON object.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Mesh to voxelize.
    #[arg(long, default_value = "../shared/meshes/stanford-bunny.obj")]
    pub mesh: PathBuf,
    /// Resolutions (longest side in voxels).
    #[arg(long, value_delimiter = ',', default_value = "128,256,512,1024")]
    pub resolutions: Vec<u64>,
    /// Modes to measure (surface and line modes).
    #[arg(long, value_delimiter = ',', value_parser = choice::<Mode>(), default_value = "cover")]
    pub modes: Vec<Mode>,
    /// Thread counts to measure.
    #[arg(long, value_delimiter = ',', default_value = "1,2")]
    pub threads: Vec<usize>,
    /// Repeats per measurement (the median is reported).
    #[arg(long, default_value_t = 9)]
    pub repeats: usize,
    /// Resolution at which the reference path is timed as the baseline.
    #[arg(long, default_value_t = 128)]
    pub reference_resolution: u64,
    /// A second baseline: `brute` times, at every resolution and in
    /// alternation with the measured paths, the brute-force loop a short C
    /// program would be (every voxel of each triangle's bounding box, the
    /// f64 triangle/box test, one thread), and adds a "vs brute" column.
    #[arg(long, value_parser = choice::<Baseline>())]
    pub baseline: Option<Baseline>,
    /// Split every triangle into four this many times before measuring
    /// (e.g. 2 turns the 69k-triangle bunny into 1.1M triangles).
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=5))]
    pub subdivide: u32,
    /// Also time carrying colours into the `cover` voxels (dominant and
    /// blend), a coloured 1024x768 picture and the .vox and .vti writers,
    /// against voxelization as the baseline (the mesh must have colours).
    #[arg(long)]
    pub attributes: bool,
    /// Time `cover` on the GPU (upload, GPU, download separately) against
    /// the CPU fast path as the baseline.
    #[arg(long)]
    pub gpu: bool,
    /// Print JSON lines instead of a Markdown table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug)]
pub struct GapsArgs {
    /// Meshes to compare on.
    #[arg(required = true)]
    pub meshes: Vec<PathBuf>,
    /// The mode under test.
    #[arg(long, value_parser = choice::<Mode>(), default_value = "pos")]
    pub mode: Mode,
    /// Modes it is compared against (voxels they set that it lacks).
    #[arg(long, value_delimiter = ',', value_parser = choice::<Mode>(), default_value = "sep6,cover")]
    pub against: Vec<Mode>,
    /// Resolutions (longest side in voxels).
    #[arg(long, value_delimiter = ',', default_value = "128,256,512,1024")]
    pub resolutions: Vec<u64>,
    /// Print JSON lines instead of a Markdown table.
    #[arg(long)]
    pub json: bool,
}

#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// Read a voxel folder (.zarr) through links that lead outside it. Off
    /// by default: a link inside the folder must stay inside.
    #[arg(long)]
    pub allow_external_paths: bool,
    /// Voxel file written by topovox (.npy, .npz, .binvox, .vox, .txt, .schem, .vti, .ply, .vdb, .zarr).
    pub input: PathBuf,
    /// Output voxel file, or `.obj` / `.glb` for a mesh of the voxels; the format comes from the extension unless --format is given.
    pub output: PathBuf,
    /// Output format (default: from the extension).
    #[arg(long, value_name = "FORMAT", value_parser = choice::<Output>())]
    pub format: Option<Output>,
    #[command(flatten)]
    pub export: Flags<ExportOptions>,
    /// Grid origin X,Y,Z for formats that record it (binvox, txt), when the input does not carry it (default 0,0,0).
    #[arg(long, value_delimiter = ',', value_name = "X,Y,Z", allow_hyphen_values = true)]
    pub origin: Option<Vec<f64>>,
    /// Voxel size (S, or SX,SY,SZ per axis) for formats that record it, when the input does not carry it (default 1).
    #[arg(long, value_name = "S|SX,SY,SZ", value_parser = crate::values::voxel_size)]
    pub voxel_size: Option<topovox::VoxelSize>,
    /// Print one JSON object on stdout instead of the summary line.
    #[arg(long)]
    pub json: bool,
    /// No summary line.
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(Args, Debug)]
pub struct BatchArgs {
    /// Input meshes, or folders searched (recursively) for them.
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output folder: each output mirrors its input's path below the
    /// inputs' common folder, with the format's extension; the manifest is
    /// `manifest.jsonl` in it.
    #[arg(short, long, value_name = "OUT_DIR")]
    pub output: PathBuf,
    /// Which files of the input folders to take, e.g. '**/*.obj' (default:
    /// every mesh extension topovox reads).
    #[arg(long, value_name = "PATTERN")]
    pub glob: Option<String>,
    /// Output format: with --run voxelize one of the voxelize formats
    /// (default npy), with --run sdf npy, vdb, zarr or vti (default npy),
    /// with --run remesh obj, ply, stl or glb (default obj).
    #[arg(long, value_name = "FORMAT", ignore_case = true, value_parser = clap::builder::PossibleValuesParser::new(batch_formats()))]
    pub format: Option<String>,
    /// What runs on each mesh: voxelize (the voxelize options), sdf (a
    /// distance field: the grid options, --band, --unsigned, --sign) or
    /// remesh (a watertight mesh: the grid options, --inside, --surface,
    /// --min-part, --check).
    #[arg(long, value_parser = choice::<Run>(), default_value = "voxelize")]
    pub run: Run,
    #[command(flatten)]
    pub options: RunFlags<BatchRuns>,
    /// Meshes processed at once (default: all cores); each is voxelized on the same threads.
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Print the summary as one JSON object.
    #[arg(long)]
    pub json: bool,
    /// No progress bar and no summary line.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Every format some run of `batch` writes (each run checks its own).
fn batch_formats() -> Vec<clap::builder::PossibleValue> {
    use topovox::choice::Choice;
    let mut names: Vec<&'static str> = Output::ALL.iter().map(|f| Choice::name(*f)).collect();
    for n in DistanceFormat::ALL.iter().map(|f| f.name()).chain(MeshOut::ALL.iter().map(|f| f.name())) {
        if !names.contains(&n) {
            names.push(n);
        }
    }
    names.into_iter().map(clap::builder::PossibleValue::new).collect()
}

/// The works `batch --run` chooses between, with their tables.
#[derive(Clone, Debug)]
pub struct BatchRuns;

impl Runs for BatchRuns {
    fn tables() -> Vec<RunTable> {
        use topovox::choice::Choice;
        vec![
            RunTable::of::<JobOptions>(Run::Voxelize.name()),
            RunTable::of::<SdfOptions>(Run::Sdf.name()),
            RunTable::of::<RemeshOptions>(Run::Remesh.name()),
            RunTable::of::<SampleOptions>(Run::Sample.name()),
        ]
    }
}

#[derive(Args, Debug)]
pub struct RasterArgs {
    /// Input SVG: <path>, <polyline>, <polygon>, <line>, <rect>, <circle>, <ellipse>.
    pub input: PathBuf,
    /// Output: .png (black on white) or .npy (uint8, shape (W, H), [i, j]).
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Rasterization mode.
    #[arg(long, value_parser = choice::<RasterMode>(), default_value = "curve8")]
    pub mode: RasterMode,
    /// Fit the grid so the longest side of the drawing spans N pixels (default 128).
    #[arg(long, value_name = "N")]
    pub resolution: Option<u64>,
    /// Pixel size in SVG user units; alone, fits the grid to the drawing.
    #[arg(long, value_name = "S")]
    pub pixel_size: Option<f64>,
    /// Explicit grid origin X,Y (with --pixel-size and --dims).
    #[arg(long, value_name = "X,Y", value_delimiter = ',', allow_hyphen_values = true)]
    pub origin: Option<Vec<f64>>,
    /// Explicit grid dims W,H (with --origin and --pixel-size).
    #[arg(long, value_name = "W,H", value_delimiter = ',')]
    pub dims: Option<Vec<u64>>,
    /// Curves and arcs are flattened until every chord lies within this
    /// distance of the curve (SVG user units; default 1e-5 of the drawing's extent).
    #[arg(long, value_name = "T")]
    pub tolerance: Option<f64>,
    /// `fast` (default) or `reference` (brute force from the definition; the same pixels).
    #[arg(long, default_value = "fast", value_parser = choice::<RasterMethod>())]
    pub method: RasterMethod,
    /// Print one JSON object on stdout instead of the summary line.
    #[arg(long)]
    pub json: bool,
}

#[cfg(test)]
mod tests {
    use clap::Parser;
    use topovox::render::Culling;
    use topovox_job::{Fill, GpuPath, Hollow, Method};

    use super::*;

    fn parse(args: &[&str]) -> Command {
        Cli::try_parse_from(std::iter::once("topovox").chain(args.iter().copied())).unwrap_or_else(|e| panic!("{args:?}: {e}")).command
    }

    #[test]
    fn flags_parse_into_their_types_in_any_case() {
        let Command::Voxelize(v) = parse(&[
            "voxelize",
            "m.obj",
            "-o",
            "o.npy",
            "--mode",
            "Solid",
            "--method",
            "WINDING",
            "--hollow",
            "26",
            "--fill",
            "flood",
            "--color-rule",
            "blend",
            "--up",
            "Z",
            "--watertight",
            "OFF",
            "--gpu-path",
            "msaa-approx",
            "--max-memory",
            "64M",
        ]) else {
            panic!("not voxelize")
        };
        let j = &v.job.options;
        assert_eq!((j.mode, j.method, j.hollow, j.fill), (Mode::Solid, Method::Winding, Some(Hollow::TwentySix), Some(Fill::Flood)));
        assert_eq!((j.export.colour_rule, j.export.up, j.export.watertight), (ColourRule::Blend, Up::Z, false));
        assert_eq!((j.gpu_path, j.run.max_memory), (GpuPath::MsaaApprox, Some(64 << 20)));
        assert!(v.job.given.contains(&"up") && !v.job.given.contains(&"resolution"));
        // Negative numbers, lists and a size per axis; sdf's band by name.
        let Command::Sdf(s) = parse(&[
            "sdf",
            "m.obj",
            "-o",
            "o.vdb",
            "--origin",
            "-1,-2.5,-3",
            "--dims",
            "4,5,6",
            "--voxel-size",
            "0.5,1,2",
            "--band",
            "all",
        ]) else {
            panic!("not sdf")
        };
        assert_eq!((s.sdf.grid.origin.clone(), s.sdf.grid.dims.clone()), (Some(vec![-1.0, -2.5, -3.0]), Some(vec![4, 5, 6])));
        assert_eq!((s.sdf.grid.voxel_size, s.sdf.field.band), (Some([0.5, 1.0, 2.0].into()), topovox_job::distance::Width::All));
        let Command::Render(r) =
            parse(&["render", "s.obj", "-o", "a.png", "--gpu", "--camera", "-5,2,3,0,0,0", "--culling", "Frustum", "--gamma", "off"])
        else {
            panic!("not render")
        };
        assert_eq!((r.gpu.culling, r.gpu.gamma), (Culling::Frustum, Switch::Off));
        assert_eq!(r.gpu.camera.unwrap().eye, glam::Vec3::new(-5.0, 2.0, 3.0));
        let Command::Raster(r) = parse(&["raster", "a.svg", "-o", "a.png", "--mode", "FILL", "--method", "reference"]) else {
            panic!("not raster")
        };
        assert_eq!((r.mode, r.method), (RasterMode::Fill, RasterMethod::Reference));
        let Command::Render(r) = parse(&["render", "v.npy", "-o", "a.png", "--view=-30,20", "--size", "64x48"]) else { panic!() };
        assert_eq!((r.picture.view, r.picture.size.width), (View::Angles(-30.0, 20.0), 64));
    }

    #[test]
    fn bad_values_are_refused_by_the_flag() {
        for args in [
            &["voxelize", "m.obj", "-o", "o.npy", "--mode", "cube"][..],
            &["voxelize", "m.obj", "-o", "o.npy", "--hollow", "7"],
            &["render", "s.obj", "-o", "a.png", "--up", "w"],
            &["render", "s.obj", "-o", "a.png", "--gpu", "--gamma", "maybe"],
            &["render", "s.obj", "-o", "a.png", "--gpu", "--camera", "1,2,3"],
            &["spray", "s.obj", "-o", "a.ply", "--size", "0x5"],
            &["voxelize", "m.obj", "-o", "o.npy", "--max-memory", "lots"],
            &["voxelize", "m.obj", "-o", "o.npy", "--resolution", "0"],
            &["voxelize", "m.obj", "-o", "o.npy", "--dims", "1,2"],
            &["sdf", "m.obj", "-o", "o.vdb", "--band", "-1"],
            &["batch", "in", "-o", "out", "--tile", "4"],
            &["batch", "in", "-o", "out", "--run", "remesh", "--min-part", "-1"],
            &["batch", "in", "-o", "out", "--surface", "round"],
        ] {
            assert!(Cli::try_parse_from(std::iter::once("topovox").chain(args.iter().copied())).is_err(), "{args:?}");
        }
    }
}
