//! Calls from different threads that each ask for one worker thread run
//! side by side (issue 45, item 8): one kept pool per thread count made
//! them queue on its single worker, so a data loader's threads got no
//! speed-up. Shown without timing: two calls that each wait for the other
//! to start can only both finish if they run at once.

use std::sync::mpsc;
use std::time::Duration;

mod common;

#[test]
fn one_thread_calls_from_two_threads_run_at_once() {
    let (to_b, from_a) = mpsc::channel::<()>();
    let (to_a, from_b) = mpsc::channel::<()>();
    let call = move |send: mpsc::Sender<()>, recv: mpsc::Receiver<()>| {
        move || {
            topovox_job::pool(1).unwrap().install(move || {
                send.send(()).unwrap();
                // The other call's worker must be running too.
                recv.recv_timeout(Duration::from_secs(20)).is_ok()
            })
        }
    };
    let a = std::thread::spawn(call(to_b, from_b));
    let b = std::thread::spawn(call(to_a, from_a));
    assert!(a.join().unwrap() && b.join().unwrap(), "the two calls did not run at the same time");
}

/// The same through the job itself: two batches' meshes asking for one
/// thread each (as Dask and Ray tasks do) voxelize the same voxels as one
/// alone.
#[test]
fn concurrent_voxelizations_give_the_same_voxels() {
    let cow = topovox_io::read_mesh(&common::repo("examples/meshes/cow.obj"), &topovox_io::ReadOptions::default()).unwrap();
    let plan = common::plan("sep26", 64, None);
    let run = || {
        topovox_job::pool(1)
            .unwrap()
            .install(|| topovox_job::voxelize(&plan, cow.mesh.as_ref(), "cow", None, None).unwrap().voxels.to_dense())
    };
    let alone = run();
    let both: Vec<_> = std::thread::scope(|s| {
        let h: Vec<_> = (0..2).map(|_| s.spawn(run)).collect();
        h.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert!(both.iter().all(|b| b.first_difference(&alone).is_none()));
}
