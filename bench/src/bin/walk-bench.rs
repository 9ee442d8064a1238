//! `walk-bench`: a walk in-process against the kinematic simulator, as fast as the machine runs
//! (`walk_bench::command`).

use clap::Parser;

/// Generate (or read), post-process and execute a walk in-process against the kinematic
/// simulator; report outcome, safety and timing.
#[derive(Parser)]
#[command(name = "walk-bench", version, about)]
struct Cli {
    #[command(flatten)]
    args: walk_bench::command::BenchArgs,
}

fn main() -> std::process::ExitCode {
    walk_bench::command::main(&Cli::parse().args)
}
