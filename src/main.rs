//! `nbv`: the command-line front end of nbv-twin. Each subcommand lives in its own file
//! under `src/cli/`; this file only parses and dispatches.

mod cli;

use clap::{Parser, Subcommand};

/// Digital-twin testbed for hybrid-range next-best-view exploration of unknown objects.
#[derive(Debug, Parser)]
#[command(name = "nbv", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Scene files: validate, describe, generate random scenes, write the object meshes.
    Scene(cli::scene::SceneArgs),
    /// Acquire on the twin: the phase-1 LMS400 sweep (`mid`) or one Dinast frame (`short`);
    /// writes PLY/PCD clouds with sensor origins and ground truth, and PNG depth images.
    Scan(cli::scan::ScanArgs),
}

fn main() -> std::process::ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
        .with_writer(std::io::stderr)
        .init();
    let result = match Cli::parse().command {
        Command::Scene(args) => cli::scene::run(args),
        Command::Scan(args) => cli::scan::run(args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            // The error and its causes on one line each, without a backtrace.
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
