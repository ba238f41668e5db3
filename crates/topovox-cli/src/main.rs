//! The `topovox` command-line tool: arguments → plan → `commands/*`.

mod args;
mod choice;
mod commands;
mod console;
mod export;
mod flags;
mod pictures;
mod plan;
mod progress;
#[cfg(feature = "gpu")]
mod scene_input;
mod values;

use std::process::ExitCode;

use clap::error::{ContextKind, ContextValue, ErrorKind};
use clap::Parser;

use args::{Cli, Command};

fn main() -> ExitCode {
    // Panics inside third-party parsers are turned into errors by topovox-io;
    // keep them silent. Any other panic is a bug: say so in one line.
    std::panic::set_hook(Box::new(|info| {
        if !topovox_io::panic_is_fenced() {
            eprintln!("topovox: internal error (please report): {info}");
        }
    }));
    // Before any thread starts (it may set an environment variable).
    #[cfg(feature = "gpu")]
    topovox_gpu::quiet_without_display();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return usage_error(e),
    };
    remove_temporaries_on_interrupt();
    let result = match &cli.command {
        Command::Voxelize(a) => commands::voxelize::run(a),
        Command::Sdf(a) => commands::sdf::run(a),
        Command::Remesh(a) => commands::remesh::run(a),
        Command::Sample(a) => commands::sample::run(a),
        Command::Info(a) => commands::info::run(a),
        Command::Bench(a) => commands::bench::run(a),
        Command::Check(a) => commands::check::run(a),
        Command::Gaps(a) => commands::gaps::run(a),
        Command::Render(a) => commands::render::run(a),
        #[cfg(feature = "gpu")]
        Command::Scene(a) => commands::scene::run(a),
        #[cfg(feature = "gpu")]
        Command::View(a) => commands::view::run(a),
        #[cfg(feature = "gpu")]
        Command::Spray(a) => commands::spray::run(a),
        #[cfg(not(feature = "gpu"))]
        Command::Spray(_) => Err(anyhow::anyhow!("this topovox was built without the gpu feature, which holds the ray spray")),
        #[cfg(not(feature = "gpu"))]
        Command::View(_) => Err(anyhow::anyhow!("this topovox was built without the gpu feature, which holds the viewer")),
        #[cfg(not(feature = "gpu"))]
        Command::Scene(_) => Err(anyhow::anyhow!("this topovox was built without the gpu feature, which holds the scene generators")),
        Command::Convert(a) => commands::convert::run(a),
        Command::Batch(a) => commands::batch::run(a),
        Command::Raster(a) => commands::raster::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if is_broken_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("topovox: error: {}", console::one_line(&format!("{e:#}")));
            ExitCode::from(1)
        }
    }
}

/// A command line clap refused, in one line (help and the version are
/// printed whole): a flag's own parser names the flag and the problem; a
/// wrong choice lists the right ones. Exit status 2, as clap's.
fn usage_error(e: clap::Error) -> ExitCode {
    if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand) {
        e.exit();
    }
    let rendered = e.render().to_string();
    let first = rendered.lines().next().unwrap_or("invalid arguments").trim_start_matches("error: ");
    let source = std::error::Error::source(&e).map(ToString::to_string);
    let mut line = match (e.kind(), source) {
        (ErrorKind::ValueValidation, Some(why)) => match e.get(ContextKind::InvalidValue) {
            Some(ContextValue::String(v)) => format!("{why} (got {v:?})"),
            _ => why,
        },
        (ErrorKind::MissingRequiredArgument, _) => match e.get(ContextKind::InvalidArg) {
            Some(ContextValue::Strings(args)) => format!("missing {}", args.join(", ")),
            _ => first.trim_end_matches(':').to_string(),
        },
        _ => first.trim_end_matches(':').to_string(),
    };
    if let Some(ContextValue::Strings(valid)) = e.get(ContextKind::ValidValue) {
        line += &format!(" (expected one of: {})", valid.join(", "));
    }
    eprintln!("topovox: error: {}; see --help", console::one_line(&line));
    ExitCode::from(2)
}

/// On Ctrl-C (SIGINT) or SIGTERM, removes the temporaries of the outputs
/// being written and exits at once with 130 or 143, as a shell expects: an
/// interrupted run leaves neither a partial output nor a temporary behind.
fn remove_temporaries_on_interrupt() {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGINT, SIGTERM};
        let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM]) else { return };
        std::thread::spawn(move || {
            if let Some(sig) = signals.forever().next() {
                topovox_io::atomic::remove_live_temporaries(Some(128 + sig));
            }
        });
    }
}

fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe))
}
