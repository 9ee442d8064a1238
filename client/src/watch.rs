//! `walkctl watch`: a progress bar of the executing sequence, its phase and faults.

use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};
use shm_types::DaemonStatus;

use crate::daemon_client::{DaemonClient, DaemonTarget, status_text};

/// Arguments of `walkctl watch`.
#[derive(Debug, clap::Args)]
pub struct WatchArgs {
    /// Give up after this many seconds, 1-604800 (a week).
    #[arg(long, default_value_t = 3600, value_parser = clap::value_parser!(u64).range(1..=604_800))]
    pub timeout_s: u64,
    #[command(flatten)]
    pub target: DaemonTarget,
}

/// A progress bar fed with statuses: stances done, state, phase, last fault.
pub struct StanceProgress {
    bar: ProgressBar,
}

impl StanceProgress {
    /// A bar drawn on stderr (hidden when stderr is not a terminal).
    pub fn new() -> Self {
        let bar = ProgressBar::new(0);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} stance {pos}/{len} {msg}")
                .expect("constant template is valid"),
        );
        Self { bar }
    }

    /// Shows `status`.
    pub fn update(&self, status: &DaemonStatus) {
        self.bar.set_length(u64::from(status.stance_count));
        self.bar.set_position(u64::from(status.stance_index));
        let mut message = format!("{} {}", status.state.name(), status.phase);
        if !status.fault.is_empty() {
            message.push_str(&format!(" | fault: {}", status.fault));
        }
        if status.link.name() != "fresh" {
            message.push_str(&format!(" | adapter {}", status.link.name()));
        }
        self.bar.set_message(message);
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl Default for StanceProgress {
    fn default() -> Self {
        Self::new()
    }
}

/// Watches the current sequence until it stops executing, then prints the final status.
pub fn run(args: &WatchArgs) -> anyhow::Result<()> {
    let client = DaemonClient::connect(&args.target.prefix()?)?;
    let status = client.status()?;
    let progress = StanceProgress::new();
    progress.update(&status);
    let last = if status.walking() {
        client.wait_for_sequence(
            status.sequence_id,
            Duration::from_secs(args.timeout_s),
            |status| progress.update(status),
        )?
    } else {
        status
    };
    progress.finish();
    println!("{}", status_text(&last));
    Ok(())
}
