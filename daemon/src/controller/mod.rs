//! The controller core: a velocity-resolved whole-body QP and the stance state machine.
//!
//! It never touches IPC, clocks, files or threads: the runtime, the bench and the tests feed it a
//! [`Measurement`] and a time step, and it writes a [`Command`]. After [`Controller::new`] a tick
//! allocates nothing. See `docs/controller.md` for the behaviour and tuning.
//!
//! Each executing tick:
//! 1. checks the measurement (sizes, finite values);
//! 2. estimates the floating base from the feet in contact (leg odometry);
//! 3. advances the state machine ([`Phase`]s per transition; contact changes confirmed by FT);
//! 4. builds the QP (CoM x/y, end-effector, upright and posture tasks; contact, support polygon,
//!    joint position and velocity constraints) and solves it with the chosen back-end;
//! 5. integrates the joint command from the previous one, `q_des ← q_des + q̇·dt`, kept within
//!    `command_lead_max_rad` of the measured angle, no faster than the URDF velocity limit and inside
//!    the joint limits; `qd_des = q̇`.
//!    Integrating from the command rather than from the measurement keeps the servo offset that
//!    holds a loaded joint against gravity (a position-controlled joint commanded to where it
//!    already is exerts no torque).
//!
//! A failed solve, an invalid measurement or a phase timeout holds the last safe command and
//! enters [`ControllerState::Fault`]. A dynamic walk cannot stop in single support (its DCM keeps
//! moving), so there an invalid measurement (also: feet carrying less than
//! `support_force_min_fraction` of the weight), a missed touchdown, a hold or an abort end it with a
//! [`ControllerState::ControlledStop`] first: the swing foot lands, the robot comes to rest on both
//! feet, then it holds (`docs/safety.md`, "Controlled stop"). A tick without a usable measurement
//! meanwhile runs on the last valid state: the joints where the last command sent them, the last
//! valid wrenches, no IMU, and the plan fed forward. What the controller cannot compute through (a
//! failed solve, a non-finite command, lost support, tipping) holds at once; a static walk tipping
//! with a foot in the air first puts that foot down (a catch step, `catch_tilt_rad`).
//!
//! Joint limits are a hard guarantee: every command written is finite and inside the URDF
//! limits. A measurement is invalid when it has the wrong size, a non-finite value, or a joint
//! beyond its limits by more than `joint_limit_tolerance_rad` (a fault naming the joint). Until
//! the first valid measurement after start-up or an adapter restart ([`Controller::relink`])
//! there is no safe command at all, and [`Controller::tick`] writes none (the adapter keeps
//! holding on its own); after it, hold keeps the last command, which is always inside the
//! limits, also for a joint that is then measured outside them.

mod assembly;
mod config;
mod debounce;
mod estimator;
mod gait;
mod hand_clearance;
mod hand_press;
mod hand_support;
mod machine;
mod plan;
mod sequence;
mod sequencer;
mod status;
mod telemetry;
mod trajectory;

use std::sync::Arc;

use kinematics::configuration::Configuration;
use kinematics::kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{DVector, Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};

pub use config::{ConfigError, ControllerConfig};
pub use gait::{DynamicGaitConfig, GaitConfig, StabilizerConfig};
pub use sequence::{PreparedSequence, Refusal, SceneLimits};
pub use stance::Gait;
pub use status::{
    BalanceStatus, ControllerState, ControllerStatus, FaultCode, FaultDescription,
    MeasurementFault, Phase, PhaseTiming, PlannedPhase,
};
pub use telemetry::ControllerTelemetry;

use assembly::QpAssembler;
use estimator::BaseEstimator;
use gait::{DynamicPlan, Sensors};
use hand_clearance::HandClearance;
use hand_press::HandPress;
use machine::{Feedback, Progress};
use sequencer::Sequencer;

use crate::qp::{ClarabelSolver, DenseActiveSetSolver, QpError, QpProblem, QpSolver};

/// Which QP back-end the controller uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SolverKind {
    /// The allocation-free, warm-started dense active-set solver (the real-time default).
    #[default]
    Dense,
    /// The clarabel interior-point reference (allocates per solve; for comparison).
    Clarabel,
}

impl SolverKind {
    /// Lower-case name (`dense`, `clarabel`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Dense => "dense",
            Self::Clarabel => "clarabel",
        }
    }
}

/// One tick's input, borrowed from whatever transport delivered it.
#[derive(Clone, Copy, Debug)]
pub struct Measurement<'a> {
    /// Joint angles, model order, `len == model.dof()`.
    pub q: &'a [f64],
    /// Joint velocities.
    pub qd: &'a [f64],
    /// Force xyz and torque xyz at the FT frames, by `EndEffector` (LF, RF, LH, RH), in
    /// world-aligned axes at the sensor frame origin: the force the environment exerts on the robot.
    pub wrenches: &'a [[f64; 6]; 4],
    /// Base orientation if the adapter has an IMU (sets up the world frame on the first tick;
    /// leg odometry estimates the base afterwards, see `estimator`).
    pub imu_orientation: Option<UnitQuaternion<f64>>,
}

/// Why [`Controller::start`] gave a sequence back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StartRefusal {
    /// Another sequence is executing.
    Busy,
    /// The controller is in fault (acknowledge it with [`Controller::reset`]).
    Faulted,
    /// The last measurement was invalid (or the adapter restarted since): nothing to start from.
    NoMeasurement,
    /// The IMU shows the robot tilted beyond `tipping_detection_rad` from upright.
    NotUpright,
    /// A dynamic walk must start on both feet, and the robot does not stand on them.
    NotOnBothFeet,
    /// A controlled stop is under way.
    Stopping,
}

impl StartRefusal {
    /// Why, for the submitter.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Busy => "busy: a sequence is executing; hold or abort it first",
            Self::Faulted => "the controller is in fault; send hold or abort to acknowledge it",
            Self::NoMeasurement => {
                "no valid measurement from the adapter yet: the sequence cannot start"
            }
            Self::NotUpright => {
                "the robot is not upright (its IMU is tilted beyond tipping_detection_rad): \
                 stand it up first"
            }
            Self::NotOnBothFeet => {
                "a dynamic walk starts on both feet, and the robot does not stand on both: \
                 finish on both feet with a static walk first"
            }
            Self::Stopping => {
                "a controlled stop is under way: the robot comes to rest on both feet first"
            }
        }
    }
}

/// Why [`Controller::reset`] did not acknowledge a fault.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResetRefusal {
    /// A tipping fault stays until the IMU shows the robot upright again.
    NotUpright,
    /// A fault's controlled stop is under way; it is acknowledged once the robot rests.
    Stopping,
}

impl ResetRefusal {
    /// What a person must do.
    pub fn describe(self) -> &'static str {
        match self {
            Self::NotUpright => {
                "the robot is not upright (its IMU is tilted beyond tipping_detection_rad): stand \
                 it upright (or restart the simulator), then send hold again"
            }
            Self::Stopping => {
                "a controlled stop is under way (the swing foot lands, the robot comes to rest on \
                 both feet): send hold again once it holds"
            }
        }
    }
}

/// Whether the actuators should track the command or hold position.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommandMode {
    /// Hold `q_des` (velocity zero).
    Hold,
    /// Track `q_des` with feed-forward `qd_des`.
    Track,
}

/// One tick's output, preallocated by the caller.
#[derive(Clone, Debug, PartialEq)]
pub struct Command {
    /// Desired joint angles (always finite and inside the joint limits).
    pub q_des: DVector<f64>,
    /// Desired joint velocities.
    pub qd_des: DVector<f64>,
    /// Track or hold.
    pub mode: CommandMode,
}

impl Command {
    /// A zero hold command for `dof` joints.
    pub fn new(dof: usize) -> Self {
        Self {
            q_des: DVector::zeros(dof),
            qd_des: DVector::zeros(dof),
            mode: CommandMode::Hold,
        }
    }

    /// Whether every angle and velocity is finite: half of what the controller guarantees for
    /// every command it writes (the other half: inside the joint limits).
    pub fn is_finite(&self) -> bool {
        self.q_des.iter().chain(&self.qd_des).all(|v| v.is_finite())
    }
}

/// Why a controller could not be built.
#[derive(Debug, thiserror::Error)]
pub enum ControllerError {
    /// The configuration is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
}

/// The controller core; see the module docs.
pub struct Controller {
    robot: Arc<Robot>,
    config: ControllerConfig,
    solver: Box<dyn QpSolver + Send>,
    kinematics: Kinematics,
    configuration: Configuration,
    estimator: BaseEstimator,
    machine: Sequencer,
    assembler: QpAssembler,
    solution: Vec<f64>,
    poses: [Isometry3<f64>; 4],
    /// The last command written; inside the joint limits whenever `world_ready`.
    last_command: DVector<f64>,
    /// The world frame is set up from a valid measurement, so `last_command` is a safe command.
    world_ready: bool,
    /// The last measurement was refused, or the adapter restarted since: no walk may start
    /// until a valid one comes.
    measurement_refused: bool,
    /// The IMU orientation of the last valid measurement.
    last_imu: Option<UnitQuaternion<f64>>,
    /// The wrenches of the last valid measurement (a tick on the last valid state reads them).
    last_wrenches: [[f64; 6]; 4],
    /// The held hands' force regulation on their targets.
    hand_press: HandPress,
    /// The free hands' offsets out of the walk's railings' way.
    hand_clearance: HandClearance,
    /// Joint angles and velocities of a tick on the last valid state (preallocated).
    substitute_q: Vec<f64>,
    substitute_qd: Vec<f64>,
    /// Where a controlled stop ends: `Fault` when a fault caused it, else `Holding`.
    stop_ends_in: ControllerState,
    /// The robot's weight (N).
    weight: f64,
    /// How long the feet have carried less than `support_force_min_fraction` of it (s).
    unloaded_s: f64,
    status: ControllerStatus,
}

impl Controller {
    /// Builds a controller for `robot`; every buffer of the tick is allocated here.
    pub fn new(
        robot: Arc<Robot>,
        config: ControllerConfig,
        solver: SolverKind,
    ) -> Result<Controller, ControllerError> {
        config.validate("controller config")?;
        let model = &robot.model;
        let nv = model.nv();
        let solver: Box<dyn QpSolver + Send> = match solver {
            SolverKind::Dense => Box::new(DenseActiveSetSolver::new(
                nv,
                assembly::MAX_EQUALITY_ROWS,
                assembly::MAX_INEQUALITY_ROWS,
            )),
            SolverKind::Clarabel => Box::new(ClarabelSolver::new()),
        };
        let weight = model.total_mass() * kinematics::ground::GRAVITY;
        Ok(Controller {
            kinematics: Kinematics::new(model),
            configuration: robot.standing.clone(),
            estimator: BaseEstimator::new(robot.standing.base),
            machine: Sequencer::new(&config, robot.sole, weight),
            assembler: QpAssembler::new(&robot),
            solution: vec![0.0; nv],
            poses: [Isometry3::identity(); 4],
            last_command: robot.standing.joints.clone(),
            world_ready: false,
            measurement_refused: false,
            last_imu: None,
            last_wrenches: [[0.0; 6]; 4],
            hand_press: HandPress::default(),
            hand_clearance: HandClearance::default(),
            substitute_q: vec![0.0; model.dof()],
            substitute_qd: vec![0.0; model.dof()],
            stop_ends_in: ControllerState::Holding,
            weight,
            unloaded_s: 0.0,
            status: ControllerStatus::default(),
            solver,
            config,
            robot,
        })
    }

    /// Non-RT: validates a post-processed sequence against the robot and config and prepares it
    /// for the static gait.
    pub fn prepare(
        robot: &Robot,
        config: &ControllerConfig,
        seq: &stance::PostProcessedSequence,
    ) -> Result<PreparedSequence, Refusal> {
        PreparedSequence::new(robot, config, &config.scene_limits(), seq)
    }

    /// Non-RT: [`prepare`](Self::prepare) for `gait`; a dynamic walk is also planned here (its
    /// footsteps and walking pattern), and refused when the config has no `[gait.dynamic]` or the
    /// sequence does not end on both feet.
    pub fn prepare_gait(
        robot: &Robot,
        config: &ControllerConfig,
        gaits: &GaitConfig,
        seq: &stance::PostProcessedSequence,
        gait: Gait,
    ) -> Result<PreparedSequence, Refusal> {
        let Gait::Dynamic = gait else {
            return Self::prepare(robot, config, seq);
        };
        let dynamic = gaits.dynamic().map_err(|e| Refusal(e.to_string()))?;
        let mut prepared = PreparedSequence::new(robot, config, &dynamic.scene_limits(), seq)?;
        let plan = DynamicPlan::new(
            robot,
            &prepared.stances,
            dynamic,
            config.velocity_limit_scale,
        )?;
        prepared.dynamic = Some(Box::new(plan));
        Ok(prepared)
    }

    /// RT: begins executing `seq` (from the next tick) in Idle, Holding or Done, unless the
    /// last measurement was refused, the IMU shows the robot tilted, or `seq` is dynamic and the
    /// feet the robot stands on are not both its first stance's. Returns the previously held
    /// sequence (drop it off the RT thread); gives `seq` back with the reason otherwise.
    #[allow(clippy::type_complexity)]
    pub fn start(
        &mut self,
        seq: Box<PreparedSequence>,
    ) -> Result<Option<Box<PreparedSequence>>, (Box<PreparedSequence>, StartRefusal)> {
        let refusal = match self.status.state {
            ControllerState::Executing => Some(StartRefusal::Busy),
            ControllerState::ControlledStop => Some(StartRefusal::Stopping),
            ControllerState::Fault => Some(StartRefusal::Faulted),
            _ if self.measurement_refused => Some(StartRefusal::NoMeasurement),
            _ if !self.upright() => Some(StartRefusal::NotUpright),
            _ if self.world_ready && !self.machine.on_both_feet_for(&seq) => {
                Some(StartRefusal::NotOnBothFeet)
            }
            _ => None,
        };
        if let Some(refusal) = refusal {
            return Err((seq, refusal));
        }
        let previous = self.machine.load(seq);
        self.status.state = ControllerState::Executing;
        self.status.fault = FaultCode::None;
        self.status.stop_s = 0.0;
        self.status.stance_index = 0;
        self.status.stance_count = self.machine.progress().1 as u32;
        Ok(previous)
    }

    /// RT: one control step; see the module docs. Returns whether `out` holds a command: false
    /// until a valid measurement has set up the world (then there is no safe posture to
    /// command, and `out` is left as it is). A written command is never NaN or out of limits.
    #[must_use]
    pub fn tick(&mut self, measurement: &Measurement, dt: f64, out: &mut Command) -> bool {
        self.status.ticks += 1;
        if let Err(fault) = self
            .check_measurement(measurement, dt)
            .and_then(|()| self.check_load(measurement, dt))
        {
            return self.refuse_measurement(fault, dt, out);
        }
        self.measurement_refused = false;
        self.last_imu = measurement.imu_orientation;
        self.last_wrenches = *measurement.wrenches;
        self.control(measurement, dt, out, true)
    }

    /// RT: a measurement that could not even be decoded (e.g. a flag byte that is neither 0
    /// nor 1) or failed its checks: fault with `fault`. A dynamic walk ends with a controlled
    /// stop, and this tick runs on the last valid state; otherwise the robot holds. Returns
    /// whether `out` holds a command (see [`Controller::tick`]).
    #[must_use]
    pub fn refuse_measurement(
        &mut self,
        fault: MeasurementFault,
        dt: f64,
        out: &mut Command,
    ) -> bool {
        self.measurement_refused = true;
        let force_sensors_sane = !matches!(
            fault,
            MeasurementFault::Unloaded(_) | MeasurementFault::NonFiniteWrench(_)
        );
        self.stop_for(FaultCode::InvalidMeasurement(fault), force_sensors_sane);
        if self.status.state != ControllerState::ControlledStop || !(dt.is_finite() && dt > 0.0) {
            return self.write_hold(out);
        }
        self.tick_on_last_state(dt, out)
    }

    /// RT: a control period without a sample (the adapter link is stale). A controlled stop
    /// under way goes on, on the last valid state with the plan fed forward, so an adapter that
    /// still receives commands brings the robot to rest; otherwise nothing is commanded. Returns
    /// whether `out` holds a command.
    #[must_use]
    pub fn tick_without_measurement(&mut self, dt: f64, out: &mut Command) -> bool {
        if !(self.stopping() && dt.is_finite() && dt > 0.0) {
            return false;
        }
        self.status.ticks += 1;
        self.tick_on_last_state(dt, out)
    }

    /// Whether a controlled stop is under way: the controller needs its ticks, with or without
    /// measurements, until the robot rests.
    pub fn stopping(&self) -> bool {
        self.status.state == ControllerState::ControlledStop
    }

    /// RT: the adapter restarted, or its link came back after the watchdog tripped: the robot
    /// may stand anywhere now. The world frame, the base estimate and the hold posture are set
    /// up again from the next valid measurement (no command until then); a walk in progress
    /// faults with [`FaultCode::AdapterRestarted`].
    pub fn relink(&mut self) {
        if matches!(
            self.status.state,
            ControllerState::Executing | ControllerState::ControlledStop
        ) {
            self.enter_fault(FaultCode::AdapterRestarted);
        }
        self.world_ready = false;
        self.measurement_refused = true;
    }

    /// RT: stops executing and holds (→ Holding), as [`hold`](Self::hold) does.
    pub fn abort(&mut self) {
        self.hold();
    }

    /// RT: holds the last command (→ Holding), from any state except a fault; a dynamic walk
    /// under way ends with a controlled stop first (→ ControlledStop → Holding), and a stop
    /// under way goes on. The last command rather than the measured posture, so loaded joints
    /// keep their holding torque.
    pub fn hold(&mut self) {
        match self.status.state {
            ControllerState::Fault | ControllerState::ControlledStop => {}
            ControllerState::Executing if self.machine.stop_early(true) => {
                self.status.state = ControllerState::ControlledStop;
                self.stop_ends_in = ControllerState::Holding;
            }
            _ => {
                self.machine.stop();
                self.status.state = ControllerState::Holding;
                self.status.phase = Phase::None;
            }
        }
    }

    /// RT: acknowledges a fault (→ Holding the last safe command); no effect otherwise. A
    /// tipping fault is acknowledged only once the IMU shows the robot upright; the world frame
    /// and the base estimate then restart from the next measurement.
    pub fn reset(&mut self) -> Result<(), ResetRefusal> {
        if self.status.state == ControllerState::ControlledStop
            && self.stop_ends_in == ControllerState::Fault
        {
            return Err(ResetRefusal::Stopping);
        }
        if self.status.state != ControllerState::Fault {
            return Ok(());
        }
        if self.status.fault == FaultCode::Tipping {
            if !self.upright() {
                return Err(ResetRefusal::NotUpright);
            }
            self.world_ready = false;
        }
        self.machine.stop();
        self.status.state = ControllerState::Holding;
        self.status.phase = Phase::None;
        Ok(())
    }

    /// The status of the last tick.
    pub fn status(&self) -> &ControllerStatus {
        &self.status
    }

    /// Row capacities (equality, inequality) of the controller's QPs, to size a solver for them.
    pub fn qp_capacity() -> (usize, usize) {
        (assembly::MAX_EQUALITY_ROWS, assembly::MAX_INEQUALITY_ROWS)
    }

    /// The QP of the last executing tick (for export and solver comparison).
    pub fn last_problem(&self) -> &QpProblem {
        self.assembler.problem()
    }

    /// The robot controlled.
    pub fn robot(&self) -> &Arc<Robot> {
        &self.robot
    }

    /// One control step on `measurement` (`measured`: a real one, else the last valid state):
    /// estimation, the state machine, the QP and the command.
    fn control(
        &mut self,
        measurement: &Measurement,
        dt: f64,
        out: &mut Command,
        measured: bool,
    ) -> bool {
        if self.status.state == ControllerState::ControlledStop {
            self.status.stop_s += dt;
        }
        self.configuration.joints.copy_from_slice(measurement.q);
        if !self.world_ready {
            self.initialise_world(measurement);
        }
        if measured {
            self.correct_heading(measurement.imu_orientation, dt);
        }
        if !self.estimate(measurement, measured) {
            self.enter_fault(FaultCode::LostSupport);
            return self.write_hold(out);
        }
        if measured {
            let tilt = self.odometry_tilt_error(measurement);
            let catching = tilt > self.config.catch_tilt_rad && self.catch_for_tipping();
            if !catching && tilt > self.config.tipping_detection_rad {
                self.enter_fault(FaultCode::Tipping);
                return self.write_hold(out);
            }
        }
        if !matches!(
            self.status.state,
            ControllerState::Executing | ControllerState::ControlledStop
        ) {
            return self.write_hold(out);
        }
        let feedback = Feedback {
            com: self.kinematics.com(),
            pelvis: *self.kinematics.link_pose(self.robot.base_link),
            poses: &self.poses,
            normal_forces: measurement.wrenches.map(|w| w[2]),
            measured,
        };
        let (robot, kinematics) = (&self.robot, &self.kinematics);
        let sensors = || Sensors {
            wrenches: measurement.wrenches,
            ft_origins: robot.ft_sensors.map(|frame| {
                kinematics
                    .frame_pose(&robot.model, frame)
                    .translation
                    .vector
            }),
            base_rotation: self.configuration.base.rotation,
            imu: measurement.imu_orientation,
            measured,
        };
        match self.machine.update(&feedback, sensors, dt) {
            Progress::Running => {}
            Progress::Stopping(code) => self.stop_for(code, false),
            Progress::Done => {
                // Keep holding the last command: it carries the servo offsets of the load.
                self.status.state = match self.status.state {
                    ControllerState::ControlledStop => self.stop_ends_in,
                    _ => ControllerState::Done,
                };
                self.publish_progress();
                self.status.phase = Phase::None;
                return self.write_hold(out);
            }
            Progress::Fault(code) => {
                self.enter_fault(code);
                return self.write_hold(out);
            }
        }
        self.publish_progress();
        let posture = self
            .machine
            .posture()
            .expect("executing implies a sequence");
        let mut targets = *self.machine.targets();
        self.hand_press
            .apply(&mut targets, measurement.wrenches, &self.config, dt);
        self.hand_clearance.apply(
            &mut targets,
            &self.poses,
            self.machine.railings(),
            self.robot.palm_radius,
            &self.config,
            dt,
        );
        self.assembler.assemble(
            &self.robot,
            &self.machine.qp_config(&self.config),
            &self.kinematics,
            &self.configuration,
            &self.last_command,
            &targets,
            posture,
            dt,
        );
        match self
            .solver
            .solve(self.assembler.problem(), &mut self.solution)
        {
            Ok(info) => {
                self.status.qp_iterations = info.iterations as u32;
                self.status.qp_active_constraints = info.active_constraints as u32;
            }
            Err(error) => {
                self.enter_fault(match error {
                    QpError::Infeasible => FaultCode::QpInfeasible,
                    _ => FaultCode::QpFailed,
                });
                return self.write_hold(out);
            }
        }
        self.write_track(measurement, dt, out)
    }

    /// A tick of a controlled stop without a usable measurement: on the last valid state, the
    /// joints where the last command sent them (see the module docs). Allocation-free.
    fn tick_on_last_state(&mut self, dt: f64, out: &mut Command) -> bool {
        let mut q = std::mem::take(&mut self.substitute_q);
        let qd = std::mem::take(&mut self.substitute_qd);
        q.copy_from_slice(self.last_command.as_slice());
        let wrenches = self.last_wrenches;
        let state = Measurement {
            q: &q,
            qd: &qd,
            wrenches: &wrenches,
            imu_orientation: None,
        };
        let written = self.control(&state, dt, out, false);
        self.substitute_q = q;
        self.substitute_qd = qd;
        written
    }

    /// A fault the dynamic gait answers with a controlled stop (see the module docs), on the
    /// force-torque sensors' word when `force_sensors_sane`; a stop under way goes on and now
    /// ends in `Fault`. Anything else faults and holds at once.
    fn stop_for(&mut self, code: FaultCode, force_sensors_sane: bool) {
        match self.status.state {
            ControllerState::Executing if self.machine.stop_early(force_sensors_sane) => {
                self.status.state = ControllerState::ControlledStop;
                self.status.fault = code;
                self.stop_ends_in = ControllerState::Fault;
            }
            ControllerState::ControlledStop => {
                self.machine.stop_early(force_sensors_sane);
                if self.stop_ends_in != ControllerState::Fault {
                    self.status.fault = code;
                    self.stop_ends_in = ControllerState::Fault;
                }
            }
            _ => self.enter_fault(code),
        }
    }

    /// A robot tipping with a foot in the air puts it down before it holds (a catch step,
    /// `StateMachine::catch_swing_foot`; the static gait), from `catch_tilt_rad` on: frozen in
    /// the air, that foot stays off the ground the robot tips towards (ARMAR-4, rolling over its
    /// stance sole's inner edge mid-swing, was detected at 0.25 rad and fell a second later). A
    /// controlled stop that ends in the tipping fault; true while the foot is coming down.
    fn catch_for_tipping(&mut self) -> bool {
        match self.status.state {
            ControllerState::ControlledStop => {
                self.stop_ends_in == ControllerState::Fault
                    && self.status.fault == FaultCode::Tipping
            }
            ControllerState::Executing
                if self
                    .machine
                    .catch_swing_foot(&self.poses, self.tipped_com_offset()) =>
            {
                self.status.state = ControllerState::ControlledStop;
                self.status.fault = FaultCode::Tipping;
                self.stop_ends_in = ControllerState::Fault;
                true
            }
            _ => false,
        }
    }

    /// How far the tilt the IMU sees beyond leg odometry's has carried the CoM horizontally
    /// (world, m): the difference of the two verticals times the CoM's height above the lower
    /// foot (small angles); zero without an IMU.
    fn tipped_com_offset(&self) -> Vector2<f64> {
        let Some(imu) = self.last_imu else {
            return Vector2::zeros();
        };
        let up = Vector3::z();
        let lean = imu * up - self.configuration.base.rotation * up;
        let ground = self.poses[EndEffector::LeftFoot as usize]
            .translation
            .z
            .min(self.poses[EndEffector::RightFoot as usize].translation.z);
        lean.xy() * (self.kinematics.com().z - ground)
    }

    /// While a walk executes on force-torque it trusts, the feet must carry at least
    /// `support_force_min_fraction` of the weight, but for moments of up to `unloaded_max_s` (a
    /// sole rocking off the ground for a tick is physics; a robot that stays unloaded has lost
    /// its force-torque sensors, or the ground).
    fn check_load(&mut self, m: &Measurement, dt: f64) -> Result<(), MeasurementFault> {
        let walking = matches!(
            self.status.state,
            ControllerState::Executing | ControllerState::ControlledStop
        );
        let load = m.wrenches[EndEffector::LeftFoot as usize][2]
            + m.wrenches[EndEffector::RightFoot as usize][2];
        if !walking
            || !self.machine.trusts_force_sensors()
            || load >= self.config.support_force_min_fraction * self.weight
        {
            self.unloaded_s = 0.0;
            return Ok(());
        }
        self.unloaded_s += dt;
        if self.unloaded_s <= self.config.unloaded_max_s {
            return Ok(());
        }
        Err(MeasurementFault::Unloaded(load.max(0.0) as u32))
    }

    /// The first thing wrong with `m`, if anything: size, finiteness, joint limits.
    fn check_measurement(&self, m: &Measurement, dt: f64) -> Result<(), MeasurementFault> {
        let dof = self.robot.model.dof();
        if m.q.len() != dof || m.qd.len() != dof {
            return Err(MeasurementFault::JointCount(m.q.len() as u32));
        }
        if !(dt.is_finite() && dt > 0.0) {
            return Err(MeasurementFault::BadTimeStep);
        }
        let tolerance = self.config.joint_limit_tolerance_rad;
        for (j, limit) in self.robot.model.joint_limits().iter().enumerate() {
            let (q, qd) = (m.q[j], m.qd[j]);
            if !q.is_finite() {
                return Err(MeasurementFault::NonFiniteAngle(j as u16));
            }
            if !qd.is_finite() {
                return Err(MeasurementFault::NonFiniteVelocity(j as u16));
            }
            if q < limit.lower - tolerance || q > limit.upper + tolerance {
                return Err(MeasurementFault::OutsideLimits(j as u16));
            }
        }
        if let Some(k) = m
            .wrenches
            .iter()
            .position(|w| !w.iter().all(|v| v.is_finite()))
        {
            return Err(MeasurementFault::NonFiniteWrench(k as u8));
        }
        if m.imu_orientation
            .is_some_and(|r| !r.coords.iter().all(|v| v.is_finite()))
        {
            return Err(MeasurementFault::NonFiniteImu);
        }
        Ok(())
    }

    /// Whether the last IMU reading (if any) shows the base within `tipping_detection_rad` of
    /// its standing orientation's vertical. Without an IMU the robot counts as upright.
    fn upright(&self) -> bool {
        self.last_imu.is_none_or(|imu| {
            let relative = imu * self.robot.standing.base.rotation.inverse();
            (relative * nalgebra::Vector3::z()).angle(&nalgebra::Vector3::z())
                <= self.config.tipping_detection_rad
        })
    }

    /// Sets up the world frame on the first valid measurement and anchors the standing feet.
    fn initialise_world(&mut self, measurement: &Measurement) {
        let standing = self.estimator.initialise(
            &self.robot,
            &mut self.kinematics,
            &mut self.configuration,
            measurement.imu_orientation,
        );
        self.update_poses();
        self.machine.set_standing(standing, &self.poses);
        // The measurement may lie up to the tolerance beyond a limit; the command may not.
        for ((command, &q), limit) in self
            .last_command
            .iter_mut()
            .zip(measurement.q)
            .zip(self.robot.model.joint_limits())
        {
            *command = q.clamp(limit.lower, limit.upper);
        }
        self.world_ready = true;
    }

    /// Turns the world the anchors are held in about the vertical through the CoM, by at most
    /// `heading_correction_speed · dt`, towards the IMU's heading (`BaseEstimator::heading_error`).
    /// The base estimate turns with the anchors, so no joint moves; what changes is where the
    /// plan's world targets lie from the robot, so the next footholds are found again.
    fn correct_heading(&mut self, imu: Option<UnitQuaternion<f64>>, dt: f64) {
        let Some(imu) = imu else {
            return;
        };
        let most = self.config.heading_correction_speed * dt;
        let turn = self.estimator.heading_error(&imu).clamp(-most, most);
        if turn == 0.0 {
            return;
        }
        let com = self.kinematics.com();
        let pivot = Translation3::new(com.x, com.y, 0.0);
        let rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), turn);
        self.machine
            .move_anchors(&(pivot * rotation * pivot.inverse()));
    }

    /// Leg odometry, the anchored feet weighted by their measured load (equally when the
    /// force-torque readings are not trusted); false if no foot is anchored.
    fn estimate(&mut self, measurement: &Measurement, measured: bool) -> bool {
        let weights = if measured && self.machine.trusts_force_sensors() {
            [
                measurement.wrenches[EndEffector::LeftFoot as usize][2],
                measurement.wrenches[EndEffector::RightFoot as usize][2],
            ]
        } else {
            [1.0, 1.0]
        };
        let ok = self.estimator.update(
            &self.robot,
            &mut self.kinematics,
            &mut self.configuration,
            self.machine.foot_anchors(),
            weights,
        );
        self.update_poses();
        let com = self.kinematics.com();
        self.status.com = [com.x, com.y, com.z];
        self.status.left_foot = pose_array(&self.poses[EndEffector::LeftFoot as usize]);
        self.status.right_foot = pose_array(&self.poses[EndEffector::RightFoot as usize]);
        self.status.contacts = self.machine.targets().contacts;
        self.status.reaches_given_up = self.machine.reaches_given_up();
        ok
    }

    /// How far the IMU sees the base tilted away from where leg odometry puts it (rad; 0
    /// without an IMU): above `catch_tilt_rad` / `tipping_detection_rad` the anchored feet are no
    /// longer flat on the ground. Only the tilt counts (the angle between the two vertical axes): a
    /// stance foot turning about the vertical makes the yaws differ without any tipping.
    fn odometry_tilt_error(&self, measurement: &Measurement) -> f64 {
        measurement.imu_orientation.map_or(0.0, |imu| {
            let up = nalgebra::Vector3::z();
            let estimated = self.configuration.base.rotation * up;
            (imu * up).angle(&estimated)
        })
    }

    fn update_poses(&mut self) {
        for e in EndEffector::ALL {
            self.poses[e as usize] = self
                .kinematics
                .frame_pose(&self.robot.model, self.robot.frame(e));
        }
    }

    fn publish_progress(&mut self) {
        let (stance, count) = self.machine.progress();
        self.status.stance_index = stance as u32;
        self.status.stance_count = count as u32;
        self.status.phase = self.machine.phase();
        self.status.contacts = self.machine.targets().contacts;
        self.status.balance = *self.machine.balance();
    }

    /// Enters `Fault` with `code`; a fault already present is kept (it is the first cause).
    fn enter_fault(&mut self, code: FaultCode) {
        if self.status.state == ControllerState::Fault {
            return;
        }
        self.machine.stop();
        self.status.state = ControllerState::Fault;
        self.status.fault = code;
    }

    /// Holds `last_command`, if there is a safe one; returns whether `out` holds a command.
    fn write_hold(&self, out: &mut Command) -> bool {
        if !self.world_ready {
            return false;
        }
        out.q_des.copy_from(&self.last_command);
        out.qd_des.fill(0.0);
        out.mode = CommandMode::Hold;
        true
    }

    /// Integrates `q_des ← q_des + q̇·dt` from the last command (`last_command`), within
    /// `command_lead_max_rad` of the measured angle, no faster than the joint's URDF velocity
    /// limit (even when the lead bound drags the command after a measurement that jumped) and
    /// inside the joint limits; non-finite → fault and hold. Returns true (a command is written
    /// either way).
    fn write_track(&mut self, measurement: &Measurement, dt: f64, out: &mut Command) -> bool {
        let limits = self.robot.model.joint_limits();
        let qd = &self.solution[6..];
        if qd.iter().any(|v| !v.is_finite()) {
            self.enter_fault(FaultCode::NonFiniteCommand);
            return self.write_hold(out);
        }
        let lead = self.config.command_lead_max_rad;
        for (j, limit) in limits.iter().enumerate() {
            let measured = measurement.q[j];
            let previous = self.last_command[j];
            let reach = limit.velocity * dt;
            let q = (previous + qd[j] * dt)
                .clamp(measured - lead, measured + lead)
                .clamp(previous - reach, previous + reach)
                .clamp(limit.lower, limit.upper);
            out.q_des[j] = q;
            out.qd_des[j] = (q - previous) / dt;
        }
        out.mode = CommandMode::Track;
        self.last_command.copy_from(&out.q_des);
        true
    }
}

fn pose_array(pose: &Isometry3<f64>) -> [f64; 7] {
    let t = pose.translation.vector;
    let r = pose.rotation.coords;
    [t.x, t.y, t.z, r.x, r.y, r.z, r.w]
}
