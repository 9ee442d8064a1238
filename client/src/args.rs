//! The ranges of the command-line numbers several commands share (walkctl's subcommands,
//! walk-bench, physics-matrix, the latency report). Each flag takes its range's parser, so a value
//! outside is refused while the command line is parsed, naming the flag:
//! `#[arg(value_parser = DISTANCE_M.parser())]`. docs/ipc.md lists every flag's range.

use kinematics::bounds::Range;
use shm_types::RuntimeConfig;

/// How far a walk goes after post-processing (m): `--distance`, `--distances`.
pub const DISTANCE_M: Range = Range::new(0.01, 1000.0);

/// A requested walking speed (m/s): from a crawl to a human's brisk walk.
pub const SPEED_M_S: Range = Range::new(0.01, 3.0);

/// A control rate (Hz): every `--rate-hz`, the range of `[runtime] rate_hz`.
pub const RATE_HZ: Range = Range::new(
    *RuntimeConfig::RATE_HZ.start(),
    *RuntimeConfig::RATE_HZ.end(),
);

/// How long to record or serve (s): `--duration` of `walkctl record` and `view`.
pub const DURATION_S: Range = Range::new(0.01, 1e6);
