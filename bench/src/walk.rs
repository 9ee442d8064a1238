//! A walk to its end against the kinematic simulator, as fast as the machine runs: the closed
//! loop ([`ClosedLoop`]) until `done`, a fault, a fall (the simulated CoM left the support
//! polygon; for the dynamic gait its ZMP, `SimOptions::judge_by_zmp`) or the time limit.

use kinematic_sim::Simulator;
use std::sync::Arc;

use daemon::controller::{
    Command, Controller, ControllerConfig, ControllerState, ControllerStatus, Gait, GaitConfig,
    SolverKind,
};
use kinematic_sim::{KinematicSim, SafetySummary, SimMeasurement, SimOptions};
use kinematics::ConfigFile;
use kinematics::robot::Robot;
use sim_adapter::SceneGround;
use stance::PostProcessedSequence;

use crate::closed_loop::{ClosedLoop, TickError, feet_midpoint};

/// How to run a walk.
#[derive(Clone, Debug)]
pub struct WalkOptions {
    /// QP back-end.
    pub solver: SolverKind,
    /// Control rate (Hz); the simulator steps by its period.
    pub rate_hz: f64,
    /// Simulated time after which an unfinished walk is stopped (s).
    pub time_limit_s: f64,
    /// The gait walked.
    pub gait: Gait,
    /// Its `[gait]` tuning (for the dynamic gait, see [`kinematic_gaits`]).
    pub gaits: GaitConfig,
}

impl Default for WalkOptions {
    /// The static gait with the dense solver at 500 Hz for at most 120 s.
    fn default() -> Self {
        Self {
            solver: SolverKind::Dense,
            rate_hz: 500.0,
            time_limit_s: 120.0,
            gait: Gait::Static,
            gaits: GaitConfig::default(),
        }
    }
}

/// A robot's `[gait]` tuning for the kinematic simulator: its config with
/// [`client::process::kinematic_sim_settings`] applied, the values walkd runs with against
/// `walk-sim --physics kinematic`, so both loops walk the same controller. Those switch off the
/// stabilizer parts that act through contact compliance (foot damping, tilt damping): an ideal
/// kinematic robot is rigid, its synthetic centre of pressure follows the commanded motion, and
/// with them on the kinematic dynamic walk's ZMP leaves the support (docs/controller.md).
pub fn kinematic_gaits(file: &ConfigFile) -> anyhow::Result<GaitConfig> {
    let mut file = file.clone();
    for setting in client::process::kinematic_sim_settings(&file) {
        file.set(setting)?;
    }
    Ok(GaitConfig::from_config(&file)?)
}

/// One closed-loop tick, handed to the observer after the simulator stepped.
pub struct TickObservation<'a> {
    /// Tick number (from 0).
    pub tick: u64,
    /// Simulator state and safety metrics after applying the command.
    pub sim: &'a SimMeasurement,
    /// Controller status after the tick.
    pub status: &'a ControllerStatus,
    /// The command sent.
    pub command: &'a Command,
    /// The controller (for its last QP).
    pub controller: &'a Controller,
    /// Wall time of `Controller::tick` (ns).
    pub tick_ns: u64,
}

/// How a walk ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The controller reached `Done`.
    Done,
    /// The controller faulted; the code names why.
    Fault(daemon::controller::FaultCode),
    /// The simulated CoM left the support polygon.
    Fell,
    /// The simulated time limit passed first.
    TimeLimit,
}

impl Outcome {
    /// `done` or `fault:<reason>` as printed by `walk-bench`.
    pub fn label(self) -> String {
        match self {
            Self::Done => "done".to_owned(),
            Self::Fault(code) => format!("fault:{}", code.code()),
            Self::Fell => "fault:fall".to_owned(),
            Self::TimeLimit => "fault:time_limit".to_owned(),
        }
    }
}

/// Result of a walk.
#[derive(Clone, Copy, Debug)]
pub struct WalkReport {
    /// How it ended.
    pub outcome: Outcome,
    /// Stances in the sequence.
    pub stances: usize,
    /// Control ticks run.
    pub ticks: u64,
    /// Worst safety values seen by the simulator.
    pub safety: SafetySummary,
    /// Horizontal distance the feet midpoint travelled (m, simulator truth).
    pub distance_m: f64,
    /// Hand reaches the controller gave up (`ControllerStatus::reaches_given_up`).
    pub reaches_given_up: u32,
}

/// Errors setting up or running a walk.
#[derive(Debug, thiserror::Error)]
pub enum WalkError {
    /// The controller could not be built.
    #[error(transparent)]
    Controller(#[from] daemon::controller::ControllerError),
    /// The controller refused the sequence.
    #[error(transparent)]
    Refused(#[from] daemon::controller::Refusal),
    /// The simulator refused the start state or a command, or the controller wrote none.
    #[error("{0}")]
    Loop(String),
}

/// Executes `sequence` on `robot` (starting from its standing posture) in closed loop with the
/// kinematic simulator, on the surfaces it was post-processed on (a scene's stairs and ramps);
/// `observe` sees every tick.
pub fn walk(
    robot: Arc<Robot>,
    config: ControllerConfig,
    sequence: &PostProcessedSequence,
    options: &WalkOptions,
    mut observe: impl FnMut(&TickObservation),
) -> Result<WalkReport, WalkError> {
    let prepared =
        Controller::prepare_gait(&robot, &config, &options.gaits, sequence, options.gait)?;
    let stances = prepared.len();
    let controller = Controller::new(robot.clone(), config, options.solver)?;
    let sim_options = SimOptions {
        judge_by_zmp: options.gait == Gait::Dynamic,
        ..SimOptions::default()
    };
    // A sequence post-processed onto a scene's surfaces walks on them.
    let environment = sequence.environment();
    let sim = if environment.is_flat_ground() {
        KinematicSim::with_options(robot.clone(), robot.standing.clone(), sim_options)
    } else {
        let ground = Arc::new(SceneGround::new(environment.clone()));
        KinematicSim::on_ground(robot.clone(), robot.standing.clone(), sim_options, ground)
    }
    .map_err(|e| WalkError::Loop(format!("simulator: {e}")))?;
    let mut closed = ClosedLoop::new(controller, sim, options.rate_hz);
    let max_ticks = (options.time_limit_s * options.rate_hz).ceil() as u64;
    let start_midpoint = feet_midpoint(&closed.sim);
    if closed.controller.start(Box::new(prepared)).is_err() {
        unreachable!("a new controller accepts a sequence");
    }
    let mut ticks = 0;
    let outcome = loop {
        if ticks >= max_ticks {
            break Outcome::TimeLimit;
        }
        let compute = match closed.tick() {
            Ok(compute) => compute,
            Err(TickError::NoCommand) => break Outcome::Fault(closed.controller.status().fault),
            Err(error) => return Err(WalkError::Loop(error.to_string())),
        };
        observe(&TickObservation {
            tick: ticks,
            sim: closed.sim.measurement(),
            status: closed.controller.status(),
            command: &closed.command,
            controller: &closed.controller,
            tick_ns: compute.as_nanos() as u64,
        });
        ticks += 1;
        if closed.sim.measurement().safety.stability_margin < 0.0 {
            break Outcome::Fell;
        }
        match closed.controller.status().state {
            ControllerState::Done => break Outcome::Done,
            ControllerState::Fault => break Outcome::Fault(closed.controller.status().fault),
            _ => {}
        }
    };
    Ok(WalkReport {
        outcome,
        stances,
        ticks,
        safety: *closed.sim.summary(),
        distance_m: (feet_midpoint(&closed.sim) - start_midpoint).norm(),
        reaches_given_up: closed.controller.status().reaches_given_up,
    })
}
