//! The grid request: `resolution`, `voxel_size`, or an explicit
//! `origin`/`voxel_size`/`dims`, plus `pad` — validated before the mesh
//! is read, fitted to its bounds after.

use glam::DVec3;
use topovox::{Aabb, GridSpec};

use crate::error::{JobError, Result};
use crate::invalid;

/// The grid request, validated but not yet fitted to a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct GridRequest {
    kind: GridKind,
    /// Voxels of margin on every side of a fitted grid.
    pad: u32,
}

#[derive(Clone, Debug, PartialEq)]
enum GridKind {
    /// Longest side spans N voxels.
    Resolution(u64),
    /// Fit to the bounding box with this voxel size.
    VoxelSize(f64),
    /// Fully explicit.
    Explicit { origin: DVec3, voxel_size: f64, dims: [u64; 3] },
}

/// The grid options as a user gives them (CLI flags, Python keywords).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GridOptions {
    /// Longest side of the mesh's bounding box in voxels.
    pub resolution: Option<u64>,
    /// Voxel edge length.
    pub voxel_size: Option<f64>,
    /// Explicit origin (with `voxel_size` and `dims`).
    pub origin: Option<Vec<f64>>,
    /// Explicit dims (with `origin` and `voxel_size`).
    pub dims: Option<Vec<u64>>,
    /// Empty voxels on every side of a fitted grid.
    pub pad: Option<u32>,
}

impl GridOptions {
    /// Whether any grid option was given.
    pub fn any(&self) -> bool {
        self.resolution.is_some() || self.voxel_size.is_some() || self.origin.is_some() || self.dims.is_some() || self.pad.is_some()
    }
}

impl GridRequest {
    /// Checks that the grid options form one of the three documented ways
    /// (none: resolution 128).
    pub fn new(g: &GridOptions) -> Result<GridRequest> {
        let kind = GridKind::new(g)?;
        let pad = g.pad.unwrap_or(0);
        if pad > 0 && matches!(kind, GridKind::Explicit { .. }) {
            invalid!("--pad applies to fitted grids (--resolution or --voxel-size), not to an explicit --origin/--dims grid");
        }
        Ok(GridRequest { kind, pad })
    }

    /// The grid for a mesh with these bounds.
    pub fn fit(&self, bounds: &Aabb) -> Result<GridSpec> {
        let g = self.kind.fit(bounds)?;
        if self.pad == 0 {
            return Ok(g);
        }
        let (p, s) = (self.pad as f64, g.voxel_size());
        GridSpec::new(g.origin() - DVec3::splat(p * s), s, g.dims().map(|d| d as u64 + 2 * self.pad as u64))
            .map_err(|e| JobError::invalid(format!("invalid grid: {e}")))
    }

    /// The explicit grid, if the request is one (it needs no mesh).
    pub fn explicit(&self) -> Option<GridSpec> {
        match self.kind {
            GridKind::Explicit { origin, voxel_size, dims } => GridSpec::new(origin, voxel_size, dims).ok(),
            _ => None,
        }
    }
}

impl GridKind {
    fn new(g: &GridOptions) -> Result<GridKind> {
        if g.origin.is_some() || g.dims.is_some() {
            let (Some(o), Some(s), Some(d)) = (&g.origin, g.voxel_size, &g.dims) else {
                invalid!("an explicit grid needs all of --origin X,Y,Z --voxel-size S --dims NX,NY,NZ");
            };
            if o.len() != 3 || d.len() != 3 {
                invalid!("--origin and --dims take three comma-separated values (X,Y,Z and NX,NY,NZ)");
            }
            if g.resolution.is_some() {
                invalid!("--resolution cannot be combined with an explicit grid (--origin/--dims)");
            }
            let kind = GridKind::Explicit { origin: DVec3::new(o[0], o[1], o[2]), voxel_size: s, dims: [d[0], d[1], d[2]] };
            // Validate now: nothing about it depends on the mesh.
            kind.fit(&Aabb::EMPTY)?;
            return Ok(kind);
        }
        match (g.resolution, g.voxel_size) {
            (Some(_), Some(_)) => invalid!("give either --resolution or --voxel-size, not both"),
            (Some(n), None) => {
                if n == 0 || n > topovox::grid::spec::MAX_DIM as u64 {
                    invalid!("invalid grid: {}", topovox::GridError::BadResolution(n));
                }
                Ok(GridKind::Resolution(n))
            }
            (None, Some(s)) => {
                if !(s.is_finite() && s > 0.0) {
                    invalid!("invalid grid: {}", topovox::GridError::BadVoxelSize(s));
                }
                Ok(GridKind::VoxelSize(s))
            }
            (None, None) => Ok(GridKind::Resolution(128)),
        }
    }

    fn fit(&self, bounds: &Aabb) -> Result<GridSpec> {
        let g = match *self {
            GridKind::Resolution(n) => GridSpec::from_resolution(bounds, n),
            GridKind::VoxelSize(s) => GridSpec::from_voxel_size(bounds, s),
            GridKind::Explicit { origin, voxel_size, dims } => GridSpec::new(origin, voxel_size, dims),
        };
        g.map_err(|e| JobError::invalid(format!("invalid grid: {e}")))
    }
}
