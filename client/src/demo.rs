//! `walkctl demo`: the whole system in one command.
//!
//! Starts `walkd` and `walk-sim --physics kinematic|mujoco` as child processes (found next to
//! `walkctl`'s own executable), unless a `walkd` already serves the robot's services; generates a
//! walk, post-processes it, submits it, watches it, prints the outcome and shuts the children
//! down with SIGTERM. The simulator's ground truth (`sim-truth`) is recorded meanwhile, so a walk
//! the daemon finished with the simulated robot on the floor is reported as a fall.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, bail};
use kinematics::ConfigFile;
use kinematics::robot::Robot;
use shm_types::process::Physics;
use shm_types::{ClockMode, DaemonState, DaemonStatus, LatencySummary, RuntimeConfig};
use stance::learned::SourceArgs;
use stance::{Gait, Scene, WalkRequest};

use crate::args::{DISTANCE_M, RATE_HZ, SPEED_M_S};
use crate::daemon_client::connect_when_fresh;
use crate::daemon_client::{DaemonClient, feet_midpoint, status_text};
use crate::evaluate::truth::judged_outcome;
use crate::evaluate::watch::{WatchOptions, WatchedWalk, watch_walk};
use crate::pace::walking_speed;
use crate::process::{Launch, PlantArgs, Processes, executable_dir};
use crate::watch::StanceProgress;

/// How far the demo walks on the flat floor when `--distance` is not given (m).
const DEFAULT_DISTANCE_M: f64 = 1.0;

/// The robots with a vendored config.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DemoRobot {
    /// KIT ARMAR-4.
    Armar4,
    /// JVRC-1.
    Jvrc1,
    /// Kawada HRP-4 (needs --urdf: its model is not vendored).
    Hrp4,
}

impl DemoRobot {
    fn name(self) -> &'static str {
        match self {
            Self::Armar4 => "armar4",
            Self::Jvrc1 => "jvrc1",
            Self::Hrp4 => "hrp4",
        }
    }
}

/// Arguments of `walkctl demo`.
#[derive(Debug, clap::Args)]
pub struct DemoArgs {
    /// Robot to walk.
    #[arg(long, value_enum, default_value = "armar4")]
    pub robot: DemoRobot,
    /// Distance to walk forward (m, 0.01-1000; default 1). Through a `--scene`: its path's
    /// first D m, at most its length (default the whole path).
    #[arg(long, value_parser = DISTANCE_M.parser())]
    pub distance: Option<f64>,
    /// Simulator of the started `walk-sim`: kinematic or mujoco.
    #[arg(long, default_value = "kinematic")]
    pub physics: Physics,
    /// Clock of the started processes: realtime (at the config's rate) or lockstep (fast).
    #[arg(long, default_value = "realtime")]
    pub clock: ClockMode,
    /// Control rate of the started processes, overriding the config's (Hz, 10-10000).
    #[arg(long, value_parser = RATE_HZ.parser())]
    pub rate_hz: Option<f64>,
    /// Robot config (default: configs/<robot>.toml in the current directory or the source tree).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// URDF overriding the config's (required for HRP-4).
    #[arg(long)]
    pub urdf: Option<PathBuf>,
    /// Service prefix, overriding the config's (to run beside another daemon).
    #[arg(long)]
    pub service_prefix: Option<String>,
    /// Seed of the stance generator.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[command(flatten)]
    pub source: SourceArgs,
    /// Walking speed to pace the walk for (m/s, 0.01-3): step length and stance durations from
    /// the model's gait law (docs/learning.md). Needs --model.
    #[arg(long, value_name = "V", value_parser = SPEED_M_S.parser(), requires = "model")]
    pub speed: Option<f64>,
    /// Gait: static or dynamic (default: the config's `[gait] default`). The walk is
    /// post-processed with that gait's limits and asks walkd for it. A gait the robot cannot
    /// walk is refused before anything is started.
    #[arg(long)]
    pub gait: Option<Gait>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Record the walk (an observer beside walkd) to `DIR/demo-<robot>.mcap`.
    #[arg(long, value_name = "DIR")]
    pub record: Option<PathBuf>,
    /// Write the walk's Fig. 6 (target, controller and simulator for the CoM and both feet) to
    /// `DIR/fig6-<robot>.svg`.
    #[arg(long, value_name = "DIR")]
    pub plots: Option<PathBuf>,
    /// Walk through this scene (docs/scenes.md) from its start towards its goal instead of on
    /// the flat floor.
    #[arg(long, value_name = "FILE")]
    pub scene: Option<PathBuf>,
}

/// What the demo measured: the watched walk, its gait and the plot.
pub struct DemoOutcome {
    walk: WatchedWalk,
    /// A status asked for after the walk, with the complete tick statistics.
    status: DaemonStatus,
    gait: Gait,
    plot: Option<PathBuf>,
}

impl DemoOutcome {
    /// The daemon's status after the walk, with its complete tick statistics.
    pub fn status(&self) -> &DaemonStatus {
        &self.status
    }

    /// Forward distance the feet midpoint covered, by the controller's estimate (m).
    pub fn distance_m(&self) -> f64 {
        feet_midpoint(self.status())[0] - feet_midpoint(&self.walk.start)[0]
    }

    /// Stances completed.
    pub fn stances(&self) -> u32 {
        let status = self.status();
        if status.state == DaemonState::Done {
            status.stance_count
        } else {
            status.stance_index
        }
    }

    /// Simulated time from submission at which the simulator's fall rule first fired (s).
    pub fn fell_at_s(&self) -> Option<f64> {
        self.walk.verdict.and_then(|v| v.fell_at_s)
    }

    /// Largest tilt of the simulated `base_link` since submission (rad); `None` when no
    /// simulator published its truth (e.g. a running walkd driving a real robot).
    pub fn max_tilt_rad(&self) -> Option<f64> {
        self.walk.verdict.map(|v| v.max_tilt_rad)
    }

    /// Walking speed: the simulated soles' travel over the simulated time from the first step
    /// (a sole rising 1 cm) to the end (m/s); `None` without simulator truth or a step.
    pub fn speed_m_s(&self) -> Option<f64> {
        self.walk.verdict.and_then(|v| v.speed_m_s(self.walk.sim_s))
    }

    /// `done`, the fault / state the walk ended in, or `fell at <t> s (daemon: ...)`.
    pub fn outcome(&self) -> String {
        let status = self.status();
        let daemon = if status.state == DaemonState::Done {
            "done".to_owned()
        } else {
            format!("{}: {}", status.state.name(), status.fault)
        };
        judged_outcome(self.fell_at_s(), &daemon)
    }

    /// The walk completed and the simulated robot (if any) never fell.
    pub fn succeeded(&self) -> bool {
        self.status().state == DaemonState::Done && self.fell_at_s().is_none()
    }

    fn json(&self) -> serde_json::Value {
        let tick =
            |s: &LatencySummary| serde_json::json!({"p50": s.p50, "p99": s.p99, "max": s.max});
        let (status, walk) = (self.status(), &self.walk);
        serde_json::json!({
            "outcome": self.outcome(),
            "distance_m": self.distance_m(),
            "gait": self.gait.name(),
            "speed_m_s": self.speed_m_s(),
            "stances": self.stances(),
            "sim_s": walk.sim_s,
            "wall_s": walk.wall_s,
            "real_time_factor": walk.sim_s / walk.wall_s,
            "fell_at_s": self.fell_at_s(),
            "max_tilt_rad": self.max_tilt_rad(),
            "deadline_misses": status.deadline_misses,
            "stale_periods": status.stale_periods,
            "tick_us": tick(&status.tick_us),
            "latency_us": tick(&status.latency_us),
            "clock": status.clock.name(),
            "rate_hz": status.rate_hz,
            "plot": self.plot,
            "recording": walk.recording.as_ref().map(|r| serde_json::json!({
                "file": r.summary.path,
                "messages": r.summary.messages,
                "bytes": r.summary.bytes,
                "observer": r.report.json(),
            })),
        })
    }
}

/// The config of `robot`: `configs/<robot>.toml` in the current directory, else in the source
/// tree the executable was built in (`target/<profile>/../../configs`).
fn default_config(robot: DemoRobot) -> anyhow::Result<PathBuf> {
    let file = format!("{}.toml", robot.name());
    let mut candidates = vec![Path::new("configs").join(&file)];
    if let Ok(dir) = executable_dir() {
        candidates.push(dir.join("../../configs").join(&file));
    }
    candidates
        .iter()
        .find(|path| path.is_file())
        .cloned()
        .with_context(|| {
            format!(
                "no config for {} found (looked at {candidates:?}); pass --config",
                robot.name()
            )
        })
}

/// A forward walk of `distance` on the feet for `robot`, post-processed with the config's
/// parameters for `gait` (which the sequence then asks walkd for).
pub fn walk_sequence(
    robot: &Robot,
    file: &ConfigFile,
    distance: f64,
    seed: u64,
    gait: Gait,
) -> anyhow::Result<stance::PostProcessedSequence> {
    let params = stance::PostProcessParams::from_config_for(file, gait)?;
    Ok(stance::synthetic_walk(
        robot,
        &params,
        &WalkRequest::feet(distance, seed),
    )?)
}

/// The scene of `--scene`, refused before anything starts when it does not validate. Both
/// simulators model its surfaces; only MuJoCo models its railings.
pub fn load_scene(path: Option<&Path>) -> anyhow::Result<Option<Scene>> {
    path.map(Scene::from_path).transpose().map_err(Into::into)
}

/// Runs the demo and returns what it measured (also used by the e2e tests).
pub fn run_demo(args: &DemoArgs) -> anyhow::Result<DemoOutcome> {
    let config = match &args.config {
        Some(config) => config.clone(),
        None => default_config(args.robot)?,
    };
    let file = ConfigFile::load(&config)?;
    // A gait the robot cannot walk is refused before walkd and walk-sim are started.
    let gait = Gait::for_walk(args.gait, &file)?;
    let runtime = RuntimeConfig::from_section(file.section("runtime"), &file.origin())?;
    let prefix = args
        .service_prefix
        .clone()
        .unwrap_or(runtime.service_prefix);
    let robot = std::sync::Arc::new(Robot::from_config(&file, args.urdf.as_deref())?);
    let scene = load_scene(args.scene.as_deref())?;
    let source = args.source.load()?;
    let params = stance::PostProcessParams::from_config_for(&file, gait)?;
    let distance = match &scene {
        Some(scene) => scene.walk_length(args.distance).context("--distance")?,
        None => args.distance.unwrap_or(DEFAULT_DISTANCE_M),
    };
    let request = WalkRequest {
        speed: walking_speed(args.speed, &file, gait)?,
        ..WalkRequest::feet(distance, args.seed)
    };
    let sequence = match &scene {
        Some(scene) => source.walk_in(&robot, &params, &request, &scene.walk_environment())?,
        None => source.walk(&robot, &params, &request)?,
    };
    let mut children = Processes::default();
    let running = DaemonClient::connect(&prefix).is_ok_and(|client| client.is_running());
    if !running {
        let launch = Launch {
            bin_dir: executable_dir()?,
            config: config.clone(),
            prefix: prefix.clone(),
            clock: args.clock,
            rate_hz: args.rate_hz,
            urdf: args.urdf.clone(),
        };
        let mut plant = PlantArgs::new(args.physics, gait, &file);
        if let Some(path) = &args.scene {
            plant.walk_sim.extend(["--scene".into(), path.into()]);
        }
        children.0.push(launch.walkd(&plant.walkd, &[])?);
        children
            .0
            .push(launch.walk_sim(args.physics, &plant.walk_sim)?);
    }
    let client = connect_when_fresh(&prefix, &children.0, Duration::from_secs(20))?;
    let progress = (!args.json).then(StanceProgress::new);
    let options = WatchOptions {
        record: args
            .record
            .as_ref()
            .map(|dir| dir.join(format!("demo-{}.mcap", args.robot.name()))),
        telemetry: gait == Gait::Dynamic && args.plots.is_some(),
        timeout: Duration::from_secs(60 + 30 * sequence.len() as u64),
        on_status: &|status| {
            if let Some(progress) = &progress {
                progress.update(status);
            }
        },
        controller_frame: scene
            .as_ref()
            .map_or_else(nalgebra::Isometry3::identity, |scene| scene.start),
    };
    let walk = watch_walk(&client, &prefix, &robot, &sequence, &options)?;
    if let Some(progress) = &progress {
        progress.finish();
    }
    // A status after the walk's last one carries the complete tick statistics.
    let status = client.status().unwrap_or(walk.last);
    drop(client);
    let plot = match &args.plots {
        Some(dir) => {
            std::fs::create_dir_all(dir)?;
            let file = dir.join(format!("fig6-{}.svg", args.robot.name()));
            let title = format!(
                "{}, {} m, walkctl demo --physics {} --gait {}",
                args.robot.name(),
                distance,
                args.physics.name(),
                gait.name()
            );
            crate::evaluate::write_fig6(
                &file,
                &title,
                &walk.trace,
                &walk.balance,
                &walk.hand_forces,
            )?;
            Some(file)
        }
        None => None,
    };
    let problems = children.shut_down()?;
    if !problems.is_empty() {
        bail!("shutting down: {}", problems.join("; "));
    }
    Ok(DemoOutcome {
        walk,
        status,
        gait,
        plot,
    })
}

/// `walkctl demo`: runs the demo and prints the outcome; fails unless the walk is done.
pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    let outcome = run_demo(args)?;
    if args.json {
        println!("{}", outcome.json());
    } else {
        let tilt = outcome.max_tilt_rad().map_or_else(
            || "no simulator truth".to_owned(),
            |tilt| format!("{tilt:.3} rad"),
        );
        let walk = &outcome.walk;
        println!(
            "outcome: {}\ndistance covered: {:.3} m ({} gait, {})\nstances executed: {}\n\
             simulated {:.2} s in {:.2} s wall (real-time factor {:.1})\n\
             largest base tilt in the simulator: {tilt}\n{}",
            outcome.outcome(),
            outcome.distance_m(),
            outcome.gait.name(),
            outcome.speed_m_s().map_or_else(
                || "no step seen".to_owned(),
                |v| format!("{v:.3} m/s from the first step")
            ),
            outcome.stances(),
            walk.sim_s,
            walk.wall_s,
            walk.sim_s / walk.wall_s,
            status_text(outcome.status())
        );
        if let Some(recording) = &walk.recording {
            println!(
                "recording: {} ({} messages, {:.1} MB; the observer lost {} telemetries, {} \
                 samples, {} commands)\n  open it in Foxglove (Open local file; docs/observe.md \
                 lists the channels), or read it with `python3 tests/python/check_recording.py \
                 {} docs/observe.md`",
                recording.summary.path.display(),
                recording.summary.messages,
                recording.summary.bytes as f64 / 1e6,
                recording.report.telemetry.lost,
                recording.report.samples.lost,
                recording.report.commands.lost,
                recording.summary.path.display()
            );
        }
        if let Some(plot) = &outcome.plot {
            println!(
                "plot: {} (Fig. 6: target, controller and simulator of the CoM and both feet; \
                 open it in a web browser)",
                plot.display()
            );
        }
    }
    if !outcome.succeeded() {
        bail!("the walk did not complete: {}", outcome.outcome());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scene_is_loaded_for_either_simulator_and_a_bad_one_refused() {
        let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/scenes");
        let loaded = load_scene(Some(&scenes.join("ramp-10deg.toml")))
            .unwrap()
            .unwrap();
        assert_eq!(loaded.name, "ramp-10deg");
        assert!(load_scene(None).unwrap().is_none());
        let error = load_scene(Some(&scenes.join("missing.toml"))).unwrap_err();
        assert!(error.to_string().contains("missing.toml"), "{error}");
    }
}
