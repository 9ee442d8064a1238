//! The observer's own message schemas, for what no Foxglove well-known schema describes. Derived
//! with `foxglove::Encode` (protobuf); the schema name is `<lower-case name>.<Name>`, e.g.
//! `walktick.WalkTick`. Units: metres, radians, newtons, newton-metres, microseconds.

use foxglove::Encode;
use foxglove::messages::{Timestamp, Vector3};

/// One control tick of walkd (`/controller/tick`): where the walk is and how the tick went.
#[derive(Debug, Clone, Encode)]
pub struct WalkTick {
    /// The answered sample's time stamp.
    pub timestamp: Timestamp,
    /// Telemetry sequence number (increases by one per tick; a gap is a lost tick).
    pub telemetry_seq: u64,
    /// Control ticks executed, this one included.
    pub tick: u64,
    /// `seq` of the sensor sample the tick answered.
    pub sample_seq: u64,
    /// `seq` of the command sent (0: none).
    pub command_seq: u64,
    /// Daemon state after the tick (`idle`, `holding`, `executing`, `done`, `fault`, …).
    pub state: String,
    /// Transition phase (`none`, `shift_com`, `unload`, `lift`, `swing`, `lower`, `reach`,
    /// `settle`).
    pub phase: String,
    /// Index of the stance being moved towards.
    pub stance_index: u32,
    /// Stances in the sequence.
    pub stance_count: u32,
    /// End-effectors in the contact set: left foot, right foot, left hand, right hand.
    pub contacts: Vec<bool>,
    /// Which end-effectors have a target (same order).
    pub target_set: Vec<bool>,
    /// Whether `com_target` holds the CoM set-point (only while executing).
    pub com_target_set: bool,
    /// CoM x/y set-point (z = 0).
    pub com_target: Vector3,
    /// Whether the ZMP and DCM fields hold values (the dynamic gait's; the static gait has none).
    pub dynamics_valid: bool,
    /// Reference ZMP (z = 0).
    pub zmp_reference: Vector3,
    /// Measured ZMP (z = 0).
    pub zmp_measured: Vector3,
    /// Reference DCM (z = 0).
    pub dcm_reference: Vector3,
    /// Measured DCM (z = 0).
    pub dcm_measured: Vector3,
    /// Planned duration of the dynamic gait's current phase (s; 0 outside a planned phase).
    pub phase_duration_s: f64,
    /// Where that duration came from: `sequence`, `clamped` (the sequence's, moved into the
    /// config's limits), `config`, or `none`.
    pub phase_timing: String,
    /// The vertical force (N) asked of each held hand, left and right (0: not held): the desired
    /// split beside the palms' measured wrenches on `/wrenches`.
    pub hand_forces_desired: Vec<f64>,
    /// Controller compute time (µs).
    pub compute_us: f64,
    /// Sample time stamp → command sent (µs; 0 without a command).
    pub latency_us: f64,
    /// Deadline misses counted before this tick.
    pub deadline_misses: u64,
}

/// One wrench: force and torque the environment exerts on the robot, world-aligned axes at the
/// force-torque frame.
#[derive(Debug, Clone, Encode)]
pub struct WalkWrench {
    /// `left_foot`, `right_foot`, `left_hand` or `right_hand`.
    pub end_effector: String,
    /// Force (N).
    pub force: Vector3,
    /// Torque (N·m).
    pub torque: Vector3,
}

/// The four wrenches of a sensor sample (`/wrenches`).
#[derive(Debug, Clone, Encode)]
pub struct WalkWrenches {
    /// The sample's time stamp.
    pub timestamp: Timestamp,
    /// The sample's `seq` (increases by one per sample; a gap is a lost sample).
    pub sample_seq: u64,
    /// Left foot, right foot, left hand, right hand.
    pub wrenches: Vec<WalkWrench>,
}

/// What a joint command is besides its joints (`/joint_commands/info`): one per command.
#[derive(Debug, Clone, Encode)]
pub struct WalkCommandInfo {
    /// When walkd sent the command.
    pub timestamp: Timestamp,
    /// The command's `seq` (increases by one per command; a gap is a lost command).
    pub seq: u64,
    /// `seq` of the sample it answers.
    pub answers_seq: u64,
    /// `hold` or `track`.
    pub mode: String,
}

/// Latency percentiles (µs).
#[derive(Debug, Clone, Encode)]
pub struct WalkLatency {
    /// Median.
    pub p50: f64,
    /// 99th percentile.
    pub p99: f64,
    /// Maximum.
    pub max: f64,
}

/// walkd's published status (`/status`, about 20 Hz).
#[derive(Debug, Clone, Encode)]
pub struct WalkStatus {
    /// When walkd assembled it.
    pub timestamp: Timestamp,
    /// Daemon state.
    pub state: String,
    /// Sequence executing or last executed (0: none).
    pub sequence_id: u64,
    /// Stance being moved towards.
    pub stance_index: u32,
    /// Stances in the sequence.
    pub stance_count: u32,
    /// Transition phase.
    pub phase: String,
    /// Unacknowledged fault: first cause, then what followed (empty: none).
    pub fault: String,
    /// Adapter link: `waiting`, `fresh` or `stale`.
    pub link: String,
    /// Control rate (Hz).
    pub rate_hz: f64,
    /// Ticks executed.
    pub ticks: u64,
    /// Periods whose command went out late.
    pub deadline_misses: u64,
    /// Periods without a fresh sample.
    pub stale_periods: u64,
    /// Sample watchdog trips.
    pub watchdog_trips: u64,
    /// Controller compute time.
    pub tick_us: WalkLatency,
    /// Sample → command.
    pub latency_us: WalkLatency,
    /// Tick start jitter.
    pub jitter_us: WalkLatency,
}
