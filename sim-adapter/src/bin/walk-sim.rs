//! `walk-sim`: a simulated robot process behind the adapter side of the walkd IPC contract.
//!
//! ```text
//! walk-sim --config configs/armar4.toml --physics kinematic|mujoco [--clock realtime|lockstep]
//!          [--rate-hz F] [--urdf PATH] [--service-prefix P] [--judge-by-zmp] [--scene FILE]
//!          [--snapshots DIR [--snapshot-period S] [--snapshot-lookat X,Y,Z]]
//!          [--inject KIND [--inject-step K] [--inject-delay S]]
//! ```
//! With `--judge-by-zmp` (kinematic only) the kinematic simulator judges stability, and
//! synthesises the foot forces, by the ZMP of its motion instead of its CoM: for dynamic walks,
//! as `walk-bench` does for the dynamic gait (`kinematic_sim::SimOptions::judge_by_zmp`).
//! With `--inject` (evaluation of the controlled stop, `sim_adapter::inject`) it reports one bad
//! sample, withholds a touchdown or asks walkd for a hold or abort, `--inject-delay` seconds of
//! simulated time after the `--inject-step`-th lift-off of a foot.
//! With `--scene` the world is the scene's terrain (docs/scenes.md; MuJoCo:
//! `sim_adapter::mujoco::Terrain`, its surfaces and railings; kinematic: `sim_adapter::SceneGround`,
//! its surfaces) instead of the flat floor, and the robot starts standing at the scene's start.
//! With `--snapshots` (MuJoCo only, feature `render`) it saves a side view of the robot every
//! `--snapshot-period` of simulated time (`sim_adapter::mujoco::render`).
//! Besides the adapter side of the contract it publishes the simulator's ground truth (CoM,
//! sole poses, base height and tilt, fall flag, motor load, leg-terrain collision count) on
//! `<prefix>/sim-truth` with every sample.
//!
//! Exit codes: see `shm_types::process::exit_code` (0 clean, 3 config/model, 4 IPC, 1 other).

use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::time::Duration;

use clap::Parser;
use kinematic_sim::{KinematicSim, SimOptions, Simulator};
use kinematics::ConfigFile;
use kinematics::bounds::Range;
use kinematics::robot::Robot;
use shm_types::process::{
    InjectedFault, Physics, exit_code, install_termination_handler, termination_requested,
};
use shm_types::{
    AdapterPorts, ClockMode, RuntimeConfig, RuntimeOverrides, ServiceNames, TruthPublisher,
    current_thread_is_fifo,
};
use sim_adapter::inject::{FaultInjector, FaultPlan};
use sim_adapter::{
    AdapterOptions, MotorLoad, PublishTruth, SceneGround, SimulatedRobot, TerrainContacts,
    run_adapter,
};

/// Simulated robot for walkd: publishes sensor samples, applies joint commands.
#[derive(Parser)]
#[command(name = "walk-sim", version, about)]
struct Args {
    /// Robot config (its [robot] and [runtime] sections are used).
    #[arg(long)]
    config: PathBuf,
    /// URDF to use instead of the one named in the config.
    #[arg(long)]
    urdf: Option<PathBuf>,
    /// Simulator backend.
    #[arg(long, value_enum)]
    physics: Physics,
    /// realtime: a sample every period; lockstep: the next sample once the previous is answered.
    #[arg(long, default_value = "realtime")]
    clock: ClockMode,
    /// Sample rate, overriding `[runtime] rate_hz`.
    #[arg(long)]
    rate_hz: Option<f64>,
    /// Service prefix, overriding `[runtime] service_prefix`.
    #[arg(long)]
    service_prefix: Option<String>,
    /// `--physics kinematic`: judge stability, and synthesise the foot forces, by the ZMP of the
    /// simulated motion instead of its CoM, for dynamic walks (a dynamic walk's CoM leaves the
    /// support polygon by design).
    #[arg(long)]
    judge_by_zmp: bool,
    /// Build the world from this scene file (docs/scenes.md) instead of the flat floor, and
    /// stand the robot at the scene's start (the kinematic simulator models its surfaces, not
    /// its railings).
    #[arg(long, value_name = "FILE")]
    scene: Option<PathBuf>,
    /// `--physics mujoco`: save a picture of the robot (MuJoCo's offscreen renderer, EGL) every
    /// `--snapshot-period` of simulated time into this directory (needs --features
    /// sim-adapter/render).
    #[arg(long, value_name = "DIR")]
    snapshots: Option<PathBuf>,
    /// Simulated time between two pictures (s, 0.01-60).
    #[arg(long, default_value_t = 0.5, value_parser = Range::new(0.01, 60.0).parser())]
    snapshot_period: f64,
    /// The point the side camera looks at: x,y,z (m, world; each within ±100).
    #[arg(
        long,
        value_delimiter = ',',
        default_values_t = [0.0, 0.0, 0.8],
        allow_hyphen_values = true,
        value_parser = Range::new(-100.0, 100.0).parser()
    )]
    snapshot_lookat: Vec<f64>,
    /// Fault injection for evaluation: what goes wrong (a NaN or out-of-limit joint in one
    /// sample, one sample without foot forces, a hold or abort request, a withheld touchdown).
    #[arg(long)]
    inject: Option<InjectedFault>,
    /// With --inject: after this lift-off of a foot (1: the walk's first step).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    inject_step: u32,
    /// With --inject: this long after that lift-off (s of simulated time, 0–10).
    #[arg(long, default_value_t = 0.0)]
    inject_delay: f64,
}

impl Args {
    /// The fault to inject, if any (its delay checked).
    fn fault_plan(&self) -> Result<Option<FaultPlan>, (u8, anyhow::Error)> {
        let Some(kind) = self.inject else {
            return Ok(None);
        };
        if !(0.0..=10.0).contains(&self.inject_delay) {
            return Err((
                exit_code::USAGE,
                anyhow::anyhow!("--inject-delay {} must be in [0, 10] s", self.inject_delay),
            ));
        }
        Ok(Some(FaultPlan {
            kind,
            step: self.inject_step,
            delay_s: self.inject_delay,
        }))
    }
}

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info")),
        )
        .init();
    let args = Args::parse();
    match run(&args) {
        Ok(()) => ExitCode::from(exit_code::OK),
        Err((code, error)) => {
            tracing::error!("{error:#}");
            ExitCode::from(code)
        }
    }
}

/// A bad config, URDF, scene or model: exit code [`exit_code::CONFIG`].
fn config_error(error: anyhow::Error) -> (u8, anyhow::Error) {
    (exit_code::CONFIG, error)
}

fn run(args: &Args) -> Result<(), (u8, anyhow::Error)> {
    let file = ConfigFile::load(&args.config).map_err(|e| config_error(e.into()))?;
    let runtime = RuntimeConfig::from_section(file.section("runtime"), &file.origin())
        .map_err(|e| config_error(e.into()))?;
    let overrides = RuntimeOverrides {
        rate_hz: args.rate_hz,
        service_prefix: args.service_prefix.clone(),
        ..RuntimeOverrides::default()
    };
    let runtime = overrides
        .apply(runtime)
        .map_err(|e| (exit_code::USAGE, e.into()))?;
    let robot =
        Robot::from_config(&file, args.urdf.as_deref()).map_err(|e| config_error(e.into()))?;
    let robot = Arc::new(robot);
    match args.physics {
        Physics::Kinematic => {
            let standing = robot.standing.clone();
            let options = SimOptions {
                judge_by_zmp: args.judge_by_zmp,
                ..SimOptions::default()
            };
            // On a scene the robot stands at its start on its surfaces, as under MuJoCo (its
            // railings are not modelled).
            let sim = match &args.scene {
                None => KinematicSim::with_options(robot, standing, options),
                Some(path) => {
                    let scene =
                        stance::Scene::from_path(path).map_err(|e| config_error(e.into()))?;
                    let at_start = scene.place(&standing);
                    let ground = Arc::new(SceneGround::new(scene.environment));
                    KinematicSim::on_ground(robot, at_start, options, ground)
                }
            }
            .map_err(|e| config_error(anyhow::Error::from(e).context("standing posture")))?;
            serve(&runtime, args, SimulatedRobot::new(sim))
        }
        Physics::Mujoco if args.judge_by_zmp => Err((
            exit_code::USAGE,
            anyhow::anyhow!(
                "--judge-by-zmp applies to --physics kinematic only (MuJoCo's contacts carry \
                 the forces its physics makes)"
            ),
        )),
        Physics::Mujoco => serve_mujoco(robot, &runtime, args),
    }
}

/// `--physics mujoco`: the robot standing in its configured posture under MuJoCo, on the flat
/// floor or at the start of the `--scene`.
#[cfg(feature = "mujoco")]
fn serve_mujoco(
    robot: Arc<Robot>,
    runtime: &RuntimeConfig,
    args: &Args,
) -> Result<(), (u8, anyhow::Error)> {
    use sim_adapter::mujoco::{MujocoOptions, MujocoSim, Terrain};
    let (urdf, standing) = (robot.urdf.clone(), robot.standing.clone());
    let options = MujocoOptions::default();
    let sim = match &args.scene {
        None => MujocoSim::new(robot, &urdf, &standing, options),
        Some(path) => {
            let scene = stance::Scene::from_path(path).map_err(|e| config_error(e.into()))?;
            let terrain = Terrain::from_scene(&scene).map_err(|e| {
                config_error(anyhow::Error::from(e).context(path.display().to_string()))
            })?;
            tracing::info!(
                scene = scene.name,
                surfaces = scene.environment.surfaces.len(),
                railings = scene.environment.hand_affordances.len(),
                "terrain"
            );
            let initial = terrain.place(&standing);
            MujocoSim::on_terrain(robot, &urdf, &initial, options, terrain)
        }
    }
    .map_err(|e| config_error(anyhow::Error::from(e).context("MuJoCo model")))?;
    match &args.snapshots {
        None => serve(runtime, args, SimulatedRobot::new(sim)),
        Some(dir) => serve_with_snapshots(runtime, args, sim, dir),
    }
}

/// `--snapshots DIR`: the MuJoCo robot photographed while it walks.
#[cfg(feature = "render")]
fn serve_with_snapshots(
    runtime: &RuntimeConfig,
    args: &Args,
    sim: sim_adapter::mujoco::MujocoSim,
    dir: &std::path::Path,
) -> Result<(), (u8, anyhow::Error)> {
    use sim_adapter::mujoco::render::{PhotographedSim, SnapshotOptions};
    let &[x, y, z] = args.snapshot_lookat.as_slice() else {
        return Err((
            exit_code::USAGE,
            anyhow::anyhow!("--snapshot-lookat takes x,y,z (three numbers)"),
        ));
    };
    let options = SnapshotOptions::side_view(dir.to_owned(), args.snapshot_period, [x, y, z]);
    let sim = PhotographedSim::new(sim, options)
        .map_err(|e| (exit_code::CONFIG, anyhow::Error::from(e)))?;
    serve(runtime, args, SimulatedRobot::new(sim))
}

/// `--snapshots DIR` in a build without the renderer: says how to get it.
#[cfg(all(feature = "mujoco", not(feature = "render")))]
fn serve_with_snapshots(
    _runtime: &RuntimeConfig,
    _args: &Args,
    _sim: sim_adapter::mujoco::MujocoSim,
    _dir: &std::path::Path,
) -> Result<(), (u8, anyhow::Error)> {
    Err((
        exit_code::CONFIG,
        anyhow::anyhow!(
            "walk-sim was built without the renderer: rebuild it with --features sim-adapter/render"
        ),
    ))
}

/// `--physics mujoco` in a build without the backend: says how to get it.
#[cfg(not(feature = "mujoco"))]
fn serve_mujoco(
    _robot: Arc<Robot>,
    _runtime: &RuntimeConfig,
    _args: &Args,
) -> Result<(), (u8, anyhow::Error)> {
    Err((
        exit_code::CONFIG,
        anyhow::anyhow!(
            "walk-sim was built without MuJoCo: run `eval \"$(scripts/setup-mujoco.sh)\"`, then rebuild \
             it with `cargo build --release -p sim-adapter --features mujoco` (or a workspace build \
             with `--features sim-adapter/mujoco`)"
        ),
    ))
}

/// Runs the adapter loop for `sim` until terminated, publishing its ground truth with every
/// sample (and injecting the fault of `--inject`); logs the simulator's safety summary.
fn serve<S: Simulator + MotorLoad + TerrainContacts>(
    runtime: &RuntimeConfig,
    args: &Args,
    sim: SimulatedRobot<S>,
) -> Result<(), (u8, anyhow::Error)> {
    let (clock, fault) = (args.clock, args.fault_plan()?);
    let limit_fault = (0, sim.sim().robot().model.joint_limits()[0].upper);
    let names =
        ServiceNames::new(&runtime.service_prefix).map_err(|e| (exit_code::IPC, e.into()))?;
    let ports = AdapterPorts::open(&names, "walk-sim").map_err(|e| (exit_code::IPC, e.into()))?;
    let truth =
        TruthPublisher::open(&names, "walk-sim-truth").map_err(|e| (exit_code::IPC, e.into()))?;
    let sim = PublishTruth::new(sim, truth);
    install_termination_handler();
    // Busy-wait the end of each period like walkd does, and only where it pays off: on
    // SCHED_FIFO (e.g. `chrt -f`), in real time.
    let spin = if runtime.spin_us > 0 && clock == ClockMode::Realtime && current_thread_is_fifo() {
        Duration::from_micros(u64::from(runtime.spin_us))
    } else {
        Duration::ZERO
    };
    let options = AdapterOptions {
        clock,
        rate_hz: runtime.rate_hz,
        watchdog_periods: runtime.watchdog_periods,
        lockstep_timeout: Duration::from_millis(runtime.lockstep_timeout_ms),
        spin,
    };
    tracing::info!(
        prefix = names.prefix(),
        clock = clock.name(),
        rate_hz = runtime.rate_hz,
        spin_us = spin.as_micros() as u64,
        "walk-sim running"
    );
    let (report, safety, terrain_collisions) = match fault {
        None => {
            let mut sim = sim;
            let report = run_adapter(&ports, &mut sim, &options, &termination_requested);
            let sim = sim.robot().sim();
            (report, *sim.summary(), sim.terrain_collision_count())
        }
        Some(plan) => {
            tracing::info!(
                fault = plan.kind.name(),
                step = plan.step,
                delay_s = plan.delay_s,
                "fault injection armed"
            );
            let mut sim = FaultInjector::new(sim, plan, limit_fault, &names);
            let report = run_adapter(&ports, &mut sim, &options, &termination_requested);
            let sim = sim.robot().robot().sim();
            (report, *sim.summary(), sim.terrain_collision_count())
        }
    };
    let report = report.map_err(|e| (exit_code::IPC, e.into()))?;
    tracing::info!(
        samples = report.samples,
        commands = report.commands,
        watchdog_trips = report.watchdog_trips,
        overruns = report.overruns,
        fell = safety.fell,
        min_stability_margin_m = safety.min_stability_margin,
        terrain_collisions,
        "walk-sim stopped"
    );
    Ok(())
}
