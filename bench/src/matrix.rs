//! `physics-matrix`: a matrix of in-process MuJoCo walks (affordance sets × distances × seeds)
//! for one robot and gait, with config overrides, model error and pushes, reported per run and
//! per group. The tool behind the dynamic gait's timing sweeps, the stabilizer's on/off
//! experiments and the push sweep: each is one command line (docs/controller.md). The walks
//! over separate processes, as engineers run them, are `walkctl evaluate`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::{Arc, Mutex};

use anyhow::Context;
use clap::builder::RangedU64ValueParser;

use client::args::RATE_HZ;
use client::evaluate::{GroupSummary, MatrixCells, WalkRecord, group_by_cell, speed_cell};
use kinematics::ConfigFile;
use kinematics::bounds::Range;
use serde::Serialize;
use sim_adapter::mujoco::MujocoOptions;
use stance::{Gait, Scene, WalkRequest};

use crate::physics::{PhysicsWalkOptions, PhysicsWalkReport, Push, walk_distance};

/// Arguments of `physics-matrix` (its whole command line).
#[derive(Debug, clap::Parser)]
#[command(
    name = "physics-matrix",
    version,
    about = "Walk affordance sets × distances × seeds under MuJoCo in one process; report each \
             run and each group (done, speed, drift, tick time). Exit 0 when every walk is done."
)]
pub struct MatrixArgs {
    /// Robot config (TOML).
    #[arg(long, value_name = "CONFIG")]
    pub robot: PathBuf,
    /// URDF overriding the config's (required for HRP-4).
    #[arg(long, value_name = "PATH")]
    pub urdf: Option<PathBuf>,
    /// Gait; default: the config's `[gait] default`.
    #[arg(long)]
    pub gait: Option<Gait>,
    /// Affordance sets, distances and runs (run i uses generator seed `first_seed + i`).
    #[command(flatten)]
    pub cells: MatrixCells,
    /// Control rate (Hz, 10-10000).
    #[arg(long, default_value_t = 500.0, value_parser = RATE_HZ.parser())]
    pub rate_hz: f64,
    /// Replaces one config value, `section.key=value` (repeatable), e.g.
    /// `gait.dynamic.single_support_s=0.5` or `gait.dynamic.stabilizer.foot_damping=false`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<String>,
    /// Model error in the simulator only: every body's mass and inertia scaled by this
    /// (0.1-10, the MuJoCo option `mass_scale`).
    #[arg(long, default_value_t = 1.0)]
    pub mass_scale: f64,
    /// Friction stiffness in the simulator: MuJoCo's `impratio` (1-100; default 20, where a sole
    /// loaded inside its friction cone does not creep; at MuJoCo's own 1 it does:
    /// docs/mujoco.md, "Contacts").
    #[arg(long, default_value_t = MujocoOptions::default().impratio)]
    pub impratio: f64,
    /// MuJoCo's physics step (s; 1e-5-0.01): whether a cell's result holds at a finer step
    /// (docs/mujoco.md, "Integrator and step").
    #[arg(long, default_value_t = MujocoOptions::default().timestep)]
    pub timestep: f64,
    /// Model error in the simulator only: the pelvis CoM moved by x,y,z (m, pelvis frame; each
    /// within ±0.5, the MuJoCo option `pelvis_com_offset`).
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "X,Y,Z",
        allow_hyphen_values = true
    )]
    pub pelvis_com_offset: Option<Vec<f64>>,
    /// A sideways push on the pelvis (N·s along world y, + = left, within ±1000), centred on
    /// the middle of single support number `--push-step` (dynamic gait).
    #[arg(
        long,
        value_name = "N·s",
        allow_hyphen_values = true,
        value_parser = Range::new(-1000.0, 1000.0).parser()
    )]
    pub push_impulse: Option<f64>,
    /// Which single support the push falls in (0: the first), at most 1000.
    #[arg(long, default_value_t = 4, value_parser = RangedU64ValueParser::<usize>::new().range(0..=1000))]
    pub push_step: usize,
    /// How long the push acts (s, 0.001-5).
    #[arg(long, default_value_t = 0.1, value_parser = Range::new(0.001, 5.0).parser())]
    pub push_duration: f64,
    /// Walk every run through this scene (docs/scenes.md), from its start towards its goal,
    /// instead of on the flat floor: the whole path, or its first `--distances` metres.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
    /// Walks run at once (each in its own thread), 1-64.
    #[arg(long, default_value_t = 1, value_parser = RangedU64ValueParser::<usize>::new().range(1..=64))]
    pub jobs: usize,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// One walk of the matrix.
#[derive(Clone, Debug, Serialize)]
pub struct MatrixRun {
    /// What the walk measured (the record `walkctl evaluate` keeps too).
    #[serde(flatten)]
    pub record: WalkRecord,
    /// Why the walk could not run at all (its outcome is then `error`).
    pub error: Option<String>,
    /// Measured minus reference ZMP, rms (m; dynamic gait).
    pub zmp_rms_m: f64,
    /// True minus reference DCM, rms (m; dynamic gait).
    pub dcm_rms_m: f64,
    /// Controller tick wall time: median, 99th percentile, largest (µs).
    pub tick_us: [f64; 3],
    /// The held hands' share of the weight (`PhysicsWalkReport::hand_support_share`).
    pub hand_support_share: Option<f64>,
    /// How far the CoM stood outside the soles for a second (`PhysicsWalkReport::
    /// com_outside_feet_m`).
    pub com_outside_feet_m: f64,
}

impl MatrixRun {
    fn new(request: &WalkRequest, result: anyhow::Result<PhysicsWalkReport>) -> Self {
        let record = |outcome: String| WalkRecord {
            affordances: request.affordances,
            distance_m: request.distance,
            seed: request.seed,
            outcome,
            success: false,
            stances: 0,
            walked_m: 0.0,
            speed_m_s: None,
            sim_s: 0.0,
            drift_m: None,
            max_tilt_rad: 0.0,
            actuators: None,
            reaches_given_up: None,
        };
        match result {
            Err(error) => Self {
                record: record("error".to_owned()),
                error: Some(format!("{error:#}")),
                zmp_rms_m: 0.0,
                dcm_rms_m: 0.0,
                tick_us: [0.0; 3],
                hand_support_share: None,
                com_outside_feet_m: 0.0,
            },
            Ok(report) => Self {
                record: WalkRecord {
                    success: report.success(),
                    stances: report.stances,
                    walked_m: report.distance_m,
                    speed_m_s: report.speed_m_s(),
                    sim_s: report.sim_s,
                    drift_m: Some(report.drift_m()),
                    max_tilt_rad: report.max_tilt_rad,
                    actuators: Some(report.actuators.clone()),
                    reaches_given_up: Some(report.reaches_given_up),
                    ..record(report.outcome.label())
                },
                error: None,
                zmp_rms_m: report.balance.zmp_rms_m,
                dcm_rms_m: report.balance.dcm_rms_m,
                tick_us: report.tick_us,
                hand_support_share: report.hand_support_share,
                com_outside_feet_m: report.com_outside_feet_m,
            },
        }
    }
}

/// The runs of one affordance set and distance, summed up.
#[derive(Clone, Debug, Serialize)]
pub struct MatrixGroup {
    /// Successes, speeds and drift (as `walkctl evaluate` sums them up).
    #[serde(flatten)]
    pub summary: GroupSummary,
    /// Largest tick p99 of a run (µs).
    pub tick_p99_max_us: f64,
}

/// The whole matrix.
#[derive(Clone, Debug, Serialize)]
pub struct MatrixReport {
    /// Robot name.
    pub robot: String,
    /// Gait walked.
    pub gait: String,
    /// The `--set` overrides applied.
    pub overrides: Vec<String>,
    /// Every run, in matrix order.
    pub runs: Vec<MatrixRun>,
    /// Per affordance set and distance.
    pub groups: Vec<MatrixGroup>,
    /// Runs `done` over all.
    pub done: usize,
}

/// Runs `physics-matrix`; exit code 0 when every walk is `done`, 1 otherwise, 2 on bad input.
pub fn main(args: &MatrixArgs) -> ExitCode {
    match run(args) {
        Ok(report) => {
            if args.json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&report).expect("the report serialises")
                );
            } else {
                print_table(&report);
            }
            if report.done == report.runs.len() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
        Err(error) => {
            eprintln!("physics-matrix: {error:#}");
            ExitCode::from(2)
        }
    }
}

fn run(args: &MatrixArgs) -> anyhow::Result<MatrixReport> {
    let mut config = ConfigFile::load(&args.robot)?;
    for assignment in &args.overrides {
        config.set(assignment)?;
    }
    let gait = Gait::for_walk(args.gait, &config)?;
    walk_matrix(&config, args, gait)
}

/// Walks the matrix of `args` (its cells, rate, model error, push and jobs) for the robot of
/// `config` in `gait`; `args.robot` and `args.overrides` are not read again (`walk-tune` walks
/// configs of its own).
pub fn walk_matrix(
    config: &ConfigFile,
    args: &MatrixArgs,
    gait: Gait,
) -> anyhow::Result<MatrixReport> {
    let options = walk_options(args, gait)?;
    let robot_name = config
        .section("robot")
        .and_then(|robot| robot.get("name"))
        .and_then(toml::Value::as_str)
        .unwrap_or("robot")
        .to_owned();
    let requests = args.cells.requests(options.scene.as_deref())?;
    let runs = run_all(config, args, &options, &requests);
    let groups = groups(&runs);
    Ok(MatrixReport {
        robot: robot_name,
        gait: gait.name().to_owned(),
        overrides: args.overrides.clone(),
        done: runs.iter().filter(|r| r.record.success).count(),
        runs,
        groups,
    })
}

/// The options of every walk of the matrix: the gait's, with the command line's rate, model
/// error, friction stiffness and push; those are checked like every MuJoCo option, naming the
/// flags.
pub fn walk_options(args: &MatrixArgs, gait: Gait) -> anyhow::Result<PhysicsWalkOptions> {
    let mut options = match gait {
        Gait::Dynamic => PhysicsWalkOptions::dynamic(),
        Gait::Static => PhysicsWalkOptions::default(),
    };
    options.rate_hz = args.rate_hz;
    options.trace_every = 0;
    options.mujoco.mass_scale = args.mass_scale;
    options.mujoco.impratio = args.impratio;
    options.mujoco.timestep = args.timestep;
    if let Some(offset) = &args.pelvis_com_offset {
        let &[x, y, z] = offset.as_slice() else {
            anyhow::bail!(
                "--pelvis-com-offset {offset:?}: expected three numbers x,y,z (m), e.g. 0.01,0,0"
            );
        };
        options.mujoco.pelvis_com_offset = [x, y, z];
    }
    options
        .mujoco
        .check()
        .context("--mass-scale / --pelvis-com-offset / --impratio / --timestep")?;
    if let Some(path) = &args.scene {
        options.scene = Some(Arc::new(Scene::from_path(path)?));
    }
    if let Some(impulse) = args.push_impulse {
        options.push = Some(Push {
            step: args.push_step,
            force_n: [0.0, impulse / args.push_duration, 0.0],
            duration_s: args.push_duration,
        });
    }
    Ok(options)
}

/// Every walk of `requests`, `args.jobs` at a time, in `requests` order.
fn run_all(
    config: &ConfigFile,
    args: &MatrixArgs,
    options: &PhysicsWalkOptions,
    requests: &[WalkRequest],
) -> Vec<MatrixRun> {
    let next = Mutex::new(0usize);
    let results: Mutex<Vec<Option<MatrixRun>>> = Mutex::new(vec![None; requests.len()]);
    std::thread::scope(|scope| {
        for _ in 0..args.jobs.max(1) {
            scope.spawn(|| {
                loop {
                    let index = {
                        let mut next = next.lock().expect("no worker panics holding it");
                        let index = *next;
                        *next += 1;
                        index
                    };
                    let Some(request) = requests.get(index) else {
                        break;
                    };
                    let result = walk_distance(config, args.urdf.as_deref(), request, options)
                        .and_then(|report| pushed_if_asked(options, report))
                        .with_context(|| {
                            format!(
                                "{} {} m seed {}",
                                request.affordances, request.distance, request.seed
                            )
                        });
                    let run = MatrixRun::new(request, result);
                    if !args.json {
                        eprintln!("{}", run_line(&run));
                    }
                    results.lock().expect("no worker panics holding it")[index] = Some(run);
                }
            });
        }
    });
    results
        .into_inner()
        .expect("the workers have finished")
        .into_iter()
        .map(|run| run.expect("every request ran"))
        .collect()
}

/// A walk asked to be pushed that reached `done` without its push (it had fewer single
/// supports than `--push-step`) is an error, not a survived push.
fn pushed_if_asked(
    options: &PhysicsWalkOptions,
    report: PhysicsWalkReport,
) -> anyhow::Result<PhysicsWalkReport> {
    match options.push {
        Some(push) if report.success() && report.pushed_at_s.is_none() => anyhow::bail!(
            "the walk ended before single support number {} (--push-step, 0: the first): it was \
             never pushed; choose an earlier step",
            push.step
        ),
        _ => Ok(report),
    }
}

fn groups(runs: &[MatrixRun]) -> Vec<MatrixGroup> {
    group_by_cell(runs, |run| &run.record)
        .into_iter()
        .map(|(summary, members)| MatrixGroup {
            summary,
            tick_p99_max_us: members.iter().map(|r| r.tick_us[1]).fold(0.0, f64::max),
        })
        .collect()
}

fn run_line(run: &MatrixRun) -> String {
    let r = &run.record;
    if let Some(error) = &run.error {
        return format!(
            "{} {} m seed {}: error: {error}",
            r.affordances, r.distance_m, r.seed
        );
    }
    format!(
        "{} {} m seed {}: {}{} after {} stances, {:.3} m in {:.2} s, {}, drift {:.3} m, tilt \
         {:.3} rad, ZMP rms {:.3} m, DCM rms {:.3} m, tick p50 {:.1} p99 {:.1} µs{}",
        r.affordances,
        r.distance_m,
        r.seed,
        r.outcome,
        r.reaches_given_up_note(),
        r.stances,
        r.walked_m,
        r.sim_s,
        r.speed_m_s
            .map_or("no step".to_owned(), |v| format!("{v:.3} m/s")),
        r.drift_m.unwrap_or(0.0),
        r.max_tilt_rad,
        run.zmp_rms_m,
        run.dcm_rms_m,
        run.tick_us[0],
        run.tick_us[1],
        run.hand_support_share
            .map_or_else(String::new, |share| format!(
                ", hand share {share:.3}, CoM outside the soles {:.3} m for 1 s",
                run.com_outside_feet_m
            )),
    )
}

fn print_table(report: &MatrixReport) {
    println!(
        "{} {} gait{}",
        report.robot,
        report.gait,
        if report.overrides.is_empty() {
            String::new()
        } else {
            format!(", with {}", report.overrides.join(" "))
        }
    );
    println!(
        "{:<16} {:>6} {:>6} {:>11} {:>10} {:>9} {:>10}",
        "affordances", "dist", "done", "speed mean", "speed min", "drift", "tick p99"
    );
    for group in &report.groups {
        let g = &group.summary;
        println!(
            "{:<16} {:>5}m {:>3}/{:<2} {:>11} {:>10} {:>8.3}m {:>8.1}µs",
            g.affordances.name(),
            g.distance_m,
            g.done,
            g.runs,
            speed_cell(g.speed_mean_m_s),
            speed_cell(g.speed_min_m_s),
            g.drift_max_m,
            group.tick_p99_max_us
        );
        if let Some(actuators) = &g.actuators {
            println!("{:<16} peak {}", "", actuators.describe());
        }
        let shares: Vec<f64> = report
            .runs
            .iter()
            .filter(|run| {
                run.record.affordances == g.affordances && run.record.distance_m == g.distance_m
            })
            .filter_map(|run| run.hand_support_share)
            .collect();
        if !shares.is_empty() {
            println!(
                "{:<16} hand share mean {:.3}, min {:.3}, max {:.3}",
                "",
                shares.iter().sum::<f64>() / shares.len() as f64,
                shares.iter().copied().fold(f64::INFINITY, f64::min),
                shares.iter().copied().fold(f64::NEG_INFINITY, f64::max)
            );
        }
    }
    println!("{} of {} runs done", report.done, report.runs.len());
}
