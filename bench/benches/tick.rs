//! Full controller tick (measurement check, leg odometry, kinematics, state machine, QP assembly
//! and solve) per robot and QP back-end, in closed loop with the kinematic simulator walking a
//! generated 1 m sequence. Only `Controller::tick` is timed (by the closed loop); the simulator
//! steps outside the measurement. Percentiles at the default 500 Hz come from `walk-bench`
//! (docs/controller.md).

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use daemon::controller::{Controller, ControllerConfig, ControllerState, SolverKind};
use kinematic_sim::KinematicSim;
use kinematics::ConfigFile;
use kinematics::robot::Robot;
use stance::{PostProcessParams, PostProcessedSequence, WalkRequest, synthetic_walk};
use walk_bench::ClosedLoop;

const RATE_HZ: f64 = 500.0;

/// A robot walking its 1 m sequence again and again.
struct Walk {
    robot: Arc<Robot>,
    config: ControllerConfig,
    sequence: PostProcessedSequence,
    solver: SolverKind,
    closed: ClosedLoop<KinematicSim>,
}

impl Walk {
    fn new(name: &str, solver: SolverKind) -> Self {
        let path =
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../configs/{name}.toml"));
        let file = ConfigFile::load(&path).expect("config reads");
        let robot = Arc::new(Robot::from_config(&file, None).expect("robot loads"));
        let config = ControllerConfig::from_config(&file).expect("controller config");
        let params = PostProcessParams::from_config(&file).expect("postprocess params");
        let sequence =
            synthetic_walk(&robot, &params, &WalkRequest::feet(1.0, 0)).expect("a 1 m walk");
        let closed = Self::fresh(&robot, &config, &sequence, solver);
        Self {
            robot,
            config,
            sequence,
            solver,
            closed,
        }
    }

    /// The robot standing at the start of the walk.
    fn fresh(
        robot: &Arc<Robot>,
        config: &ControllerConfig,
        sequence: &PostProcessedSequence,
        solver: SolverKind,
    ) -> ClosedLoop<KinematicSim> {
        let mut controller = Controller::new(robot.clone(), *config, solver).expect("controller");
        let prepared = Controller::prepare(robot, config, sequence).expect("sequence accepted");
        assert!(controller.start(Box::new(prepared)).is_ok());
        let sim = KinematicSim::new(robot.clone(), robot.standing.clone()).expect("sim");
        ClosedLoop::new(controller, sim, RATE_HZ)
    }

    /// Runs `ticks` closed-loop ticks; returns the time spent in `Controller::tick`.
    fn run(&mut self, ticks: u64) -> Duration {
        let mut total = Duration::ZERO;
        for _ in 0..ticks {
            if self.closed.controller.status().state != ControllerState::Executing {
                self.closed = Self::fresh(&self.robot, &self.config, &self.sequence, self.solver);
            }
            total += self.closed.tick().expect("closed-loop tick");
        }
        total
    }
}

fn tick(c: &mut Criterion) {
    let mut group = c.benchmark_group("controller_tick");
    for robot in ["jvrc1", "armar4"] {
        for solver in [SolverKind::Dense, SolverKind::Clarabel] {
            let mut walk = Walk::new(robot, solver);
            group.bench_function(format!("{robot}/{}", solver.name()), |b| {
                b.iter_custom(|iters| walk.run(iters))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, tick);
criterion_main!(benches);
