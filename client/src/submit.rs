//! `walkctl submit FILE [--postprocess]`: send a stance sequence to a running `walkd`.

use std::path::PathBuf;

use anyhow::Context;
use kinematics::robot::Robot;

use crate::daemon_client::{DaemonClient, DaemonTarget, read_text};

/// Arguments of `walkctl submit`.
#[derive(Debug, clap::Args)]
pub struct SubmitArgs {
    /// Post-processed sequence (JSON), or a raw one with --postprocess.
    pub file: PathBuf,
    /// Run the post-processing pipeline (needs --config) on a raw sequence first.
    #[arg(long)]
    pub postprocess: bool,
    /// URDF overriding the config's (with --postprocess).
    #[arg(long)]
    pub urdf: Option<PathBuf>,
    #[command(flatten)]
    pub target: DaemonTarget,
}

/// Post-processes a raw sequence file's text for the robot of `config`.
pub fn postprocess_text(
    text: &str,
    config: &std::path::Path,
    urdf: Option<&std::path::Path>,
) -> anyhow::Result<String> {
    let robot = Robot::load(config, urdf)?;
    let raw = stance::RawSequence::from_json_str(text, &robot)?;
    let params = stance::PostProcessParams::from_config_path(config)?;
    let processed = stance::PostProcessor::new(&robot, params).process(&raw)?;
    Ok(processed.to_json_string())
}

/// Submits the file; prints the sequence id, or fails with the daemon's reason.
pub fn run(args: &SubmitArgs) -> anyhow::Result<()> {
    let mut json = read_text(&args.file)?;
    if args.postprocess {
        let config =
            args.target.config.as_deref().context(
                "--postprocess needs --config CONFIG (robot and [postprocess] parameters)",
            )?;
        json = postprocess_text(&json, config, args.urdf.as_deref())
            .with_context(|| format!("post-processing {}", args.file.display()))?;
    }
    let client = DaemonClient::connect(&args.target.prefix()?)?;
    let id = client.submit_json(&json)?;
    println!("accepted: sequence {id}");
    Ok(())
}
