//! `walk-tune`: the fastest dynamic gait a robot walks without a fall, searched over step timing
//! and step length under MuJoCo (`walk_bench::tune`).

use clap::Parser;
use walk_bench::tune::TuneArgs;

fn main() -> std::process::ExitCode {
    walk_bench::tune::main(&TuneArgs::parse())
}
