//! `walkctl submit FILE [--postprocess] [--gait static|dynamic]`: send a stance sequence to a
//! running `walkd`, walked with the gait the file names (or `--gait`), else the robot config's
//! `[gait] default`.

use std::path::PathBuf;

use anyhow::{Context, bail};
use kinematics::ConfigFile;
use kinematics::robot::Robot;
use stance::Gait;

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
    /// Gait to walk with, replacing the one the file names. With --postprocess: also the limits
    /// it is post-processed with (default there: the config's `[gait] default`). With --config,
    /// a gait the robot cannot walk is refused before the file is read.
    #[arg(long)]
    pub gait: Option<Gait>,
    #[command(flatten)]
    pub target: DaemonTarget,
}

/// Post-processes a raw sequence file's text for the robot of `file` with the limits of `gait`.
fn postprocess_text(
    text: &str,
    file: &ConfigFile,
    urdf: Option<&std::path::Path>,
    gait: Gait,
) -> anyhow::Result<String> {
    let robot = Robot::from_config(file, urdf)?;
    let raw = stance::RawSequence::from_json_str(text, &robot)?;
    let params = stance::PostProcessParams::from_config_for(file, gait)?;
    let processed = stance::PostProcessor::new(&robot, params).process(&raw)?;
    Ok(processed.to_json_string())
}

/// A post-processed file's text asking for `gait` instead of the gait it names.
fn with_gait(text: &str, gait: Gait) -> anyhow::Result<String> {
    let sequence = stance::PostProcessedSequence::parse_json_str(text)?;
    Ok(sequence.with_gait(Some(gait)).to_json_string())
}

/// Submits the file; prints the sequence id, or fails with the daemon's reason.
pub fn run(args: &SubmitArgs) -> anyhow::Result<()> {
    let config = args
        .target
        .config
        .as_deref()
        .map(ConfigFile::load)
        .transpose()?;
    if args.postprocess && config.is_none() {
        bail!("--postprocess needs --config CONFIG (robot and [postprocess] parameters)");
    }
    // The gait asked for (with --postprocess: by default the config's), refused now when the
    // robot cannot walk it; without --config, or for the gait the file names, walkd judges.
    let gait = match &config {
        Some(file) if args.postprocess || args.gait.is_some() => {
            Some(Gait::for_walk(args.gait, file)?)
        }
        _ => args.gait,
    };
    let mut json = read_text(&args.file)?;
    match (&config, gait) {
        (Some(file), Some(gait)) if args.postprocess => {
            json = postprocess_text(&json, file, args.urdf.as_deref(), gait)
                .with_context(|| format!("post-processing {}", args.file.display()))?;
        }
        (_, Some(gait)) => {
            json = with_gait(&json, gait)
                .with_context(|| format!("reading {}", args.file.display()))?;
        }
        _ => {}
    }
    let client = DaemonClient::connect(&args.target.prefix()?)?;
    let id = client.submit_json(&json)?;
    println!("accepted: sequence {id}");
    Ok(())
}
