//! A requested stop (Python's Ctrl-C, issue 44 item 8) ends a job with
//! [`JobError::Interrupted`] and leaves nothing behind: no output, no
//! temporary, no manifest line for a mesh that was not finished; a later
//! batch does the rest.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use common::{plan, repo};
use serde_json::{json, Value};
use topovox::voxelize::Stop;
use topovox_io::{VoxelFormat, WriteOptions};
use topovox_job::batch::{self, BatchOptions, BatchProgress, Item};
use topovox_job::output::{MeshKind, Output};
use topovox_job::JobError;

mod common;

fn folder(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("topovox-job-stop-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn names(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d).unwrap().flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

fn requested() -> Arc<Stop> {
    let s = Arc::new(Stop::new());
    s.request();
    s
}

#[test]
fn a_stopped_voxelization_is_interrupted_on_every_path() {
    let cow = topovox_io::read_mesh(&repo("examples/meshes/cow.obj"), &topovox_io::ReadOptions::default()).unwrap();
    for (mode, tile) in [("cover", None), ("cover", Some(32)), ("solid", None), ("solid", Some(32)), ("tunnel26", Some(32))] {
        let p = plan(mode, 96, tile);
        let free = topovox_job::voxelize(&p, cow.mesh.as_ref(), "cow", None, Some(&Stop::new())).unwrap();
        assert!(free.report.voxels > 0, "{mode} {tile:?}");
        let r = topovox_job::voxelize(&p, cow.mesh.as_ref(), "cow", None, Some(&requested()));
        assert!(matches!(r, Err(JobError::Interrupted)), "{mode} {tile:?}: {:?}", r.map(|v| v.report.voxels));
    }
}

#[test]
fn a_stopped_write_leaves_the_old_output_and_no_temporary() {
    let d = folder("write");
    let cow = topovox_io::read_mesh(&repo("examples/meshes/cow.obj"), &topovox_io::ReadOptions::default()).unwrap();
    let v = topovox_job::voxelize(&plan("cover", 40, None), cow.mesh.as_ref(), "cow", None, None).unwrap();
    let formats = [
        ("old.npy", Output::Voxels(VoxelFormat::Npy)),
        ("old.vdb", Output::Voxels(VoxelFormat::Vdb)),
        ("old.zarr", Output::Voxels(VoxelFormat::Zarr)),
        ("old.obj", Output::Mesh(MeshKind::Obj)),
        ("old.glb", Output::Mesh(MeshKind::Glb)),
    ];
    for (name, target) in formats {
        let out = d.join(name);
        topovox_job::output::write(&out, target, &v.voxels, &v.grid, None, &WriteOptions::default()).unwrap();
    }
    let before: Vec<(String, Vec<u8>)> =
        names(&d).into_iter().filter(|n| !n.ends_with(".zarr")).map(|n| (n.clone(), std::fs::read(d.join(&n)).unwrap())).collect();
    let zarr_before = std::fs::read(d.join("old.zarr/zarr.json")).unwrap();
    let stopping = WriteOptions { stop: Some(requested()), ..WriteOptions::default() };
    let small = topovox_job::voxelize(&plan("cover", 24, None), cow.mesh.as_ref(), "cow", None, None).unwrap();
    for (name, target) in formats {
        let r = topovox_job::output::write(&d.join(name), target, &small.voxels, &small.grid, None, &stopping);
        assert!(matches!(r, Err(JobError::Interrupted)), "{name}: {r:?}");
    }
    let after: Vec<(String, Vec<u8>)> =
        names(&d).into_iter().filter(|n| !n.ends_with(".zarr")).map(|n| (n.clone(), std::fs::read(d.join(&n)).unwrap())).collect();
    assert_eq!(before, after, "a stopped write changed or left files");
    assert_eq!(std::fs::read(d.join("old.zarr/zarr.json")).unwrap(), zarr_before);
    assert!(names(&d).iter().all(|n| !n.contains(".topovox-")), "{:?}", names(&d));
    let _ = std::fs::remove_dir_all(&d);
}

/// Requests the stop once the first mesh is finished.
struct StopAfterFirst(Arc<Stop>);

impl BatchProgress for StopAfterFirst {
    fn start(&self, _total: u64, _skipped: u64) {}
    fn finished(&self, _record: &Value) {
        self.0.request();
    }
}

#[test]
fn a_stopped_batch_records_only_finished_meshes_and_resumes() {
    let d = folder("batch");
    let inputs = d.join("in");
    std::fs::create_dir_all(&inputs).unwrap();
    for n in 0..4 {
        std::fs::copy(repo("examples/meshes/cow.obj"), inputs.join(format!("cow{n}.obj"))).unwrap();
    }
    let out = d.join("out");
    let mut o = topovox_job::JobOptions::default();
    o.grid.resolution = Some(48);
    let opts =
        BatchOptions { fingerprint: json!({"test": "stop"}), ..BatchOptions::voxelize(&o, Output::Voxels(VoxelFormat::Npy)).unwrap() };
    let (files, _) = batch::collect_inputs(&[inputs], None, &out).unwrap();
    let items: Vec<Item> = batch::plan_items(&files, &out, "npy").unwrap();
    let stop = Arc::new(Stop::new());
    let one = topovox_job::pool(1).unwrap();
    let r = one.install(|| batch::run(&items, &out, &opts, &StopAfterFirst(stop.clone()), Some(&stop)));
    assert!(matches!(r, Err(JobError::Interrupted)), "{r:?}");
    let manifest = std::fs::read_to_string(out.join(batch::Manifest::open(&out).unwrap().path().file_name().unwrap())).unwrap();
    assert_eq!(manifest.lines().count(), 1, "{manifest}");
    assert!(names(&out).iter().all(|n| !n.contains(".topovox-")), "{:?}", names(&out));
    let again = one.install(|| batch::run(&items, &out, &opts, &batch::Silent, Some(&Arc::new(Stop::new())))).unwrap();
    assert_eq!((again.done, again.skipped, again.failed), (3, 1, 0));
    let _ = std::fs::remove_dir_all(&d);
}
