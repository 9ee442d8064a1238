//! `walkctl`: the command-line front of the walking controller.
//!
//! Every subcommand lives in its own module of the `client` library, which owns its arguments
//! (`clap::Args`) and its `run` function; this file only dispatches.

use clap::{Parser, Subcommand};

/// Generate, post-process, submit and watch stance sequences; inspect robot models.
#[derive(Parser)]
#[command(name = "walkctl", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print a robot model's kinematics (links, frames, CoM, Jacobians) as JSON.
    Inspect(client::inspect::InspectArgs),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Inspect(args) => client::inspect::run(args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("walkctl: error: {error:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
