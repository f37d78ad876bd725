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
    /// The method end to end on a scene in the twin: report, models, map and pictures.
    Explore(cli::explore::ExploreArgs),
    /// Acquire on the twin: the phase-1 LMS400 sweep (`mid`) or one Dinast frame (`short`);
    /// writes PLY/PCD clouds with sensor origins and ground truth, and PNG depth images.
    Scan(cli::scan::ScanArgs),
    /// Phase 1 on a mid-range cloud: object clusters, occupancy grid and reduced map.
    Map(cli::map::MapArgs),
    /// PNG pictures of a scene, of point clouds, or of an occupancy map (headless).
    Render(cli::render::RenderArgs),
    /// Register views (PLY/PCD) globally by p-ICP-GPA or sequential ICP; write the poses
    /// and the merged model.
    Register(cli::register::RegisterArgs),
    /// Fuse depth views in Open3D's layout (an episode's objects/<name>/rgbd/, or another
    /// dataset) into a surface mesh; score a mesh against a true one.
    Fuse(cli::fuse::FuseArgs),
    /// Phase 1 in the twin, then each object's sorted next-best-view candidates: |O_v|,
    /// score, reachable, planned, collision in truth.
    Views(cli::views::ViewsArgs),
    /// The ground-truth ceiling of each object: the coverage every reachable camera pose
    /// achieves together, and the greedy set cover's coverage after 1, 2, … views.
    Oracle(cli::oracle::OracleArgs),
    /// Episodes of `nbv explore` over a grid of scenes, parameters and seeds: CSV, summary,
    /// plots, shards, resume, `--require` gates for CI.
    Sweep(cli::sweep::SweepArgs),
    /// Scene parameters (α_u, α_o, the gain threshold, …) tuned by Bayesian optimisation
    /// over training episodes: trials, a Pareto front of two objectives, validation.
    Tune(cli::tune::TuneArgs),
}

/// A closed standard output (`nbv scene describe … | head`) ends the program quietly with
/// status 141, as SIGPIPE ends C tools, instead of `println!`'s panic.
fn exit_quietly_on_closed_stdout() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map_or("", String::as_str);
        if message.starts_with("failed printing to stdout") && message.contains("Broken pipe") {
            std::process::exit(141);
        }
        default(info);
    }));
}

fn main() -> std::process::ExitCode {
    exit_quietly_on_closed_stdout();
    tracing_subscriber::fmt()
        // RUST_LOG overrides; by default warnings, but not wgpu-hal's complaints about
        // backends it probes and drops (a missing adapter is reported as an error anyway).
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn,wgpu_hal=off")),
        )
        .with_writer(std::io::stderr)
        .init();
    let result = match Cli::parse().command {
        Command::Scene(args) => cli::scene::run(args).map(|()| std::process::ExitCode::SUCCESS),
        Command::Explore(args) => cli::explore::run(args).map(|()| std::process::ExitCode::SUCCESS),
        Command::Scan(args) => cli::scan::run(args).map(|()| std::process::ExitCode::SUCCESS),
        Command::Map(args) => cli::map::run(args).map(|()| std::process::ExitCode::SUCCESS),
        Command::Render(args) => cli::render::run(args).map(|()| std::process::ExitCode::SUCCESS),
        Command::Register(args) => cli::register::run(args),
        Command::Fuse(args) => cli::fuse::run(args).map(|()| std::process::ExitCode::SUCCESS),
        Command::Views(args) => cli::views::run(args).map(|()| std::process::ExitCode::SUCCESS),
        Command::Oracle(args) => cli::oracle::run(args).map(|()| std::process::ExitCode::SUCCESS),
        Command::Sweep(args) => cli::sweep::run(args),
        Command::Tune(args) => cli::tune::run(args).map(|()| std::process::ExitCode::SUCCESS),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            // The error and its causes on one line each, without a backtrace.
            eprintln!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
