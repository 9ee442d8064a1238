//! The message types carried by the services (see the crate docs for who sends what).
//!
//! All are `#[repr(C)]`, `ZeroCopySend` and named `walk.v<PROTOCOL_VERSION>.<Type>` so a peer of
//! another protocol version cannot open the same service by accident. None holds a Rust `enum`
//! or `bool`: enums travel as [`Code`]s and flags as [`Flag`]s, so every bit pattern another
//! process writes is a valid message, and the receiver decodes them with a check
//! ([`crate::wire`]).

use iceoryx2::prelude::ZeroCopySend;

use crate::wire::{Code, DecodeError, Flag, wire_enum};
use crate::{FixedText, MAX_JOINTS};

/// Wrench order in [`SensorSample::wrenches`]: left foot, right foot, left hand, right hand.
pub const WRENCH_ORDER: [&str; 4] = ["left_foot", "right_foot", "left_hand", "right_hand"];

/// One sensor reading, adapter → daemon.
#[repr(C)]
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[type_name("walk.v8.SensorSample")]
pub struct SensorSample {
    /// Strictly increasing per adapter run.
    pub seq: u64,
    /// When the reading was taken, [`crate::monotonic_ns`].
    pub timestamp_ns: u64,
    /// Used entries of `q` and `qd`, in the model's joint order.
    pub joint_count: u32,
    /// Whether `imu_orientation` holds a reading.
    pub has_imu: Flag,
    /// Whether the adapter currently holds position on its own (its command watchdog tripped).
    pub adapter_holding: Flag,
    /// Joint angles (rad or m).
    pub q: [f64; MAX_JOINTS],
    /// Joint velocities.
    pub qd: [f64; MAX_JOINTS],
    /// Four 6-axis wrenches (force xyz, torque xyz) in [`WRENCH_ORDER`], world-aligned axes at
    /// the sensor frame origin.
    pub wrenches: [[f64; 6]; 4],
    /// Base orientation quaternion (x, y, z, w) when `has_imu`.
    pub imu_orientation: [f64; 4],
}

wire_enum! {
    /// What the adapter shall do with a [`JointCommand`].
    pub enum CommandMode {
        /// Keep the posture in `q_des` (velocities are zero).
        Hold = 0 => "hold",
        /// Track `q_des` / `qd_des`.
        Track = 1 => "track",
    }
}

/// One joint command, daemon → adapter.
#[repr(C)]
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[type_name("walk.v8.JointCommand")]
pub struct JointCommand {
    /// Strictly increasing per daemon run.
    pub seq: u64,
    /// `seq` of the [`SensorSample`] this command answers.
    pub answers_seq: u64,
    /// When the command was sent, [`crate::monotonic_ns`].
    pub timestamp_ns: u64,
    /// Used entries of `q_des` and `qd_des`.
    pub joint_count: u32,
    /// Hold or track.
    pub mode: Code<CommandMode>,
    /// Desired joint positions.
    pub q_des: [f64; MAX_JOINTS],
    /// Desired joint velocities.
    pub qd_des: [f64; MAX_JOINTS],
}

impl SensorSample {
    /// An all-zero sample (no joints, no IMU).
    pub const ZERO: Self = Self {
        seq: 0,
        timestamp_ns: 0,
        joint_count: 0,
        has_imu: Flag::NO,
        adapter_holding: Flag::NO,
        q: [0.0; MAX_JOINTS],
        qd: [0.0; MAX_JOINTS],
        wrenches: [[0.0; 6]; 4],
        imu_orientation: [0.0, 0.0, 0.0, 1.0],
    };

    /// The used joint angles.
    pub fn q(&self) -> &[f64] {
        &self.q[..joint_len(self.joint_count)]
    }

    /// The used joint velocities.
    pub fn qd(&self) -> &[f64] {
        &self.qd[..joint_len(self.joint_count)]
    }

    /// The IMU orientation (x, y, z, w) if the sample has one, or why `has_imu` is unreadable.
    pub fn imu(&self) -> Result<Option<[f64; 4]>, DecodeError> {
        let has_imu = self.has_imu.get().map_err(|e| e.in_field("has_imu"))?;
        Ok(has_imu.then_some(self.imu_orientation))
    }

    /// Whether the adapter holds on its own, or why `adapter_holding` is unreadable.
    pub fn holding(&self) -> Result<bool, DecodeError> {
        self.adapter_holding
            .get()
            .map_err(|e| e.in_field("adapter_holding"))
    }
}

impl Default for SensorSample {
    fn default() -> Self {
        Self::ZERO
    }
}

impl JointCommand {
    /// An all-zero hold command.
    pub const ZERO: Self = Self {
        seq: 0,
        answers_seq: 0,
        timestamp_ns: 0,
        joint_count: 0,
        mode: Code::from_raw(0),
        q_des: [0.0; MAX_JOINTS],
        qd_des: [0.0; MAX_JOINTS],
    };

    /// The used desired joint positions.
    pub fn q_des(&self) -> &[f64] {
        &self.q_des[..joint_len(self.joint_count)]
    }

    /// The used desired joint velocities.
    pub fn qd_des(&self) -> &[f64] {
        &self.qd_des[..joint_len(self.joint_count)]
    }
}

impl Default for JointCommand {
    fn default() -> Self {
        Self::ZERO
    }
}

/// A received joint count clamped to the capacity, so a corrupt count cannot index out of bounds.
fn joint_len(count: u32) -> usize {
    (count as usize).min(MAX_JOINTS)
}

wire_enum! {
    /// The daemon's state as clients see it.
    pub enum DaemonState {
        /// Up, no sequence run yet.
        Idle = 0 => "idle",
        /// Holding the current posture (after hold, abort, a watchdog trip or a finished hold).
        Holding = 1 => "holding",
        /// Executing a sequence.
        Executing = 2 => "executing",
        /// The last sequence completed.
        Done = 3 => "done",
        /// The controller faulted; `DaemonStatus::fault` says why.
        Fault = 4 => "fault",
        /// Shutting down (the last status before the daemon exits).
        Stopping = 5 => "stopping",
        /// A dynamic walk ends early under control (a fault, a hold or an abort): the swing foot
        /// lands and the robot comes to rest on both feet; then `Fault` (a fault caused it,
        /// `DaemonStatus::fault` says which) or `Holding`.
        ControlledStop = 6 => "controlled_stop",
    }
}

wire_enum! {
    /// How the daemon's control loop is clocked.
    pub enum ClockMode {
        /// Fixed rate on absolute deadlines of `CLOCK_MONOTONIC`.
        Realtime = 0 => "realtime",
        /// One tick per received sample; the simulator drives time.
        Lockstep = 1 => "lockstep",
    }
}

wire_enum! {
    /// Health of the link to the adapter as the daemon's watchdog sees it.
    pub enum LinkState {
        /// No sample received yet.
        Waiting = 0 => "waiting",
        /// Samples arrive in time.
        Fresh = 1 => "fresh",
        /// The watchdog tripped: no fresh sample for the configured number of periods.
        Stale = 2 => "stale",
    }
}

/// Percentiles of a latency distribution in microseconds.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("walk.v8.LatencySummary")]
pub struct LatencySummary {
    /// Median.
    pub p50: f32,
    /// 99th percentile.
    pub p99: f32,
    /// Maximum.
    pub max: f32,
}

/// Number of buckets of a [`LogHistogram`].
pub const HISTOGRAM_BUCKETS: usize = 20;

/// A coarse histogram of durations: bucket 0 counts [0, 2) µs, bucket `b` counts
/// [2^b, 2^(b+1)) µs, the last bucket everything above.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[type_name("walk.v8.LogHistogram")]
pub struct LogHistogram {
    /// Samples per bucket.
    pub counts: [u64; HISTOGRAM_BUCKETS],
}

impl LogHistogram {
    /// Lower bound of bucket `b` in µs.
    pub fn bucket_floor_us(b: usize) -> u64 {
        if b == 0 { 0 } else { 1 << b }
    }
}

/// The daemon's state, published at a low rate (daemon → clients) and returned by `control`.
#[repr(C)]
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[type_name("walk.v8.DaemonStatus")]
pub struct DaemonStatus {
    /// [`crate::PROTOCOL_VERSION`] of the daemon.
    pub protocol_version: u32,
    /// Process id of the daemon.
    pub pid: u32,
    /// When this status was assembled, [`crate::monotonic_ns`].
    pub timestamp_ns: u64,
    /// Controller state.
    pub state: Code<DaemonState>,
    /// Clock mode of the control loop.
    pub clock: Code<ClockMode>,
    /// Control rate.
    pub rate_hz: f64,
    /// Id of the sequence executing or last executed (0: none yet).
    pub sequence_id: u64,
    /// Index of the current stance within the sequence.
    pub stance_index: u32,
    /// Stances in the sequence.
    pub stance_count: u32,
    /// Name of the current phase of the stance transition.
    pub phase: FixedText<32>,
    /// Centre of mass in world frame (m).
    pub com: [f64; 3],
    /// Left sole pose: translation xyz + quaternion xyzw.
    pub left_foot: [f64; 7],
    /// Right sole pose: translation xyz + quaternion xyzw.
    pub right_foot: [f64; 7],
    /// The standing conditions hold and abort do not clear (another process on `sensors`,
    /// telemetry or status publication off), then the fault not yet acknowledged: its first
    /// cause, then what followed from it (empty: none).
    pub fault: FixedText<FAULT_TEXT>,
    /// Duration of the current or last controlled stop (s): from the fault or request that began
    /// it to rest on both feet (0: none since the last walk began).
    pub stop_s: f64,
    /// Adapter link as seen by the watchdog.
    pub link: Code<LinkState>,
    /// Whether the adapter reports holding on its own.
    pub adapter_holding: Flag,
    /// Control ticks executed.
    pub ticks: u64,
    /// Periods whose command went out after the period's deadline (realtime clock only).
    pub deadline_misses: u64,
    /// Periods that ended without a fresh sample.
    pub stale_periods: u64,
    /// Times the sample watchdog tripped.
    pub watchdog_trips: u64,
    /// Samples refused: for their time stamp (in the future, or older than the last one), for
    /// their publisher (not the adapter walkd pinned), or the pinned adapter's sequence going back.
    pub rejected_samples: u64,
    /// Why the last sample was refused (empty: none yet).
    pub last_rejection: FixedText<96>,
    /// Compute time of `Controller::tick`.
    pub tick_us: LatencySummary,
    /// Sample timestamp → command sent.
    pub latency_us: LatencySummary,
    /// |tick start − its grid time| (realtime clock only).
    pub jitter_us: LatencySummary,
    /// Distribution of `tick_us`.
    pub tick_histogram: LogHistogram,
    /// Distribution of `latency_us`.
    pub latency_histogram: LogHistogram,
    /// Distribution of `jitter_us`.
    pub jitter_histogram: LogHistogram,
}

impl DaemonStatus {
    /// The status of a daemon that has not ticked yet.
    pub const INITIAL: Self = Self {
        protocol_version: crate::PROTOCOL_VERSION,
        pid: 0,
        timestamp_ns: 0,
        state: Code::from_raw(0),
        clock: Code::from_raw(0),
        rate_hz: 0.0,
        sequence_id: 0,
        stance_index: 0,
        stance_count: 0,
        phase: FixedText::EMPTY,
        com: [0.0; 3],
        left_foot: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        right_foot: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        fault: FixedText::EMPTY,
        stop_s: 0.0,
        link: Code::from_raw(0),
        adapter_holding: Flag::NO,
        ticks: 0,
        deadline_misses: 0,
        stale_periods: 0,
        watchdog_trips: 0,
        rejected_samples: 0,
        last_rejection: FixedText::EMPTY,
        tick_us: LatencySummary {
            p50: 0.0,
            p99: 0.0,
            max: 0.0,
        },
        latency_us: LatencySummary {
            p50: 0.0,
            p99: 0.0,
            max: 0.0,
        },
        jitter_us: LatencySummary {
            p50: 0.0,
            p99: 0.0,
            max: 0.0,
        },
        tick_histogram: LogHistogram {
            counts: [0; HISTOGRAM_BUCKETS],
        },
        latency_histogram: LogHistogram {
            counts: [0; HISTOGRAM_BUCKETS],
        },
        jitter_histogram: LogHistogram {
            counts: [0; HISTOGRAM_BUCKETS],
        },
    };
}

impl DaemonStatus {
    /// Whether the robot is still walking its sequence: executing it, or coming to a controlled
    /// stop (a client waiting for a walk's end waits for both).
    pub fn walking(&self) -> bool {
        self.state == DaemonState::Executing || self.state == DaemonState::ControlledStop
    }

    /// Checks the fields a client decodes (state, clock, link, flags); names the first bad one.
    pub fn validate(&self) -> Result<(), DecodeError> {
        self.state.get().map_err(|e| e.in_field("state"))?;
        self.clock.get().map_err(|e| e.in_field("clock"))?;
        self.link.get().map_err(|e| e.in_field("link"))?;
        self.adapter_holding
            .get()
            .map_err(|e| e.in_field("adapter_holding"))?;
        Ok(())
    }
}

impl Default for DaemonStatus {
    fn default() -> Self {
        Self::INITIAL
    }
}

/// Capacity of [`DaemonStatus::fault`] (bytes): a first cause and the effects that followed.
pub const FAULT_TEXT: usize = 256;

/// The simulated robot's true state, simulator → evaluation clients (`sim-truth` service).
///
/// What a real robot cannot report: `walk-sim` publishes one with every sensor sample so a client
/// can measure how far the controller's estimate (in [`DaemonStatus`]) drifts from the simulated
/// robot, and judge falls from the simulator's base height and tilt. Poses use the conventions of
/// [`DaemonStatus`] (world frame, translation xyz + quaternion xyzw of the sole frames).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("walk.v8.SimTruth")]
pub struct SimTruth {
    /// Strictly increasing per simulator run (a gap means a subscriber missed messages).
    pub seq: u64,
    /// When this state was read, [`crate::monotonic_ns`]: just before the sensor sample taken
    /// from the same state was published, so it orders with the daemon's status time stamps.
    pub timestamp_ns: u64,
    /// Simulated time since the simulator started (s).
    pub sim_time_s: f64,
    /// Centre of mass in the world (m).
    pub com: [f64; 3],
    /// Left sole pose: translation xyz + quaternion xyzw.
    pub left_foot: [f64; 7],
    /// Right sole pose: translation xyz + quaternion xyzw.
    pub right_foot: [f64; 7],
    /// Height of the robot's `base_link` (pelvis) origin above the floor (m).
    pub base_height_m: f64,
    /// Angle between the `base_link` z axis and the world vertical (rad).
    pub tilt_rad: f64,
    /// Whether the simulator's fall rule fired at any time since the start (it stays set).
    pub fallen: Flag,
    /// How hard the simulated motors have worked since the start (all zero from a simulator
    /// without actuator dynamics).
    pub actuators: ActuatorLoad,
    /// How often a leg (a thigh or shin, not a sole) began touching the terrain since the start:
    /// walk-sim's `MujocoSim::terrain_collisions()` count (always 0 from the kinematic simulator
    /// and on the flat floor, where the legs have no collision geometry). Follows `actuators`
    /// (8-byte aligned, a multiple of 8 long) with no padding before it.
    pub terrain_collisions: u64,
    /// The force (N, world axes) the environment exerts on each palm (left hand, right hand): a
    /// railing it presses on, or the ground. Measured from the simulator's contact forces, not
    /// from the wrist sensors the controller reads, so a hand's share of the robot's weight can
    /// be judged (all zero from the kinematic simulator, which has no hand contacts).
    pub hand_forces: [[f64; 3]; 2],
}

/// The load of a simulated robot's motors since the simulator started, against the URDF's limits:
/// whether a walk asked more of a motor than it has. Per joint group (legs, arms, torso, head:
/// the order of `kinematics::robot::JointGroups::named`) the peak
/// of `|τ| / effort limit` (sustained: |τ| low-passed over 20 ms, see walk-sim's
/// `mujoco::actuators`) and of `|q̇| / velocity limit` over the group's joints (0 for an empty
/// group or joints without a limit).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("walk.v8.ActuatorLoad")]
pub struct ActuatorLoad {
    /// Peak sustained torque as a fraction of the effort limit, per joint group.
    pub peak_torque_fraction: [f64; 4],
    /// Peak joint speed as a fraction of the velocity limit, per joint group.
    pub peak_speed_fraction: [f64; 4],
    /// The longest stretch one joint spent at its torque limit (s).
    pub longest_at_torque_limit_s: f64,
    /// That joint's model index ([`ActuatorLoad::NO_JOINT`]: none was at its limit).
    pub longest_at_torque_limit_joint: u32,
}

impl ActuatorLoad {
    /// `longest_at_torque_limit_joint` when no joint reached its limit.
    pub const NO_JOINT: u32 = u32::MAX;
    /// Nothing measured.
    pub const ZERO: Self = Self {
        peak_torque_fraction: [0.0; 4],
        peak_speed_fraction: [0.0; 4],
        longest_at_torque_limit_s: 0.0,
        longest_at_torque_limit_joint: Self::NO_JOINT,
    };
}

impl SimTruth {
    /// An all-zero state (identity orientations, not fallen).
    pub const ZERO: Self = Self {
        seq: 0,
        timestamp_ns: 0,
        sim_time_s: 0.0,
        com: [0.0; 3],
        left_foot: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        right_foot: [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        base_height_m: 0.0,
        tilt_rad: 0.0,
        fallen: Flag::NO,
        actuators: ActuatorLoad::ZERO,
        terrain_collisions: 0,
        hand_forces: [[0.0; 3]; 2],
    };
}

impl Default for SimTruth {
    fn default() -> Self {
        Self::ZERO
    }
}

/// The daemon's answer to a submitted sequence.
#[repr(C)]
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[type_name("walk.v8.SubmitReply")]
pub struct SubmitReply {
    /// Whether the sequence was validated, prepared and started.
    pub accepted: Flag,
    /// Id given to an accepted sequence (0 when refused).
    pub sequence_id: u64,
    /// Why it was refused (empty when accepted).
    pub reason: FixedText<512>,
}

impl SubmitReply {
    /// An acceptance with the sequence's id.
    pub fn accepted(sequence_id: u64) -> Self {
        Self {
            accepted: Flag::YES,
            sequence_id,
            reason: FixedText::EMPTY,
        }
    }

    /// A refusal with its reason.
    pub fn refused(reason: &str) -> Self {
        Self {
            accepted: Flag::NO,
            sequence_id: 0,
            reason: FixedText::new(reason),
        }
    }
}

impl Default for SubmitReply {
    fn default() -> Self {
        Self::refused("")
    }
}

wire_enum! {
    /// What a client asks of the daemon on the `control` service.
    pub enum ControlCommand {
        /// Only return the current status.
        Query = 0 => "query",
        /// Stop where it is and hold the current posture (acknowledges a fault).
        Hold = 1 => "hold",
        /// Abort the executing sequence and hold safely (acknowledges a fault).
        Abort = 2 => "abort",
    }
}

/// A control request (client → daemon).
#[repr(C)]
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[type_name("walk.v8.ControlRequest")]
pub struct ControlRequest {
    /// The command.
    pub command: Code<ControlCommand>,
}

impl ControlRequest {
    /// A request for `command`.
    pub fn new(command: ControlCommand) -> Self {
        Self {
            command: Code::new(command),
        }
    }
}

impl Default for ControlRequest {
    fn default() -> Self {
        Self::new(ControlCommand::Query)
    }
}

/// The daemon's answer to a control request.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, ZeroCopySend)]
#[type_name("walk.v8.ControlReply")]
pub struct ControlReply {
    /// Whether the command was carried out.
    pub accepted: Flag,
    /// A short explanation (why refused, or what happened).
    pub message: FixedText<160>,
    /// The status right after handling the command.
    pub status: DaemonStatus,
}

#[cfg(test)]
mod tests {
    use super::*;
    use iceoryx2::prelude::ZeroCopySend;

    /// Every type name carries the protocol version, so bumping the version changes them all.
    #[test]
    fn type_names_carry_the_protocol_version() {
        let version = format!("walk.v{}.", crate::PROTOCOL_VERSION);
        // SAFETY: type_name only returns the string given in #[type_name].
        let names = unsafe {
            [
                SensorSample::type_name(),
                JointCommand::type_name(),
                DaemonStatus::type_name(),
                LatencySummary::type_name(),
                LogHistogram::type_name(),
                SubmitReply::type_name(),
                ControlRequest::type_name(),
                ControlReply::type_name(),
                SimTruth::type_name(),
                FixedText::<8>::type_name(),
                Flag::type_name(),
                Code::<CommandMode>::type_name(),
            ]
        };
        for name in names {
            assert!(name.starts_with(&version), "{name} lacks {version}");
        }
    }

    /// The fields protocols v5 and v6 added end the struct without padding before, between or
    /// after them, so the layout is the same on every target iceoryx2 maps it on.
    #[test]
    fn the_collision_count_and_the_palm_forces_end_the_truth_without_padding() {
        use std::mem::{offset_of, size_of};
        let after_actuators = offset_of!(SimTruth, actuators) + size_of::<ActuatorLoad>();
        assert_eq!(size_of::<ActuatorLoad>() % 8, 0);
        assert_eq!(offset_of!(SimTruth, terrain_collisions), after_actuators);
        let after_count = after_actuators + size_of::<u64>();
        assert_eq!(offset_of!(SimTruth, hand_forces), after_count);
        assert_eq!(
            size_of::<SimTruth>(),
            after_count + size_of::<[[f64; 3]; 2]>()
        );
    }

    #[test]
    fn joint_slices_follow_the_count_and_clamp_corrupt_counts() {
        let mut sample = SensorSample::ZERO;
        sample.joint_count = 3;
        sample.q[2] = 1.5;
        assert_eq!(sample.q(), &[0.0, 0.0, 1.5]);
        sample.joint_count = 1000;
        assert_eq!(sample.qd().len(), MAX_JOINTS);
    }
}
