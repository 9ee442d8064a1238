//! Shared helpers of the walk and state-machine tests: robots from the vendored configs, a
//! synthetic step-to walking sequence, and per-tick safety checks.
#![allow(dead_code)]

use kinematic_sim::Simulator;
use std::path::PathBuf;
use std::sync::Arc;

use daemon::controller::{Controller, ControllerConfig, Gait, GaitConfig, Phase, SolverKind};
use kinematic_sim::{KinematicSim, SimOptions};
use kinematics::ConfigFile;
use kinematics::kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Translation3};
use stance::{Environment, PostProcessedSequence, Stance};
use walk_bench::{ClosedLoop, Outcome, TickObservation, WalkOptions, WalkReport, walk};

/// Path of `configs/<name>.toml`.
pub fn config_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../configs")
        .join(format!("{name}.toml"))
}

/// The vendored robot `name`.
pub fn robot(name: &str) -> Arc<Robot> {
    Arc::new(Robot::load(&config_path(name), None).expect("vendored robot loads"))
}

/// The `[gait]` section of `name`'s config, for the kinematic simulator: the parts of the
/// stabilizer that need forces and inertia (foot damping, tilt damping) switched off, as an ideal
/// kinematic robot has neither: its synthetic centre of pressure follows the commanded motion.
pub fn kinematic_gait_config(name: &str) -> GaitConfig {
    let file = ConfigFile::load(&config_path(name)).expect("vendored config loads");
    let gaits = walk_bench::kinematic_gaits(&file).expect("gait config parses");
    assert!(gaits.dynamic.is_some(), "{name} has a dynamic gait");
    gaits
}

/// The `[controller]` section of `name`'s config.
pub fn controller_config(name: &str) -> ControllerConfig {
    ControllerConfig::from_config_file(&config_path(name)).expect("controller config parses")
}

/// A step-to walk from the standing posture: the right foot, then the left, each moves
/// `step` metres forward per step, `steps` steps in all, the swing foot passing 5 cm above
/// the ground halfway. Postures are the standing posture. With `hand`, the left hand first
/// takes a contact 3 cm in front of where it hangs and keeps it to the end.
pub fn synthetic_walk(robot: &Robot, steps: usize, step: f64, hand: bool) -> PostProcessedSequence {
    synthetic_walk_in(robot, steps, step, hand, Environment::default())
}

/// [`synthetic_walk`] in `environment` (its railings, for instance).
pub fn synthetic_walk_in(
    robot: &Robot,
    steps: usize,
    step: f64,
    hand: bool,
    environment: Environment,
) -> PostProcessedSequence {
    let mut kinematics = Kinematics::new(&robot.model);
    kinematics.update(&robot.model, &robot.standing);
    let mut poses = EndEffector::ALL.map(|e| kinematics.frame_pose(&robot.model, robot.frame(e)));
    let posture: Vec<f64> = robot.standing.joints.iter().copied().collect();
    let stance = |contacts: [bool; 4]| Stance {
        q: posture.clone(),
        contacts,
        translation: nalgebra::Vector3::zeros(),
        root_orientation: nalgebra::UnitQuaternion::identity(),
        duration_s: None,
    };
    let mut stances = vec![stance([true, true, false, false])];
    let mut targets = vec![poses];
    let mut base_contacts = [true, true, false, false];
    if hand {
        let left_hand = EndEffector::LeftHand as usize;
        poses[left_hand].translation.vector.x += 0.03;
        base_contacts[left_hand] = true;
        stances.push(stance(base_contacts));
        targets.push(poses);
    }
    for k in 0..steps {
        let foot = if k % 2 == 0 {
            EndEffector::RightFoot
        } else {
            EndEffector::LeftFoot
        };
        let from = poses[foot as usize];
        let to = Isometry3::from_parts(
            Translation3::from(from.translation.vector + nalgebra::Vector3::x() * step),
            from.rotation,
        );
        let mut swing = poses;
        swing[foot as usize] = Isometry3::from_parts(
            Translation3::from(
                (from.translation.vector + to.translation.vector) / 2.0
                    + nalgebra::Vector3::z() * 0.05,
            ),
            from.rotation,
        );
        let mut single = base_contacts;
        single[foot as usize] = false;
        stances.push(stance(single));
        targets.push(swing);
        poses[foot as usize] = to;
        stances.push(stance(base_contacts));
        targets.push(poses);
    }
    PostProcessedSequence::new(
        robot.name.clone(),
        robot.model.joint_names().to_vec(),
        environment,
        stances,
        targets,
    )
    .expect("synthetic sequence is valid")
}

/// Per-tick safety: stability margin ≥ 0, slip < 1 mm, no joint limit violation, finite command.
pub fn check_tick(o: &TickObservation) {
    let s = &o.sim.safety;
    assert!(
        s.stability_margin >= 0.0,
        "tick {}: stability margin {} < 0 (phase {:?}, stance {})",
        o.tick,
        s.stability_margin,
        o.status.phase,
        o.status.stance_index
    );
    assert!(
        s.contact_slip < 1e-3,
        "tick {}: contact slip {} m (phase {:?}, stance {})",
        o.tick,
        s.contact_slip,
        o.status.phase,
        o.status.stance_index
    );
    assert_eq!(
        s.limit_violations, 0,
        "tick {}: joint limit violated",
        o.tick
    );
    assert!(
        o.command
            .q_des
            .iter()
            .chain(o.command.qd_des.iter())
            .all(|v| v.is_finite()),
        "tick {}: non-finite command",
        o.tick
    );
}

/// Walks `sequence` on the vendored robot `name` at `rate_hz` with [`check_tick`] on every tick
/// and asserts that it reaches `done` and covers more than half of `distance`; `label` names
/// the case in failure messages, which also give the stance index and phase it stopped in.
pub fn assert_walks_to_done(
    name: &str,
    sequence: &PostProcessedSequence,
    solver: SolverKind,
    rate_hz: f64,
    distance: f64,
    label: &str,
) -> WalkReport {
    let options = WalkOptions {
        solver,
        rate_hz,
        time_limit_s: 60.0 + 20.0 * sequence.len() as f64,
        ..WalkOptions::default()
    };
    let mut last = (0, Phase::None);
    let report = walk(
        robot(name),
        controller_config(name),
        sequence,
        &options,
        |o| {
            last = (o.status.stance_index, o.status.phase);
            check_tick(o)
        },
    )
    .expect("walk runs");
    assert_eq!(
        report.outcome,
        Outcome::Done,
        "{label}: stopped at stance {} of {} in phase {:?}: {report:?}",
        last.0,
        report.stances,
        last.1
    );
    assert!(
        report.distance_m > 0.5 * distance,
        "{label}: walked {} m of {distance} m",
        report.distance_m
    );
    report
}

/// A controller and the kinematic simulator in closed loop, stepped one tick at a time so tests
/// can tamper with the measurement.
pub struct Harness {
    pub robot: Arc<Robot>,
    pub closed: ClosedLoop<KinematicSim>,
    pub dt: f64,
}

impl Harness {
    /// A standing robot `name` with the dense solver at `rate_hz`.
    pub fn new(name: &str, rate_hz: f64) -> Self {
        Self::with_config(name, controller_config(name), rate_hz)
    }

    /// [`Harness::new`] with `config` instead of the robot's `[controller]` section.
    pub fn with_config(name: &str, config: ControllerConfig, rate_hz: f64) -> Self {
        Self::with_sim_options(name, config, SimOptions::default(), rate_hz)
    }

    /// A standing robot `name` for dynamic walks: the simulator judges by the ZMP.
    pub fn dynamic(name: &str, rate_hz: f64) -> Self {
        let options = SimOptions {
            judge_by_zmp: true,
            ..SimOptions::default()
        };
        Self::with_sim_options(name, controller_config(name), options, rate_hz)
    }

    /// [`Harness::dynamic`] standing on the surfaces of `environment` (a scene's): the feet
    /// stand on the treads a sequence post-processed into it steps onto.
    pub fn dynamic_on(name: &str, rate_hz: f64, environment: &Environment) -> Self {
        let robot = robot(name);
        let options = SimOptions {
            judge_by_zmp: true,
            ..SimOptions::default()
        };
        let ground = Arc::new(sim_adapter::SceneGround::new(environment.clone()));
        let sim = KinematicSim::on_ground(robot.clone(), robot.standing.clone(), options, ground)
            .unwrap();
        Self::around(robot, controller_config(name), sim, rate_hz)
    }

    fn with_sim_options(
        name: &str,
        config: ControllerConfig,
        options: SimOptions,
        rate_hz: f64,
    ) -> Self {
        let robot = robot(name);
        let sim =
            KinematicSim::with_options(robot.clone(), robot.standing.clone(), options).unwrap();
        Self::around(robot, config, sim, rate_hz)
    }

    fn around(
        robot: Arc<Robot>,
        config: ControllerConfig,
        sim: KinematicSim,
        rate_hz: f64,
    ) -> Self {
        let controller = Controller::new(robot.clone(), config, SolverKind::Dense).unwrap();
        let closed = ClosedLoop::new(controller, sim, rate_hz);
        Self {
            dt: closed.dt(),
            robot,
            closed,
        }
    }

    /// Prepares and starts `sequence`.
    pub fn start(&mut self, sequence: &PostProcessedSequence) {
        let config = controller_config(&self.robot.name);
        let prepared = Controller::prepare(&self.robot, &config, sequence).unwrap();
        assert!(self.closed.controller.start(Box::new(prepared)).is_ok());
    }

    /// Prepares `sequence` for the dynamic gait with `gaits` and starts it.
    pub fn start_dynamic(&mut self, sequence: &PostProcessedSequence, gaits: &GaitConfig) {
        let config = controller_config(&self.robot.name);
        let prepared =
            Controller::prepare_gait(&self.robot, &config, gaits, sequence, Gait::Dynamic)
                .expect("sequence accepted");
        assert!(self.closed.controller.start(Box::new(prepared)).is_ok());
    }

    /// One tick: the measurement's wrenches pass through `tamper`, then the simulator applies
    /// the command.
    pub fn tick_with(&mut self, tamper: impl FnOnce(&mut [[f64; 6]; 4])) {
        self.closed
            .tick_with(|readings| tamper(readings.wrenches))
            .expect("the simulator's measurements are valid, so every tick commands");
    }

    /// One untampered tick.
    pub fn tick(&mut self) {
        self.tick_with(|_| {});
    }

    /// The command is finite and inside the joint limits; the simulator is safe.
    pub fn assert_safe(&self) {
        let limits = self.robot.model.joint_limits();
        for (j, (q, limit)) in self.closed.command.q_des.iter().zip(limits).enumerate() {
            assert!(
                q.is_finite() && *q >= limit.lower && *q <= limit.upper,
                "joint {j}: q_des {q}"
            );
        }
        assert!(self.closed.command.qd_des.iter().all(|v| v.is_finite()));
        let s = &self.closed.sim.measurement().safety;
        assert!(
            s.stability_margin >= 0.0,
            "stability margin {}",
            s.stability_margin
        );
        assert!(s.contact_slip < 1e-3, "slip {}", s.contact_slip);
        assert_eq!(s.limit_violations, 0);
    }
}
