//! Fuzzes the Zarr reader (what `check`, `convert` and `render` read, and
//! Python's `load_voxels`): the input is laid out as a Zarr folder
//! (`topovox_fuzz::zarr_folder`: `zarr.json`, then marked files such as
//! `c/0/0/0`), read densely and sparsely. Any folder gives voxels or an
//! error, never a panic or a hang; both readers agree; and nothing outside
//! the folder is read: the folder is read once with bait files beside it
//! (every byte a set voxel) and once without, and both reads must give the
//! same answer.
#![no_main]

use libfuzzer_sys::fuzz_target;

fn summary(dir: &std::path::Path) -> Option<String> {
    let v = topovox_io::read_voxels(dir, &topovox_io::ReadOptions::default()).ok()?;
    let mut set = Vec::new();
    v.bits.for_each_set(|i, j, k| {
        if set.len() < 4096 {
            set.push([i, j, k]);
        }
    });
    Some(format!("{:?} {} {:?} {:?}", v.bits.dims(), v.bits.count(), set, v.placement))
}

fuzz_target!(init: topovox_fuzz::fence_panics(), |data: &[u8]| {
    let root = std::env::temp_dir().join(format!("topovox-fuzz-zarr-{}", std::process::id()));
    let dir = root.join("a.zarr");
    topovox_fuzz::zarr_folder(data, &dir);
    let baits = ["OUT", "c", "0", "1"].map(|b| root.join(b));
    for b in &baits {
        let _ = std::fs::write(b, vec![1u8; 4096]);
    }
    let sparse = topovox_io::read_voxels_sparse(&dir, &topovox_io::ReadOptions { attributes: true, ..Default::default() }).ok();
    if let Ok(v) = topovox_io::read_voxels(&dir, &topovox_io::ReadOptions::default()) {
        topovox_fuzz::check_loaded(&v, sparse.as_ref());
    }
    let with_bait = summary(&dir);
    for b in &baits {
        let _ = std::fs::remove_file(b);
    }
    assert_eq!(with_bait, summary(&dir), "the read depends on files outside the Zarr folder");
});
