//! Work off the GIL that Ctrl-C stops: the result comes back the moment
//! the work ends, and Python's signal handlers run while it has not.

use pyo3::exceptions::PyRuntimeError;
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
    mut tick: impl FnMut(Python<'_>) -> PyResult<()>,
) -> PyResult<T> {
    use std::sync::mpsc::{self, RecvTimeoutError};
    std::thread::scope(|s| {
        let (done, mut result) = mpsc::sync_channel(1);
        // The stack of the main thread the work would otherwise run on.
        let worker = std::thread::Builder::new()
            .stack_size(8 << 20)
            .spawn_scoped(s, move || {
                // The receiver is gone only when the caller has returned.
                let _ = done.send(work());
            })
            .map_err(|e| PyRuntimeError::new_err(format!("cannot start a worker thread: {e}")))?;
        loop {
            // The receiver travels into the wait and back: it is not `Sync`.
            let got;
            (got, result) = py.detach(move || (result.recv_timeout(SIGNAL_POLL), result));
            match got {
                Ok(r) => return tick(py).map(|()| r),
                // The worker ended without a result: it panicked.
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(worker.join().map_or_else(
                        |p| std::panic::resume_unwind(p),
                        |()| PyRuntimeError::new_err("the worker thread ended without a result"),
                    ))
                }
                Err(RecvTimeoutError::Timeout) => {}
            }
            if let Err(e) = py.check_signals().and_then(|()| tick(py)) {
                stop.request();
                // Its result (incomplete, or an Interrupted error) is dropped.
                let _ = py.detach(|| worker.join());
                return Err(e);
            }
        }
    })
}
