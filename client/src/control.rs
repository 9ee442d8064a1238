//! `walkctl hold` and `walkctl abort`: stop a walk and hold the current posture.

use shm_types::ControlCommand;

use crate::daemon_client::{DaemonClient, DaemonTarget};

/// Arguments of `walkctl hold` / `walkctl abort`.
#[derive(Debug, clap::Args)]
pub struct ControlArgs {
    #[command(flatten)]
    pub target: DaemonTarget,
}

/// Sends `command` (hold or abort) and prints the resulting state.
pub fn run(args: &ControlArgs, command: ControlCommand) -> anyhow::Result<()> {
    let client = DaemonClient::connect(&args.target.prefix()?)?;
    let status = client.control(command)?;
    println!("{}: walkd is {}", command.name(), status.state.name());
    Ok(())
}
