//! `walkctl evaluate`: the paper's execution evaluation over the real processes.
//!
//! For every robot × affordance set × distance × run it generates a walk (seed = run number),
//! post-processes it, starts its own `walkd` and `walk-sim --physics <backend>` in lockstep on a
//! service prefix of its own, submits the walk, records the daemon's status stream and stops the
//! processes. A run succeeds when the daemon reports `done` and `walk-sim` reports no fall in
//! its final safety summary. `--plots DIR` writes the paper's Fig. 6 per robot (first run of
//! the first distance, feet only): target vs controller state over time for the CoM and both
//! feet — plus the simulator's truth where the caller has it ([`write_fig6`] is shared with the
//! in-process physics walk of the `walk-tests` package, which does).
//!
//! What the process path cannot measure yet: the simulator's ground truth (CoM and foot poses)
//! is not published over IPC, so `drift_m` is `null` and the final position error is taken from
//! the controller's own estimate (`final_error_source: "controller"`).

use std::ffi::OsString;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use kinematics::kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};
use nalgebra::Vector3;
use plotters::prelude::*;
use shm_types::{DaemonState, DaemonStatus};
use stance::{AffordanceSet, PostProcessedSequence};

use crate::daemon_client::DaemonClient;

/// Simulator backends `walk-sim` offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum EvaluatePhysics {
    /// Rigid-body dynamics with contacts (the paper's Bullet role).
    Mujoco,
    /// The deterministic kinematic simulator.
    Kinematic,
}

impl EvaluatePhysics {
    fn name(self) -> &'static str {
        match self {
            Self::Mujoco => "mujoco",
            Self::Kinematic => "kinematic",
        }
    }
}

/// Arguments of `walkctl evaluate`.
#[derive(Debug, clap::Args)]
pub struct EvaluateArgs {
    /// Robots (config names under the config directory).
    #[arg(long, value_delimiter = ',', default_value = "armar4,jvrc1")]
    pub robots: Vec<String>,
    /// Affordance sets.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "feet,feet+left-hand,feet+right-hand"
    )]
    pub affordances: Vec<AffordanceSet>,
    /// Distances to walk (m).
    #[arg(long, value_delimiter = ',', default_value = "1,5")]
    pub distances: Vec<f64>,
    /// Runs per robot, affordance set and distance (run i uses generator seed i).
    #[arg(long, default_value_t = 10)]
    pub runs: u32,
    /// Simulator backend of `walk-sim`.
    #[arg(long, value_enum, default_value = "mujoco")]
    pub physics: EvaluatePhysics,
    /// Directory with the robot configs (`<robot>.toml`).
    #[arg(long, default_value = "configs")]
    pub config_dir: PathBuf,
    /// URDF overriding the configs' (HRP-4's model is not vendored).
    #[arg(long)]
    pub urdf: Option<PathBuf>,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Write Fig. 6 per robot (`fig6_<robot>.svg`) into this directory.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
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
    /// The CoM and sole positions a daemon status reports.
    pub fn from_status(com: &[f64; 3], left_foot: &[f64; 7], right_foot: &[f64; 7]) -> Self {
        let xyz = |p: &[f64]| Vector3::new(p[0], p[1], p[2]);
        Self {
            com: xyz(com),
            left_foot: xyz(left_foot),
            right_foot: xyz(right_foot),
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

/// Moves `targets` (in the sequence's frame) onto the robot's standing feet `start` by the planar
/// transform (x, y, yaw) that takes the first stance's feet midpoint and left-to-right direction
/// onto the standing ones — the alignment the controller makes when a walk begins.
pub fn align_targets(targets: &mut [Points], start: &Points) {
    let Some(first) = targets.first().copied() else {
        return;
    };
    let heading = |p: &Points| {
        let d = p.left_foot - p.right_foot;
        d.y.atan2(d.x)
    };
    let midpoint = |p: &Points| (p.left_foot + p.right_foot) / 2.0;
    let rotation =
        nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), heading(start) - heading(&first));
    let (from, to) = (midpoint(&first), midpoint(start));
    let map = |v: Vector3<f64>| {
        let mut p = rotation * (v - from);
        p.x += to.x;
        p.y += to.y;
        p.z += from.z;
        p
    };
    for target in targets {
        *target = Points {
            com: map(target.com),
            left_foot: map(target.left_foot),
            right_foot: map(target.right_foot),
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

/// What one run measured.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// Robot config name.
    pub robot: String,
    /// Affordance set.
    pub affordances: AffordanceSet,
    /// Requested distance (m).
    pub distance_m: f64,
    /// Run number (= generator seed).
    pub run: u32,
    /// `done` and no fall reported by the simulator.
    pub success: bool,
    /// `done`, `fault: <reason>`, `fell`, ...
    pub outcome: String,
    /// Simulated (control-tick) time from submission to the end (s).
    pub sim_s: f64,
    /// Wall time from submission to the end (s).
    pub wall_s: f64,
    /// Largest distance of a sole from its final target at the end, controller estimate (m).
    pub final_position_error_m: f64,
    /// Simulator-vs-controller drift (m); `None` when the simulator's truth is not available.
    pub drift_m: Option<f64>,
    /// Stances in the walk.
    pub stances: usize,
    /// The stance the daemon was moving towards at the end.
    pub stance_reached: u32,
    /// The status stream as a Fig. 6 trace.
    pub trace: Vec<TraceSample>,
}

impl RunResult {
    fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "robot": self.robot,
            "affordances": self.affordances.name(),
            "distance_m": self.distance_m,
            "run": self.run,
            "success": self.success,
            "outcome": self.outcome,
            "sim_s": self.sim_s,
            "wall_s": self.wall_s,
            "drift_m": self.drift_m,
            "final_position_error_m": self.final_position_error_m,
            "final_error_source": "controller",
            "stances": self.stances,
            "stance_reached": self.stance_reached,
        })
    }
}

/// `walkctl evaluate`: runs the matrix, prints the table or JSON, writes the plots; fails unless
/// every run succeeded.
pub fn run(args: &EvaluateArgs) -> anyhow::Result<()> {
    anyhow::ensure!(args.runs > 0, "--runs must be at least 1");
    anyhow::ensure!(
        args.distances.iter().all(|d| d.is_finite() && *d > 0.0),
        "--distances must be positive numbers"
    );
    let mut results = Vec::new();
    for robot in &args.robots {
        let config = args.config_dir.join(format!("{robot}.toml"));
        let model = Robot::load(&config, args.urdf.as_deref())
            .with_context(|| format!("robot `{robot}` ({})", config.display()))?;
        for &affordances in &args.affordances {
            for &distance in &args.distances {
                for run in 0..args.runs {
                    let result = run_once(args, robot, &model, &config, affordances, distance, run)
                        .with_context(|| format!("{robot} {affordances} {distance} m run {run}"))?;
                    if !args.json {
                        eprintln!("{}", row(&result));
                    }
                    results.push(result);
                }
            }
        }
        if let Some(dir) = &args.plots {
            plot_robot(dir, robot, &results)?;
        }
    }
    if args.json {
        let runs: Vec<_> = results.iter().map(RunResult::json).collect();
        println!("{}", serde_json::json!({ "runs": runs }));
    } else {
        print!("{}", summary(&results));
    }
    let failed = results.iter().filter(|r| !r.success).count();
    if failed > 0 {
        bail!("{failed} of {} runs did not succeed", results.len());
    }
    Ok(())
}

/// Fig. 6 of `robot`'s first feet-only run (or its first run) into `dir`.
fn plot_robot(dir: &Path, robot: &str, results: &[RunResult]) -> anyhow::Result<()> {
    let mine = || results.iter().filter(|r| r.robot == robot);
    let Some(result) = mine()
        .find(|r| r.affordances == AffordanceSet::Feet)
        .or_else(|| mine().next())
    else {
        return Ok(());
    };
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let file = dir.join(format!("fig6_{robot}.svg"));
    let title = format!(
        "{robot}, {} m, {}, run {} ({})",
        result.distance_m,
        result.affordances.name(),
        result.run,
        result.outcome
    );
    write_fig6(&file, &title, &result.trace)
}

/// One run: own processes on an own prefix, submit, record, stop.
fn run_once(
    args: &EvaluateArgs,
    robot: &str,
    model: &Robot,
    config: &Path,
    affordances: AffordanceSet,
    distance: f64,
    run: u32,
) -> anyhow::Result<RunResult> {
    let params = stance::PostProcessParams::from_config_path(config)?;
    let raw = stance::generate(
        model,
        &stance::GenerateOptions {
            distance: distance / params.scf,
            affordances,
            seed: u64::from(run),
        },
    )?;
    let sequence = stance::PostProcessor::new(model, params).process(&raw)?;
    let mut targets = stance_points(model, &sequence);
    let prefix = format!("walk-eval/{robot}/{}/{run}", std::process::id());
    let mut common: Vec<OsString> = vec![
        "--config".into(),
        config.into(),
        "--service-prefix".into(),
        prefix.clone().into(),
        "--clock".into(),
        "lockstep".into(),
    ];
    if let Some(urdf) = &args.urdf {
        common.extend(["--urdf".into(), urdf.into()]);
    }
    let mut walkd_args = common.clone();
    walkd_args.push("--no-lock-memory".into());
    let walkd = Process::start("walkd", &walkd_args)?;
    let mut sim_args = common;
    sim_args.extend(["--physics".into(), args.physics.name().into()]);
    let sim = Process::start("walk-sim", &sim_args)?;
    let client = connect(&prefix, &[&walkd, &sim], Duration::from_secs(30))?;
    let start = client.status()?;
    align_targets(
        &mut targets,
        &Points::from_status(&start.com, &start.left_foot, &start.right_foot),
    );
    let wall = Instant::now();
    let id = client.submit_json(&sequence.to_json_string())?;
    let mut trace = Vec::new();
    let timeout = Duration::from_secs(120 + 60 * sequence.len() as u64);
    let last = client.wait_for_sequence(id, timeout, |status| {
        if status.sequence_id == id {
            trace.push(sample(status, &start, &targets));
        }
    })?;
    let wall_s = wall.elapsed().as_secs_f64();
    drop(client);
    let walkd_log = walkd.stop()?;
    let sim_log = sim.stop()?;
    let fell = reported_fall(&sim_log)
        .with_context(|| format!("walk-sim's log:\n{sim_log}\nwalkd's log:\n{walkd_log}"))?;
    let end = Points::from_status(&last.com, &last.left_foot, &last.right_foot);
    let final_target = targets[targets.len() - 1];
    let done = last.state == DaemonState::Done;
    let outcome = match (done, fell) {
        (_, true) => "fell".to_owned(),
        (true, false) => "done".to_owned(),
        (false, false) => format!("{}: {}", last.state.name(), last.fault),
    };
    Ok(RunResult {
        robot: robot.to_owned(),
        affordances,
        distance_m: distance,
        run,
        success: done && !fell,
        outcome,
        sim_s: (last.ticks - start.ticks) as f64 / last.rate_hz,
        wall_s,
        final_position_error_m: end.distances(&final_target).1,
        drift_m: None,
        stances: sequence.len(),
        stance_reached: last.stance_index,
        trace,
    })
}

fn sample(status: &DaemonStatus, start: &DaemonStatus, targets: &[Points]) -> TraceSample {
    let index = (status.stance_index as usize).min(targets.len() - 1);
    TraceSample {
        t: (status.ticks.saturating_sub(start.ticks)) as f64 / status.rate_hz,
        stance_index: status.stance_index,
        target: targets[index],
        controller: Points::from_status(&status.com, &status.left_foot, &status.right_foot),
        sim: None,
    }
}

/// `fell=true|false` from walk-sim's final safety summary (its "walk-sim stopped" log line).
fn reported_fall(log: &str) -> anyhow::Result<bool> {
    let line = log
        .lines()
        .rfind(|line| line.contains("walk-sim stopped"))
        .context("walk-sim did not log its final safety summary (`walk-sim stopped`)")?;
    if line.contains("fell=true") {
        Ok(true)
    } else if line.contains("fell=false") {
        Ok(false)
    } else {
        bail!("walk-sim's final summary has no `fell=` field: {line}")
    }
}

/// Waits until the daemon on `prefix` serves with a fresh adapter link.
fn connect(
    prefix: &str,
    processes: &[&Process],
    timeout: Duration,
) -> anyhow::Result<DaemonClient> {
    let start = Instant::now();
    loop {
        for process in processes {
            process.check_running()?;
        }
        if let Ok(client) = DaemonClient::connect(prefix)
            && client.is_running()
            && let Ok(status) = client.status()
            && status.link == shm_types::LinkState::Fresh
        {
            return Ok(client);
        }
        if start.elapsed() > timeout {
            bail!("walkd on `{prefix}` did not get fresh samples within {timeout:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A child process (found next to `walkctl`) whose stderr goes to a temporary log file; killed
/// if dropped while it runs.
struct Process {
    name: &'static str,
    child: std::cell::RefCell<Child>,
    log: PathBuf,
}

impl Process {
    fn start(name: &'static str, args: &[OsString]) -> anyhow::Result<Self> {
        let binary = std::env::current_exe()?
            .parent()
            .map(|dir| dir.join(name))
            .filter(|path| path.is_file())
            .with_context(|| format!("`{name}` not found next to walkctl (build all binaries)"))?;
        static COUNT: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        let n = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let log = std::env::temp_dir().join(format!(
            "walkctl-evaluate-{}-{name}-{n}.log",
            std::process::id()
        ));
        let child = Command::new(&binary)
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log)?)
            .spawn()
            .with_context(|| format!("cannot start {}", binary.display()))?;
        Ok(Self {
            name,
            child: std::cell::RefCell::new(child),
            log,
        })
    }

    fn check_running(&self) -> anyhow::Result<()> {
        if let Ok(Some(status)) = self.child.borrow_mut().try_wait() {
            let log = std::fs::read_to_string(&self.log).unwrap_or_default();
            bail!("{} exited during start-up ({status}):\n{log}", self.name);
        }
        Ok(())
    }

    /// SIGTERM, wait up to 5 s (then SIGKILL); returns the process's log.
    fn stop(self) -> anyhow::Result<String> {
        let mut child = self.child.borrow_mut();
        // SAFETY: kill with the pid of our own child has no memory-safety preconditions.
        unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
        let start = Instant::now();
        while child.try_wait()?.is_none() {
            if start.elapsed() > Duration::from_secs(5) {
                child.kill()?;
                child.wait()?;
                break;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        drop(child);
        let log = std::fs::read_to_string(&self.log).unwrap_or_default();
        Ok(log)
    }
}

impl Drop for Process {
    fn drop(&mut self) {
        let child = self.child.get_mut();
        if matches!(child.try_wait(), Ok(None)) {
            let _ = child.kill();
            let _ = child.wait();
        }
        let _ = std::fs::remove_file(&self.log);
    }
}

fn row(r: &RunResult) -> String {
    format!(
        "{:<8} {:<16} {:>5.1} m run {:>2}: {:<5} {:<40} sim {:>7.2} s wall {:>7.2} s (×{:.1}) final error {:.4} m stance {}/{}",
        r.robot,
        r.affordances.name(),
        r.distance_m,
        r.run,
        if r.success { "ok" } else { "FAIL" },
        r.outcome,
        r.sim_s,
        r.wall_s,
        r.sim_s / r.wall_s,
        r.final_position_error_m,
        r.stance_reached,
        r.stances
    )
}

/// Per robot, affordance set and distance: successes, mean simulated and wall time, real-time factor.
fn summary(results: &[RunResult]) -> String {
    let mut out = String::from(
        "robot    affordances      distance  success  sim_s(mean)  wall_s(mean)  real-time factor\n",
    );
    let mut groups: Vec<(&str, AffordanceSet, f64)> = Vec::new();
    for r in results {
        let key = (r.robot.as_str(), r.affordances, r.distance_m);
        if !groups.contains(&key) {
            groups.push(key);
        }
    }
    for (robot, affordances, distance) in groups {
        let runs: Vec<_> = results
            .iter()
            .filter(|r| {
                r.robot == robot && r.affordances == affordances && r.distance_m == distance
            })
            .collect();
        let n = runs.len() as f64;
        let ok = runs.iter().filter(|r| r.success).count();
        let sim: f64 = runs.iter().map(|r| r.sim_s).sum();
        let wall: f64 = runs.iter().map(|r| r.wall_s).sum();
        let _ = writeln!(
            out,
            "{robot:<8} {:<16} {distance:>6.1} m  {ok:>3}/{:<3} {:>11.2}  {:>12.2}  {:>16.1}",
            affordances.name(),
            runs.len(),
            sim / n,
            wall / n,
            sim / wall
        );
    }
    out
}

/// Writes the paper's Fig. 6: x, y and z over time of the CoM and both soles — target (dashed),
/// controller estimate (solid) and, where present, the simulator's truth (dotted) — nine panels.
pub fn write_fig6(file: &Path, title: &str, trace: &[TraceSample]) -> anyhow::Result<()> {
    draw_fig6(file, title, trace)
        .map_err(|e| anyhow::anyhow!("{}: cannot draw Fig. 6: {e}", file.display()))
}

type DrawResult = Result<(), Box<dyn std::error::Error>>;
/// Picks one of the three plotted points.
type PointOf = fn(&Points) -> Vector3<f64>;

fn draw_fig6(file: &Path, title: &str, trace: &[TraceSample]) -> DrawResult {
    let root = SVGBackend::new(file, (1500, 900)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(title, ("sans-serif", 20))?;
    let end = trace.last().map_or(1.0, |s| s.t.max(1e-3));
    let series: [(&str, PointOf); 3] = [
        ("CoM", |p| p.com),
        ("left foot", |p| p.left_foot),
        ("right foot", |p| p.right_foot),
    ];
    for (r, row_area) in root.split_evenly((3, 1)).iter().enumerate() {
        let (name, point) = series[r];
        for (axis, area) in row_area.split_evenly((1, 3)).iter().enumerate() {
            let value = |p: &Points| point(p)[axis];
            let values = trace.iter().flat_map(|s| {
                [
                    Some(value(&s.target)),
                    Some(value(&s.controller)),
                    s.sim.as_ref().map(value),
                ]
                .into_iter()
                .flatten()
            });
            let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
            let (lo, hi) = if lo.is_finite() { (lo, hi) } else { (0.0, 1.0) };
            let margin = ((hi - lo) * 0.1).max(0.005);
            let mut chart = ChartBuilder::on(area)
                .caption(
                    format!("{name} {}", ["x", "y", "z"][axis]),
                    ("sans-serif", 14),
                )
                .margin(6)
                .x_label_area_size(28)
                .y_label_area_size(52)
                .build_cartesian_2d(0.0..end, lo - margin..hi + margin)?;
            chart
                .configure_mesh()
                .x_desc("t (s)")
                .y_desc("m")
                .light_line_style(WHITE)
                .draw()?;
            let line = |get: &dyn Fn(&TraceSample) -> Option<f64>| -> Vec<(f64, f64)> {
                trace
                    .iter()
                    .filter_map(|s| get(s).map(|v| (s.t, v)))
                    .collect()
            };
            chart
                .draw_series(DashedLineSeries::new(
                    line(&|s| Some(value(&s.target))),
                    6,
                    4,
                    RED.stroke_width(2),
                ))?
                .label("target")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], RED));
            chart
                .draw_series(LineSeries::new(
                    line(&|s| Some(value(&s.controller))),
                    BLUE.stroke_width(2),
                ))?
                .label("controller")
                .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], BLUE));
            let sim = line(&|s| s.sim.as_ref().map(value));
            if !sim.is_empty() {
                chart
                    .draw_series(DashedLineSeries::new(sim, 2, 3, GREEN.stroke_width(2)))?
                    .label("simulator")
                    .legend(|(x, y)| PathElement::new([(x, y), (x + 16, y)], GREEN));
            }
            if r == 0 && axis == 0 {
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK)
                    .draw()?;
            }
        }
    }
    root.present()?;
    Ok(())
}
