//! The facts a job learns while it works, typed: what the commands read
//! (`closed`, the sign) and what the JSON summaries print (serialized as
//! they are, so the summaries keep their keys).

use serde::Serialize;
use topovox::query::orient::OrientReport;
use topovox::voxelize::solid::SolidReport;
use topovox::voxelize::winding::WindingReport;

/// How a solid was made and what it learned of the mesh.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SolidFacts {
    /// The method's own facts.
    #[serde(flatten)]
    pub made: SolidMade,
    /// Bricks stored as full runs (the sparse path).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub full_bricks: Option<u64>,
    /// The surface mode united with the solid (`solid+surface`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surface: Option<&'static str>,
    /// The connectivity `--hollow` kept (6 or 26).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hollow: Option<u8>,
    /// The rule that decided inside: `parity`, `nonzero winding` (a mesh
    /// closed once oriented), `generalized winding` (open) or `none
    /// (sheets)` (wrap around sheets alone).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inside_rule: Option<&'static str>,
    /// What orienting the mesh found and repaired (the winding rules).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub orientation: Option<OrientFacts>,
}

/// What [`topovox::query::orient`] found and repaired before the winding
/// rules decided inside.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct OrientFacts {
    /// Parts (triangles joined by manifold edges) with area.
    pub parts: u64,
    /// Of them closed.
    pub closed_parts: u64,
    /// Closed parts inside an odd number of others: cavities.
    pub nested_parts: u64,
    /// Open parts that enclose no volume.
    pub sheets: u64,
    /// Triangles turned round.
    pub faces_reoriented: u64,
    /// Manifold edges left inconsistent (parts that cannot be oriented).
    pub unorientable_edges: u64,
}

impl From<OrientReport> for OrientFacts {
    fn from(r: OrientReport) -> OrientFacts {
        OrientFacts {
            parts: r.parts,
            closed_parts: r.closed_parts,
            nested_parts: r.nested_parts,
            sheets: r.sheets,
            faces_reoriented: r.faces_reoriented,
            unorientable_edges: r.inconsistent_edges,
        }
    }
}

/// A solid's method facts: a flood fill's shell, or a mesh test's.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum SolidMade {
    /// `fill flood`: the shell filled from outside.
    Flood {
        /// The shell's surface mode.
        shell: &'static str,
        /// Voxels of the shell.
        shell_voxels: u64,
        /// Voxels the shell enclosed.
        enclosed_voxels: u64,
    },
    /// Parity or a winding number: the mesh's closedness and the exact pass.
    Mesh {
        /// Every edge has two faces.
        closed: bool,
        /// Every edge is used once in each direction.
        consistently_oriented: bool,
        /// Edges used by an odd number of triangles.
        boundary_edges: u64,
        /// Edges not used equally often in both directions.
        inconsistent_edges: u64,
        /// The generalized winding number's work (open meshes).
        generalized_winding: Option<WindingFacts>,
        /// The voxels decided again on the mesh as given.
        exact: ExactFacts,
    },
}

/// The generalized winding number's work.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct WindingFacts {
    /// Boundary cycles capped.
    pub boundary_cycles: u64,
    /// Triangles of the caps.
    pub cap_triangles: u64,
    /// Voxels whose winding number was evaluated.
    pub evaluated_voxels: u64,
}

impl From<&WindingReport> for WindingFacts {
    fn from(r: &WindingReport) -> Self {
        WindingFacts { boundary_cycles: r.cycles, cap_triangles: r.cap_triangles, evaluated_voxels: r.evaluated }
    }
}

/// The voxels snapping could change, decided again.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ExactFacts {
    /// Voxels decided again.
    pub checked_voxels: u64,
    /// Of those, voxels that changed.
    pub changed_voxels: u64,
}

impl SolidMade {
    /// A mesh test's facts from its report.
    pub fn mesh(rep: &SolidReport, generalized_winding: Option<WindingFacts>, exact: ExactFacts) -> SolidMade {
        SolidMade::Mesh {
            closed: rep.boundary_edges == 0,
            consistently_oriented: rep.unbalanced_edges == 0,
            boundary_edges: rep.boundary_edges,
            inconsistent_edges: rep.unbalanced_edges,
            generalized_winding,
            exact,
        }
    }
}

impl SolidFacts {
    /// Facts with no variant applied yet.
    pub fn new(made: SolidMade) -> SolidFacts {
        SolidFacts { made, full_bricks: None, surface: None, hollow: None, inside_rule: None, orientation: None }
    }

    /// Whether the mesh was found closed (`None` for a flood fill, which
    /// does not test it).
    pub fn closed(&self) -> Option<bool> {
        match self.made {
            SolidMade::Mesh { closed, .. } => Some(closed),
            SolidMade::Flood { .. } => None,
        }
    }
}

/// What a GPU run reports.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GpuFacts {
    /// The path (`compute`, `raster`, `msaa-approx`).
    pub path: String,
    /// The adapter's name.
    pub adapter: String,
    /// A software rasterizer (lavapipe).
    pub software: bool,
    /// The whole grid's run, the tiles' or a batch's.
    #[serde(flatten)]
    pub run: GpuRun,
}

/// Where a GPU run's triangles went.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GpuCounts {
    /// The adapter rasterizes conservatively in hardware.
    pub hardware_conservative: bool,
    /// Triangles voxelized on the GPU.
    pub gpu_triangles: u64,
    /// Triangles voxelized on the CPU beside it.
    pub cpu_triangles: u64,
}

/// A GPU run's timings (whole grid), tile count (tiled) or batch.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum GpuRun {
    /// One run on the whole grid.
    Whole {
        /// Where the triangles went.
        #[serde(flatten)]
        counts: GpuCounts,
        /// `msaa-approx`: voxels of the exact mode it missed.
        missed_voxels: Option<u64>,
        /// Seconds uploading.
        upload_s: f64,
        /// Seconds of the GPU step, as the host saw it.
        gpu_s: f64,
        /// Seconds the GPU measured itself.
        gpu_time_s: Option<f64>,
        /// Seconds downloading.
        download_s: f64,
        /// Seconds of the CPU's share.
        cpu_share_s: f64,
        /// Slabs the grid was cut into.
        slabs: u32,
    },
    /// Tile by tile.
    Tiled {
        /// Where the triangles went.
        #[serde(flatten)]
        counts: GpuCounts,
        /// Tiles run.
        tiles: u64,
    },
    /// Many meshes in one dispatch (`voxelize_many`).
    Batch {
        /// The batch's facts.
        batch: GpuBatch,
    },
}

/// A batch's dispatch.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GpuBatch {
    /// Meshes in the dispatch.
    pub meshes: usize,
    /// Meshes stacked in the tall grid.
    pub stacked: u64,
    /// Meshes that ran alone.
    pub alone: u64,
    /// Seconds of the whole batch.
    pub seconds: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// The summaries keep the keys they had as hand-written JSON.
    #[test]
    fn facts_serialize_as_the_summaries_print_them() {
        let mut f = SolidFacts::new(SolidMade::Mesh {
            closed: false,
            consistently_oriented: true,
            boundary_edges: 3,
            inconsistent_edges: 0,
            generalized_winding: Some(WindingFacts { boundary_cycles: 1, cap_triangles: 2, evaluated_voxels: 9 }),
            exact: ExactFacts { checked_voxels: 5, changed_voxels: 1 },
        });
        f.full_bricks = Some(4);
        f.hollow = Some(26);
        assert_eq!(
            serde_json::to_value(&f).unwrap(),
            json!({"closed": false, "consistently_oriented": true, "boundary_edges": 3, "inconsistent_edges": 0,
                "generalized_winding": {"boundary_cycles": 1, "cap_triangles": 2, "evaluated_voxels": 9},
                "exact": {"checked_voxels": 5, "changed_voxels": 1}, "full_bricks": 4, "hollow": 26})
        );
        assert_eq!(f.closed(), Some(false));
        let flood = SolidFacts::new(SolidMade::Flood { shell: "cover", shell_voxels: 7, enclosed_voxels: 8 });
        assert_eq!(serde_json::to_value(&flood).unwrap(), json!({"shell": "cover", "shell_voxels": 7, "enclosed_voxels": 8}));
        assert_eq!(flood.closed(), None);
        let counts = GpuCounts { hardware_conservative: false, gpu_triangles: 1, cpu_triangles: 2 };
        let tiled = GpuFacts { path: "compute".into(), adapter: "a".into(), software: true, run: GpuRun::Tiled { counts, tiles: 3 } };
        assert_eq!(
            serde_json::to_value(&tiled).unwrap(),
            json!({"path": "compute", "adapter": "a", "software": true, "hardware_conservative": false,
                "gpu_triangles": 1, "cpu_triangles": 2, "tiles": 3})
        );
    }
}
