//! `nbv`: the command-line front end of nbv-twin.

use clap::Parser;

/// Digital-twin testbed for hybrid-range next-best-view exploration of unknown objects.
#[derive(Debug, Parser)]
#[command(name = "nbv", version, about, long_about = None)]
struct Cli {}

fn main() -> anyhow::Result<()> {
    tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
        .with_writer(std::io::stderr)
        .init();
    let _cli = Cli::parse();
    Ok(())
}
