//! `physics-matrix`: a matrix of in-process MuJoCo walks (affordance sets × distances × seeds)
//! for one robot and gait, with config overrides, model error and pushes, reported per run and
//! per group. The tool behind the dynamic gait's timing sweeps, the stabilizer's on/off
//! experiments and the push sweep: each is one command line (docs/controller.md). The walks
//! over separate processes, as engineers run them, are `walkctl evaluate`.

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Mutex;

use anyhow::Context;

use kinematics::ConfigFile;
use serde::Serialize;
use stance::{AffordanceSet, Gait, WalkRequest};

use crate::physics::{PhysicsWalkOptions, PhysicsWalkReport, Push, walk_distance};

/// Arguments of `physics-matrix`.
#[derive(Debug, clap::Args)]
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
    /// Runs per affordance set and distance; run i uses generator seed `first_seed + i`.
    #[arg(long, default_value_t = 10)]
    pub runs: u64,
    /// Seed of the first run.
    #[arg(long, default_value_t = 0)]
    pub first_seed: u64,
    /// Control rate (Hz).
    #[arg(long, default_value_t = 500.0)]
    pub rate_hz: f64,
    /// Replaces one config value, `section.key=value` (repeatable), e.g.
    /// `gait.dynamic.single_support_s=0.5` or `gait.dynamic.stabilizer.foot_damping=false`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub overrides: Vec<String>,
    /// Model error in the simulator only: every body's mass and inertia scaled by this.
    #[arg(long, default_value_t = 1.0)]
    pub mass_scale: f64,
    /// Model error in the simulator only: the pelvis CoM moved by x,y,z (m, pelvis frame).
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "X,Y,Z",
        allow_hyphen_values = true
    )]
    pub pelvis_com_offset: Option<Vec<f64>>,
    /// A sideways push on the pelvis (N·s along world y, + = left), centred on the middle of
    /// single support number `--push-step` (dynamic gait).
    #[arg(long, value_name = "N·s", allow_hyphen_values = true)]
    pub push_impulse: Option<f64>,
    /// Which single support the push falls in (0: the first).
    #[arg(long, default_value_t = 4)]
    pub push_step: usize,
    /// How long the push acts (s).
    #[arg(long, default_value_t = 0.1)]
    pub push_duration: f64,
    /// Walks run at once (each in its own thread).
    #[arg(long, default_value_t = 1)]
    pub jobs: usize,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// One walk of the matrix.
#[derive(Clone, Debug, Serialize)]
pub struct MatrixRun {
    /// Affordance set.
    pub affordances: String,
    /// Requested distance (m).
    pub distance_m: f64,
    /// Generator seed.
    pub seed: u64,
    /// `done`, `fell`, `fault:<code>`, `time_limit`, `unstable`, or `error` (see `error`).
    pub outcome: String,
    /// Why the walk could not run at all.
    pub error: Option<String>,
    /// Stances in the sequence.
    pub stances: usize,
    /// Distance the feet travelled (m).
    pub walked_m: f64,
    /// Walked distance over the time from the first step to the outcome (m/s).
    pub speed_m_s: Option<f64>,
    /// Simulated time to the outcome (s).
    pub sim_s: f64,
    /// Largest controller-vs-simulator CoM or sole distance (m).
    pub drift_m: f64,
    /// Largest base tilt (rad).
    pub max_tilt_rad: f64,
    /// Measured minus reference ZMP, rms (m; dynamic gait).
    pub zmp_rms_m: f64,
    /// True minus reference DCM, rms (m; dynamic gait).
    pub dcm_rms_m: f64,
    /// Controller tick wall time: median, 99th percentile, largest (µs).
    pub tick_us: [f64; 3],
}

impl MatrixRun {
    fn new(request: &WalkRequest, result: anyhow::Result<PhysicsWalkReport>) -> Self {
        let mut run = Self {
            affordances: request.affordances.name().to_owned(),
            distance_m: request.distance,
            seed: request.seed,
            outcome: "error".to_owned(),
            error: None,
            stances: 0,
            walked_m: 0.0,
            speed_m_s: None,
            sim_s: 0.0,
            drift_m: 0.0,
            max_tilt_rad: 0.0,
            zmp_rms_m: 0.0,
            dcm_rms_m: 0.0,
            tick_us: [0.0; 3],
        };
        match result {
            Err(error) => run.error = Some(format!("{error:#}")),
            Ok(report) => {
                run.outcome = report.outcome.label();
                run.stances = report.stances;
                run.walked_m = report.distance_m;
                run.speed_m_s = report.speed_m_s();
                run.sim_s = report.sim_s;
                run.drift_m = report.drift_m();
                run.max_tilt_rad = report.max_tilt_rad;
                run.zmp_rms_m = report.balance.zmp_rms_m;
                run.dcm_rms_m = report.balance.dcm_rms_m;
                run.tick_us = report.tick_us;
            }
        }
        run
    }

    fn done(&self) -> bool {
        self.outcome == "done"
    }
}

/// The runs of one affordance set and distance, summed up.
#[derive(Clone, Debug, Serialize)]
pub struct MatrixGroup {
    /// Affordance set.
    pub affordances: String,
    /// Requested distance (m).
    pub distance_m: f64,
    /// Runs `done`.
    pub done: usize,
    /// Runs in all.
    pub runs: usize,
    /// Speed of the `done` runs: mean, smallest (m/s).
    pub speed_mean_m_s: Option<f64>,
    /// Smallest speed of a `done` run (m/s).
    pub speed_min_m_s: Option<f64>,
    /// Largest drift of a run (m).
    pub drift_max_m: f64,
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
    let gait = Gait::chosen_or_configured(args.gait, &config)?;
    let options = walk_options(args, gait)?;
    let robot_name = config
        .section("robot")
        .and_then(|robot| robot.get("name"))
        .and_then(toml::Value::as_str)
        .unwrap_or("robot")
        .to_owned();
    let requests: Vec<WalkRequest> = args
        .affordances
        .iter()
        .flat_map(|&affordances| {
            args.distances.iter().flat_map(move |&distance| {
                (0..args.runs).map(move |i| WalkRequest {
                    distance,
                    affordances,
                    seed: args.first_seed + i,
                })
            })
        })
        .collect();
    let runs = run_all(&config, args, &options, &requests);
    let groups = groups(args, &runs);
    Ok(MatrixReport {
        robot: robot_name,
        gait: gait.name().to_owned(),
        overrides: args.overrides.clone(),
        done: runs.iter().filter(|r| r.done()).count(),
        runs,
        groups,
    })
}

fn walk_options(args: &MatrixArgs, gait: Gait) -> anyhow::Result<PhysicsWalkOptions> {
    let mut options = match gait {
        Gait::Dynamic => PhysicsWalkOptions::dynamic(),
        Gait::Static => PhysicsWalkOptions::default(),
    };
    options.rate_hz = args.rate_hz;
    options.trace_every = 0;
    options.mujoco.mass_scale = args.mass_scale;
    if let Some(offset) = &args.pelvis_com_offset {
        let &[x, y, z] = offset.as_slice() else {
            anyhow::bail!(
                "--pelvis-com-offset {offset:?}: expected three numbers x,y,z (m), e.g. 0.01,0,0"
            );
        };
        anyhow::ensure!(
            offset.iter().all(|v| v.is_finite()),
            "--pelvis-com-offset {offset:?}: must be finite"
        );
        options.mujoco.pelvis_com_offset = [x, y, z];
    }
    if let Some(impulse) = args.push_impulse {
        anyhow::ensure!(
            args.push_duration.is_finite() && args.push_duration > 0.0,
            "--push-duration {}: must be a positive number of seconds",
            args.push_duration
        );
        anyhow::ensure!(
            impulse.is_finite(),
            "--push-impulse {impulse}: must be finite"
        );
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

fn groups(args: &MatrixArgs, runs: &[MatrixRun]) -> Vec<MatrixGroup> {
    let mut groups = Vec::new();
    for affordances in &args.affordances {
        for &distance in &args.distances {
            let members: Vec<&MatrixRun> = runs
                .iter()
                .filter(|r| r.affordances == affordances.name() && r.distance_m == distance)
                .collect();
            let speeds: Vec<f64> = members
                .iter()
                .filter(|r| r.done())
                .filter_map(|r| r.speed_m_s)
                .collect();
            groups.push(MatrixGroup {
                affordances: affordances.name().to_owned(),
                distance_m: distance,
                done: members.iter().filter(|r| r.done()).count(),
                runs: members.len(),
                speed_mean_m_s: (!speeds.is_empty())
                    .then(|| speeds.iter().sum::<f64>() / speeds.len() as f64),
                speed_min_m_s: speeds.iter().copied().reduce(f64::min),
                drift_max_m: members.iter().map(|r| r.drift_m).fold(0.0, f64::max),
                tick_p99_max_us: members.iter().map(|r| r.tick_us[1]).fold(0.0, f64::max),
            });
        }
    }
    groups
}

fn run_line(run: &MatrixRun) -> String {
    if let Some(error) = &run.error {
        return format!(
            "{} {} m seed {}: error: {error}",
            run.affordances, run.distance_m, run.seed
        );
    }
    format!(
        "{} {} m seed {}: {} after {} stances, {:.3} m in {:.2} s, {}, drift {:.3} m, tilt {:.3} \
         rad, ZMP rms {:.3} m, DCM rms {:.3} m, tick p50 {:.1} p99 {:.1} µs",
        run.affordances,
        run.distance_m,
        run.seed,
        run.outcome,
        run.stances,
        run.walked_m,
        run.sim_s,
        run.speed_m_s
            .map_or("no step".to_owned(), |v| format!("{v:.3} m/s")),
        run.drift_m,
        run.max_tilt_rad,
        run.zmp_rms_m,
        run.dcm_rms_m,
        run.tick_us[0],
        run.tick_us[1],
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
    let speed = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.3}"));
    for g in &report.groups {
        println!(
            "{:<16} {:>5}m {:>3}/{:<2} {:>11} {:>10} {:>8.3}m {:>8.1}µs",
            g.affordances,
            g.distance_m,
            g.done,
            g.runs,
            speed(g.speed_mean_m_s),
            speed(g.speed_min_m_s),
            g.drift_max_m,
            g.tick_p99_max_us
        );
    }
    println!("{} of {} runs done", report.done, report.runs.len());
}
