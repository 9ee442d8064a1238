//! Plain `Copy` status data the controller publishes every tick (state, phase, fault, estimates).

use kinematics::robot::Robot;

/// The top-level state of the controller.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ControllerState {
    /// No sequence yet; holding the posture measured on the first tick.
    #[default]
    Idle,
    /// Holding the current posture (after `hold`/`abort`, or a fault reset).
    Holding,
    /// Executing a sequence; see [`ControllerStatus::phase`] and the stance index.
    Executing,
    /// A dynamic walk ends early under control (a fault, or a hold or abort request): the swing
    /// foot lands and the robot comes to rest on both feet, then it holds (→ `Fault` when a fault
    /// caused the stop, see [`ControllerStatus::fault`], else → `Holding`).
    ControlledStop,
    /// The sequence finished; holding the final posture.
    Done,
    /// Something went wrong; holding the last safe command. See [`ControllerStatus::fault`].
    Fault,
}

impl ControllerState {
    /// Lower-case name for logs and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Self::Idle => "idle",
            Self::Holding => "holding",
            Self::Executing => "executing",
            Self::ControlledStop => "controlled_stop",
            Self::Done => "done",
            Self::Fault => "fault",
        }
    }
}

/// The phase of a transition towards the next stance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Phase {
    /// Not executing.
    #[default]
    None,
    /// Moving the CoM over the support that remains after the next release.
    ShiftCom,
    /// Raising a foot slightly until its FT normal force drops below the release threshold.
    Unload,
    /// Lifting the released foot vertically.
    Lift,
    /// Moving a foot through the air to its next swing or pre-contact pose.
    Swing,
    /// Descending onto the contact pose until FT confirms touchdown (debounced).
    Lower,
    /// Moving a hand to its contact pose (hand contacts are confirmed by pose).
    Reach,
    /// Centring the CoM in the final support before `Done` (dynamic gait: the pendulum comes to
    /// rest over the final feet).
    Settle,
    /// Dynamic gait: both feet carry the robot while the ZMP crosses to the next stance foot.
    DoubleSupport,
    /// Dynamic gait: one foot carries the robot while the other swings to its landing.
    SingleSupport,
    /// Dynamic gait: the swing ended without a touchdown; the foot keeps descending and the plan
    /// waits, up to `late_touchdown_max_s`.
    LateTouchdown,
    /// Dynamic gait: the double support ended with the foot to lift still loaded; the plan waits,
    /// up to `late_lift_off_max_s`.
    LateLiftOff,
}

impl Phase {
    /// Lower-case name for logs and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::ShiftCom => "shift_com",
            Self::Unload => "unload",
            Self::Lift => "lift",
            Self::Swing => "swing",
            Self::Lower => "lower",
            Self::Reach => "reach",
            Self::Settle => "settle",
            Self::DoubleSupport => "double_support",
            Self::SingleSupport => "single_support",
            Self::LateTouchdown => "late_touchdown",
            Self::LateLiftOff => "late_lift_off",
        }
    }
}

/// Why the controller entered [`ControllerState::Fault`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FaultCode {
    /// No fault.
    #[default]
    None,
    /// The measurement could not be used; the detail says what was wrong with it.
    InvalidMeasurement(MeasurementFault),
    /// The adapter restarted (or its link came back) while a sequence executed.
    AdapterRestarted,
    /// The QP had no feasible point.
    QpInfeasible,
    /// The QP solver failed (iterations, numerics, bad input).
    QpFailed,
    /// The solution would have produced a non-finite command.
    NonFiniteCommand,
    /// No foot in contact to estimate the floating base from.
    LostSupport,
    /// The IMU and leg odometry disagree about the base orientation by more than
    /// `tipping_detection_rad`: the robot is rolling over a sole edge (a fall in progress).
    Tipping,
    /// A phase did not reach its target within its planned duration plus the timeout.
    Timeout(Phase),
    /// Dynamic gait: force-torque did not confirm a swing foot's touchdown within
    /// `late_touchdown_max_s` of the planned instant.
    MissedTouchdown,
    /// Dynamic gait: a walk starts standing on both feet, and the robot did not.
    NotOnBothFeet,
    /// Dynamic gait: a controlled stop could not land its swing foot (no force-torque contact
    /// and the sole not at its foothold's height): the robot holds on one foot.
    StopCouldNotLand,
    /// Static gait: landing the foot in the air would have taken a deeper crouch of the
    /// standing leg than `standing_crouch_max_m` (a landing beyond reach); the foot was put
    /// back where it lifted off, and the robot holds on both feet.
    StepOutOfReach,
}

impl FaultCode {
    /// A human-readable reason.
    pub fn describe(self) -> &'static str {
        match self {
            Self::None => "no fault",
            Self::InvalidMeasurement(_) => "invalid measurement",
            Self::AdapterRestarted => "the adapter restarted during the walk",
            Self::QpInfeasible => "QP infeasible",
            Self::QpFailed => "QP solver failed",
            Self::NonFiniteCommand => "non-finite command",
            Self::LostSupport => "no foot in contact",
            Self::Tipping => {
                "tipping: IMU and leg odometry disagree on the base orientation; stand the robot \
                 upright, then send hold to acknowledge"
            }
            Self::Timeout(Phase::ShiftCom) => "timeout: CoM shift did not reach its target",
            Self::Timeout(Phase::Unload) => {
                "timeout: foot force did not drop below the release threshold"
            }
            Self::Timeout(Phase::Lift) => "timeout: foot lift did not reach its target",
            Self::Timeout(Phase::Swing) => "timeout: swing did not reach its target",
            Self::Timeout(Phase::Lower) => "timeout: touchdown never confirmed by force-torque",
            Self::Timeout(Phase::Settle) => "timeout: CoM did not settle",
            Self::Timeout(_) => "timeout",
            Self::MissedTouchdown => "missed touchdown: force-torque never confirmed the landing",
            Self::NotOnBothFeet => "a dynamic walk starts on both feet",
            Self::StopCouldNotLand => {
                "the controlled stop could not land the swing foot (no contact where its foothold \
                 should be): holding on one foot"
            }
            Self::StepOutOfReach => {
                "step out of reach: landing the foot would have taken a deeper crouch of the \
                 standing leg than standing_crouch_max_m; the foot was put back where it lifted \
                 off, holding on both feet"
            }
        }
    }

    /// A short machine-readable code (`timeout_lower`, `qp_infeasible`, ...).
    pub fn code(self) -> &'static str {
        match self {
            Self::None => "none",
            Self::InvalidMeasurement(_) => "invalid_measurement",
            Self::AdapterRestarted => "adapter_restarted",
            Self::QpInfeasible => "qp_infeasible",
            Self::QpFailed => "qp_failed",
            Self::NonFiniteCommand => "non_finite_command",
            Self::LostSupport => "lost_support",
            Self::Tipping => "tipping",
            Self::Timeout(Phase::ShiftCom) => "timeout_shift_com",
            Self::Timeout(Phase::Unload) => "timeout_unload",
            Self::Timeout(Phase::Lift) => "timeout_lift",
            Self::Timeout(Phase::Swing) => "timeout_swing",
            Self::Timeout(Phase::Lower) => "timeout_lower",
            Self::Timeout(Phase::Settle) => "timeout_settle",
            Self::Timeout(_) => "timeout",
            Self::MissedTouchdown => "missed_touchdown",
            Self::NotOnBothFeet => "not_on_both_feet",
            Self::StopCouldNotLand => "stop_could_not_land",
            Self::StepOutOfReach => "step_out_of_reach",
        }
    }
}

impl FaultCode {
    /// The description with its details (the joint concerned, by name); writes without
    /// allocating, so the real-time thread can put it into a status text.
    pub fn describe_for(self, robot: &Robot) -> FaultDescription<'_> {
        FaultDescription { fault: self, robot }
    }
}

/// [`FaultCode::describe_for`]: a fault described with the robot's joint names.
pub struct FaultDescription<'a> {
    fault: FaultCode,
    robot: &'a Robot,
}

impl core::fmt::Display for FaultDescription<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let FaultCode::InvalidMeasurement(detail) = self.fault else {
            return f.write_str(self.fault.describe());
        };
        let names = self.robot.model.joint_names();
        let name = |j: u16| names.get(usize::from(j)).map_or("?", String::as_str);
        f.write_str("invalid measurement: ")?;
        match detail {
            MeasurementFault::JointCount(count) => write!(
                f,
                "{count} joints, the robot has {}",
                self.robot.model.dof()
            ),
            MeasurementFault::NonFiniteAngle(j) => write!(f, "q of {} is not finite", name(j)),
            MeasurementFault::NonFiniteVelocity(j) => {
                write!(f, "q̇ of {} is not finite", name(j))
            }
            MeasurementFault::NonFiniteWrench(k) => write!(f, "wrench {k} is not finite"),
            MeasurementFault::NonFiniteImu => f.write_str("the IMU orientation is not finite"),
            MeasurementFault::OutsideLimits(j) => {
                let limits = self.robot.model.joint_limits()[usize::from(j)];
                write!(
                    f,
                    "joint {} is measured outside its limits [{:.4}, {:.4}] (an encoder or \
                     calibration fault?)",
                    name(j),
                    limits.lower,
                    limits.upper
                )
            }
            MeasurementFault::BadFlag { field, value } => {
                write!(f, "{field} holds {value}, expected 0 or 1")
            }
            MeasurementFault::BadTimeStep => f.write_str("the time step is not positive"),
            MeasurementFault::Unloaded(newtons) => write!(
                f,
                "the feet carry {newtons} N of the robot's {:.0} N weight while it walks (a \
                 force-torque dropout?)",
                self.robot.model.total_mass() * kinematics::ground::GRAVITY
            ),
        }
    }
}

/// What made a measurement unusable (see [`FaultCode::InvalidMeasurement`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeasurementFault {
    /// The sample carries this many joints, not the robot's number.
    JointCount(u32),
    /// A joint angle (model index) is NaN or infinite.
    NonFiniteAngle(u16),
    /// A joint velocity is NaN or infinite.
    NonFiniteVelocity(u16),
    /// A wrench (`EndEffector` index) has a NaN or infinite entry.
    NonFiniteWrench(u8),
    /// The IMU orientation has a NaN or infinite entry.
    NonFiniteImu,
    /// A joint is measured beyond its limits by more than `joint_limit_tolerance_rad`.
    OutsideLimits(u16),
    /// A flag of the sample holds neither 0 nor 1.
    BadFlag {
        /// The field.
        field: &'static str,
        /// Its byte.
        value: u8,
    },
    /// The control period is not a positive number.
    BadTimeStep,
    /// While a walk executes, the feet carry less than `support_force_min_fraction` of the
    /// robot's weight (N, the sum measured): a force-torque dropout, or the robot off the ground.
    Unloaded(u32),
}

/// Everything a client or log needs about the controller, updated every tick (plain data).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ControllerStatus {
    /// Top-level state.
    pub state: ControllerState,
    /// Phase within the current transition (`None` unless executing).
    pub phase: Phase,
    /// Index of the stance being moved towards.
    pub stance_index: u32,
    /// Number of stances in the sequence.
    pub stance_count: u32,
    /// Estimated CoM in the world (m).
    pub com: [f64; 3],
    /// Estimated left sole pose: translation xyz + quaternion xyzw.
    pub left_foot: [f64; 7],
    /// Estimated right sole pose: translation xyz + quaternion xyzw.
    pub right_foot: [f64; 7],
    /// Feet and hands in the QP contact set, by `EndEffector` order.
    pub contacts: [bool; 4],
    /// The last fault (kept after leaving `Fault` until the next one).
    pub fault: FaultCode,
    /// Duration of the current or last controlled stop (s; 0: none since the walk began).
    pub stop_s: f64,
    /// Hand reaches the static gait gave up in this walk: a hand that did not reach its contact
    /// in time stays free and the walk goes on without it (`StateMachine::give_up_reach`).
    pub reaches_given_up: u32,
    /// Ticks since construction.
    pub ticks: u64,
    /// Iterations of the last QP solve.
    pub qp_iterations: u32,
    /// Active inequality/box constraints at the last QP solution.
    pub qp_active_constraints: u32,
    /// The dynamic gait's balance readings (zero otherwise).
    pub balance: BalanceStatus,
}

/// What the dynamic gait's stabilizer sees and asks for, ground plane (x, y; m), world frame.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct BalanceStatus {
    /// The walking pattern's ZMP.
    pub zmp_reference: [f64; 2],
    /// The stabilizer's desired ZMP (reference plus DCM feedback, inside the support).
    pub zmp_desired: [f64; 2],
    /// The ZMP from the ankle wrenches (NaN without enough load on the feet).
    pub zmp_measured: [f64; 2],
    /// The walking pattern's DCM.
    pub dcm_reference: [f64; 2],
    /// The DCM of the estimated CoM (corrected by the IMU tilt and the ZMP offset).
    pub dcm_measured: [f64; 2],
    /// The estimated CoM model error, true minus model (the ZMP offset).
    pub com_offset: [f64; 2],
    /// The footstep-plan phase under way as planned (`None` while settling), so a client sees
    /// whether the step times come from the sequence.
    pub planned_phase: Option<PlannedPhase>,
}

/// A dynamic-gait phase as the footstep plan timed it.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PlannedPhase {
    /// Its planned duration (s).
    pub duration_s: f64,
    /// Where that duration came from.
    pub timing: PhaseTiming,
}

/// Where a dynamic-gait phase's duration came from: a timed sequence sets the pace of the steps
/// it times, within the config's limits (docs/controller.md, "Footstep plan").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum PhaseTiming {
    /// The config's duration: an untimed stance in its span, or a phase the sequence does not
    /// time (hand transitions, the final and the stop's double support).
    #[default]
    Configured,
    /// The sum of its stances' durations, as the sequence gave them.
    Sequence,
    /// The sum of its stances' durations, moved into the config's limits.
    Clamped,
}

impl PhaseTiming {
    /// Lower-case name for logs and telemetry (`config`, `sequence`, `clamped`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Configured => "config",
            Self::Sequence => "sequence",
            Self::Clamped => "clamped",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names are the telemetry's wire names (runtime/telemetry.rs checks each code's name).
    #[test]
    fn phase_timings_have_their_wire_names() {
        let timings = [
            PhaseTiming::Configured,
            PhaseTiming::Sequence,
            PhaseTiming::Clamped,
        ];
        assert_eq!(
            timings.map(PhaseTiming::name),
            ["config", "sequence", "clamped"]
        );
    }
}
