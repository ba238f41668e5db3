//! The grid specification: origin, voxel size per axis and dims.
//!
//! Voxels are boxes `s = (sx, sy, sz)`; cubes are the case `sx = sy = sz`.
//! Every algorithm works in *index space*, `u = (p - origin) / s` per axis,
//! where a voxel is the unit cube `[i, i+1] × [j, j+1] × [k, k+1]`: each
//! mode's definition, tie rule and guarantee hold there exactly as for cubes.

use glam::DVec3;

use crate::aabb::Aabb;

/// Largest number of voxels along one axis. Keeps every lattice coordinate
/// of a clipped triangle inside the fixed-point range (see [`crate::geom::fixed`]).
pub const MAX_DIM: u32 = 65_536;

/// Why a grid could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GridError {
    /// Voxel size zero, negative, NaN or infinite (on some axis).
    #[error("voxel size must be a positive finite number, got {0}")]
    BadVoxelSize(f64),
    /// Origin has a NaN or infinite coordinate.
    #[error("grid origin must be finite, got {0:?}")]
    BadOrigin([f64; 3]),
    /// The grid reaches past ±[`crate::COORDINATE_LIMIT`], or its voxel
    /// size lies outside [`crate::MIN_VOXEL_SIZE`]`..=`[`crate::COORDINATE_LIMIT`].
    #[error("the grid {0}, outside the range topovox computes in (coordinates within ±2^100 = 1.27e30, voxel sizes at least 2^-100 = 7.9e-31); scale the mesh first")]
    OutOfRange(String),
    /// A dimension is zero or above [`MAX_DIM`].
    #[error("grid dims must each be between 1 and {MAX_DIM}, got {0:?}")]
    BadDims([u64; 3]),
    /// A voxel size so small that some axis would need more than [`MAX_DIM`] voxels.
    #[error("voxel size {voxel_size} would need {:.3e} x {:.3e} x {:.3e} voxels; at most {MAX_DIM} per axis", needed[0], needed[1], needed[2])]
    VoxelSizeTooSmall {
        /// The voxel size asked for.
        voxel_size: VoxelSize,
        /// Voxels each axis would need.
        needed: [f64; 3],
    },
    /// Resolution zero or above [`MAX_DIM`].
    #[error("resolution must be between 1 and {MAX_DIM}, got {0}")]
    BadResolution(u64),
    /// The bounding box to fit is empty or not finite.
    #[error("cannot fit a grid to an empty or non-finite bounding box")]
    EmptyBounds,
    /// The bounding box has zero extent on every axis (a single point).
    #[error("cannot fit a grid to a mesh of zero extent (all vertices coincide)")]
    ZeroExtent,
}

/// A voxel's edge lengths along x, y and z; one number for cubes.
///
/// Built from an `f64` (a cube), a `[f64; 3]` or a [`DVec3`]. Displays as
/// the one number for cubes and as `sx,sy,sz` otherwise, the form
/// `--voxel-size` takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VoxelSize(pub DVec3);

impl VoxelSize {
    /// The edge length when all three are equal (bit for bit).
    pub fn cube(self) -> Option<f64> {
        let s = self.0;
        (s.x == s.y && s.y == s.z).then_some(s.x)
    }

    /// The three edge lengths.
    pub fn to_array(self) -> [f64; 3] {
        self.0.to_array()
    }

    /// The sizes as files record them: one for cubes (the form written
    /// before boxes, so cubic files stay as they were), three for boxes.
    pub fn recorded(self) -> Vec<f64> {
        match self.cube() {
            Some(s) => vec![s],
            None => self.to_array().to_vec(),
        }
    }
}

impl From<f64> for VoxelSize {
    fn from(s: f64) -> VoxelSize {
        VoxelSize(DVec3::splat(s))
    }
}

impl From<[f64; 3]> for VoxelSize {
    fn from(s: [f64; 3]) -> VoxelSize {
        VoxelSize(DVec3::from(s))
    }
}

impl From<DVec3> for VoxelSize {
    fn from(s: DVec3) -> VoxelSize {
        VoxelSize(s)
    }
}

impl std::fmt::Display for VoxelSize {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.cube() {
            Some(s) => write!(f, "{s}"),
            None => write!(f, "{},{},{}", self.0.x, self.0.y, self.0.z),
        }
    }
}

/// Where the voxels are.
///
/// Voxel `(i, j, k)` is the **closed** box
/// `[origin + (i,j,k)∘s, origin + (i+1,j+1,k+1)∘s]` with `s = voxel_size`
/// per axis (`∘` multiplies component by component), for `0 <= i < dims[0]`
/// and so on. Neighbouring voxels share their faces.
///
/// # Guarantees
/// Built only through [`GridSpec::new`], [`GridSpec::from_resolution`] or
/// [`GridSpec::from_voxel_size`]: origin finite, each voxel size `> 0`
/// finite, `1 <= dims[a] <= MAX_DIM`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    origin: DVec3,
    voxel_size: DVec3,
    dims: [u32; 3],
}

impl GridSpec {
    /// An explicit grid; `voxel_size` is one number (cubes) or three.
    pub fn new(origin: DVec3, voxel_size: impl Into<VoxelSize>, dims: [u64; 3]) -> Result<GridSpec, GridError> {
        let voxel_size = checked_size(voxel_size.into())?;
        if !origin.is_finite() {
            return Err(GridError::BadOrigin(origin.to_array()));
        }
        if dims.iter().any(|&d| d == 0 || d > MAX_DIM as u64) {
            return Err(GridError::BadDims(dims));
        }
        if let Some(&h) = voxel_size.to_array().iter().find(|&&h| !(crate::MIN_VOXEL_SIZE..=crate::COORDINATE_LIMIT).contains(&h)) {
            return Err(GridError::OutOfRange(format!("has the voxel size {h:e}")));
        }
        let far = origin + DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) * voxel_size;
        if !crate::in_range(origin) || !crate::in_range(far) {
            return Err(GridError::OutOfRange(format!("reaches {:e}", origin.abs().max(far.abs()).max_element())));
        }
        Ok(GridSpec { origin, voxel_size, dims: dims.map(|d| d as u32) })
    }

    /// Fits a grid to `bounds` so its longest side spans `n` voxels:
    /// `s = longest / n`, `origin = bounds.min`, and on each axis
    /// `dims = max(1, ceil(extent / s))` clamped to `n` (so floating-point
    /// rounding never adds a voxel).
    pub fn from_resolution(bounds: &Aabb, n: u64) -> Result<GridSpec, GridError> {
        if n == 0 || n > MAX_DIM as u64 {
            return Err(GridError::BadResolution(n));
        }
        let ext = checked_extent(bounds)?;
        let longest = ext.max_element();
        if longest <= 0.0 {
            return Err(GridError::ZeroExtent);
        }
        let s = longest / n as f64;
        let dims = ext.to_array().map(|e| ((e / s).ceil() as u64).clamp(1, n));
        GridSpec::new(bounds.min, s, dims)
    }

    /// Fits a grid of voxel size `s` (one number or three) to `bounds`:
    /// `origin = bounds.min`, `dims = max(1, ceil(extent / s))` on each axis.
    pub fn from_voxel_size(bounds: &Aabb, s: impl Into<VoxelSize>) -> Result<GridSpec, GridError> {
        let size = s.into();
        let s = checked_size(size)?;
        let ext = checked_extent(bounds)?;
        let needed = (ext / s).to_array().map(f64::ceil);
        if needed.iter().any(|&d| d > MAX_DIM as f64) {
            return Err(GridError::VoxelSizeTooSmall { voxel_size: size, needed });
        }
        let dims = needed.map(|d| (d as u64).max(1));
        GridSpec::new(bounds.min, s, dims)
    }

    /// World position of the grid's minimum corner.
    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    /// A voxel's edge lengths: `.0` along x, y, z; `.cube()` the edge of
    /// cubic voxels; shown as one number for cubes, three otherwise.
    pub fn voxel_size(&self) -> VoxelSize {
        VoxelSize(self.voxel_size)
    }

    /// Voxels along x, y, z.
    pub fn dims(&self) -> [u32; 3] {
        self.dims
    }

    /// Total number of voxels.
    pub fn voxel_count(&self) -> u64 {
        self.dims.iter().map(|&d| d as u64).product()
    }

    /// Bytes a [`crate::DenseBits`] of this grid occupies.
    pub fn dense_bytes(&self) -> u64 {
        let words_per_row = (self.dims[0] as u64).div_ceil(64);
        words_per_row * self.dims[1] as u64 * self.dims[2] as u64 * 8
    }

    /// `(p - origin) / voxel_size` per axis: position in index space.
    #[inline]
    pub fn to_grid_units(&self, p: DVec3) -> DVec3 {
        (p - self.origin) / self.voxel_size
    }

    /// World position of voxel `(i,j,k)`'s minimum corner.
    pub fn voxel_min(&self, ijk: [u32; 3]) -> DVec3 {
        self.origin + DVec3::new(ijk[0] as f64, ijk[1] as f64, ijk[2] as f64) * self.voxel_size
    }

    /// World position of voxel `(i,j,k)`'s centre.
    pub fn voxel_center(&self, ijk: [u32; 3]) -> DVec3 {
        self.voxel_min(ijk) + 0.5 * self.voxel_size
    }
}

fn checked_size(s: VoxelSize) -> Result<DVec3, GridError> {
    match s.to_array().into_iter().find(|v| !(v.is_finite() && *v > 0.0)) {
        Some(bad) => Err(GridError::BadVoxelSize(bad)),
        None => Ok(s.0),
    }
}

fn checked_extent(bounds: &Aabb) -> Result<DVec3, GridError> {
    if bounds.is_empty() || !bounds.min.is_finite() || !bounds.max.is_finite() {
        return Err(GridError::EmptyBounds);
    }
    Ok(bounds.extent())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bbox(min: [f64; 3], max: [f64; 3]) -> Aabb {
        Aabb { min: DVec3::from(min), max: DVec3::from(max) }
    }

    #[test]
    fn resolution_fits_longest_side() {
        let g = GridSpec::from_resolution(&bbox([0.0; 3], [2.0, 1.0, 0.5]), 8).unwrap();
        assert_eq!(g.dims(), [8, 4, 2]);
        assert_eq!(g.voxel_size().cube(), Some(0.25));
    }

    #[test]
    fn resolution_never_adds_a_voxel() {
        // 0.1*3 / (0.3/3) may round above 3 in f64; the clamp keeps n.
        let g = GridSpec::from_resolution(&bbox([0.0; 3], [0.3, 0.3, 0.1]), 3).unwrap();
        assert_eq!(g.dims()[0], 3);
        assert_eq!(g.dims()[1], 3);
    }

    #[test]
    fn flat_axis_gets_one_voxel() {
        let g = GridSpec::from_resolution(&bbox([0.0; 3], [1.0, 1.0, 0.0]), 10).unwrap();
        assert_eq!(g.dims(), [10, 10, 1]);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let b = bbox([0.0; 3], [1.0; 3]);
        assert!(GridSpec::from_resolution(&b, 0).is_err());
        assert!(GridSpec::from_resolution(&b, 1 << 20).is_err());
        assert!(GridSpec::from_voxel_size(&b, 0.0).is_err());
        assert!(GridSpec::from_voxel_size(&b, f64::NAN).is_err());
        assert!(GridSpec::from_voxel_size(&b, 1e-12).is_err());
        assert!(GridSpec::from_resolution(&bbox([1.0; 3], [1.0; 3]), 4).is_err());
        assert!(GridSpec::new(DVec3::ZERO, 1.0, [0, 1, 1]).is_err());
        assert!(GridSpec::new(DVec3::NAN, 1.0, [1, 1, 1]).is_err());
        assert!(GridSpec::new(DVec3::ZERO, [1.0, 0.0, 1.0], [1, 1, 1]).is_err());
        assert!(GridSpec::new(DVec3::ZERO, [1.0, 1.0, f64::INFINITY], [1, 1, 1]).is_err());
        assert!(GridSpec::from_voxel_size(&b, [0.5, 1e-12, 0.5]).is_err());
    }

    #[test]
    fn boxes_fit_per_axis() {
        let g = GridSpec::from_voxel_size(&bbox([0.0; 3], [1.4, 1.4, 5.0]), [0.7, 0.7, 2.5]).unwrap();
        assert_eq!(g.dims(), [2, 2, 2]);
        assert_eq!(g.voxel_size().cube(), None);
        assert_eq!(g.to_grid_units(DVec3::new(0.7, 1.4, 2.5)), DVec3::new(1.0, 2.0, 1.0));
        assert!((g.voxel_center([1, 0, 1]) - DVec3::new(1.05, 0.35, 3.75)).length() < 1e-12);
        assert_eq!(g.voxel_size().to_string(), "0.7,0.7,2.5");
        assert_eq!(VoxelSize::from(0.5).to_string(), "0.5");
    }
}
