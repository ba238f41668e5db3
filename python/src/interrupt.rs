//! Work off the GIL that Ctrl-C stops: the result comes back the moment
//! the work ends, and Python's signal handlers run while it has not.

use pyo3::exceptions::PyRuntimeError;
use std::sync::mpsc::{self, RecvTimeoutError};

use pyo3::prelude::*;
use topovox::voxelize::Stop;

/// How often [`interruptible`] looks for a signal while the work runs.
pub(crate) const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// Runs `work` on a thread of its own, without the GIL, while this thread
/// waits for its result and runs Python's signal handlers every
/// [`SIGNAL_POLL`]. The result comes back over a channel, so the caller
/// wakes the moment the work is done, never a poll later. When a handler
/// raises (Ctrl-C: `KeyboardInterrupt`), `stop` is requested, the work is
/// waited for (it gives up at its next look at `stop`: a slab, tile, brick
/// row, mesh or buffered write) and the handler's exception is raised;
/// what the work made is dropped. Outside the main thread Python runs no
/// signal handlers, and this only runs the work.
pub(crate) fn interruptible<T: Send>(py: Python<'_>, stop: &Stop, work: impl FnOnce() -> T + Send) -> PyResult<T> {
    interruptible_ticking(py, stop, work, |_| Ok(()))
}

/// [`interruptible`], calling `tick` on this thread, with the GIL, at every
/// poll and once when the work is done (a progress callback). An error
/// from `tick` stops the work as Ctrl-C does.
pub(crate) fn interruptible_ticking<T: Send>(
    py: Python<'_>,
    stop: &Stop,
    work: impl FnOnce() -> T + Send,
    tick: impl FnMut(Python<'_>) -> PyResult<()>,
) -> PyResult<T> {
    std::thread::scope(|s| {
        let (done, result) = mpsc::sync_channel(1);
        // The stack of the main thread the work would otherwise run on.
        let worker = std::thread::Builder::new()
            .stack_size(8 << 20)
            .spawn_scoped(s, move || {
                // The receiver is gone only when the caller has returned.
                let _ = done.send(work());
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start a worker thread: {e}")))?;
        match wait(py, result, tick) {
            Waited::Done(r) => Ok(r),
            Waited::Raised(e) => {
                stop.request();
                // Its result (incomplete, or an Interrupted error) is dropped.
                let _ = py.detach(|| worker.join());
                Err(e)
            }
            Waited::Died => Err(died(worker.join())),
        }
    })
}

/// The `tick` of a call that takes `progress=`, for [`interruptible_ticking`]:
/// calls `progress(finished, total)` whenever `now()` gives a new count
/// and the total is known (above zero); nothing without a callable.
pub(crate) fn progress_tick<'a, 'py>(
    progress: Option<&'a Bound<'py, PyAny>>,
    now: impl Fn() -> (u64, u64) + 'a,
) -> impl FnMut(Python<'_>) -> PyResult<()> + 'a
where
    'py: 'a,
{
    let mut shown = None;
    move |_| {
        let Some(f) = progress else { return Ok(()) };
        let counts = now();
        if counts.1 > 0 && shown != Some(counts) {
            shown = Some(counts);
            f.call1(counts)?;
        }
        Ok(())
    }
}

/// [`interruptible`] for work that cannot be stopped part way and changes
/// nothing (a read, a check): on Ctrl-C the caller returns at once and the
/// work, left to finish on its own thread, is dropped when it ends.
pub(crate) fn interruptible_read<T: Send + 'static>(py: Python<'_>, work: impl FnOnce() -> T + Send + 'static) -> PyResult<T> {
    let (done, result) = mpsc::sync_channel(1);
    let worker = std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(move || {
            let _ = done.send(work());
        })
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start a worker thread: {e}")))?;
    match wait(py, result, |_| Ok(())) {
        Waited::Done(r) => Ok(r),
        Waited::Raised(e) => Err(e),
        Waited::Died => Err(died(worker.join())),
    }
}

/// How [`wait`] ended.
enum Waited<T> {
    /// The work's result.
    Done(T),
    /// A signal handler or `tick` raised this.
    Raised(PyErr),
    /// The worker ended without a result: it panicked.
    Died,
}

/// The error of a worker that ended without a result: its panic goes on
/// here.
fn died(joined: std::thread::Result<()>) -> PyErr {
    joined.map_or_else(|p| std::panic::resume_unwind(p), |()| PyRuntimeError::new_err("the worker thread ended without a result"))
}

/// Waits for `result`, running Python's signal handlers and `tick` every
/// [`SIGNAL_POLL`] and once at the end.
fn wait<T: Send>(py: Python<'_>, mut result: mpsc::Receiver<T>, mut tick: impl FnMut(Python<'_>) -> PyResult<()>) -> Waited<T> {
    loop {
        // The receiver travels into the wait and back: it is not `Sync`.
        let got;
        (got, result) = py.detach(move || (result.recv_timeout(SIGNAL_POLL), result));
        match got {
            Ok(r) => {
                return match tick(py) {
                    Ok(()) => Waited::Done(r),
                    Err(e) => Waited::Raised(e),
                }
            }
            Err(RecvTimeoutError::Disconnected) => return Waited::Died,
            Err(RecvTimeoutError::Timeout) => {}
        }
        if let Err(e) = py.check_signals().and_then(|()| tick(py)) {
            return Waited::Raised(e);
        }
    }
}
