//! `walkd`: the walking daemon.
//!
//! Without a subcommand it runs the long-lived daemon (`daemon::runtime`); `walkd bench` executes
//! a generated walk in-process against the kinematic simulator (`daemon::bench`).

use clap::{Parser, Subcommand};

/// The real-time walking daemon.
#[derive(Parser)]
#[command(name = "walkd", version, about, args_conflicts_with_subcommands = true)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    daemon: daemon::runtime::DaemonArgs,
}

#[derive(Subcommand)]
enum Command {
    /// Generate, post-process and execute a walk in-process against the kinematic simulator.
    Bench(daemon::bench::BenchArgs),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Some(Command::Bench(args)) => daemon::bench::main(&args),
        None => daemon::runtime::main(&cli.daemon),
    }
}
