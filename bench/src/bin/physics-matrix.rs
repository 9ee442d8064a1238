//! `physics-matrix`: a matrix of in-process MuJoCo walks for one robot and gait, with config
//! overrides, model error and pushes (`walk_bench::matrix`).

use clap::Parser;

/// Walk affordance sets × distances × seeds under MuJoCo in one process; report each run and
/// each group (done, speed, drift, tick time). Exit 0 when every walk is done.
#[derive(Parser)]
#[command(name = "physics-matrix", version, about)]
struct Cli {
    #[command(flatten)]
    args: walk_bench::matrix::MatrixArgs,
}

fn main() -> std::process::ExitCode {
    walk_bench::matrix::main(&Cli::parse().args)
}
