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
    /// Write a starting robot config derived from a URDF (or from a robot's dimensions).
    InitRobot(client::init_robot::InitRobotArgs),
    /// Generate a human-like, impeded raw stance sequence for a robot.
    Generate(client::generate::GenerateArgs),
    /// Post-process a raw stance sequence (Algorithm 1) into an executable one.
    Postprocess(client::postprocess::PostprocessArgs),
    /// Measure post-processing time with the paper's Table I protocol.
    BenchPostprocess(client::bench_postprocess::BenchPostprocessArgs),
    /// Train the n-gram stance model on human demonstrations.
    Learn(client::learn::LearnArgs),
    /// Compare a trained model's generated walks with a held-out human walker (gait measures).
    Realism(client::realism::RealismArgs),
    /// Fig. 4: covered vs requested distance of learned, post-processed walks.
    BenchCoverage(client::bench_coverage::BenchCoverageArgs),
    /// Submit a stance sequence to a running walkd (post-processing it first with --postprocess).
    Submit(client::submit::SubmitArgs),
    /// Print a running walkd's status.
    Status(client::status::StatusArgs),
    /// Watch the executing sequence: stances, phase, faults.
    Watch(client::watch::WatchArgs),
    /// Abort the executing sequence; walkd holds the current posture safely.
    Abort(client::control::ControlArgs),
    /// Stop and hold the current posture.
    Hold(client::control::ControlArgs),
    /// Start walkd and walk-sim (or use a running walkd), walk, and report the outcome.
    Demo(client::demo::DemoArgs),
    /// The paper's evaluation: robots × affordance sets × distances × runs under walk-sim.
    Evaluate(client::evaluate::EvaluateArgs),
    /// Record a running walkd's streams to an MCAP file (an observer; walkd is not disturbed).
    Record(client::observe::RecordArgs),
    /// Serve a running walkd's streams live to Foxglove over its WebSocket protocol.
    View(client::observe::ViewArgs),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Inspect(args) => client::inspect::run(args),
        Command::InitRobot(args) => client::init_robot::run(args),
        Command::Submit(args) => client::submit::run(args),
        Command::Status(args) => client::status::run(args),
        Command::Watch(args) => client::watch::run(args),
        Command::Abort(args) => client::control::run(args, shm_types::ControlCommand::Abort),
        Command::Hold(args) => client::control::run(args, shm_types::ControlCommand::Hold),
        Command::Demo(args) => client::demo::run(args),
        Command::Evaluate(args) => client::evaluate::run(args),
        Command::Record(args) => client::observe::run_record(args),
        Command::View(args) => client::observe::run_view(args),
        Command::Generate(args) => client::generate::run(args),
        Command::Postprocess(args) => client::postprocess::run(args),
        Command::BenchPostprocess(args) => client::bench_postprocess::run(args),
        Command::Learn(args) => client::learn::run(args),
        Command::Realism(args) => client::realism::run(args),
        Command::BenchCoverage(args) => client::bench_coverage::run(args),
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("walkctl: error: {error:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
