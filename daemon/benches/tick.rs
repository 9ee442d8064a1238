//! Full controller tick (measurement check, leg odometry, kinematics, state machine, QP assembly
//! and solve) per robot and QP back-end, in closed loop with the kinematic simulator walking a
//! generated 1 m sequence. Only `Controller::tick` is timed; the simulator steps outside the
//! measurement. Percentiles at the default 500 Hz come from `walkd bench` (docs/controller.md).

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use daemon::controller::{
    Command, Controller, ControllerConfig, ControllerState, Measurement, SolverKind,
};
use kinematic_sim::KinematicSim;
use kinematics::robot::Robot;
use stance::{
    AffordanceSet, GenerateOptions, PostProcessParams, PostProcessedSequence, PostProcessor,
};

const RATE_HZ: f64 = 500.0;

struct Loop {
    robot: Arc<Robot>,
    config: ControllerConfig,
    sequence: PostProcessedSequence,
    solver: SolverKind,
    controller: Controller,
    sim: KinematicSim,
    command: Command,
}

impl Loop {
    fn new(name: &str, solver: SolverKind) -> Self {
        let path =
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../configs/{name}.toml"));
        let robot = Arc::new(Robot::load(&path, None).expect("robot loads"));
        let config = ControllerConfig::from_config_file(&path).expect("controller config");
        let params = PostProcessParams::from_config_path(&path).expect("postprocess params");
        let raw = stance::generate(
            &robot,
            &GenerateOptions {
                distance: 1.0 / params.scf,
                affordances: AffordanceSet::Feet,
                seed: 0,
            },
        )
        .expect("generator");
        let sequence = PostProcessor::new(&robot, params)
            .process(&raw)
            .expect("post-processing");
        let (controller, sim) = Self::fresh(&robot, &config, &sequence, solver);
        let command = Command::new(robot.model.dof());
        Self {
            robot,
            config,
            sequence,
            solver,
            controller,
            sim,
            command,
        }
    }

    fn fresh(
        robot: &Arc<Robot>,
        config: &ControllerConfig,
        sequence: &PostProcessedSequence,
        solver: SolverKind,
    ) -> (Controller, KinematicSim) {
        let mut controller = Controller::new(robot.clone(), *config, solver).expect("controller");
        let prepared = Controller::prepare(robot, config, sequence).expect("sequence accepted");
        assert!(controller.start(Box::new(prepared)).is_ok());
        let sim = KinematicSim::new(robot.clone(), robot.standing.clone()).expect("sim");
        (controller, sim)
    }

    /// Runs `ticks` closed-loop ticks; returns the time spent in `Controller::tick`.
    fn run(&mut self, ticks: u64) -> Duration {
        let dt = 1.0 / RATE_HZ;
        let mut total = Duration::ZERO;
        for _ in 0..ticks {
            if self.controller.status().state != ControllerState::Executing {
                (self.controller, self.sim) =
                    Self::fresh(&self.robot, &self.config, &self.sequence, self.solver);
            }
            let m = self.sim.measurement();
            let measurement = Measurement {
                q: m.q.as_slice(),
                qd: m.qd.as_slice(),
                wrenches: &m.wrenches,
                imu_orientation: Some(m.base_orientation),
            };
            let started = Instant::now();
            let commanded = self.controller.tick(&measurement, dt, &mut self.command);
            total += started.elapsed();
            assert!(commanded, "the simulator's measurements are valid");
            self.sim
                .step(
                    self.command.q_des.as_slice(),
                    self.command.qd_des.as_slice(),
                    dt,
                )
                .expect("sim step");
        }
        total
    }
}

fn tick(c: &mut Criterion) {
    let mut group = c.benchmark_group("controller_tick");
    for robot in ["jvrc1", "armar4"] {
        for solver in [SolverKind::Dense, SolverKind::Clarabel] {
            let mut walk = Loop::new(robot, solver);
            group.bench_function(format!("{robot}/{}", solver.name()), |b| {
                b.iter_custom(|iters| walk.run(iters))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, tick);
criterion_main!(benches);
