//! The progress bar: drawn on a terminal, silent when stderr is piped or
//! with `--quiet`.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A progress bar that is hidden unless stderr is a terminal.
pub struct Bar(ProgressBar);

impl Bar {
    pub fn new(quiet: bool) -> Bar {
        let target = if !quiet && std::io::stderr().is_terminal() { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() };
        let pb = ProgressBar::with_draw_target(None, target);
        Bar(pb)
    }

    /// Shows a spinner with a message (for phases of unknown length).
    pub fn phase(&self, msg: &'static str) {
        self.0.set_length(0);
        self.0.set_position(0);
        self.0.set_style(ProgressStyle::with_template("{spinner} {msg} {elapsed}").unwrap_or_else(|_| ProgressStyle::default_spinner()));
        self.0.set_message(msg);
        self.0.enable_steady_tick(std::time::Duration::from_millis(120));
    }

    pub fn finish(&self) {
        self.0.finish_and_clear();
    }
}

impl topovox::voxelize::Progress for Bar {
    fn set_total(&self, total: u64) {
        self.0.disable_steady_tick();
        self.0.set_style(
            ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} slabs {elapsed}").unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        self.0.set_message("voxelizing");
        self.0.set_length(total);
        self.0.set_position(0);
    }

    fn advance(&self, n: u64) {
        self.0.inc(n);
    }

    fn phase(&self, name: &'static str) {
        Bar::phase(self, name);
    }
}
