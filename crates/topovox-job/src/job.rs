//! A voxelize job in the two steps every front end takes:
//! [`VoxelizeJob::prepare`] does each check that needs no mesh once (the
//! plan, the output's folder, outputs that are inputs, the writer's
//! options), and [`VoxelizeJob::run`] does the rest on a loaded mesh: the
//! files the mesh led to, whether the format can hold the fitted grid, the
//! voxels, the one attribute rule ([`crate::attributes_for`]) and the write.
//! `topovox voxelize` and `topovox batch` run it; Python's `voxelize`,
//! which writes nothing, runs the plan and the rule directly.
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

/// A voxelize job checked before any mesh is read.
#[derive(Clone, Debug)]
pub struct VoxelizeJob {
    /// The validated plan.
    pub plan: Plan,
    /// The output format.
    pub format: Output,
    /// A picture of the result is also drawn (its colours are carried).
    pub preview: Option<PathBuf>,
    options: JobOptions,
    write: topovox_io::WriteOptions,
}

/// What [`VoxelizeJob::run`] made and wrote.
pub struct Done {
    /// The voxels and the facts of their making.
    pub voxels: Voxelized,
    /// The attributes carried, when the output or the preview wanted them.
    pub attributes: Option<VoxelAttributes>,
    /// What the writer reports (`.obj` faces, `.vox` models, …).
    pub export: Value,
    /// Seconds carrying attributes.
    pub attributes_s: f64,
    /// Seconds writing.
    pub write_s: f64,
}

impl VoxelizeJob {
    /// Checks everything that needs no mesh: the options, the output's
    /// folder, and that neither the output nor the preview is one of
    /// `inputs`.
    pub fn prepare(options: &JobOptions, out: &Path, format: Output, inputs: &[PathBuf], preview: Option<&Path>) -> Result<VoxelizeJob> {
        crate::output::check_output_path(out)?;
        crate::output::refuse_overwriting(out, format, inputs)?;
        if let Some(p) = preview {
            topovox_io::atomic::refuse_overwriting_inputs(p, inputs)?;
        }
        VoxelizeJob::new(options, format, preview)
    }

    /// The job without the path checks of [`VoxelizeJob::prepare`] (a
    /// batch checks its outputs itself).
    pub fn new(options: &JobOptions, format: Output, preview: Option<&Path>) -> Result<VoxelizeJob> {
        let mut plan = options.plan()?;
        if let Some(why) = plan.request.grid.boxes().and_then(|s| crate::output::refuses(format, s)) {
            return Err(crate::error::JobError::invalid(why));
        }
        plan.request.writer_bytes_per_brick = crate::output::writer_bytes_per_brick(format);
        let write = options.export.write_options()?;
        Ok(VoxelizeJob { plan, format, preview: preview.map(Path::to_path_buf), options: options.clone(), write })
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
        crate::output::refuse_overwriting(out, self.format, &loaded.sources)?;
        if let Some(p) = &self.preview {
            topovox_io::atomic::refuse_overwriting_inputs(p, &loaded.sources)?;
        }
        // A dense format for a grid past memory is refused before any work.
        let fitted = self.plan.request.grid.fit(&loaded.mesh.as_ref().bounds())?;
        crate::output::check_fits(self.format, &fitted, self.plan.request.max_memory)?;
        let phase = |name| progress.inspect(|p| p.phase(name));
        let reference = self.plan.surface_method == crate::plan::SurfaceMethod::Reference;
        phase(if reference { "voxelizing (reference, serial)" } else { "voxelizing" });
        let v = crate::voxelize(&self.plan, loaded.mesh.as_ref(), name, progress, stop.map(|s| &**s))?;
        let t = Instant::now();
        phase("carrying colours into voxels");
        let asked = (self.preview.is_some(), self.options.export.attributes);
        let attributes = crate::run::attributes_for(&self.plan, loaded, &v, self.format, asked, &self.options.export.carry())?;
        let attributes_s = t.elapsed().as_secs_f64();
        phase("writing");
        let t = Instant::now();
        let write = topovox_io::WriteOptions { stop: stop.cloned(), ..self.write.clone() };
        let export = crate::output::write(out, self.format, &v.voxels, &v.grid, attributes.as_ref(), &write)?;
        Ok(Done { voxels: v, attributes, export, attributes_s, write_s: t.elapsed().as_secs_f64() })
    }
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
