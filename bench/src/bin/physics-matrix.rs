//! `physics-matrix`: a matrix of in-process MuJoCo walks for one robot and gait, with config
//! overrides, model error and pushes (`walk_bench::matrix`).

use clap::Parser;
use walk_bench::matrix::MatrixArgs;

fn main() -> std::process::ExitCode {
    walk_bench::matrix::main(&MatrixArgs::parse())
}
