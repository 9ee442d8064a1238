//! The controller walking under rigid-body physics, in one process: `daemon::controller` in
//! closed loop with `sim_adapter::mujoco::MujocoSim` (feature `mujoco`).
//!
//! Each control tick the controller reads the simulator's joint encoders, foot FT wrenches and
//! IMU orientation, and the simulator advances one control period (four 0.5 ms physics steps at
//! 500 Hz) with the servos tracking the command. A walk succeeds when the controller reaches
//! `Done` and the simulated robot never fell (base height and torso tilt,
//! [`MujocoSim::has_fallen`]) — neither during the walk nor while holding the final posture for
//! [`PhysicsWalkOptions::settle_s`] afterwards. A walk that faults is held as long and watched
//! the same way: a fault the controller detected must not become a fall.
//!
//! Besides the outcome it measures what the paper's evaluation reports: simulated and wall time,
//! the final position error of the feet, the drift between the controller's estimate and the
//! simulator's truth (CoM and soles), and a time trace of target vs controller vs simulator for
//! the paper's Fig. 6.

use kinematic_sim::Simulator;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::Context;
use client::evaluate::actuators::ActuatorReport;
use client::evaluate::hands::hand_planned_held;
use client::evaluate::{Points, TraceSample, WATCH_AFTER_END_S, align_targets, stance_points};
use daemon::controller::{
    BalanceStatus, Controller, ControllerConfig, ControllerState, ControllerStatus,
    DynamicGaitConfig, FaultCode, Gait, GaitConfig, Phase, SolverKind,
};
use kinematics::ConfigFile;
use kinematics::ground::{GRAVITY, SupportPolygon};
use kinematics::robot::{EndEffector, Robot, SoleRectangle};
use nalgebra::{Isometry3, Vector2, Vector3};
use sim_adapter::MotorLoad;
use sim_adapter::mujoco::{MujocoError, MujocoOptions, MujocoSim, Terrain};
use stance::poses::FEET;
use stance::{
    PostProcessParams, PostProcessedSequence, Scene, WalkRequest, generate, synthetic_walk, walk_in,
};

use crate::closed_loop::{ClosedLoop, TickError, feet_midpoint};

/// How to run a physics walk.
#[derive(Clone, Debug)]
pub struct PhysicsWalkOptions {
    /// QP back-end of the controller.
    pub solver: SolverKind,
    /// Control rate (Hz); the simulator advances by its period each tick.
    pub rate_hz: f64,
    /// Simulated time after which an unfinished walk is stopped; `None`: 60 s + 20 s per stance
    /// (as `walkd bench`).
    pub time_limit_s: Option<f64>,
    /// Simulated time the final posture (or a fault's hold) is held after `Done` (or the fault)
    /// while still checking for a fall (s); by default as long as `walkctl evaluate` watches.
    pub settle_s: f64,
    /// Every this many ticks one [`TraceSample`] is recorded (0: no trace).
    pub trace_every: u64,
    /// The physics model (the walk-sim defaults).
    pub mujoco: MujocoOptions,
    /// The gait the sequence is post-processed for and walked with.
    pub gait: Gait,
    /// Replaces the robot config's `[gait.dynamic]` (experiments); `None`: the config's.
    pub dynamic: Option<DynamicGaitConfig>,
    /// A push on the pelvis during the walk.
    pub push: Option<Push>,
    /// The scene the walk goes through from its start to its goal (docs/scenes.md); `None`:
    /// the flat floor.
    pub scene: Option<Arc<Scene>>,
}

impl Default for PhysicsWalkOptions {
    fn default() -> Self {
        Self {
            solver: SolverKind::Dense,
            rate_hz: 500.0,
            time_limit_s: None,
            settle_s: WATCH_AFTER_END_S,
            trace_every: 10,
            mujoco: MujocoOptions::default(),
            gait: Gait::Static,
            dynamic: None,
            push: None,
            scene: None,
        }
    }
}

impl PhysicsWalkOptions {
    /// The defaults for a dynamic walk.
    pub fn dynamic() -> Self {
        Self {
            gait: Gait::Dynamic,
            ..Self::default()
        }
    }
}

/// An external force on the pelvis (MuJoCo `xfrc_applied`), centred on the middle of a single
/// support of the dynamic gait.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Push {
    /// Which single support (0: the first step).
    pub step: usize,
    /// Force (N, world frame).
    pub force_n: [f64; 3],
    /// How long it acts (s).
    pub duration_s: f64,
}

/// How a physics walk ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PhysicsOutcome {
    /// `Done`, and the robot stood through the settle time.
    Done,
    /// The simulated robot fell (base too low or torso tilted) at this simulated time (s).
    Fell {
        /// Simulated time of the fall (s).
        at_s: f64,
        /// The fault the controller detected before the fall, holding since: a fault it
        /// detected that still became a fall.
        after: Option<FaultCode>,
    },
    /// The controller faulted.
    Fault(FaultCode),
    /// The simulated time limit passed before `Done`.
    TimeLimit,
    /// MuJoCo found the state diverged at this simulated time (s).
    Unstable {
        /// Simulated time of the divergence (s).
        at_s: f64,
    },
}

impl PhysicsOutcome {
    /// `done`, `fell`, `fault:<code>`, `time_limit` or `unstable`.
    pub fn label(&self) -> String {
        match self {
            Self::Done => "done".to_owned(),
            Self::Fell { after: None, .. } => "fell".to_owned(),
            Self::Fell {
                after: Some(code), ..
            } => format!("fell after fault:{}", code.code()),
            Self::Fault(code) => format!("fault:{}", code.code()),
            Self::TimeLimit => "time_limit".to_owned(),
            Self::Unstable { .. } => "unstable".to_owned(),
        }
    }
}

/// Everything measured in one physics walk.
#[derive(Clone, Debug)]
pub struct PhysicsWalkReport {
    /// How it ended.
    pub outcome: PhysicsOutcome,
    /// Stances in the sequence.
    pub stances: usize,
    /// The stance the controller was moving towards at the end.
    pub stance_reached: u32,
    /// Hand reaches the controller gave up (`ControllerStatus::reaches_given_up`).
    pub reaches_given_up: u32,
    /// Control ticks until the outcome (settle time excluded).
    pub ticks: u64,
    /// Simulated time until the outcome (s, settle time excluded).
    pub sim_s: f64,
    /// Wall time of the whole closed loop, settle time included (s).
    pub wall_s: f64,
    /// Wall time spent in `Controller::tick` (s).
    pub controller_s: f64,
    /// Wall time spent in `MujocoSim::step` (s).
    pub physics_s: f64,
    /// Simulated time including the settle time (s), for the real-time factor.
    pub total_sim_s: f64,
    /// Largest distance of a simulated sole from its final-stance target at the end (m); the
    /// targets are placed on the standing feet as the controller places them.
    pub final_position_error_m: f64,
    /// Largest controller-vs-simulator CoM distance over the walk (m).
    pub max_com_drift_m: f64,
    /// Largest controller-vs-simulator sole distance over the walk (m).
    pub max_foot_drift_m: f64,
    /// Horizontal distance the simulated feet midpoint travelled (m).
    pub distance_m: f64,
    /// Largest horizontal slip of a foot in contact since its touchdown (m).
    pub max_contact_slip_m: f64,
    /// Largest tilt of the base link from vertical seen (rad).
    pub max_tilt_rad: f64,
    /// The Fig. 6 trace (every [`PhysicsWalkOptions::trace_every`] ticks), with the simulator's
    /// truth; draw it with `client::evaluate::write_fig6`.
    pub trace: Vec<TraceSample>,
    /// Simulated time of the first step: a foot left the controller's contact set (s).
    pub first_step_s: Option<f64>,
    /// Wall time of each `Controller::tick` (µs): median, 99th percentile, largest.
    pub tick_us: [f64; 3],
    /// The dynamic gait's balance tracking over the walk (zero for the static gait).
    pub balance: BalanceTracking,
    /// The controller's balance readings next to the simulator's CoM, every
    /// [`PhysicsWalkOptions::trace_every`] ticks.
    pub balance_trace: Vec<BalanceSample>,
    /// How hard the walk worked the motors against the URDF's limits (the whole run, settle
    /// time included).
    pub actuators: ActuatorReport,
    /// The held hands' mean vertical force (at the wrists, as the simulator measures it) over
    /// the robot's weight, over the ticks a hand is planned to carry
    /// (`client::evaluate::hands::hand_planned_held`); `None` when none is: what `walkctl
    /// evaluate` reports as `hand_support_share`.
    pub hand_support_share: Option<f64>,
    /// The farthest the simulator's CoM stood outside the polygon of the soles the controller
    /// had in contact for [`COM_OUTSIDE_HELD_S`] without a break (m; 0 if never): a robot
    /// leaning on a held hand stands where its feet alone would not hold it.
    pub com_outside_feet_m: f64,
    /// Simulated time the [`PhysicsWalkOptions::push`] began (s): `None` without a push, or
    /// when the walk ended before its single support, so that a push sweep cannot count a walk
    /// that was never pushed as surviving.
    pub pushed_at_s: Option<f64>,
}

/// One sample of [`PhysicsWalkReport::balance_trace`].
#[derive(Clone, Copy, Debug)]
pub struct BalanceSample {
    /// Simulated time (s).
    pub t: f64,
    /// The controller's phase.
    pub phase: Phase,
    /// The controller's ZMP and DCM readings.
    pub balance: BalanceStatus,
    /// The controller's estimated CoM (m).
    pub com_estimated: [f64; 3],
    /// The simulator's CoM (m).
    pub com_true: [f64; 3],
    /// Normal force on each foot (left, right; N).
    pub foot_forces: [f64; 2],
    /// Force on each hand at its wrist (left, right; N, world axes).
    pub hand_forces: [[f64; 3]; 2],
}

/// How closely a dynamic walk's ZMP and DCM followed the walking pattern (m), over the executing
/// ticks. The true DCM is the simulator's CoM plus its velocity over ω = √(g / z_CoM).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BalanceTracking {
    /// Measured (ankle wrenches) minus reference ZMP, root mean square.
    pub zmp_rms_m: f64,
    /// Measured minus reference ZMP, largest.
    pub zmp_max_m: f64,
    /// True minus reference DCM, root mean square.
    pub dcm_rms_m: f64,
    /// True minus reference DCM, largest.
    pub dcm_max_m: f64,
    /// Largest estimated CoM model error (the stabilizer's ZMP offset).
    pub com_offset_max_m: f64,
}

impl PhysicsWalkReport {
    /// Reached `Done` without a fall.
    pub fn success(&self) -> bool {
        self.outcome == PhysicsOutcome::Done
    }

    /// The drift reported per run: the larger of the CoM and sole drifts over the walk (m).
    pub fn drift_m(&self) -> f64 {
        self.max_com_drift_m.max(self.max_foot_drift_m)
    }

    /// Simulated time over wall time of the whole loop.
    pub fn real_time_factor(&self) -> f64 {
        self.total_sim_s / self.wall_s
    }

    /// Walking speed: the distance walked over the time from the first step to the outcome
    /// (m/s); `None` if the robot never stepped.
    pub fn speed_m_s(&self) -> Option<f64> {
        self.first_step_s
            .map(|first| self.distance_m / (self.sim_s - first))
    }
}

/// Generates the walk of `request` for the robot of `config`, post-processes it with the
/// parameters of `options.gait` (onto `options.scene`'s surfaces and railings, if any) and walks
/// it under physics.
pub fn walk_distance(
    config: &ConfigFile,
    urdf: Option<&Path>,
    request: &WalkRequest,
    options: &PhysicsWalkOptions,
) -> anyhow::Result<PhysicsWalkReport> {
    let robot = Arc::new(
        Robot::from_config(config, urdf).with_context(|| format!("loading {}", config.origin()))?,
    );
    let params = PostProcessParams::from_config_for(config, options.gait)?;
    let controller_config = ControllerConfig::from_config(config)?;
    let mut gaits = GaitConfig::from_config(config)?;
    if options.dynamic.is_some() {
        gaits.dynamic = options.dynamic;
    }
    let sequence = match &options.scene {
        Some(scene) => walk_in(
            &robot,
            &params,
            request,
            &scene.walk_environment(),
            |options| generate(&robot, options),
        )?,
        None => synthetic_walk(&robot, &params, request)?,
    };
    walk_sequence(robot, controller_config, &gaits, &sequence, options)
}

/// Executes `sequence` on `robot` with `options.gait` (tuned by `gaits`), starting from its
/// standing posture, in closed loop with MuJoCo.
pub fn walk_sequence(
    robot: Arc<Robot>,
    config: ControllerConfig,
    gaits: &GaitConfig,
    sequence: &PostProcessedSequence,
    options: &PhysicsWalkOptions,
) -> anyhow::Result<PhysicsWalkReport> {
    anyhow::ensure!(
        options.rate_hz.is_finite() && options.rate_hz > 0.0,
        "rate {} Hz: must be a positive number",
        options.rate_hz
    );
    let prepared = Controller::prepare_gait(&robot, &config, gaits, sequence, options.gait)
        .map_err(|refusal| anyhow::anyhow!("the controller refused the sequence: {refusal}"))?;
    let push = options.push.map(|push| {
        let single_support = gaits.dynamic.map_or(0.0, |d| d.single_support_s);
        PushSchedule::new(push, single_support)
    });
    let mut targets = stance_points(&robot, sequence);
    let controller = Controller::new(robot.clone(), config, options.solver)?;
    let sim = match &options.scene {
        Some(scene) => {
            let terrain = Terrain::from_scene(scene).context("building the scene's terrain")?;
            let initial = terrain.place(&robot.standing);
            MujocoSim::on_terrain(
                robot.clone(),
                &robot.urdf,
                &initial,
                options.mujoco,
                terrain,
            )
        }
        None => MujocoSim::new(robot.clone(), &robot.urdf, &robot.standing, options.mujoco),
    }
    .context("building the MuJoCo model")?;
    let mut closed = ClosedLoop::new(controller, sim, options.rate_hz);
    if closed.controller.start(Box::new(prepared)).is_err() {
        anyhow::bail!("a new controller refused to start");
    }
    let time_limit = options
        .time_limit_s
        .unwrap_or(60.0 + 20.0 * sequence.len() as f64);
    let max_ticks = (time_limit * options.rate_hz).ceil() as u64;
    let settle_ticks = (options.settle_s * options.rate_hz).ceil() as u64;
    let start_midpoint = feet_midpoint(&closed.sim);
    // The controller's world is the scene's start (identity on the flat floor): the targets are
    // aligned there, with the standing soles at its z = 0, as the controller aligns the
    // sequence, then mapped into the simulator's world (as `walkctl evaluate` maps them).
    let controller_frame = options
        .scene
        .as_ref()
        .map_or_else(Isometry3::identity, |scene| scene.start);
    align_targets(
        &mut targets,
        sequence,
        &FEET.map(|f| controller_frame.inverse() * closed.sim.end_effector_pose(f)),
    );
    for target in &mut targets {
        *target = target.transformed(&controller_frame);
    }
    let mut loop_state = LoopState {
        trace: Vec::with_capacity((max_ticks / options.trace_every.max(1)).min(1 << 20) as usize),
        max_com_drift: 0.0,
        max_foot_drift: 0.0,
        controller_frame,
        max_tilt: 0.0,
        controller_time: Duration::ZERO,
        physics_time: Duration::ZERO,
        tick_ns: Vec::with_capacity(max_ticks.min(1 << 22) as usize),
        balance_trace: Vec::new(),
        first_step_s: None,
        push,
        balance: BalanceAccumulator::default(),
        contacts: (0..sequence.len()).map(|i| sequence.contacts(i)).collect(),
        hand_support: HandSupportSum::default(),
        sole: robot.sole,
        com_outside: Vec::with_capacity(max_ticks.min(1 << 22) as usize),
    };
    let wall = Instant::now();
    let mut ticks = 0u64;
    let mut outcome = loop {
        if ticks >= max_ticks {
            break PhysicsOutcome::TimeLimit;
        }
        if let Err(outcome) = loop_state.tick(&mut closed) {
            break outcome;
        }
        ticks += 1;
        let dt = closed.dt();
        loop_state.observe_walk(&mut closed.sim, closed.controller.status(), dt);
        let (sim, status) = (&closed.sim, closed.controller.status());
        loop_state.observe(sim, status);
        if options.trace_every > 0 && ticks % options.trace_every == 0 {
            let sample = TraceSample {
                t: sim.time(),
                stance_index: status.stance_index,
                target: targets[(status.stance_index as usize).min(targets.len() - 1)],
                controller: controller_points(status).transformed(&loop_state.controller_frame),
                sim: Some(sim_points(sim)),
            };
            loop_state.trace.push(sample);
            let m = sim.measurement();
            loop_state.balance_trace.push(BalanceSample {
                t: sim.time(),
                phase: status.phase,
                balance: status.balance,
                com_estimated: status.com,
                com_true: m.com.into(),
                foot_forces: [m.wrenches[0][2], m.wrenches[1][2]],
                hand_forces: [2, 3].map(|h| [0, 1, 2].map(|k| m.wrenches[h][k])),
            });
        }
        if sim.has_fallen() {
            break PhysicsOutcome::Fell {
                at_s: sim.time(),
                after: None,
            };
        }
        match status.state {
            ControllerState::Done => break PhysicsOutcome::Done,
            ControllerState::Fault => break PhysicsOutcome::Fault(status.fault),
            _ => {}
        }
    };
    let sim_s = closed.sim.time();
    // After `Done` the robot holds its last posture, after a fault the command it holds in: in
    // both it must stand (a detected fault must not become a fall).
    let fault = match outcome {
        PhysicsOutcome::Fault(code) => Some(code),
        _ => None,
    };
    if outcome == PhysicsOutcome::Done || fault.is_some() {
        for _ in 0..settle_ticks {
            if let Err(o) = loop_state.tick(&mut closed) {
                outcome = o;
                break;
            }
            loop_state.observe(&closed.sim, closed.controller.status());
            if closed.sim.has_fallen() {
                outcome = PhysicsOutcome::Fell {
                    at_s: closed.sim.time(),
                    after: fault,
                };
                break;
            }
        }
    }
    let wall_s = wall.elapsed().as_secs_f64();
    let sim = &closed.sim;
    let tick_us = percentiles_us(&mut loop_state.tick_ns);
    let last = targets[targets.len() - 1];
    let final_position_error_m = sim_points(sim).distances(&last).1;
    Ok(PhysicsWalkReport {
        outcome,
        stances: sequence.len(),
        stance_reached: closed.controller.status().stance_index,
        reaches_given_up: closed.controller.status().reaches_given_up,
        ticks,
        sim_s,
        wall_s,
        controller_s: loop_state.controller_time.as_secs_f64(),
        physics_s: loop_state.physics_time.as_secs_f64(),
        total_sim_s: sim.time(),
        final_position_error_m,
        max_com_drift_m: loop_state.max_com_drift,
        max_foot_drift_m: loop_state.max_foot_drift,
        distance_m: (feet_midpoint(sim) - start_midpoint).norm(),
        max_contact_slip_m: sim.summary().max_contact_slip,
        max_tilt_rad: loop_state.max_tilt,
        trace: loop_state.trace,
        first_step_s: loop_state.first_step_s,
        tick_us,
        balance: loop_state.balance.tracking(),
        balance_trace: loop_state.balance_trace,
        pushed_at_s: loop_state.push.and_then(|push| push.applied_at),
        hand_support_share: loop_state
            .hand_support
            .share(robot.model.total_mass() * GRAVITY),
        com_outside_feet_m: held_for(
            &loop_state.com_outside,
            (COM_OUTSIDE_HELD_S * options.rate_hz).round() as usize,
        ),
        actuators: ActuatorReport::new(&sim.actuator_load(), &robot),
    })
}

/// Median, 99th percentile and largest of tick durations in ns, as µs.
fn percentiles_us(ticks: &mut [u64]) -> [f64; 3] {
    if ticks.is_empty() {
        return [0.0; 3];
    }
    ticks.sort_unstable();
    let at = |q: f64| ticks[((ticks.len() - 1) as f64 * q).round() as usize] as f64 / 1e3;
    [at(0.5), at(0.99), at(1.0)]
}

/// When a [`Push`] acts: from the middle of its single support less half its duration.
#[derive(Clone, Copy, Debug)]
struct PushSchedule {
    push: Push,
    /// Time into the single support at which it starts (s).
    start_s: f64,
    /// Single supports seen so far, and the simulated time the current one began.
    steps: usize,
    single_support_since: Option<f64>,
    /// The simulated time the force was applied, once it was.
    applied_at: Option<f64>,
    done: bool,
}

impl PushSchedule {
    fn new(push: Push, single_support_s: f64) -> Self {
        Self {
            push,
            start_s: (single_support_s - push.duration_s).max(0.0) / 2.0,
            steps: 0,
            single_support_since: None,
            applied_at: None,
            done: false,
        }
    }

    /// The force to apply after a tick that ended in `phase` at simulated time `t`.
    fn force(&mut self, phase: Phase, t: f64) -> Vector3<f64> {
        if self.done {
            return Vector3::zeros();
        }
        let single = matches!(phase, Phase::SingleSupport | Phase::LateTouchdown);
        match (single, self.single_support_since) {
            (true, None) => self.single_support_since = Some(t),
            (false, Some(_)) => {
                self.single_support_since = None;
                self.steps += 1;
            }
            _ => {}
        }
        if let Some(applied) = self.applied_at {
            if t - applied >= self.push.duration_s - 1e-9 {
                self.done = true;
                return Vector3::zeros();
            }
            return Vector3::from(self.push.force_n);
        }
        match self.single_support_since {
            Some(since) if self.steps == self.push.step && t - since >= self.start_s => {
                self.applied_at = Some(t);
                Vector3::from(self.push.force_n)
            }
            _ => Vector3::zeros(),
        }
    }
}

/// Sums for [`BalanceTracking`].
#[derive(Clone, Copy, Debug, Default)]
struct BalanceAccumulator {
    zmp: (f64, f64, usize),
    dcm: (f64, f64, usize),
    com_offset_max: f64,
    previous_com: Option<Vector3<f64>>,
}

impl BalanceAccumulator {
    fn add(sum: &mut (f64, f64, usize), error: f64) {
        sum.0 += error * error;
        sum.1 = sum.1.max(error);
        sum.2 += 1;
    }

    fn observe(&mut self, status: &ControllerStatus, true_com: Vector3<f64>, dt: f64) {
        let previous = self.previous_com.replace(true_com);
        let b = &status.balance;
        if status.state != ControllerState::Executing {
            return;
        }
        let reference = Vector2::from(b.zmp_reference);
        let measured = Vector2::from(b.zmp_measured);
        if measured.iter().all(|v| v.is_finite()) {
            Self::add(&mut self.zmp, (measured - reference).norm());
        }
        // The pendulum's height is the CoM's above the feet in contact, not its world z: down
        // a stair scene the controller's frame has the goal a metre below its origin, and the
        // square root of a negative z made the DCM error NaN.
        let feet = [
            (EndEffector::LeftFoot, status.left_foot),
            (EndEffector::RightFoot, status.right_foot),
        ];
        let (sum, count) = feet
            .iter()
            .filter(|(foot, _)| status.contacts[*foot as usize])
            .fold((0.0, 0.0), |(sum, n), (_, pose)| (sum + pose[2], n + 1.0));
        let height = true_com.z - sum / count;
        if let Some(previous) = previous.filter(|_| count > 0.0 && height > 0.0) {
            let omega = (GRAVITY / height).sqrt();
            let dcm = true_com.xy() + (true_com - previous).xy() / dt / omega;
            Self::add(&mut self.dcm, (dcm - Vector2::from(b.dcm_reference)).norm());
        }
        self.com_offset_max = self.com_offset_max.max(Vector2::from(b.com_offset).norm());
    }

    fn tracking(&self) -> BalanceTracking {
        let rms = |sum: &(f64, f64, usize)| {
            if sum.2 == 0 {
                0.0
            } else {
                (sum.0 / sum.2 as f64).sqrt()
            }
        };
        BalanceTracking {
            zmp_rms_m: rms(&self.zmp),
            zmp_max_m: self.zmp.1,
            dcm_rms_m: rms(&self.dcm),
            dcm_max_m: self.dcm.1,
            com_offset_max_m: self.com_offset_max,
        }
    }
}

/// What the closed loop accumulates while it runs.
struct LoopState {
    trace: Vec<TraceSample>,
    max_com_drift: f64,
    max_foot_drift: f64,
    /// Where the controller's world frame lies in the simulator's (a scene's start).
    controller_frame: Isometry3<f64>,
    max_tilt: f64,
    controller_time: Duration,
    physics_time: Duration,
    tick_ns: Vec<u64>,
    balance_trace: Vec<BalanceSample>,
    first_step_s: Option<f64>,
    push: Option<PushSchedule>,
    balance: BalanceAccumulator,
    /// The sequence's contact flags per stance.
    contacts: Vec<[bool; 4]>,
    hand_support: HandSupportSum,
    sole: SoleRectangle,
    /// How far the simulator's CoM stood outside the soles in contact, each tick (m; negative
    /// inside).
    com_outside: Vec<f64>,
}

/// How long (s) [`PhysicsWalkReport::com_outside_feet_m`] asks the CoM to stay outside.
pub const COM_OUTSIDE_HELD_S: f64 = 1.0;

/// The largest value that `values` stays at or above for `window` consecutive entries (0 when
/// none does, or it never is positive): the sliding-window minimum's maximum.
fn held_for(values: &[f64], window: usize) -> f64 {
    let window = window.max(1);
    let mut best = 0.0_f64;
    // Indices of a window's candidates for its minimum, their values increasing.
    let mut candidates = std::collections::VecDeque::new();
    for (i, &value) in values.iter().enumerate() {
        while candidates.back().is_some_and(|&j| values[j] >= value) {
            candidates.pop_back();
        }
        candidates.push_back(i);
        if candidates.front().is_some_and(|&j| j + window <= i) {
            candidates.pop_front();
        }
        if i + 1 >= window {
            best = best.max(values[candidates[0]]);
        }
    }
    best
}

/// The hands' vertical force summed over the ticks a hand is planned to carry.
#[derive(Default)]
struct HandSupportSum {
    newtons: f64,
    ticks: u64,
}

impl HandSupportSum {
    /// The mean over the robot's weight `weight_n` (N); `None` without a tick.
    fn share(&self, weight_n: f64) -> Option<f64> {
        (self.ticks > 0).then(|| self.newtons / self.ticks as f64 / weight_n)
    }
}

impl LoopState {
    /// One control tick of the closed loop, its controller and physics time accounted.
    fn tick(&mut self, closed: &mut ClosedLoop<MujocoSim>) -> Result<(), PhysicsOutcome> {
        let started = Instant::now();
        let result = closed.tick();
        let total = started.elapsed();
        match result {
            Ok(compute) => {
                self.tick_ns.push(compute.as_nanos() as u64);
                self.controller_time += compute;
                self.physics_time += total.saturating_sub(compute);
                Ok(())
            }
            Err(TickError::Sim(MujocoError::Unstable { time })) => {
                Err(PhysicsOutcome::Unstable { at_s: time })
            }
            Err(TickError::NoCommand) => {
                Err(PhysicsOutcome::Fault(closed.controller.status().fault))
            }
            // Commands are always finite, in-limit and sized by the controller's contract.
            Err(TickError::Sim(error)) => {
                panic!("the simulator refused a controller command: {error}")
            }
        }
    }

    /// The first step, the balance tracking and the push, after a tick of the walk.
    fn observe_walk(&mut self, sim: &mut MujocoSim, status: &ControllerStatus, dt: f64) {
        let feet_down = status.contacts[EndEffector::LeftFoot as usize]
            && status.contacts[EndEffector::RightFoot as usize];
        if !feet_down && self.first_step_s.is_none() {
            self.first_step_s = Some(sim.time());
        }
        // The balance readings are in the controller's frame; the simulator's CoM is mapped there.
        let com = self.controller_frame.inverse() * nalgebra::Point3::from(sim.measurement().com);
        self.balance.observe(status, com.coords, dt);
        if let Some(push) = &mut self.push {
            sim.set_pelvis_force(push.force(status.phase, sim.time()));
        }
    }

    /// Drift and fall indicators of the state after a tick.
    fn observe(&mut self, sim: &MujocoSim, status: &ControllerStatus) {
        let soles =
            FEET.map(|foot| status.contacts[foot as usize].then(|| sim.end_effector_pose(foot)));
        let mut feet = SupportPolygon::empty();
        feet.set_soles(soles.iter().flatten(), &self.sole, |p| p);
        let com = sim.measurement().com;
        // No sole in contact counts as inside: there is no polygon to be outside of.
        let outside = -feet.signed_distance([com.x, com.y]);
        self.com_outside.push(if soles.iter().all(Option::is_none) {
            f64::NEG_INFINITY
        } else {
            outside
        });
        if hand_planned_held(&self.contacts, status.stance_index as usize) {
            let wrenches = &sim.measurement().wrenches;
            let hands = EndEffector::HANDS.iter().map(|&h| wrenches[h as usize][2]);
            self.hand_support.newtons += hands.sum::<f64>();
            self.hand_support.ticks += 1;
        }
        let controller = controller_points(status).transformed(&self.controller_frame);
        let (com, feet) = sim_points(sim).distances(&controller);
        self.max_com_drift = self.max_com_drift.max(com);
        self.max_foot_drift = self.max_foot_drift.max(feet);
        self.max_tilt = self.max_tilt.max(sim.torso_tilt());
    }
}

fn controller_points(status: &ControllerStatus) -> Points {
    Points::from_status(&status.com, &status.left_foot, &status.right_foot)
}

fn sim_points(sim: &MujocoSim) -> Points {
    Points {
        com: sim.measurement().com,
        left_foot: sim
            .end_effector_pose(EndEffector::LeftFoot)
            .translation
            .vector,
        right_foot: sim
            .end_effector_pose(EndEffector::RightFoot)
            .translation
            .vector,
    }
}

#[cfg(test)]
mod tests {
    use super::held_for;

    #[test]
    fn a_distance_counts_only_as_far_as_it_was_held_for_the_whole_window() {
        // 5 cm for 3 ticks, 2 cm around them for 6: over 3 ticks 5 cm, over 5 ticks 2 cm.
        let values = [0.0, 0.02, 0.05, 0.05, 0.05, 0.02, 0.02, -0.01, 0.1];
        assert_eq!(held_for(&values, 3), 0.05);
        assert_eq!(held_for(&values, 5), 0.02);
        assert_eq!(held_for(&values, 1), 0.1);
        // Never outside, or too short a walk for the window: 0.
        assert_eq!(held_for(&[-0.1, -0.2], 1), 0.0);
        assert_eq!(held_for(&[0.1, 0.1], 3), 0.0);
    }
}
