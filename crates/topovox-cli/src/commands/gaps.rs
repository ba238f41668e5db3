//! `topovox gaps`: how a mode's voxels differ from reference modes, and
//! whether the exact checker certifies them 6-separating.

use anyhow::{Context, Result};
use serde_json::json;
use topovox::topology::certify::certify;
use topovox::voxelize::{self, Options};
use topovox::{DenseBits, GridSpec};

use crate::args::GapsArgs;
use crate::plan::core_mode;

/// Voxels set in `a` and not in `b` (same dims).
fn and_not(a: &DenseBits, b: &DenseBits) -> u64 {
    a.words().iter().zip(b.words()).map(|(x, y)| (x & !y).count_ones() as u64).sum()
}

pub fn run(a: &GapsArgs) -> Result<()> {
    let mode = core_mode(a.mode)?;
    let against = a.against.iter().map(|&m| core_mode(m)).collect::<Result<Vec<_>>>()?;
    let mut table = String::new();
    if !a.json {
        table += &format!("| mesh | closed | resolution | {} voxels |", a.mode.name());
        for &m in &a.against {
            table += &format!(" missing vs {} |", m.name());
        }
        table += &format!(" outside {} | 6-separating | 6-tunnels |\n", a.against[a.against.len() - 1].name());
        table += &"|---".repeat(7 + a.against.len());
        table += "|\n";
    }
    for path in &a.meshes {
        let loaded = topovox_io::read_mesh(path, &topovox_io::ReadOptions::default())?;
        let mesh = loaded.mesh.as_ref();
        let name = path.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default();
        for &res in &a.resolutions {
            let grid = GridSpec::from_resolution(&loaded.report.bounds, res).context("invalid grid")?;
            crate::plan::check_memory(&grid)?;
            let opts = Options::default();
            let bits = voxelize::fast(mode, mesh, &grid, &opts).0.to_dense();
            let refs: Vec<DenseBits> = against.iter().map(|&m| voxelize::fast(m, mesh, &grid, &opts).0.to_dense()).collect();
            let missing: Vec<u64> = refs.iter().map(|r| and_not(r, &bits)).collect();
            let outside = refs.last().map(|r| and_not(&bits, r)).unwrap_or(0);
            let report = certify(&bits, Some((mesh, &grid))).with_context(|| format!("{}: certify", path.display()))?;
            let facts = report.mesh.context("certify returned no mesh facts")?;
            let separating = facts.separation.as_ref().map(|s| s.witness_6.is_none());
            if a.json {
                let v = json!({"mesh": name, "closed": facts.closed, "resolution": res, "dims": grid.dims(), "mode": a.mode.name(),
                    "voxels": report.voxels,
                    "missing": a.against.iter().zip(&missing).map(|(m, n)| (m.name().to_string(), json!(n))).collect::<serde_json::Map<_, _>>(),
                    "outside": outside, "separating_6": separating, "tunnels_6": facts.tunnels_6});
                crate::console::print_stdout(&v.to_string())?;
                continue;
            }
            table += &format!("| {name} | {} | {res} | {} |", if facts.closed { "yes" } else { "no" }, report.voxels);
            for (n, r) in missing.iter().zip(&refs) {
                let total = r.count().max(1);
                table += &format!(" {n} ({:.2} %) |", 100.0 * *n as f64 / total as f64);
            }
            let sep = match separating {
                Some(true) => "yes",
                Some(false) => "**no**",
                None => "n/a (open)",
            };
            table += &format!(" {outside} | {sep} | {} |\n", facts.tunnels_6);
        }
    }
    if a.json {
        return Ok(());
    }
    crate::console::print_stdout(table.trim_end())
}
