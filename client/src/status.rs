//! `walkctl status [--json]`: print a running `walkd`'s status.

use crate::daemon_client::{DaemonClient, DaemonTarget, status_json, status_text};

/// Arguments of `walkctl status`.
#[derive(Debug, clap::Args)]
pub struct StatusArgs {
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub target: DaemonTarget,
}

/// Asks the daemon for its status and prints it.
pub fn run(args: &StatusArgs) -> anyhow::Result<()> {
    let client = DaemonClient::connect(&args.target.prefix()?)?;
    let status = client.status()?;
    if args.json {
        println!("{}", status_json(&status));
    } else {
        println!("{}", status_text(&status));
    }
    Ok(())
}
