//! Files written before the rename (voxkit 0.1.0, keys named `voxkit…`)
//! still open exactly: each fixture in `fixtures/voxkit-0.1/` reads back
//! to the grid, voxels and attributes that the old reader gave, which the
//! old binary recorded beside it as a `.vti` (a format with no named keys)
//! by `voxkit convert FILE FILE.vti`.
//!
//! The fixtures were written by the old binary from the bundled
//! `box-rotated.obj` (resolution 12) and the shared textured spot
//! (resolution 16; `.vdb` and `.zarr` with `--attributes`, `.schem` with
//! `--up z`), and a `.vox` of a 300-voxel sliver along x (`--up x`, unit
//! voxels): the recorded up axis matters, read without it they come back
//! rotated.

use std::path::{Path, PathBuf};

use topovox::VoxelSource;
use topovox_io::{read_voxels, read_voxels_sparse, LoadedVoxels};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/voxkit-0.1").join(name)
}

fn set_voxels(v: &dyn VoxelSource) -> Vec<[u32; 3]> {
    let mut out = Vec::new();
    v.for_each_set(&mut |i, j, k| out.push([i, j, k]));
    out.sort_unstable();
    out
}

/// Reads `name` and its recorded `.vti` and asserts they are the same grid.
fn reads_as_recorded(name: &str) -> LoadedVoxels {
    let path = fixture(name);
    let got = read_voxels(&path, &topovox_io::ReadOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
    let want = read_voxels(Path::new(&format!("{}.vti", path.display())), &topovox_io::ReadOptions::default()).unwrap();
    assert_eq!(got.bits.dims(), want.bits.dims(), "{name}: dims");
    assert!(got.bits.count() > 0, "{name}: no voxels");
    assert!(got.bits == want.bits, "{name}: voxels differ");
    // A `.vti` always has a placement: the unit grid where the file had none.
    let unit = Some((glam::DVec3::ZERO, glam::DVec3::ONE));
    assert_eq!(got.placement.or(unit), want.placement, "{name}: placement");
    assert_eq!(with_arrays(&got), with_arrays(&want), "{name}: attributes");
    got
}

/// The attributes when any array is present (the `.vti` reader gives an
/// empty set for a file without arrays).
fn with_arrays(v: &LoadedVoxels) -> Option<&topovox::attributes::VoxelAttributes> {
    v.attributes.as_ref().filter(|a| a.colour.is_some() || a.material.is_some() || a.normal.is_some() || a.coverage.is_some())
}

#[test]
fn text_header_named_voxkit_keeps_its_grid() {
    let text = std::fs::read_to_string(fixture("voxkit-box.txt")).unwrap();
    assert!(text.starts_with("# voxkit voxels dims 11 11 12"), "the fixture is an old file");
    let got = reads_as_recorded("voxkit-box.txt");
    assert!(got.placement.is_some());
}

#[test]
fn ply_point_cloud_with_voxkit_grid_comment_is_a_voxel_file() {
    assert!(topovox_io::is_voxel_file(&fixture("voxkit-box.ply")));
    let got = reads_as_recorded("voxkit-box.ply");
    assert!(got.placement.is_some());
}

#[test]
fn vdb_with_voxkit_metadata_keeps_grid_and_attributes() {
    let got = reads_as_recorded("voxkit-spot.vdb");
    assert!(got.attributes.is_some(), "written with --attributes");
    let sparse =
        read_voxels_sparse(&fixture("voxkit-spot.vdb"), &topovox_io::ReadOptions { attributes: true, ..Default::default() }).unwrap();
    assert_eq!(sparse.placement, got.placement);
    assert_eq!(sparse.bits.dims(), got.bits.dims());
    assert_eq!(set_voxels(&sparse.bits), set_voxels(&got.bits));
}

#[test]
fn zarr_with_voxkit_attributes_keeps_its_placement() {
    for name in ["voxkit-box.zarr", "voxkit-spot.zarr"] {
        let got = reads_as_recorded(name);
        assert!(got.placement.is_some(), "{name}");
        let sparse = read_voxels_sparse(&fixture(name), &topovox_io::ReadOptions { attributes: true, ..Default::default() }).unwrap();
        assert_eq!(sparse.placement, got.placement, "{name}");
        assert_eq!(set_voxels(&sparse.bits), set_voxels(&got.bits), "{name}");
    }
    assert!(reads_as_recorded("voxkit-spot.zarr").attributes.is_some());
}

#[test]
fn schem_and_vox_with_voxkit_up_axis_come_back_unrotated() {
    // Written with --up z and --up x: the recorded axis, not the default
    // (y), decides the orientation, so these fail if the old key is missed.
    let schem = reads_as_recorded("voxkit-spot.schem");
    assert_eq!(schem.bits.dims(), [9, 16, 16], "the spot's grid, as voxelize makes it");
    // A `.vox` records its up axis only in a scene graph, which only grids
    // wider than 256 get: a 300-voxel-long sliver.
    let vox = reads_as_recorded("voxkit-long.vox");
    let d = vox.bits.dims();
    assert!(d[0] >= 300 && d[1] < 8 && d[2] < 8, "the sliver lies along x: {d:?}");
}
