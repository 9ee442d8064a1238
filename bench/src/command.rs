//! `walk-bench`: generate (synthetic or learned source) and post-process a walk, or read one
//! from a stance file, execute it in-process against the kinematic simulator, as fast as
//! possible, and report outcome, safety and timing.
//!
//! Timing is taken here, outside the controller core: the tick duration around
//! `Controller::tick`, and the QP time by re-solving each tick's QP (the controller's
//! `last_problem`) with a second solver of the same kind, warm-started the same way.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;
use client::args::{DISTANCE_M, RATE_HZ};
use daemon::controller::{Controller, ControllerConfig, ControllerState, SolverKind};
use daemon::qp::{ClarabelSolver, DenseActiveSetSolver, QpSolver, export_json};
use hdrhistogram::Histogram;
use kinematics::ConfigFile;
use kinematics::robot::Robot;
use shm_types::RuntimeConfig;
use stance::learned::SourceArgs;
use stance::{AffordanceSet, Gait, PostProcessParams, PostProcessedSequence, Scene, WalkRequest};

use crate::sequence::{self, SequenceError};
use crate::walk::{Outcome, WalkOptions, WalkReport, kinematic_gaits, walk};

/// Control rate when neither `--rate-hz` nor `[runtime] rate_hz` gives one (Hz).
const DEFAULT_RATE_HZ: f64 = 500.0;
/// Every this many executing ticks one QP goes into the `--export-qp` sample ...
const EXPORT_EVERY: u64 = 50;
/// ... up to this many problems.
const EXPORT_MAX: usize = 200;

/// QP back-end names on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SolverArg {
    /// Dense active set (default).
    Dense,
    /// Clarabel interior point.
    Clarabel,
}

impl From<SolverArg> for SolverKind {
    fn from(arg: SolverArg) -> Self {
        match arg {
            SolverArg::Dense => SolverKind::Dense,
            SolverArg::Clarabel => SolverKind::Clarabel,
        }
    }
}

/// Arguments of `walk-bench` (its whole command line).
#[derive(Debug, clap::Parser)]
#[command(
    name = "walk-bench",
    version,
    about = "Generate (or read), post-process and execute a walk in-process against the kinematic \
             simulator; report outcome, safety and timing."
)]
pub struct BenchArgs {
    /// Robot config (TOML with [robot], [postprocess], [controller], [runtime]).
    #[arg(long, value_name = "CONFIG")]
    pub robot: PathBuf,
    /// URDF overriding the config's (required for HRP-4).
    #[arg(long, value_name = "PATH")]
    pub urdf: Option<PathBuf>,
    /// Distance to walk (m, 0.01-1000), requested from the generator as distance / scf; through
    /// a `--scene`, its path's first D m (default the whole path).
    #[arg(
        long,
        value_name = "D",
        required_unless_present_any = ["sequence", "scene"],
        value_parser = DISTANCE_M.parser()
    )]
    pub distance: Option<f64>,
    /// Execute this stance file instead of generating: a post-processed sequence (as written
    /// by `walkctl postprocess`), or a raw one (`walkctl generate`) with --postprocess.
    #[arg(
        long,
        value_name = "FILE",
        conflicts_with_all = ["distance", "source", "model", "beam", "seed", "affordances"]
    )]
    pub sequence: Option<PathBuf>,
    /// Post-process the --sequence file with the config's [postprocess] first (it is raw).
    #[arg(long, requires = "sequence", conflicts_with = "distance")]
    pub postprocess: bool,
    #[command(flatten)]
    pub source: SourceArgs,
    /// Walk through this scene (docs/scenes.md) from its start towards its goal (the whole path,
    /// or its first `--distance` metres), and the kinematic simulator stands the feet on its
    /// surfaces (its railings are not modelled).
    #[arg(long, value_name = "FILE", conflicts_with = "sequence")]
    pub scene: Option<PathBuf>,
    /// Support affordances: feet, feet+left-hand or feet+right-hand.
    #[arg(long, value_name = "SET", default_value = "feet")]
    pub affordances: AffordanceSet,
    /// QP back-end.
    #[arg(long, value_enum, default_value = "dense")]
    pub solver: SolverArg,
    /// Control rate (Hz, 10-10000); default: [runtime] rate_hz of the config, else 500.
    #[arg(long, value_name = "F", value_parser = RATE_HZ.parser())]
    pub rate_hz: Option<f64>,
    /// Seed of the stance generator (synthetic, or learned without --beam).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Gait: static or dynamic (default: the config's `[gait] default`). A generated walk is
    /// post-processed with its limits. The dynamic gait is judged by its ZMP, with the
    /// stabilizer parts that need forces and inertia off (`walk_bench::kinematic_gaits`). A
    /// gait the robot cannot walk is refused before the walk.
    #[arg(long)]
    pub gait: Option<Gait>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Write a sample of the solved QPs (JSON array, see daemon::qp::export_json) to FILE.
    #[arg(long, value_name = "FILE")]
    pub export_qp: Option<PathBuf>,
}

/// Runs `walk-bench`: exit 0 when the walk reached `done`, 1 when it did not, 2 on bad input.
pub fn main(args: &BenchArgs) -> ExitCode {
    match run(args) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(error) => {
            eprintln!("walk-bench: {error:#}");
            ExitCode::from(2)
        }
    }
}

/// Latency histograms (ns) of the walk.
struct Timing {
    tick: Histogram<u64>,
    qp: Histogram<u64>,
}

impl Timing {
    fn new() -> anyhow::Result<Self> {
        Ok(Self {
            tick: Histogram::new_with_bounds(1, 10_000_000_000, 3)?,
            qp: Histogram::new_with_bounds(1, 10_000_000_000, 3)?,
        })
    }
}

fn run(args: &BenchArgs) -> anyhow::Result<bool> {
    let file = ConfigFile::load(&args.robot)?;
    let gait = Gait::for_walk(args.gait, &file)?;
    let robot = Arc::new(
        Robot::from_config(&file, args.urdf.as_deref())
            .with_context(|| format!("loading robot {}", args.robot.display()))?,
    );
    let params = PostProcessParams::from_config_for(&file, gait)?;
    let config = ControllerConfig::from_config(&file)?;
    let gaits = kinematic_gaits(&file)?;
    let rate_hz = match (args.rate_hz, file.section("runtime")) {
        (Some(rate), _) => rate,
        (None, Some(section)) => {
            RuntimeConfig::from_section(Some(section), &file.origin())?.rate_hz
        }
        (None, None) => DEFAULT_RATE_HZ,
    };
    let (sequence, origin) = bench_sequence(args, &robot, params)?;
    let solver_kind = SolverKind::from(args.solver);
    let options = WalkOptions {
        solver: solver_kind,
        rate_hz,
        time_limit_s: 60.0 + 20.0 * sequence.len() as f64,
        gait,
        gaits,
    };
    let mut timing = Timing::new()?;
    let mut timing_solver: Box<dyn QpSolver> = match solver_kind {
        SolverKind::Dense => {
            let n = robot.model.nv();
            let p = Controller::qp_capacity();
            Box::new(DenseActiveSetSolver::new(n, p.0, p.1))
        }
        SolverKind::Clarabel => Box::new(ClarabelSolver::new()),
    };
    let mut solution = vec![0.0; robot.model.nv()];
    let mut exported = Vec::new();
    let mut executing_ticks = 0u64;
    let report = walk(robot.clone(), config, &sequence, &options, |o| {
        timing.tick.saturating_record(o.tick_ns.max(1));
        if o.status.state != ControllerState::Executing {
            return;
        }
        let problem = o.controller.last_problem();
        let started = Instant::now();
        let solved = timing_solver.solve(problem, &mut solution).is_ok();
        let qp_ns = started.elapsed().as_nanos() as u64;
        if solved {
            timing.qp.saturating_record(qp_ns.max(1));
        }
        if args.export_qp.is_some()
            && executing_ticks % EXPORT_EVERY == 0
            && exported.len() < EXPORT_MAX
        {
            exported.push(export_json(problem));
        }
        executing_ticks += 1;
    })?;
    if let Some(path) = &args.export_qp {
        std::fs::write(path, serde_json::to_string(&exported)?)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    print_report(args, &robot, &origin, &options, &report, &timing);
    Ok(report.outcome == Outcome::Done)
}

/// The walk to execute and a one-line description of where it came from: the `--sequence`
/// file, or a sequence generated by the selected source and post-processed.
fn bench_sequence(
    args: &BenchArgs,
    robot: &Robot,
    params: PostProcessParams,
) -> anyhow::Result<(PostProcessedSequence, String)> {
    if let Some(path) = &args.scene {
        let scene = Scene::from_path(path)?;
        let source = args.source.load()?;
        let request = WalkRequest {
            distance: scene.walk_length(args.distance).context("--distance")?,
            affordances: args.affordances,
            seed: args.seed,
            speed: None,
        };
        let walk = source
            .walk_in(robot, &params, &request, &scene.walk_environment())
            .map_err(SequenceError::Walk)?;
        let origin = format!(
            "scene {} ({:.2} m), affordances {}, source {}",
            path.display(),
            request.distance,
            args.affordances,
            source.describe(args.seed)
        );
        return Ok((walk, origin));
    }
    Ok(match (&args.sequence, args.distance) {
        (Some(path), _) => (
            sequence::from_file(robot, params, path, args.postprocess)?,
            path.display().to_string(),
        ),
        (None, Some(distance)) => {
            anyhow::ensure!(
                distance.is_finite() && distance > 0.0,
                "--distance {distance}: must be a positive number of metres"
            );
            let source = args.source.load()?;
            let request = WalkRequest {
                distance,
                affordances: args.affordances,
                seed: args.seed,
                speed: None,
            };
            let generated = sequence::generated(robot, &params, &source, &request)?;
            let origin = format!(
                "{distance} m requested, affordances {}, source {}",
                args.affordances,
                source.describe(args.seed)
            );
            (generated, origin)
        }
        (None, None) => anyhow::bail!("give --distance D or --sequence FILE"),
    })
}

fn micros(h: &Histogram<u64>, quantile: f64) -> f64 {
    if h.is_empty() {
        return 0.0;
    }
    let ns = if quantile >= 1.0 {
        h.max()
    } else {
        h.value_at_quantile(quantile)
    };
    (ns as f64 / 1000.0 * 100.0).round() / 100.0
}

/// Latency percentiles in microseconds.
#[derive(serde::Serialize)]
struct Quantiles {
    p50: f64,
    p99: f64,
    max: f64,
}

impl Quantiles {
    fn of(h: &Histogram<u64>) -> Self {
        Self {
            p50: micros(h, 0.5),
            p99: micros(h, 0.99),
            max: micros(h, 1.0),
        }
    }
}

/// The `--json` report, fields in the documented order.
#[derive(serde::Serialize)]
struct JsonReport {
    outcome: String,
    gait: &'static str,
    stances: usize,
    ticks: u64,
    tick_us: Quantiles,
    qp_us: Quantiles,
    min_stability_margin_m: f64,
    max_contact_slip_m: f64,
    joint_limit_violations: u64,
    distance_m: f64,
    reaches_given_up: u32,
}

fn print_report(
    args: &BenchArgs,
    robot: &Robot,
    origin: &str,
    options: &WalkOptions,
    report: &WalkReport,
    timing: &Timing,
) {
    let safety = &report.safety;
    let rate_hz = options.rate_hz;
    if args.json {
        let value = JsonReport {
            outcome: report.outcome.label(),
            gait: options.gait.name(),
            stances: report.stances,
            ticks: report.ticks,
            tick_us: Quantiles::of(&timing.tick),
            qp_us: Quantiles::of(&timing.qp),
            min_stability_margin_m: safety.min_stability_margin,
            max_contact_slip_m: safety.max_contact_slip,
            joint_limit_violations: safety.joint_limit_violations,
            distance_m: report.distance_m,
            reaches_given_up: report.reaches_given_up,
        };
        match serde_json::to_string(&value) {
            Ok(line) => println!("{line}"),
            Err(error) => eprintln!("walk-bench: cannot write the JSON report: {error}"),
        }
        return;
    }
    println!(
        "walk-bench: {} ({}), {origin}, {} gait, solver {}, {} Hz",
        robot.name,
        args.robot.display(),
        options.gait.name(),
        options.solver.name(),
        rate_hz
    );
    println!("  outcome                {}", report.outcome.label());
    println!(
        "  stances                {} in {} ticks ({:.1} s simulated)",
        report.stances,
        report.ticks,
        report.ticks as f64 / rate_hz
    );
    println!("  distance walked        {:.3} m", report.distance_m);
    println!("  hand reaches given up  {}", report.reaches_given_up);
    for (name, h) in [("tick", &timing.tick), ("qp solve", &timing.qp)] {
        println!(
            "  {name:<22} p50 {:.2} µs  p99 {:.2} µs  max {:.2} µs",
            micros(h, 0.5),
            micros(h, 0.99),
            micros(h, 1.0)
        );
    }
    let judged = match options.gait {
        Gait::Static => "CoM",
        Gait::Dynamic => "ZMP",
    };
    println!(
        "  min stability margin   {:.4} m ({judged} to the support polygon)",
        safety.min_stability_margin
    );
    println!("  max contact slip       {:.6} m", safety.max_contact_slip);
    println!("  max penetration        {:.6} m", safety.max_penetration);
    println!("  joint limit violations {}", safety.joint_limit_violations);
}
