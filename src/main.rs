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
}

fn main() -> anyhow::Result<()> {
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
        .with_writer(std::io::stderr)
        .init();
    match Cli::parse().command {
        Command::Scene(args) => cli::scene::run(args),
    }
}
