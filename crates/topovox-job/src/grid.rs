//! The grid request: `resolution`, `voxel_size`, or an explicit
//! `origin`/`voxel_size`/`dims`, plus `pad` — validated before the mesh
//! is read, fitted to its bounds after.

use glam::DVec3;
use topovox::{Aabb, GridSpec, VoxelSize};

use serde_json::json;

use crate::error::{JobError, Result};
use crate::invalid;
use crate::table::{choice, chosen, int, number, numbers, shown, value, Example, OptionValue};

topovox::choice! {
    /// How a grid is fitted to the mesh.
    pub enum Fit: "fit" default Box {
        /// To the bounding box: origin at its low corner, the longest side
        /// spanning the resolution (other sides as many voxels as they need).
        Box = "box",
        /// A cube of N³ voxels centred on the bounding box, its longest side
        /// spanning N − 2·pad voxels (the ShapeNet/ModelNet convention).
        Cube = "cube",
    }
}

/// How far a padded grid keeps the mesh from its pad, in voxels: two
/// lattice units, so that snapping to the lattice (half a unit at most)
/// leaves every vertex strictly inside the unpadded part.
pub const PAD_GAP: f64 = 2.0 / topovox::geom::fixed::ONE as f64;

/// The grid request, validated but not yet fitted to a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct GridRequest {
    kind: GridKind,
    /// Voxels of margin on every side of a fitted grid.
    pad: u32,
    /// Bounding box or centred cube.
    fit: Fit,
}

#[derive(Clone, Debug, PartialEq)]
enum GridKind {
    /// Longest side spans N voxels.
    Resolution(u64),
    /// Fit to the bounding box with this voxel size.
    VoxelSize(VoxelSize),
    /// Fully explicit.
    Explicit { origin: DVec3, voxel_size: VoxelSize, dims: [u64; 3] },
}

crate::option_table! {
    /// The grid options as a user gives them (CLI flags, Python keywords).
    pub struct GridOptions {
        resolution: Option<u64> = None,
            parse |k, v| int(k, v, 1).map(Some),
            example Example::Int(16),
            print |o| Some(json!(o.resolution.or((!o.any()).then_some(128)))),
            cli value("N"),
            "fit the grid so the longest side of the mesh's bounding box spans N voxels (default 128)";
        voxel_size: Option<VoxelSize> = None,
            parse |k, v| voxel_size(k, v).map(Some),
            example Example::Float(0.5),
            print |o| Some(json!(o.voxel_size.map(topovox_io::size_json))),
            cli value("S|SX,SY,SZ"),
            "the voxel edge, or a size per axis (boxes); alone, the grid is fitted to the mesh's bounding box";
        origin: Option<Vec<f64>> = None,
            parse |k, v| numbers(k, v).map(Some),
            example Example::Numbers(&[-1.0, -1.0, -1.0]),
            print |o| Some(json!(o.origin)),
            cli value("X,Y,Z"),
            "an explicit grid's origin (with voxel_size and dims)";
        dims: Option<Vec<u64>> = None,
            parse |k, v| dims(k, v).map(Some),
            example Example::Numbers(&[8.0, 8.0, 8.0]),
            print |o| Some(json!(o.dims)),
            cli value("NX,NY,NZ"),
            "an explicit grid's dims (with origin and voxel_size)";
        pad: Option<u32> = None,
            // 0 is no pad (so a batch's fingerprint is the one without).
            parse |k, v| Ok(Some(u32::try_from(int(k, v, 0)?).map_err(|_| JobError::invalid("pad is too large"))?).filter(|&p| p > 0)),
            example Example::Int(1),
            print |o| Some(json!(o.pad.unwrap_or(0))),
            cli value("P"),
            "empty voxels added on every side of a fitted grid (default 0)";
        fit: Option<Fit> = None,
            parse |k, v| chosen(k, v).map(Some),
            example Example::Text("cube"),
            print |o| o.cube().then(|| json!("cube")),
            cli choice::<Fit>("box|cube"),
            "how a fitted grid meets the mesh: box (default: origin at the bounding box's corner) or cube (N³ voxels centred on it, the longest side spanning N − 2·pad: ShapeNet's convention)";
    }
}

/// One number (cubes) or three (a size per axis).
fn voxel_size(key: &str, v: &OptionValue) -> Result<VoxelSize> {
    match v {
        OptionValue::Numbers(n) => Ok(<[f64; 3]>::try_from(numbers(key, v)?).unwrap_or([n[0]; 3]).into()),
        v => number(key, v)
            .map(VoxelSize::from)
            .map_err(|_| JobError::invalid(format!("{key} must be a number or 3 numbers; got {}", shown(v)))),
    }
}

/// Three integers of at least 1.
fn dims(key: &str, v: &OptionValue) -> Result<Vec<u64>> {
    let d = numbers(key, v)?;
    if d.iter().any(|&x| x < 1.0 || x.fract() != 0.0 || x > u32::MAX as f64) {
        invalid!("{key} must be 3 integers of at least 1; got {d:?}");
    }
    Ok(d.iter().map(|&x| x as u64).collect())
}

impl GridOptions {
    /// Whether any grid option was given.
    pub fn any(&self) -> bool {
        self.resolution.is_some() || self.voxel_size.is_some() || self.origin.is_some() || self.dims.is_some() || self.pad.is_some()
    }

    /// A cube fit asked for.
    pub fn cube(&self) -> bool {
        self.fit == Some(Fit::Cube)
    }
}

impl GridRequest {
    /// Checks that the grid options form one of the three documented ways
    /// (none: resolution 128).
    pub fn new(g: &GridOptions) -> Result<GridRequest> {
        let kind = GridKind::new(g)?;
        let pad = g.pad.unwrap_or(0);
        let fit = g.fit.unwrap_or_default();
        if matches!(kind, GridKind::Explicit { .. }) {
            if pad > 0 {
                invalid!("--pad applies to fitted grids (--resolution or --voxel-size), not to an explicit --origin/--dims grid");
            }
            if fit == Fit::Cube {
                invalid!("--fit cube applies to fitted grids (--resolution or --voxel-size), not to an explicit --origin/--dims grid");
            }
        }
        if let (Fit::Cube, GridKind::Resolution(n)) = (fit, &kind) {
            if *n <= 2 * pad as u64 {
                invalid!("--fit cube --resolution {n} --pad {pad}: the resolution must exceed twice the pad");
            }
        }
        Ok(GridRequest { kind, pad, fit })
    }

    /// The grid for a mesh with these bounds.
    ///
    /// With a pad, the pad's voxels are empty in every mode: the mesh is
    /// kept `PAD_GAP` (two lattice units) of a voxel clear of them on every side (its bounds grow
    /// by that much before the fit), so no closed voxel box of the margin
    /// meets it and no tie sends a vertex there. Without a pad the grid is
    /// the bounding box's, as before.
    pub fn fit(&self, bounds: &Aabb) -> Result<GridSpec> {
        let clear = self.clear_of_pad(bounds);
        let bounds = &clear;
        if self.fit == Fit::Cube {
            return self.cube(bounds);
        }
        let g = self.kind.fit(bounds)?;
        if self.pad == 0 {
            return Ok(g);
        }
        let (p, s) = (self.pad as f64, g.voxel_size().0);
        GridSpec::new(g.origin() - p * s, g.voxel_size(), g.dims().map(|d| d as u64 + 2 * self.pad as u64))
            .map_err(|e| JobError::invalid(format!("invalid grid: {e}")))
    }

    /// `bounds` grown by `PAD_GAP` of a voxel on every side when there is a
    /// pad. For `--resolution N` the voxel size itself depends on the
    /// bounds: growing by `e = L·g / (m − 2g)` (L the longest side, m the
    /// voxels it spans) makes the voxel `s = L / (m − 2g)` and `e = g·s`.
    fn clear_of_pad(&self, bounds: &Aabb) -> Aabb {
        if self.pad == 0 || bounds.is_empty() {
            return *bounds;
        }
        let g = PAD_GAP;
        let e = match &self.kind {
            GridKind::Resolution(n) => {
                let m = if self.fit == Fit::Cube { n - 2 * self.pad as u64 } else { *n } as f64;
                DVec3::splat((bounds.max - bounds.min).max_element() * g / (m - 2.0 * g))
            }
            GridKind::VoxelSize(s) => s.0 * g,
            GridKind::Explicit { .. } => return *bounds,
        };
        Aabb { min: bounds.min - e, max: bounds.max + e }
    }

    /// The centred cube: N³ voxels (`--resolution N`, the mesh's longest
    /// side spanning N − 2·pad), or as many as `--voxel-size` needs for the
    /// longest side plus the pad on both ends.
    fn cube(&self, bounds: &Aabb) -> Result<GridSpec> {
        let box_grid = match self.kind {
            GridKind::Resolution(n) => GridKind::Resolution(n - 2 * self.pad as u64),
            ref k => k.clone(),
        }
        .fit(bounds)?;
        let s = box_grid.voxel_size().0;
        let side = box_grid.dims().into_iter().max().unwrap_or(1) as u64 + 2 * self.pad as u64;
        let centre = (bounds.min + bounds.max) * 0.5;
        GridSpec::new(centre - side as f64 * s * 0.5, box_grid.voxel_size(), [side; 3])
            .map_err(|e| JobError::invalid(format!("invalid grid: {e}")))
    }

    /// The voxel size asked for when it is not cubic (`--resolution` always
    /// gives cubes): formats that only know cubes refuse it before any work.
    pub fn boxes(&self) -> Option<VoxelSize> {
        match self.kind {
            GridKind::VoxelSize(s) | GridKind::Explicit { voxel_size: s, .. } => s.cube().is_none().then_some(s),
            GridKind::Resolution(_) => None,
        }
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
                if let Some(&bad) = s.to_array().iter().find(|v| !(v.is_finite() && **v > 0.0)) {
                    invalid!("invalid grid: {}", topovox::GridError::BadVoxelSize(bad));
                }
                Ok(GridKind::VoxelSize(s))
            }
            (None, None) => Ok(GridKind::Resolution(128)),
        }
    }

    fn fit(&self, bounds: &Aabb) -> Result<GridSpec> {
        let g = match self.clone() {
            GridKind::Resolution(n) => GridSpec::from_resolution(bounds, n),
            GridKind::VoxelSize(s) => GridSpec::from_voxel_size(bounds, s),
            GridKind::Explicit { origin, voxel_size, dims } => GridSpec::new(origin, voxel_size, dims),
        };
        g.map_err(|e| JobError::invalid(format!("invalid grid: {e}")))
    }
}

#[cfg(test)]
mod cube_tests {
    use super::*;

    fn request(resolution: Option<u64>, voxel_size: Option<f64>, pad: u32) -> GridRequest {
        let voxel_size = voxel_size.map(VoxelSize::from);
        GridRequest::new(&GridOptions { resolution, voxel_size, pad: Some(pad), fit: Some(Fit::Cube), ..GridOptions::default() }).unwrap()
    }

    #[test]
    fn a_cube_is_centred_on_the_box_and_holds_it_inside_the_pad() {
        let b = Aabb { min: DVec3::new(-1.0, 2.0, 0.5), max: DVec3::new(3.0, 2.5, 1.5) };
        for (r, v, pad) in [(Some(32), None, 0), (Some(64), None, 3), (None, Some(0.3), 2), (Some(7), None, 3)] {
            let g = request(r, v, pad).fit(&b).unwrap();
            let s = g.voxel_size().cube().unwrap();
            let [nx, ny, nz] = g.dims();
            assert!(nx == ny && ny == nz, "{:?}", g.dims());
            if let Some(n) = r {
                assert_eq!(nx as u64, n);
                // The longest side spans N − 2·pad voxels, less the gap
                // that keeps it clear of the pad.
                let gap = if pad > 0 { 2.0 * PAD_GAP } else { 0.0 };
                assert!(((b.max.x - b.min.x) / s - ((n - 2 * pad as u64) as f64 - gap)).abs() < 1e-9);
            }
            let (lo, hi) = (g.origin(), g.origin() + DVec3::splat(nx as f64 * s));
            assert!(((lo + hi) * 0.5 - (b.min + b.max) * 0.5).length() < 1e-9);
            let margin = if pad > 0 { (pad as f64 + PAD_GAP) * s - 1e-12 } else { 0.0 };
            assert!((b.min - lo).min_element() >= margin && (hi - b.max).min_element() >= margin, "{r:?} {v:?} {pad}");
        }
        assert!(
            GridRequest::new(&GridOptions { resolution: Some(4), pad: Some(2), fit: Some(Fit::Cube), ..GridOptions::default() }).is_err()
        );
        let explicit = GridOptions {
            origin: Some(vec![0.0; 3]),
            voxel_size: Some(1.0.into()),
            dims: Some(vec![2; 3]),
            fit: Some(Fit::Cube),
            ..GridOptions::default()
        };
        assert!(GridRequest::new(&explicit).is_err());
    }

    #[test]
    fn boxes_fit_and_pad_per_axis() {
        let b = Aabb { min: DVec3::new(0.0, 0.0, 0.0), max: DVec3::new(1.4, 1.4, 5.0) };
        let o = GridOptions { voxel_size: Some([0.7, 0.7, 2.5].into()), pad: Some(1), ..GridOptions::default() };
        let r = GridRequest::new(&o).unwrap();
        assert_eq!(r.boxes(), Some([0.7, 0.7, 2.5].into()));
        let g = r.fit(&b).unwrap();
        // Two voxels' worth of mesh a side, clear of the pad: three, plus the pad.
        assert_eq!(g.dims(), [5, 5, 5]);
        assert!((g.origin() - DVec3::new(-0.7, -0.7, -2.5) * (1.0 + PAD_GAP)).length() < 1e-12);
        let unpadded = GridRequest::new(&GridOptions { pad: None, ..o.clone() }).unwrap().fit(&b).unwrap();
        assert_eq!((unpadded.dims(), unpadded.origin()), ([2, 2, 2], DVec3::ZERO));
        let bad = GridOptions { voxel_size: Some([0.7, -1.0, 2.5].into()), ..GridOptions::default() };
        assert!(GridRequest::new(&bad).unwrap_err().to_string().contains("-1"));
        let cubes = GridOptions { voxel_size: Some(0.5.into()), ..GridOptions::default() };
        assert_eq!(GridRequest::new(&cubes).unwrap().boxes(), None);
    }

    #[test]
    fn a_padded_grid_keeps_the_mesh_strictly_inside_its_unpadded_part() {
        let b = Aabb { min: DVec3::new(0.0, 0.0, 0.0), max: DVec3::new(1.0, 0.5, 0.25) };
        for fit in [Fit::Box, Fit::Cube] {
            for (resolution, voxel_size) in [(Some(8), None), (Some(5), None), (None, Some(0.125)), (None, Some(0.25))] {
                for pad in [1u32, 2] {
                    let o = GridOptions {
                        resolution,
                        voxel_size: voxel_size.map(VoxelSize::from),
                        pad: Some(pad),
                        fit: Some(fit),
                        ..GridOptions::default()
                    };
                    let g = GridRequest::new(&o).unwrap().fit(&b).unwrap();
                    for corner in [b.min, b.max] {
                        let u = g.to_grid_units(corner);
                        for a in 0..3 {
                            let (lo, hi) = (pad as f64, (g.dims()[a] - pad) as f64);
                            // In lattice units, after snapping: at least one unit inside.
                            let snapped = (u[a] * 4096.0).round() / 4096.0;
                            assert!(
                                snapped > lo && snapped < hi,
                                "{fit:?} {resolution:?} {voxel_size:?} pad {pad}: {u:?} in {:?}",
                                g.dims()
                            );
                        }
                    }
                }
            }
        }
    }
}
