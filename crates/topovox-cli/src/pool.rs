//! The thread pools commands run on (`--threads`, `--jobs`).

use anyhow::{Context, Result};

/// A rayon pool with `threads` workers (default: all cores).
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    thread_pool_for(threads, "--threads")
}

/// [`thread_pool`], the count named `what` (`--jobs`) in errors.
pub fn thread_pool_for(threads: Option<usize>, what: &str) -> Result<rayon::ThreadPool> {
    if let Some(n) = threads {
        topovox_job::check_threads(n, what)?;
    }
    rayon::ThreadPoolBuilder::new().num_threads(threads.unwrap_or(0)).build().context("cannot start worker threads")
}
