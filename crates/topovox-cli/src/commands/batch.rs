//! `topovox batch INPUTS... -o OUT_DIR`: whole datasets (see `topovox_job::batch`).

use anyhow::{bail, Result};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde_json::Value;
use topovox::choice::Choice;
use topovox_io::mesh_out::MeshOut;
use topovox_job::batch::{self, BatchProgress, Run};
use topovox_job::distance::{DistanceFormat, SdfOptions};
use topovox_job::output::Output;
use topovox_job::remesh::RemeshOptions;
use topovox_job::sample::SampleOptions;
use topovox_job::JobOptions;

use crate::args::BatchArgs;

/// The bar: meshes done of all, meshes per second, time to go.
struct Bar(ProgressBar);

impl BatchProgress for Bar {
    fn start(&self, total: u64, skipped: u64) {
        self.0.set_length(total);
        self.0.set_position(skipped);
        self.0.reset_eta();
    }

    fn finished(&self, record: &Value) {
        if record["status"] != "done" {
            self.0.println(format!("topovox: failed: {}", record["error"].as_str().unwrap_or("?")));
        }
        self.0.inc(1);
    }
}

/// The batch's work: each run reads its own options (`--run sdf` the
/// grid and run options and the field's, `--run remesh` the grid and run
/// options and the shell's) and its own formats; an option of another run
/// only is refused in one line.
fn options(a: &BatchArgs) -> Result<batch::BatchOptions> {
    let run = a.run.name();
    let format = a.format.as_deref().unwrap_or(a.run.default_format());
    let given = &a.options;
    let refuse = |e: &dyn std::fmt::Display| anyhow::anyhow!("--format {format:?} with --run {run}: {e}");
    Ok(match a.run {
        Run::Voxelize => {
            let format = <Output as Choice>::parse(format).map_err(|e| refuse(&e))?;
            batch::BatchOptions::voxelize(&given.table::<JobOptions>(run)?, format)?
        }
        Run::Sdf => {
            let format = <DistanceFormat as Choice>::parse(format).map_err(|e| refuse(&e))?;
            batch::BatchOptions::sdf(&given.table::<SdfOptions>(run)?, format)?
        }
        Run::Remesh => {
            let format = <MeshOut as Choice>::parse(format).map_err(|e| refuse(&e))?;
            batch::BatchOptions::remesh(&given.table::<RemeshOptions>(run)?, format)?
        }
        Run::Sample => batch::BatchOptions::sample(&given.table::<SampleOptions>(run)?, format).map_err(|e| refuse(&e))?,
    })
}

pub fn run(a: &BatchArgs) -> Result<()> {
    let opts = options(a)?;
    let pool = topovox_job::pool_for(a.jobs, "--jobs")?;
    let (items, warnings) = batch::items(&a.inputs, a.glob.as_deref(), &a.output, &opts)?;
    for w in &warnings {
        crate::console::warn(w);
    }

    use std::io::IsTerminal;
    let target =
        if !a.quiet && !a.json && std::io::stderr().is_terminal() { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() };
    let pb = ProgressBar::with_draw_target(None, target);
    pb.set_style(
        ProgressStyle::with_template("[{bar:30}] {pos}/{len} meshes, {per_sec}, {eta} to go ({elapsed})")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let bar = Bar(pb);
    let summary = pool.install(|| batch::run(&items, &a.output, &opts, &bar, None))?;
    bar.0.finish_and_clear();
    let total = summary.done + summary.skipped + summary.failed;
    if a.json {
        let mut v = summary.to_json();
        v["total"] = total.into();
        v["jobs"] = pool.current_num_threads().into();
        v["meshes_per_s"] = (summary.done as f64 / summary.total_s.max(1e-9)).into();
        crate::console::print_stdout(&v.to_string())?;
    } else if !a.quiet {
        crate::console::print_stdout(&format!(
            "batch: {} done, {} skipped (already done), {} failed, of {total} meshes in {:.2} s{} -> {} (manifest {})",
            summary.done,
            summary.skipped,
            summary.failed,
            summary.total_s,
            // A rate only of meshes voxelized now (none when all were skipped).
            if summary.done > 0 { format!(" ({:.1} meshes/s)", summary.done as f64 / summary.total_s.max(1e-9)) } else { String::new() },
            a.output.display(),
            summary.manifest.display()
        ))?;
    }
    if summary.failed > 0 {
        bail!("{} of {total} meshes failed; their errors are in {}", summary.failed, summary.manifest.display());
    }
    Ok(())
}
