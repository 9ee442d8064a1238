//! `walkctl evaluate`: the paper's execution evaluation over the real processes.
//!
//! For every robot × affordance set × distance × run it generates a walk (run i: seed
//! `--first-seed` + i),
//! post-processes it, starts its own `walkd` and `walk-sim --physics <backend>` in lockstep on a
//! service prefix of its own, submits the walk, records the daemon's status stream and stops the
//! processes. Meanwhile it records the simulator's ground truth, which `walk-sim` publishes with
//! every sample on `<prefix>/sim-truth` (true CoM, sole poses, base height and tilt, fall flag):
//!
//! - success: the daemon reports `done` and the simulator's fall rule never fired, neither during
//!   the walk nor while the robot holds its last command for [`WATCH_AFTER_END_S`] after the
//!   walk ended (after `done` or a fault alike: a fault walkd detected must not become a fall);
//! - drift: the largest distance between the controller's CoM / sole estimate in a status and
//!   the simulator's truth of the state that status's tick saw ([`truth::state_at`]);
//! - final position error: the simulated soles' distance from their final targets;
//! - steps and footholds ([`footholds`]): touchdowns of the simulated soles, their distance from
//!   the planned footholds, the soles' elevation at the start and end, the legs' terrain
//!   collisions; on a scene a walk must also land within [`footholds::FOOTHOLD_BOUND_M`] of them.
//!
//! `--inject FAULTS` injects each fault into every walk at each `--inject-at` moment of a single
//! support (walk-sim's fault injection) and judges the stop instead of the walk ([`stop`]).
//!
//! `--plots DIR` writes the paper's Fig. 6 per robot (first run of the first distance, feet
//! only): target vs controller state vs simulator over time for the CoM and both feet
//! ([`write_fig6`] is shared with the in-process physics walk of the `walk-tests` package).

pub mod actuators;
pub(crate) mod clearance;
pub mod fig6;
pub mod filmstrip;
pub mod footholds;
pub mod hands;
pub mod record;
pub mod stop;
pub(crate) mod telemetry;
pub mod timing;
pub(crate) mod truth;
pub(crate) mod watch;

use actuators::ActuatorReport;
pub use fig6::{BalanceSample, HandSample, write_fig6};
use footholds::{PlannedFootholds, StepReport};
pub use record::{GroupSummary, MatrixCells, WalkRecord, group_by_cell, speed_cell};

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use anyhow::{Context, bail};
use kinematics::ConfigFile;
use kinematics::ground::sequence_alignment;
use kinematics::kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Point3, Vector3};
use shm_types::process::Physics;
use shm_types::{ClockMode, DaemonState, SimTruth};
use stance::learned::{SourceArgs, StanceSource};
use stance::poses::FEET;
use stance::{AffordanceSet, Gait, PostProcessedSequence, Scene, WalkRequest, WalkingSpeed};

use crate::args::SPEED_M_S;
use crate::daemon_client::connect_when_fresh;
use crate::pace::walking_speed;
use crate::process::{Launch, PlantArgs, executable_dir};
use stop::{InjectArgs, Injection, StopReport};
use timing::TimingReport;
use watch::{WatchOptions, watch_walk};

/// How long (simulated s) a walk is still watched for a fall after it ended, the robot holding
/// its last command: after `done`, and after a fault walkd detected, which must not become a
/// fall. ARMAR-4 caught by its catch step (the static gait's tipping fault) fell 1.6 s after the
/// fault under MuJoCo at a 0.5 ms step, where a 1 s watch called the walk a fault, not a fall.
pub const WATCH_AFTER_END_S: f64 = 3.0;

/// Arguments of `walkctl evaluate`.
#[derive(Debug, clap::Args)]
pub struct EvaluateArgs {
    /// Robots (config names under the config directory).
    #[arg(long, value_delimiter = ',', default_value = "armar4,jvrc1")]
    pub robots: Vec<String>,
    /// Affordance sets, distances and runs (run i uses generator seed `first_seed + i`).
    #[command(flatten)]
    pub cells: MatrixCells,
    /// Simulator of `walk-sim`: mujoco or kinematic.
    #[arg(long, default_value = "mujoco")]
    pub physics: Physics,
    /// Directory with the robot configs (`<robot>.toml`).
    #[arg(long, default_value = "configs")]
    pub config_dir: PathBuf,
    /// URDF overriding the configs' (HRP-4's model is not vendored).
    #[arg(long)]
    pub urdf: Option<PathBuf>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Gait: static or dynamic (default: each robot config's `[gait] default`). The walks are
    /// post-processed with that gait's limits and ask walkd for it. Every robot is checked
    /// before the first run: one that cannot walk the gait is refused.
    #[arg(long)]
    pub gait: Option<Gait>,
    /// Write Fig. 6 per robot (`fig6_<robot>.svg`) into this directory.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Pictures of the walk (MuJoCo's offscreen renderer in walk-sim, built with --features
    /// sim-adapter/render): per robot, of its first run of the first distance and affordance set,
    /// a side view every 0.5 s of simulated time in `DIR/frames-<robot>/` and the filmstrip
    /// `DIR/filmstrip-<robot>.png` (the paper's Fig. 5).
    #[arg(long, value_name = "DIR")]
    pub snapshots: Option<PathBuf>,
    /// Record every run (an observer beside walkd) to
    /// `DIR/<robot>-<affordances>-<distance>m-run<run>.mcap`.
    #[arg(long, value_name = "DIR")]
    pub record: Option<PathBuf>,
    /// Faults to inject into every walk, and when.
    #[command(flatten)]
    pub inject: InjectArgs,
    /// Walk every run through this scene (docs/scenes.md), from its start towards its goal,
    /// instead of on the flat floor: the whole path, or its first `--distances` metres.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// The stance source of every walk (default: the synthetic generator).
    #[command(flatten)]
    pub source: SourceArgs,
    /// Walking speed to pace every walk for (m/s, 0.01-3): step length and stance durations
    /// from the model's gait law (docs/learning.md). Needs --model.
    #[arg(long, value_name = "V", value_parser = SPEED_M_S.parser(), requires = "model")]
    pub speed: Option<f64>,
}

/// The CoM and both soles' positions in the world (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Points {
    /// Centre of mass.
    pub com: Vector3<f64>,
    /// Left sole frame origin.
    pub left_foot: Vector3<f64>,
    /// Right sole frame origin.
    pub right_foot: Vector3<f64>,
}

impl Points {
    /// The true CoM and sole positions a simulator reports.
    pub fn from_truth(truth: &SimTruth) -> Self {
        Self::from_status(&truth.com, &truth.left_foot, &truth.right_foot)
    }

    /// The CoM and sole positions a daemon status reports.
    pub fn from_status(com: &[f64; 3], left_foot: &[f64; 7], right_foot: &[f64; 7]) -> Self {
        let xyz = |p: &[f64]| Vector3::new(p[0], p[1], p[2]);
        Self {
            com: xyz(com),
            left_foot: xyz(left_foot),
            right_foot: xyz(right_foot),
        }
    }

    /// The points moved by `to`.
    pub fn transformed(&self, to: &Isometry3<f64>) -> Self {
        let map = |p: &Vector3<f64>| (to * Point3::from(*p)).coords;
        Self {
            com: map(&self.com),
            left_foot: map(&self.left_foot),
            right_foot: map(&self.right_foot),
        }
    }

    /// Distances between corresponding points: (CoM, larger of the two soles).
    pub fn distances(&self, other: &Points) -> (f64, f64) {
        let com = (self.com - other.com).norm();
        let feet = (self.left_foot - other.left_foot)
            .norm()
            .max((self.right_foot - other.right_foot).norm());
        (com, feet)
    }
}

/// The target of every stance: its CoM (its posture `q_S` at its root pose) and its sole targets.
pub fn stance_points(robot: &Robot, sequence: &PostProcessedSequence) -> Vec<Points> {
    let mut kinematics = Kinematics::new(&robot.model);
    let mut configuration = robot.standing.clone();
    sequence
        .root_poses()
        .enumerate()
        .map(|(i, root)| {
            configuration.base = root;
            configuration.joints.copy_from_slice(sequence.posture(i));
            kinematics.update(&robot.model, &configuration);
            Points {
                com: kinematics.com(),
                left_foot: sequence.target(i, EndEffector::LeftFoot).translation.vector,
                right_foot: sequence
                    .target(i, EndEffector::RightFoot)
                    .translation
                    .vector,
            }
        })
        .collect()
}

/// Moves `targets` (in the sequence's frame) into the world the way the controller moves the
/// sequence when the walk begins ([`sequence_alignment`]): the first stance's contact feet onto
/// the robot's feet `standing` (`[left, right]` sole poses; every run starts on both feet).
pub fn align_targets(
    targets: &mut [Points],
    sequence: &PostProcessedSequence,
    standing: &[Isometry3<f64>; 2],
) {
    if sequence.is_empty() {
        return;
    }
    let contacts = sequence.contacts(0);
    let to_world = sequence_alignment(
        &FEET.map(|f| sequence.target(0, f)),
        FEET.map(|f| contacts[f as usize]),
        standing,
        [true, true],
    );
    let map = |v: Vector3<f64>| to_world * Point3::from(v);
    for target in targets {
        *target = Points {
            com: map(target.com).coords,
            left_foot: map(target.left_foot).coords,
            right_foot: map(target.right_foot).coords,
        };
    }
}

/// One sample of a Fig. 6 trace.
#[derive(Clone, Copy, Debug)]
pub struct TraceSample {
    /// Time since the walk started (s).
    pub t: f64,
    /// The stance being moved towards.
    pub stance_index: u32,
    /// That stance's target.
    pub target: Points,
    /// The controller's estimate.
    pub controller: Points,
    /// The simulator's truth, where known.
    pub sim: Option<Points>,
}

/// What one run of `walkctl evaluate` measured: the matrix record and what only a run over
/// processes knows.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// Robot config name.
    pub robot: String,
    /// The matrix record; its seed is the run number, its drift `None` when no status could be
    /// paired with a simulator state.
    pub record: WalkRecord,
    /// Wall time from submission to the end (s).
    pub wall_s: f64,
    /// Largest distance of a simulated sole from its final target at the end (m).
    pub final_position_error_m: f64,
    /// Statuses paired with a simulator state (the samples the drift is the maximum of).
    pub drift_samples: usize,
    /// Simulated time from submission at which the simulator's fall rule first fired (s).
    pub fell_at_s: Option<f64>,
    /// Simulated time the robot was watched past the walk's end for a fall (s,
    /// [`WATCH_AFTER_END_S`] unless the simulator stalled).
    pub watched_after_end_s: Option<f64>,
    /// The stance the daemon was moving towards at the end.
    pub stance_reached: u32,
    /// The gait walked.
    pub gait: Gait,
    /// The status stream as a Fig. 6 trace.
    pub trace: Vec<TraceSample>,
    /// A dynamic walk's ZMP and DCM from walkd's telemetry (empty for the static gait).
    pub balance: Vec<BalanceSample>,
    /// The hands' vertical forces, asked by walkd and measured at the wrists, for Fig. 6.
    pub hand_forces: Vec<HandSample>,
    /// With an injected fault: how the walk stopped (it decides `record.success`).
    pub stop: Option<StopReport>,
    /// Steps, footholds, elevations and terrain collisions from the simulator's truth.
    pub steps: StepReport,
    /// The held hands' mean vertical force over the robot's weight while a hand is planned in
    /// contact, from the simulator's contact forces; `None` without a held hand.
    pub hand_support_share: Option<f64>,
    /// The force walkd asked of the held hands over the same time, from its telemetry, divided
    /// by the robot's weight: the desired split beside the measured one; `None` when it held no
    /// hand then.
    pub hand_support_asked: Option<f64>,
    /// The walking speed asked of the walk (m/s), if any.
    pub requested_speed_m_s: Option<f64>,
    /// The dynamic gait's planned phases, from walkd's telemetry; `None` for the static gait.
    pub timing: Option<TimingReport>,
}

impl RunResult {
    fn json(&self) -> serde_json::Value {
        let r = &self.record;
        let injected = self.stop.map(|stop| {
            serde_json::json!({
                "fault": stop.injection.fault.name(),
                "at": stop.injection.moment.name(),
                "step": stop.injection.step,
                "delay_s": stop.injection.delay_s,
                "stop_s": stop.stop_s,
                "ended": stop.ended.name(),
                "feet_down": stop.feet_down,
                "fell": stop.fell,
                "max_tilt_rad": stop.max_tilt_rad,
            })
        });
        serde_json::json!({
            "robot": self.robot,
            "affordances": r.affordances.name(),
            "distance_m": r.distance_m,
            "run": r.seed,
            "success": r.success,
            "outcome": r.outcome,
            "sim_s": r.sim_s,
            "wall_s": self.wall_s,
            "drift_m": r.drift_m,
            "drift_samples": self.drift_samples,
            "max_tilt_rad": r.max_tilt_rad,
            "fell_at_s": self.fell_at_s,
            "watched_after_end_s": self.watched_after_end_s,
            "final_position_error_m": self.final_position_error_m,
            "stances": r.stances,
            "stance_reached": self.stance_reached,
            "gait": self.gait.name(),
            "walked_m": r.walked_m,
            "speed_m_s": r.speed_m_s,
            "actuators": r.actuators,
            "start_elevation_m": self.steps.start_elevation_m,
            "end_elevation_m": self.steps.end_elevation_m,
            "steps": self.steps.steps,
            "planned_steps": self.steps.planned_steps,
            "time_per_step_s": self.steps.time_per_step_s,
            "time_per_stair_s": self.steps.time_per_stair_s,
            "terrain_collisions": self.steps.terrain_collisions,
            "foothold_error_m": self.steps.foothold_error_m,
            "edge_clearance_m": self.steps.edge_clearance_m,
            "hand_support_share": self.hand_support_share,
            "hand_support_asked": self.hand_support_asked,
            "reaches_given_up": r.reaches_given_up,
            "requested_speed_m_s": self.requested_speed_m_s,
            "timing": self.timing,
            "injected": injected,
        })
    }
}

/// A robot of the matrix, loaded and checked before the first run starts a process.
struct Subject<'a> {
    /// Config name.
    robot: &'a str,
    /// Its config file, and that file loaded.
    config: PathBuf,
    file: ConfigFile,
    /// Its model.
    model: Arc<Robot>,
    /// The gait its walks use (`--gait`, else its config's default).
    gait: Gait,
    /// `--speed` within its timing limits, if asked.
    speed: Option<WalkingSpeed>,
    /// The fault injections of each walk.
    injections: Vec<Option<Injection>>,
}

impl<'a> Subject<'a> {
    /// Loads robot `robot` of the matrix; refuses it when it cannot walk the gait (or, with
    /// `--speed`, pace it).
    fn load(args: &EvaluateArgs, robot: &'a str) -> anyhow::Result<Self> {
        let config = args.config_dir.join(format!("{robot}.toml"));
        let file = ConfigFile::load(&config)?;
        let gait = Gait::for_walk(args.gait, &file)?;
        let speed = walking_speed(args.speed, &file, gait)?;
        let model = Arc::new(
            Robot::from_config(&file, args.urdf.as_deref())
                .with_context(|| format!("robot `{robot}` ({})", config.display()))?,
        );
        let injections = args.inject.injections(&file)?;
        Ok(Self {
            robot,
            config,
            file,
            model,
            gait,
            speed,
            injections,
        })
    }
}

/// `walkctl evaluate`: runs the matrix, prints the table or JSON, writes the plots; fails unless
/// every run succeeded.
pub fn run(args: &EvaluateArgs) -> anyhow::Result<()> {
    let scene = crate::demo::load_scene(args.scene.as_deref())?;
    let requests = args.cells.requests(scene.as_ref())?;
    let source = args.source.load()?;
    let subjects = args
        .robots
        .iter()
        .map(|robot| Subject::load(args, robot))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let mut results = Vec::new();
    let mut errors = Vec::new();
    for subject in &subjects {
        let robot = subject.robot;
        let runs = requests.iter().flat_map(|request| {
            subject
                .injections
                .iter()
                .map(move |injection| (request, injection))
        });
        for (i, (request, injection)) in runs.enumerate() {
            let pictured = args.snapshots.as_deref().filter(|_| i == 0);
            let run = (i, request);
            let label = format!(
                "{robot} {} {} m run {}{}",
                request.affordances,
                request.distance,
                request.seed,
                injection.map_or_else(String::new, |i| format!(" ({})", i.label()))
            );
            match run_once(
                args,
                &source,
                subject,
                run,
                scene.as_ref(),
                *injection,
                pictured,
            ) {
                Ok(result) => {
                    if !args.json {
                        eprintln!("{}", row(&result));
                    }
                    results.push(result);
                }
                Err(error) => {
                    let error = RunError {
                        run: label,
                        message: format!("{error:#}"),
                    };
                    eprintln!("{error}");
                    errors.push(error);
                }
            }
        }
        if let Some(dir) = &args.plots {
            plot_robot(dir, robot, &results)?;
        }
    }
    if args.json {
        println!("{}", report_json(&results, &errors));
    } else {
        print!("{}", summary(&results));
        for error in &errors {
            println!("{error}");
        }
    }
    verdict(&results, &errors)
}

/// A run that could not be carried to its end (a process that did not start or stopped
/// answering, a sequence that could not be generated): reported with the others, and the matrix
/// goes on, so one bad run does not lose the results of a long evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct RunError {
    /// Which run: robot, affordance set, distance, run number and injected fault.
    pub run: String,
    /// The error with its causes.
    pub message: String,
}

impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "error: {}: {}", self.run, self.message)
    }
}

/// The JSON report: every run carried out, and every run that errored.
fn report_json(results: &[RunResult], errors: &[RunError]) -> serde_json::Value {
    let runs: Vec<_> = results.iter().map(RunResult::json).collect();
    let errors: Vec<_> = errors
        .iter()
        .map(|e| serde_json::json!({ "run": e.run, "error": e.message }))
        .collect();
    serde_json::json!({ "runs": runs, "errors": errors })
}

/// Success only when every run was carried out and succeeded.
fn verdict(results: &[RunResult], errors: &[RunError]) -> anyhow::Result<()> {
    let failed = results.iter().filter(|r| !r.record.success).count();
    let total = results.len() + errors.len();
    match (failed, errors.len()) {
        (0, 0) => Ok(()),
        (_, 0) => bail!("{failed} of {total} runs did not succeed"),
        (_, errored) => bail!(
            "{} of {total} runs did not succeed ({errored} of them errored before their end)",
            failed + errored
        ),
    }
}

/// Fig. 6 of `robot`'s first feet-only run (or its first run) into `dir`.
fn plot_robot(dir: &Path, robot: &str, results: &[RunResult]) -> anyhow::Result<()> {
    let mine = || results.iter().filter(|r| r.robot == robot);
    let Some(result) = mine()
        .find(|r| r.record.affordances == AffordanceSet::Feet)
        .or_else(|| mine().next())
    else {
        return Ok(());
    };
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let file = dir.join(format!("fig6_{robot}.svg"));
    let title = format!(
        "{robot}, {} m, {}, run {} ({})",
        result.record.distance_m,
        result.record.affordances.name(),
        result.record.seed,
        result.record.outcome
    );
    write_fig6(
        &file,
        &title,
        &result.trace,
        &result.balance,
        &result.hand_forces,
    )
}

/// Run number `slot` of a robot, its walk from `source`: own processes on an own prefix, submit,
/// record, stop; through
/// `scene` if any; with `injection`, walk-sim injects that fault; with `pictured`, the
/// snapshots of `--snapshots` go there.
fn run_once(
    args: &EvaluateArgs,
    source: &StanceSource,
    subject: &Subject,
    (slot, request): (usize, &WalkRequest),
    scene: Option<&Scene>,
    injection: Option<Injection>,
    pictured: Option<&Path>,
) -> anyhow::Result<RunResult> {
    let Subject {
        robot,
        config,
        file,
        model,
        gait,
        speed,
        ..
    } = subject;
    let (robot, gait) = (*robot, *gait);
    let params = stance::PostProcessParams::from_config_for(file, gait)?;
    let request = &WalkRequest {
        speed: *speed,
        ..*request
    };
    let &WalkRequest {
        distance,
        affordances,
        seed: run,
        ..
    } = request;
    let sequence = match scene {
        Some(scene) => source.walk_in(model, &params, request, &scene.walk_environment())?,
        None => source.walk(model, &params, request)?,
    };
    // One prefix a run: the runs of one walk with different faults follow each other, and a new
    // walkd must not meet the services of the last one while they are being torn down.
    let prefix = format!("walk-eval/{robot}/{}/{slot}", std::process::id());
    let launch = Launch {
        bin_dir: executable_dir()?,
        config: config.to_owned(),
        prefix: prefix.clone(),
        clock: ClockMode::Lockstep,
        rate_hz: None,
        urdf: args.urdf.clone(),
    };
    let frames = pictured.map(|dir| dir.join(format!("frames-{robot}")));
    let plant = PlantArgs::new(args.physics, gait, file);
    let mut sim_args = plant.walk_sim;
    if let Some(scene) = &args.scene {
        sim_args.extend(["--scene".into(), scene.into()]);
    }
    if let Some(frames) = &frames {
        let _ = std::fs::remove_dir_all(frames);
        // The side camera looks at the middle of the walk: on the flat floor it starts at x = 0
        // along +x; through a scene, from its start along its heading, on the surface there.
        let middle = match scene {
            None => Point3::new(distance / 2.0, 0.0, 0.0),
            Some(scene) => {
                let on_path = scene.start * Point3::new(distance / 2.0, 0.0, 0.0);
                let z = scene.environment.highest_at(on_path.x, on_path.y);
                Point3::new(on_path.x, on_path.y, z.unwrap_or(on_path.z))
            }
        };
        let lookat = format!("{},{},{}", middle.x, middle.y, middle.z + 0.8);
        sim_args.extend(["--snapshots".into(), frames.into()]);
        sim_args.extend(["--snapshot-lookat".into(), lookat.into()]);
    }
    if let Some(injection) = &injection {
        sim_args.extend(injection.sim_args());
    }
    let processes = [
        launch.walkd(
            &[&["--no-lock-memory"], plant.walkd.as_slice()].concat(),
            &[],
        )?,
        launch.walk_sim(args.physics, &sim_args)?,
    ];
    let client = connect_when_fresh(&prefix, &processes, Duration::from_secs(30))?;
    let options = WatchOptions {
        record: args.record.as_ref().map(|dir| {
            dir.join(format!(
                "{robot}-{}-{distance}m-run{run}.mcap",
                affordances.name()
            ))
        }),
        // Always: the static gait's hand contacts (`reaches_given_up`) come from it too.
        telemetry: true,
        timeout: Duration::from_secs(120 + 60 * sequence.len() as u64),
        on_status: &|_| {},
        controller_frame: scene.map_or_else(Isometry3::identity, |scene| scene.start),
    };
    let walk = watch_walk(&client, &prefix, model, &sequence, &options)?;
    drop(client);
    let [walkd, sim] = processes;
    let walkd_log = walkd.stop()?.log;
    let sim_log = sim.stop()?.log;
    let Some(verdict) = walk.verdict else {
        bail!(
            "walk-sim published no simulator truth on `{prefix}/sim-truth`\n\
             walk-sim's log:\n{sim_log}\nwalkd's log:\n{walkd_log}"
        );
    };
    if let (Some(dir), Some(frames)) = (pictured, &frames) {
        let start = truth::state_at(&walk.states, walk.submitted_ns).map_or(0.0, |s| s.sim_time_s);
        let end = truth::state_at(&walk.states, walk.last.timestamp_ns)
            .map_or(verdict.end.sim_time_s, |s| s.sim_time_s);
        let strip = dir.join(format!("filmstrip-{robot}.png"));
        let times = filmstrip::write_filmstrip(frames, start, end, &strip)?;
        eprintln!(
            "{}: {robot} at {} s of simulated time",
            strip.display(),
            times
                .iter()
                .map(|t| format!("{:.1}", t - start))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let end = Points::from_truth(&verdict.end);
    let final_target = walk.targets[walk.targets.len() - 1];
    let last = &walk.last;
    let done = last.state == DaemonState::Done;
    let daemon_outcome = if done {
        "done".to_owned()
    } else {
        format!("{}: {}", last.state.name(), last.fault)
    };
    let stop = injection.map(|injection| stop::judge(injection, &walk));
    let success = stop.map_or(done && verdict.fell_at_s.is_none(), |s| s.success());
    let outcome = match &stop {
        Some(stop) => format!("{} ({daemon_outcome})", stop.describe()),
        None => truth::judged_outcome(verdict.fell_at_s, &daemon_outcome),
    };
    let planned = PlannedFootholds::new(
        (0..sequence.len()).map(|i| sequence.contacts(i)),
        &walk.targets,
    );
    let edges = scene.map_or_else(Vec::new, |scene| clearance::edges(&scene.environment));
    let steps = StepReport::of(
        &walk.states,
        walk.submitted_ns,
        walk.sim_s,
        &planned,
        (&edges, &model.sole),
    )
    .context("no simulator truth recorded")?;
    let contacts: Vec<_> = (0..sequence.len()).map(|i| sequence.contacts(i)).collect();
    let weight_n = model.model.total_mass() * kinematics::ground::GRAVITY;
    let hand_support_share = hands::support_share(
        &contacts,
        walk.trace
            .iter()
            .map(|sample| sample.stance_index)
            .zip(walk.status_times.iter().copied()),
        &walk.states,
        weight_n,
    );
    let hand_support_asked = hands::asked_share(&contacts, &walk.hands_asked, weight_n);
    // Through a scene a walk must also land on its footholds (its treads).
    let (success, outcome) = footholds::judged_on_terrain(
        scene.is_some() && stop.is_none(),
        (success, outcome),
        &steps,
    );
    Ok(RunResult {
        robot: robot.to_owned(),
        record: WalkRecord {
            affordances,
            distance_m: distance,
            seed: request.seed,
            outcome,
            success,
            stances: sequence.len(),
            walked_m: verdict.walked_m,
            speed_m_s: verdict.speed_m_s(walk.sim_s),
            sim_s: walk.sim_s,
            drift_m: walk.drift.map(|(largest, _)| largest),
            max_tilt_rad: verdict.max_tilt_rad,
            // Only the static gait waits for a hand and gives it up; the dynamic gait's reaches
            // run on time, and its telemetry never shows a hand held only in the first stance.
            reaches_given_up: walk
                .hands_held
                .as_ref()
                .filter(|_| gait == Gait::Static)
                .map(|held| hands::reaches_given_up(&contacts, held, last.stance_index as usize)),
            actuators: (args.physics == Physics::Mujoco)
                .then(|| ActuatorReport::new(&verdict.end.actuators, model)),
        },
        wall_s: walk.wall_s,
        final_position_error_m: end.distances(&final_target).1,
        drift_samples: walk.drift.map_or(0, |(_, samples)| samples),
        fell_at_s: verdict.fell_at_s,
        watched_after_end_s: walk.watched_after_end_s,
        stance_reached: last.stance_index,
        gait,
        trace: walk.trace,
        balance: walk.balance,
        hand_forces: walk.hand_forces,
        stop,
        steps,
        hand_support_share,
        hand_support_asked,
        requested_speed_m_s: request.speed.map(|speed| speed.m_s),
        timing: TimingReport::of(&walk.phases),
    })
}

fn row(result: &RunResult) -> String {
    let r = &result.record;
    format!(
        "{:<8} {:<7} {:<16} {:>5.1} m run {:>2}: {:<5} {:<40} sim {:>7.2} s wall {:>7.2} s (×{:.1}) walked {:.3} m at {}{} final error {:.4} m drift {} max tilt {:.3} rad stance {}/{} {}{}{}{}{}",
        result.robot,
        result.gait.name(),
        r.affordances.name(),
        r.distance_m,
        r.seed,
        if r.success { "ok" } else { "FAIL" },
        format!("{}{}", r.outcome, r.reaches_given_up_note()),
        r.sim_s,
        result.wall_s,
        r.sim_s / result.wall_s,
        r.walked_m,
        r.speed_m_s
            .map_or_else(|| "no step".to_owned(), |v| format!("{v:.3} m/s")),
        result
            .requested_speed_m_s
            .map_or_else(String::new, |v| format!(" (asked {v:.3} m/s)")),
        result.final_position_error_m,
        r.drift_m
            .map_or_else(|| "n/a".to_owned(), |d| format!("{d:.4} m")),
        r.max_tilt_rad,
        result.stance_reached,
        r.stances,
        describe_steps(&result.steps),
        result
            .hand_support_share
            .map_or_else(String::new, |share| format!(" hand share {share:.3}")),
        result
            .hand_support_asked
            .map_or_else(String::new, |asked| format!(" (asked {asked:.3})")),
        r.actuators
            .as_ref()
            .map_or_else(String::new, |a| format!(" {}", a.describe())),
        result
            .timing
            .map_or_else(String::new, |t| format!(" {}", t.describe()))
    )
}

/// Steps (of those planned) with their time, the foothold error, and where they are not zero the
/// climb and the legs' terrain collisions.
fn describe_steps(steps: &StepReport) -> String {
    let mut out = format!("steps {}/{}", steps.steps, steps.planned_steps);
    if let Some(t) = steps.time_per_step_s {
        let _ = write!(out, " ({t:.2} s each)");
    }
    if let Some(t) = steps.time_per_stair_s {
        let _ = write!(out, " {t:.2} s per stair");
    }
    let _ = match steps.foothold_error_m {
        Some(error) => write!(out, " foothold error {error:.3} m"),
        None => write!(out, " foothold error n/a"),
    };
    let climb = steps.end_elevation_m - steps.start_elevation_m;
    if climb.abs() >= 0.005 {
        let _ = write!(out, " climbed {climb:+.3} m");
    }
    if let Some(clearance) = steps.edge_clearance_m {
        let _ = write!(out, " edge clearance {clearance:.3} m");
    }
    if steps.terrain_collisions > 0 {
        let _ = write!(out, " leg-terrain collisions {}", steps.terrain_collisions);
    }
    out
}

/// Per robot, affordance set and distance: successes, mean simulated and wall time, real-time
/// factor, and the speed of the successful runs.
fn summary(results: &[RunResult]) -> String {
    let mut out = String::from(
        "robot    affordances      distance  success  sim_s(mean)  wall_s(mean)  real-time factor  speed m/s (mean, min)\n",
    );
    let mut robots: Vec<&str> = Vec::new();
    for r in results {
        if !robots.contains(&r.robot.as_str()) {
            robots.push(&r.robot);
        }
    }
    for robot in robots {
        let mine: Vec<&RunResult> = results.iter().filter(|r| r.robot == robot).collect();
        for (group, runs) in group_by_cell(&mine, |r| &r.record) {
            let n = runs.len() as f64;
            let sim: f64 = runs.iter().map(|r| r.record.sim_s).sum();
            let wall: f64 = runs.iter().map(|r| r.wall_s).sum();
            let speed = match (group.speed_mean_m_s, group.speed_min_m_s) {
                (Some(mean), Some(min)) => format!("{mean:.3}, {min:.3}"),
                _ => "-".to_owned(),
            };
            let _ = writeln!(
                out,
                "{robot:<8} {:<16} {:>6.1} m  {:>3}/{:<3} {:>11.2}  {:>12.2}  {:>16.1}  {speed}",
                group.affordances.name(),
                group.distance_m,
                group.done,
                group.runs,
                sim / n,
                wall / n,
                sim / wall
            );
            if let Some(actuators) = &group.actuators {
                let _ = writeln!(
                    out,
                    "{:<8} {:<16} {:>6.1} m  peak {}",
                    "",
                    "",
                    group.distance_m,
                    actuators.describe()
                );
            }
            let shares: Vec<f64> = runs.iter().filter_map(|r| r.hand_support_share).collect();
            if !shares.is_empty() {
                let asked: Vec<f64> = runs.iter().filter_map(|r| r.hand_support_asked).collect();
                let _ = writeln!(
                    out,
                    "{:<8} {:<16} {:>6.1} m  hand support share mean {:.3}, min {:.3}, max {:.3}{}",
                    "",
                    "",
                    group.distance_m,
                    shares.iter().sum::<f64>() / shares.len() as f64,
                    shares.iter().copied().fold(f64::INFINITY, f64::min),
                    shares.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                    if asked.is_empty() {
                        String::new()
                    } else {
                        format!(
                            " (asked mean {:.3})",
                            asked.iter().sum::<f64>() / asked.len() as f64
                        )
                    }
                );
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_errored_run_is_reported_and_fails_the_evaluation() {
        let errors = [RunError {
            run: "jvrc1 feet 5 m run 3".to_owned(),
            message: "walkd did not get fresh samples within 30 s".to_owned(),
        }];
        let json = report_json(&[], &errors);
        assert_eq!(json["runs"].as_array().map(Vec::len), Some(0));
        assert_eq!(json["errors"][0]["run"], "jvrc1 feet 5 m run 3");
        assert_eq!(
            json["errors"][0]["error"],
            "walkd did not get fresh samples within 30 s"
        );
        let verdict = verdict(&[], &errors).unwrap_err().to_string();
        assert_eq!(
            verdict,
            "1 of 1 runs did not succeed (1 of them errored before their end)"
        );
        assert_eq!(
            errors[0].to_string(),
            "error: jvrc1 feet 5 m run 3: walkd did not get fresh samples within 30 s"
        );
        assert!(super::verdict(&[], &[]).is_ok());
    }
}
