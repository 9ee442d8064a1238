//! `walk-bench`: a walk in-process against the kinematic simulator, as fast as the machine runs
//! (`walk_bench::command`).

use clap::Parser;
use walk_bench::command::BenchArgs;

fn main() -> std::process::ExitCode {
    walk_bench::command::main(&BenchArgs::parse())
}
