//! The joint-limit guarantee as a property: whatever the measurements (valid, knocked, out of
//! limits, NaN, infinite, huge), adapter restarts onto another posture in between, and whatever the
//! requests (start, hold, abort, reset), every command the controller writes is finite, inside
//! the URDF limits and no faster than the URDF velocity limits (from the previous command, and in
//! its feed-forward velocity), and before its first valid measurement it writes none.

mod walk_support;

use kinematic_sim::Simulator;
use std::sync::Arc;

use daemon::controller::{Command, Controller, Measurement, SolverKind};
use kinematic_sim::KinematicSim;
use kinematics::robot::Robot;
use proptest::prelude::*;

/// What happens between two checks.
#[derive(Debug, Clone)]
enum Event {
    /// A tick on the simulator's true measurement (the simulator then applies the command).
    Valid,
    /// A tick on a measurement with one value replaced.
    Corrupt {
        field: Field,
        index: usize,
        value: Bad,
    },
    /// The adapter restarts with the robot in another posture: its arms, torso and head moved
    /// (offsets in [-1, 1] of up to 0.3 rad), its legs standing.
    Restart { offsets: Vec<f64> },
    /// A tick on the true measurement with one joint knocked by this much (rad), kept inside
    /// its limits: a valid reading that jumped, which the command must not chase at any speed.
    Knock { index: usize, by: f64 },
    /// A request of a client.
    Request(Request),
}

#[derive(Debug, Clone, Copy)]
enum Field {
    Angle,
    Velocity,
    Wrench,
    Imu,
}

#[derive(Debug, Clone, Copy)]
enum Bad {
    Nan,
    Infinite,
    Huge,
    /// This far beyond a limit (rad).
    Beyond(f64),
}

#[derive(Debug, Clone, Copy)]
enum Request {
    Start,
    Hold,
    Abort,
    Reset,
}

fn event() -> impl Strategy<Value = Event> {
    let field = prop_oneof![
        Just(Field::Angle),
        Just(Field::Velocity),
        Just(Field::Wrench),
        Just(Field::Imu),
    ];
    let bad = prop_oneof![
        Just(Bad::Nan),
        Just(Bad::Infinite),
        Just(Bad::Huge),
        (-2.0..2.0f64).prop_map(Bad::Beyond),
    ];
    let request = prop_oneof![
        Just(Request::Start),
        Just(Request::Hold),
        Just(Request::Abort),
        Just(Request::Reset),
    ];
    prop_oneof![
        6 => Just(Event::Valid),
        3 => (field, 0..64usize, bad).prop_map(|(field, index, value)| Event::Corrupt {
            field,
            index,
            value
        }),
        1 => proptest::collection::vec(-1.0..1.0f64, 40).prop_map(|offsets| Event::Restart { offsets }),
        2 => (0..64usize, -0.3..0.3f64).prop_map(|(index, by)| Event::Knock { index, by }),
        2 => request.prop_map(Event::Request),
    ]
}

/// The standing posture with the upper body moved by `offsets`, inside the limits.
fn posture(robot: &Robot, offsets: &[f64]) -> kinematics::Configuration {
    let mut q = robot.standing.clone();
    let groups = &robot.joint_groups;
    let limits = robot.model.joint_limits();
    for &j in groups.arms.iter().chain(&groups.torso).chain(&groups.head) {
        let offset = 0.3 * offsets[j % offsets.len()];
        q.joints[j] = (q.joints[j] + offset).clamp(limits[j].lower, limits[j].upper);
    }
    q
}

struct Run {
    robot: Arc<Robot>,
    controller: Controller,
    sim: KinematicSim,
    command: Command,
    dt: f64,
    commanded_ever: bool,
    commands: usize,
    /// The last command written to the same adapter (none after a restart onto another one or a
    /// reset).
    previous: Option<nalgebra::DVector<f64>>,
}

impl Run {
    fn new(name: &str) -> Self {
        let robot = walk_support::robot(name);
        let config = walk_support::controller_config(name);
        Self {
            controller: Controller::new(robot.clone(), config, SolverKind::Dense).unwrap(),
            sim: KinematicSim::new(robot.clone(), robot.standing.clone()).unwrap(),
            command: Command::new(robot.model.dof()),
            dt: 0.005,
            commanded_ever: false,
            commands: 0,
            previous: None,
            robot,
        }
    }

    /// Ticks on `measurement` and checks what it wrote.
    fn tick(&mut self, measurement: &Measurement) -> bool {
        // A poisoned command buffer: a tick that writes must overwrite every entry.
        self.command.q_des.fill(f64::NAN);
        self.command.qd_des.fill(f64::NAN);
        let commanded = self
            .controller
            .tick(measurement, self.dt, &mut self.command);
        if commanded {
            self.commanded_ever = true;
            self.commands += 1;
            let limits = self.robot.model.joint_limits();
            for (j, limit) in limits.iter().enumerate() {
                let (q, qd) = (self.command.q_des[j], self.command.qd_des[j]);
                assert!(
                    q.is_finite() && q >= limit.lower && q <= limit.upper,
                    "joint {j}: q_des {q} outside [{}, {}]",
                    limit.lower,
                    limit.upper
                );
                assert!(qd.is_finite(), "joint {j}: qd_des {qd}");
                let speed = limit.velocity;
                assert!(
                    qd.abs() <= speed * (1.0 + 1e-9),
                    "joint {j}: qd_des {qd} beyond {speed}"
                );
                if let Some(previous) = &self.previous {
                    let moved = (q - previous[j]).abs();
                    assert!(
                        moved <= speed * self.dt * (1.0 + 1e-9),
                        "joint {j}: q_des moved {moved} rad in one tick, beyond {speed} rad/s"
                    );
                }
            }
            self.previous = Some(self.command.q_des.clone());
        }
        commanded
    }

    fn apply(&mut self, event: &Event) {
        let m = self.sim.measurement().clone();
        match event {
            Event::Valid => {
                let measurement = Measurement {
                    q: m.q.as_slice(),
                    qd: m.qd.as_slice(),
                    wrenches: &m.wrenches,
                    imu_orientation: Some(m.base_orientation),
                };
                if self.tick(&measurement) {
                    self.sim
                        .step(
                            self.command.q_des.as_slice(),
                            self.command.qd_des.as_slice(),
                            self.dt,
                        )
                        .expect("the simulator takes every command the controller writes");
                }
            }
            Event::Corrupt {
                field,
                index,
                value,
            } => {
                let (mut q, mut qd, mut wrenches) = (m.q.clone(), m.qd.clone(), m.wrenches);
                let mut imu = m.base_orientation.into_inner().coords;
                let limits = self.robot.model.joint_limits();
                let j = index % q.len();
                let number = match value {
                    Bad::Nan => f64::NAN,
                    Bad::Infinite => f64::INFINITY,
                    Bad::Huge => 1e300,
                    Bad::Beyond(by) if *by >= 0.0 => limits[j].upper + by,
                    Bad::Beyond(by) => limits[j].lower + by,
                };
                match field {
                    Field::Angle => q[j] = number,
                    Field::Velocity => qd[j] = number,
                    Field::Wrench => wrenches[index % 4][index % 6] = number,
                    Field::Imu => imu[index % 4] = number,
                }
                let orientation =
                    nalgebra::UnitQuaternion::new_unchecked(nalgebra::Quaternion::from(imu));
                let measurement = Measurement {
                    q: q.as_slice(),
                    qd: qd.as_slice(),
                    wrenches: &wrenches,
                    imu_orientation: Some(orientation),
                };
                self.tick(&measurement);
            }
            Event::Knock { index, by } => {
                let mut q = m.q.clone();
                let j = index % q.len();
                let limit = self.robot.model.joint_limits()[j];
                q[j] = (q[j] + by).clamp(limit.lower, limit.upper);
                let measurement = Measurement {
                    q: q.as_slice(),
                    qd: m.qd.as_slice(),
                    wrenches: &m.wrenches,
                    imu_orientation: Some(m.base_orientation),
                };
                self.tick(&measurement);
            }
            Event::Restart { offsets } => {
                self.controller.relink();
                self.previous = None;
                self.sim = KinematicSim::new(self.robot.clone(), posture(&self.robot, offsets))
                    .expect("a posture inside the limits");
            }
            Event::Request(Request::Start) => {
                let config = walk_support::controller_config(&self.robot.name);
                let walk = walk_support::synthetic_walk(&self.robot, 2, 0.05, false);
                let prepared = Controller::prepare(&self.robot, &config, &walk).unwrap();
                let _ = self.controller.start(Box::new(prepared));
            }
            Event::Request(Request::Hold) => self.controller.hold(),
            Event::Request(Request::Abort) => self.controller.abort(),
            Event::Request(Request::Reset) => {
                // A reset after a tipping fault re-anchors the command on the measured posture
                // (where the joints are, so no motion), wherever the last command was.
                let _ = self.controller.reset();
                self.previous = None;
            }
        }
    }
}

/// 256 random runs of up to 400 events each on both robots; prints how many commands and
/// events were checked (`--nocapture`).
#[test]
fn no_command_ever_leaves_the_limits() {
    use proptest::test_runner::{Config, TestRunner};
    let mut runner = TestRunner::new(Config {
        cases: 256,
        failure_persistence: None,
        ..Config::default()
    });
    let strategy = (
        prop_oneof![Just("armar4"), Just("jvrc1")],
        proptest::collection::vec(event(), 1..400),
    );
    let totals = std::cell::Cell::new((0usize, 0usize));
    runner
        .run(&strategy, |(robot, events)| {
            let mut run = Run::new(robot);
            for event in &events {
                run.apply(event);
            }
            let (commands, checked) = totals.get();
            totals.set((commands + run.commands, checked + events.len()));
            Ok(())
        })
        .unwrap();
    let (commands, events) = totals.get();
    eprintln!(
        "limits guarantee: {commands} commands checked over {events} events in 256 runs: all \
         finite and inside the limits"
    );
    assert!(
        commands > 10_000,
        "too few commands to mean anything: {commands}"
    );
}

/// Before any valid measurement there is nothing safe to command: corrupt samples get no
/// command at all, the first valid one does.
#[test]
fn nothing_is_commanded_before_the_first_valid_measurement() {
    let mut run = Run::new("armar4");
    for value in [Bad::Nan, Bad::Huge, Bad::Beyond(0.5)] {
        run.apply(&Event::Corrupt {
            field: Field::Angle,
            index: 3,
            value,
        });
    }
    assert!(!run.commanded_ever);
    run.apply(&Event::Request(Request::Reset));
    run.apply(&Event::Valid);
    assert!(run.commanded_ever);
}
