//! `walkd`: the walking daemon (`daemon::runtime`).

use clap::Parser;
use daemon::runtime::DaemonArgs;

fn main() -> std::process::ExitCode {
    daemon::runtime::main(&DaemonArgs::parse())
}
