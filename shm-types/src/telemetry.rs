//! The control thread's per-tick telemetry (`telemetry` service, walkd → observers).
//!
//! [`DaemonStatus`](crate::DaemonStatus) carries a 20 Hz summary; an observer that draws the walk
//! needs the controller's estimate and set-points of every tick. walkd's control thread publishes
//! one [`Telemetry`] per tick, right after the tick's command went out (never between the sample
//! and the command), so observing costs the sensor → command path nothing. Like every message it
//! holds no Rust `enum` or `bool`: codes travel as [`Code`]s and flags as [`Flag`]s.
//!
//! Poses are world-frame `[x, y, z, qx, qy, qz, qw]` (metres, unit quaternion); end-effector
//! arrays are in [`WRENCH_ORDER`](crate::WRENCH_ORDER) (left foot, right foot, left hand, right
//! hand).

use iceoryx2::prelude::ZeroCopySend;

use crate::DaemonState;
use crate::wire::{Code, Flag, wire_enum};

/// Capacity of [`Telemetry::support`]: a convex hull of at most four sole corners for each of
/// four end-effectors.
pub const SUPPORT_VERTICES: usize = 16;

/// The identity pose `[0, 0, 0, 0, 0, 0, 1]`.
const IDENTITY_POSE: [f64; 7] = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];

wire_enum! {
    /// The phase of the stance transition the controller executes (the controller's `Phase`).
    pub enum WalkPhase {
        /// Not executing.
        None = 0 => "none",
        /// Moving the CoM over the support that remains after the next release.
        ShiftCom = 1 => "shift_com",
        /// Raising a foot until its force-torque reading shows it released.
        Unload = 2 => "unload",
        /// Lifting the released foot.
        Lift = 3 => "lift",
        /// Moving a foot through the air.
        Swing = 4 => "swing",
        /// Lowering a foot until force-torque confirms touchdown.
        Lower = 5 => "lower",
        /// Moving a hand to its contact.
        Reach = 6 => "reach",
        /// Centring the CoM in the final support (the dynamic gait: the pendulum coming to rest).
        Settle = 7 => "settle",
        /// Dynamic gait: both feet carry the robot while the ZMP crosses to the next stance foot.
        DoubleSupport = 8 => "double_support",
        /// Dynamic gait: one foot carries the robot while the other swings to its landing.
        SingleSupport = 9 => "single_support",
        /// Dynamic gait: the swing ended without a touchdown; the foot keeps descending.
        LateTouchdown = 10 => "late_touchdown",
        /// Dynamic gait: the foot to lift is still loaded; the plan waits.
        LateLiftOff = 11 => "late_lift_off",
    }
}

wire_enum! {
    /// Where the planned duration of the dynamic gait's current phase came from
    /// ([`Telemetry::phase_duration_s`]).
    pub enum TimingSource {
        /// No planned phase: the static gait, not executing, or settling after the last phase.
        None = 0 => "none",
        /// The robot config's duration (an untimed sequence, or a phase a sequence does not time).
        Config = 1 => "config",
        /// The sequence's stance durations, as it gave them.
        Sequence = 2 => "sequence",
        /// The sequence's stance durations, moved into the config's limits.
        Clamped = 3 => "clamped",
    }
}

/// What the controller estimated and aimed at in one control tick (walkd → observers).
#[repr(C)]
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[type_name("walk.v8.Telemetry")]
pub struct Telemetry {
    /// Increases by one with every telemetry published in a daemon run, from 1: a gap means a
    /// subscriber lost messages.
    pub seq: u64,
    /// Control ticks executed, this one included.
    pub tick: u64,
    /// `seq` of the [`SensorSample`](crate::SensorSample) this tick answered.
    pub sample_seq: u64,
    /// That sample's `timestamp_ns` ([`crate::monotonic_ns`]).
    pub sample_timestamp_ns: u64,
    /// `seq` of the [`JointCommand`](crate::JointCommand) sent this tick; 0 when the tick sent
    /// none (no valid measurement yet).
    pub command_seq: u64,
    /// When the tick's command was sent (or the tick ended, without one), [`crate::monotonic_ns`].
    pub sent_ns: u64,
    /// Compute time of the controller tick (ns).
    pub compute_ns: u64,
    /// Deadline misses counted before this tick (realtime clock; as in the status).
    pub deadline_misses: u64,
    /// Estimated floating-base pose (the URDF root link), world frame.
    pub base: [f64; 7],
    /// Estimated centre of mass, world frame (m).
    pub com: [f64; 3],
    /// Estimated end-effector (sole and palm frame) poses.
    pub end_effectors: [[f64; 7]; 4],
    /// Each end-effector's target: its anchor while in contact, else its pose task's set-point
    /// (valid where `target_set`).
    pub targets: [[f64; 7]; 4],
    /// The CoM x/y set-point of this tick (valid where `com_target_set`).
    pub com_target: [f64; 2],
    /// Support polygon of the feet in contact: ground-plane (x, y) vertices counter-clockwise,
    /// the first `support_count` valid.
    pub support: [[f64; 2]; SUPPORT_VERTICES],
    /// Reference ZMP (x, y) of the dynamic gait (valid where `dynamics_valid`).
    pub zmp_reference: [f64; 2],
    /// Measured ZMP (x, y) from the foot wrenches (valid where `dynamics_valid`).
    pub zmp_measured: [f64; 2],
    /// Reference DCM (x, y) of the dynamic gait (valid where `dynamics_valid`).
    pub dcm_reference: [f64; 2],
    /// Measured DCM (x, y) (valid where `dynamics_valid`).
    pub dcm_measured: [f64; 2],
    /// Planned duration of the dynamic gait's current phase (s; 0 where `phase_timing` is
    /// `none`): a client sees the step times a timed sequence set.
    pub phase_duration_s: f64,
    /// The vertical force (N) asked of each held hand (left, right): what its press tracks, its
    /// share of the weight in the static gait (never less than the touch); 0 for a hand not in
    /// the contact set. Beside the palms' measured wrenches it shows the desired split.
    pub hand_forces_desired: [f64; 2],
    /// Valid vertices in `support`.
    pub support_count: u32,
    /// Index of the stance being moved towards.
    pub stance_index: u32,
    /// Stances in the sequence.
    pub stance_count: u32,
    /// The daemon's state after this tick.
    pub state: Code<DaemonState>,
    /// The transition phase after this tick.
    pub phase: Code<WalkPhase>,
    /// Where `phase_duration_s` came from.
    pub phase_timing: Code<TimingSource>,
    /// End-effectors in the controller's contact set.
    pub contacts: [Flag; 4],
    /// Which entries of `targets` hold a target.
    pub target_set: [Flag; 4],
    /// Whether `com_target` holds a set-point (only while executing).
    pub com_target_set: Flag,
    /// Whether the ZMP and DCM fields hold values (the static gait has none).
    pub dynamics_valid: Flag,
}

impl Telemetry {
    /// An all-zero telemetry (identity poses, nothing valid).
    pub const ZERO: Self = Self {
        seq: 0,
        tick: 0,
        sample_seq: 0,
        sample_timestamp_ns: 0,
        command_seq: 0,
        sent_ns: 0,
        compute_ns: 0,
        deadline_misses: 0,
        base: IDENTITY_POSE,
        com: [0.0; 3],
        end_effectors: [IDENTITY_POSE; 4],
        targets: [IDENTITY_POSE; 4],
        com_target: [0.0; 2],
        support: [[0.0; 2]; SUPPORT_VERTICES],
        zmp_reference: [0.0; 2],
        zmp_measured: [0.0; 2],
        dcm_reference: [0.0; 2],
        dcm_measured: [0.0; 2],
        phase_duration_s: 0.0,
        hand_forces_desired: [0.0; 2],
        support_count: 0,
        stance_index: 0,
        stance_count: 0,
        state: Code::from_raw(0),
        phase: Code::from_raw(0),
        phase_timing: Code::from_raw(0),
        contacts: [Flag::NO; 4],
        target_set: [Flag::NO; 4],
        com_target_set: Flag::NO,
        dynamics_valid: Flag::NO,
    };

    /// The valid support polygon vertices (a corrupt count is clamped to the capacity).
    pub fn support(&self) -> &[[f64; 2]] {
        &self.support[..(self.support_count as usize).min(SUPPORT_VERTICES)]
    }
}

impl Default for Telemetry {
    fn default() -> Self {
        Self::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn support_follows_the_count_and_clamps_corrupt_counts() {
        let mut telemetry = Telemetry::ZERO;
        telemetry.support_count = 3;
        telemetry.support[2] = [0.5, -0.25];
        assert_eq!(telemetry.support().len(), 3);
        assert_eq!(telemetry.support()[2], [0.5, -0.25]);
        telemetry.support_count = 1000;
        assert_eq!(telemetry.support().len(), SUPPORT_VERTICES);
    }

    /// The fields protocols v7 and v8 added sit next to fields of their size, without padding
    /// before or after them, so the layout is the same on every target iceoryx2 maps it on.
    #[test]
    fn the_phase_timing_and_hand_force_fields_add_no_padding() {
        use std::mem::{offset_of, size_of};
        let after_dcm = offset_of!(Telemetry, dcm_measured) + size_of::<[f64; 2]>();
        assert_eq!(offset_of!(Telemetry, phase_duration_s), after_dcm);
        assert_eq!(offset_of!(Telemetry, hand_forces_desired), after_dcm + 8);
        assert_eq!(offset_of!(Telemetry, support_count), after_dcm + 24);
        let after_phase = offset_of!(Telemetry, phase) + size_of::<u32>();
        assert_eq!(offset_of!(Telemetry, phase_timing), after_phase);
        assert_eq!(offset_of!(Telemetry, contacts), after_phase + 4);
    }

    #[test]
    fn the_type_name_carries_the_protocol_version() {
        // SAFETY: type_name only returns the string given in #[type_name].
        let name = unsafe { Telemetry::type_name() };
        assert!(name.starts_with(&format!("walk.v{}.", crate::PROTOCOL_VERSION)));
    }
}
