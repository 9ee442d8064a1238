//! `walkd`: the walking daemon (`daemon::runtime`).

use clap::Parser;

/// The real-time walking daemon.
#[derive(Parser)]
#[command(name = "walkd", version, about)]
struct Cli {
    #[command(flatten)]
    daemon: daemon::runtime::DaemonArgs,
}

fn main() -> std::process::ExitCode {
    daemon::runtime::main(&Cli::parse().daemon)
}
