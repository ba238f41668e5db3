//! A voxel size in JSON (one number for cubes, three for boxes), and the
//! half diagonal the distance-field readers threshold at.

/// A voxel size in JSON: one number for cubes (what files and scripts
/// written before boxes hold), `[sx, sy, sz]` for boxes.
pub fn size_json(size: topovox::VoxelSize) -> serde_json::Value {
    match size.cube() {
        Some(s) => serde_json::json!(s),
        None => serde_json::json!(size.to_array()),
    }
}

/// Reads [`size_json`]'s form back: a positive finite number, or three.
pub fn size_from_json(v: &serde_json::Value) -> Option<glam::DVec3> {
    let s = match v {
        serde_json::Value::Array(a) if a.len() == 3 => glam::DVec3::new(a[0].as_f64()?, a[1].as_f64()?, a[2].as_f64()?),
        v => glam::DVec3::splat(v.as_f64()?),
    };
    (s.is_finite() && s.min_element() > 0.0).then_some(s)
}

/// Half the diagonal of a voxel of `size`: an unsigned distance field
/// (`.vdb`, `.vti`, `.zarr`) is read back as the voxels whose value is at
/// most this, those whose centre lies in reach of a surface crossing them.
pub(crate) fn half_diagonal(size: glam::DVec3) -> f64 {
    0.5 * size.length()
}
