//! A voxelize job in the two steps every front end takes.
//! [`Voxelizer::new`] does each check that needs no mesh (the plan) and
//! [`Voxelizer::make`] the rest on a loaded mesh: the voxels and the one
//! attribute rule ([`Keep::wants`]). Python's `voxelize` and
//! `voxelize_many`, which write nothing, call those two.
//! [`VoxelizeJob`] wraps them for a file: [`VoxelizeJob::prepare`] adds the
//! output's checks (its folder, outputs that are inputs, the writer's
//! options) and [`VoxelizeJob::run`] the files the mesh led to, whether the
//! format can hold the fitted grid, and the write; `topovox voxelize` and
//! `topovox batch` run it.
//! [`SdfJob`] is the same two steps for distance fields (`topovox sdf`,
//! `topovox batch --run sdf`).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use serde_json::Value;
use topovox::attributes::VoxelAttributes;
use topovox::voxelize::{Progress, Stop};
use topovox_io::LoadedMesh;

use crate::error::Result;
use crate::options::JobOptions;
use crate::output::Output;
use crate::plan::Plan;
use crate::run::Voxelized;

/// Where a job's grid goes, which decides the attributes it carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Keep {
    /// Written in `format`, with a preview picture when `preview`.
    File {
        /// The output format.
        format: Output,
        /// A picture of the result is drawn too (it shows colours).
        preview: bool,
    },
    /// Kept in memory (Python): every array when the options ask for any
    /// (attributes or normals), or when `also` (a caller's own need, such
    /// as `voxelize_many`'s feature columns).
    Memory {
        /// Carry every array even when the options ask for none.
        also: bool,
    },
}

impl Keep {
    /// The one attribute rule: whether a grid kept this way carries
    /// attributes, given what the options `asked` (`attributes` for files,
    /// any attribute for memory) and whether the mesh `has_colour`. A file
    /// carries colours where its format stores them (or its preview shows
    /// them) and the mesh has them, every array for `.vti`, and for `.vdb`
    /// and `.zarr` when asked.
    pub fn wants(self, asked: bool, has_colour: bool) -> bool {
        match self {
            Keep::File { format, preview } => {
                (has_colour && (format.has_colour() || preview)) || crate::run::every_attribute(format, asked)
            }
            Keep::Memory { also } => asked || also,
        }
    }
}

/// A voxelize job's plan and attribute options, checked before any mesh
/// is read; what every front end shares.
#[derive(Clone, Debug)]
pub struct Voxelizer {
    /// The validated plan.
    pub plan: Plan,
    options: JobOptions,
}

/// What [`Voxelizer::make`] made.
pub struct Made {
    /// The voxels and the facts of their making.
    pub voxels: Voxelized,
    /// The attributes carried, when the rule wanted them.
    pub attributes: Option<VoxelAttributes>,
    /// Seconds carrying attributes.
    pub attributes_s: f64,
}

impl Voxelizer {
    /// Checks the options (the plan).
    pub fn new(options: &JobOptions) -> Result<Voxelizer> {
        Ok(Voxelizer { plan: options.plan()?, options: options.clone() })
    }

    /// Voxelizes `loaded` (named `name` in messages) and carries the
    /// attributes `keep` wants; `stop` ends it early, `progress` hears of it.
    /// Runs on the current rayon pool.
    pub fn make(&self, loaded: &LoadedMesh, name: &str, keep: Keep, progress: Option<&dyn Progress>, stop: Option<&Stop>) -> Result<Made> {
        let reference = self.plan.surface_method == crate::plan::SurfaceMethod::Reference;
        progress.inspect(|p| p.phase(if reference { "voxelizing (reference, serial)" } else { "voxelizing" }));
        let voxels = crate::voxelize(&self.plan, loaded.mesh.as_ref(), name, progress, stop)?;
        progress.inspect(|p| p.phase("carrying colours into voxels"));
        let t = Instant::now();
        let attributes = self.carried(loaded, &voxels, keep)?;
        Ok(Made { voxels, attributes, attributes_s: t.elapsed().as_secs_f64() })
    }

    /// The attributes `keep` wants of `v`, the voxels made of `loaded`
    /// (none for the line modes); an error when they would not fit in
    /// memory.
    pub fn carried(&self, loaded: &LoadedMesh, v: &Voxelized, keep: Keep) -> Result<Option<VoxelAttributes>> {
        let asked = match keep {
            Keep::File { .. } => self.options.export.attributes,
            Keep::Memory { .. } => self.options.export.carries(),
        };
        if self.plan.is_line() || !keep.wants(asked, loaded.appearance.has_colour()) {
            return Ok(None);
        }
        crate::run::check_attributes_carried(&self.plan, v)?;
        Ok(crate::run::attributes(&self.plan, loaded.mesh.as_ref(), &loaded.appearance, v, &self.options.export.carry()))
    }
}

/// A voxelize job for a file, checked before any mesh is read.
#[derive(Clone, Debug)]
pub struct VoxelizeJob {
    /// The plan and the attribute rule.
    pub voxelizer: Voxelizer,
    /// The output format.
    pub format: Output,
    /// A picture of the result is also drawn (its colours are carried).
    pub preview: Option<PathBuf>,
    write: topovox_io::WriteOptions,
}

/// What [`VoxelizeJob::run`] made and wrote.
pub struct Done {
    /// The voxels, the attributes the output or the preview wanted, and
    /// the seconds carrying them.
    pub made: Made,
    /// What the writer reports (`.obj` faces, `.vox` models, …).
    pub export: Value,
    /// Seconds writing.
    pub write_s: f64,
}

impl VoxelizeJob {
    /// Checks everything that needs no mesh: the options, the output's
    /// folder, and that neither the output nor the preview is one of
    /// `inputs`.
    pub fn prepare(options: &JobOptions, out: &Path, format: Output, inputs: &[PathBuf], preview: Option<&Path>) -> Result<VoxelizeJob> {
        crate::output::check_output_path(out)?;
        crate::output::refuse_overwriting_any(&written(out, format, preview), inputs)?;
        VoxelizeJob::new(options, format, preview)
    }

    /// The job without the path checks of [`VoxelizeJob::prepare`] (a
    /// batch checks its outputs itself).
    pub fn new(options: &JobOptions, format: Output, preview: Option<&Path>) -> Result<VoxelizeJob> {
        let mut voxelizer = Voxelizer::new(options)?;
        let request = &mut voxelizer.plan.request;
        if let Some(why) = request.grid.boxes().and_then(|s| crate::output::refuses(format, s)) {
            return Err(crate::error::JobError::invalid(why));
        }
        request.writer_bytes_per_brick = crate::output::writer_bytes_per_brick(format);
        let write = options.export.write_options()?;
        Ok(VoxelizeJob { voxelizer, format, preview: preview.map(Path::to_path_buf), write })
    }

    /// The validated plan.
    pub fn plan(&self) -> &Plan {
        &self.voxelizer.plan
    }

    /// Voxelizes `loaded` (named `name` in messages) and writes `out`;
    /// `stop` ends it early (nothing is written), `progress` hears of it.
    pub fn run(
        &self,
        out: &Path,
        loaded: &LoadedMesh,
        name: &str,
        progress: Option<&dyn Progress>,
        stop: Option<&Arc<Stop>>,
    ) -> Result<Done> {
        // Nor any file the mesh led to (its .mtl, textures, buffers).
        crate::output::refuse_overwriting_any(&written(out, self.format, self.preview.as_deref()), &loaded.sources)?;
        // A dense format for a grid past memory is refused before any work.
        let fitted = self.plan().request.grid.fit(&loaded.mesh.as_ref().bounds())?;
        crate::output::check_fits(self.format, &fitted, self.plan().request.max_memory)?;
        let keep = Keep::File { format: self.format, preview: self.preview.is_some() };
        let made = self.voxelizer.make(loaded, name, keep, progress, stop.map(|s| &**s))?;
        progress.inspect(|p| p.phase("writing"));
        let t = Instant::now();
        let write = topovox_io::WriteOptions { stop: stop.cloned(), ..self.write.clone() };
        let v = &made.voxels;
        let export = crate::output::write(out, self.format, &v.voxels, &v.grid, made.attributes.as_ref(), &write)?;
        Ok(Done { made, export, write_s: t.elapsed().as_secs_f64() })
    }
}

/// Every file a voxelize run writes for `out` in `format`: the output's
/// (a `.obj`'s `.mtl`, …) and the `preview`.
fn written(out: &Path, format: Output, preview: Option<&Path>) -> Vec<PathBuf> {
    crate::output::files_written(out, format).into_iter().chain(preview.map(Path::to_path_buf)).collect()
}

/// A distance-field job checked before any mesh is read.
#[derive(Clone, Debug)]
pub struct SdfJob {
    /// The validated request (grid, band, sign, the format it is written in).
    pub request: crate::distance::SdfRequest,
}

/// What [`SdfJob::run`] made and wrote.
pub struct SdfDone {
    /// The field and the facts of its making.
    pub sdf: crate::distance::Sdf,
    /// Seconds making it (the sign and the distances).
    pub sdf_s: f64,
    /// Seconds writing.
    pub write_s: f64,
}

impl SdfJob {
    /// Checks everything that needs no mesh: the options, the output's
    /// folder, and that the output is none of `inputs`.
    pub fn prepare(
        options: &crate::distance::SdfOptions,
        out: &Path,
        format: crate::distance::DistanceFormat,
        inputs: &[PathBuf],
    ) -> Result<SdfJob> {
        let job = SdfJob { request: options.request(format)? };
        crate::output::check_output_path(out)?;
        topovox_io::atomic::refuse_overwriting_inputs(out, inputs)?;
        Ok(job)
    }

    /// The field of `loaded` (named `name` in messages), written to `out`;
    /// `stop` ends it early (nothing is written).
    pub fn run(
        &self,
        out: &Path,
        loaded: &LoadedMesh,
        name: &str,
        progress: Option<&dyn Progress>,
        stop: Option<&Stop>,
    ) -> Result<SdfDone> {
        topovox_io::atomic::refuse_overwriting_inputs(out, &loaded.sources)?;
        progress.inspect(|p| p.phase("computing distances"));
        let t = Instant::now();
        let sdf = crate::distance::sdf(loaded.mesh.as_ref(), name, &self.request, stop)?;
        let sdf_s = t.elapsed().as_secs_f64();
        progress.inspect(|p| p.phase("writing"));
        let t = Instant::now();
        crate::distance::write(out, self.request.format, &sdf, stop)?;
        Ok(SdfDone { sdf, sdf_s, write_s: t.elapsed().as_secs_f64() })
    }
}
