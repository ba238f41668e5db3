//! The keys files carried before the project was renamed (voxkit → topovox,
//! 0.1.0), which the readers keep accepting so that files users already
//! wrote still open exactly.
//!
//! The writers put the new name in every key; the readers try the new key
//! first, then the one below (the `.schem` metadata's `VoxkitUp` is a
//! serde `alias` in `schem.rs`, which must spell it as a literal). Each is
//! pinned by a file written before the rename, in
//! `tests/fixtures/voxkit-0.1/`, read back by `tests/former_name.rs` to
//! the same grid, voxels and attributes.

/// The text format's header line (`# voxkit voxels dims …`).
pub const TEXT_HEADER: &str = "# voxkit voxels";

/// The PLY point cloud's grid comment (`comment voxkit grid origin …`).
pub const PLY_GRID_COMMENT: &str = "comment voxkit grid";

/// The `.vox` root transform's up-axis attribute.
pub const VOX_UP: &str = "_voxkit_up";

/// The `.vdb` grid metadata's prefix (`voxkit_dims`, `voxkit_origin`,
/// `voxkit_voxel_size`).
pub const VDB_META_PREFIX: &str = "voxkit_";

/// The Zarr group or array attribute holding the placement.
pub const ZARR_ATTRIBUTES: &str = "voxkit";
