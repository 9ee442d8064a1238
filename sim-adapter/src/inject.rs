//! Fault injection for evaluation (`walk-sim --inject KIND --inject-step K --inject-delay S`):
//! `delay` seconds of simulated time after the `step`-th lift-off of a foot, the simulated robot
//! reports one bad sample, withholds a touchdown, or asks walkd for a hold or an abort. Lift-offs
//! are counted from the simulator's own foot wrenches, so the moment is the same in every run of a
//! walk whatever the clock (lockstep or real time). `walkctl evaluate --inject` drives it and
//! judges the stop (docs/safety.md, "Controlled stop").

use std::sync::mpsc::{Receiver, Sender, channel};
use std::time::Duration;

use shm_types::process::InjectedFault;
use shm_types::{ClientPorts, ControlCommand, SensorSample, ServiceNames};

use crate::RobotIo;

/// When and what to inject.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultPlan {
    /// What goes wrong.
    pub kind: InjectedFault,
    /// After which lift-off (1: the walk's first step).
    pub step: u32,
    /// How long after that lift-off (s of simulated time).
    pub delay_s: f64,
}

/// A foot reads as unloaded below this share of both feet's normal force.
const UNLOADED_SHARE: f64 = 0.02;

/// A foot has lifted off once it has read unloaded this long (s): a sole chattering on the
/// ground (MuJoCo's ARMAR-4 reads no force for up to 16 ms at a time) has not.
const LIFTED_S: f64 = 0.03;

/// A foot has landed once it has read loaded this long (s).
const LANDED_S: f64 = 0.05;

/// How long [`InjectedFault::ForceDropout`] lasts (s).
const DROPOUT_S: f64 = 0.1;

/// A foot's contact as read from its force, debounced.
#[derive(Clone, Copy, Debug, Default)]
struct FootContact {
    airborne: bool,
    /// How long the reading has disagreed with `airborne` (s).
    against_s: f64,
}

impl FootContact {
    /// Takes a reading `dt` after the last; returns true at a lift-off.
    fn update(&mut self, unloaded: bool, dt: f64) -> bool {
        if unloaded == self.airborne {
            self.against_s = 0.0;
            return false;
        }
        self.against_s += dt;
        let settled = if unloaded { LIFTED_S } else { LANDED_S };
        if self.against_s < settled {
            return false;
        }
        self.airborne = unloaded;
        self.against_s = 0.0;
        unloaded
    }
}

/// Joint index and upper limit of the joint [`InjectedFault::JointOutOfLimits`] reports beyond it.
pub type LimitFault = (usize, f64);

/// A robot whose reports go wrong once, as its [`FaultPlan`] says.
pub struct FaultInjector<R> {
    robot: R,
    plan: FaultPlan,
    limit_fault: LimitFault,
    /// Each foot's contact (left, right).
    feet: [FootContact; 2],
    /// The period of the last step (s).
    dt: f64,
    lift_offs: u32,
    /// Simulated time since the planned lift-off (s), once it came.
    since_lift_off_s: Option<f64>,
    fired: bool,
    /// The foot whose touchdown is withheld (its index in `SensorSample::wrenches`).
    withheld: Option<usize>,
    /// Simulated time left in a force-torque dropout (s).
    dropout_s: f64,
    /// Where a hold or abort request goes (to a thread that sends it to walkd).
    requests: Option<Sender<ControlCommand>>,
}

impl<R: RobotIo> FaultInjector<R> {
    /// Injects `plan` into `robot`'s reports; a joint-limit fault reports joint `limit_fault.0`
    /// beyond its upper limit `limit_fault.1`. A hold or abort goes to the walkd serving `names`.
    pub fn new(robot: R, plan: FaultPlan, limit_fault: LimitFault, names: &ServiceNames) -> Self {
        let requests = matches!(plan.kind, InjectedFault::Hold | InjectedFault::Abort).then(|| {
            let (sender, receiver) = channel();
            let names = names.clone();
            std::thread::spawn(move || send_requests(&names, &receiver));
            sender
        });
        Self {
            robot,
            plan,
            limit_fault,
            feet: [FootContact::default(); 2],
            dt: 0.0,
            lift_offs: 0,
            since_lift_off_s: None,
            fired: false,
            withheld: None,
            dropout_s: 0.0,
            requests,
        }
    }

    /// The wrapped robot.
    pub fn robot(&self) -> &R {
        &self.robot
    }

    /// Counts the lift-offs in a true sample's foot wrenches; the time since the planned one
    /// starts at the moment its foot first read unloaded.
    fn watch_feet(&mut self, sample: &SensorSample) {
        // `wrenches` holds the left foot's, then the right foot's first.
        let forces = [0, 1].map(|f| sample.wrenches[f][2]);
        let total: f64 = forces.iter().map(|f| f.max(0.0)).sum();
        for (foot, force) in self.feet.iter_mut().zip(forces) {
            if foot.update(force <= UNLOADED_SHARE * total, self.dt) {
                self.lift_offs += 1;
                if self.lift_offs == self.plan.step {
                    self.since_lift_off_s = Some(LIFTED_S);
                }
            }
        }
    }

    /// Corrupts `sample` (or sends the request) now.
    fn fire(&mut self, sample: &mut SensorSample) {
        self.fired = true;
        let (joint, upper) = self.limit_fault;
        match self.plan.kind {
            InjectedFault::Nan => sample.q[joint] = f64::NAN,
            InjectedFault::JointOutOfLimits => sample.q[joint] = upper + 0.2,
            InjectedFault::ZeroForce => sample.wrenches = [[0.0; 6]; 4],
            InjectedFault::ForceDropout => self.dropout_s = DROPOUT_S,
            InjectedFault::Hold | InjectedFault::Abort => {
                let command = if self.plan.kind == InjectedFault::Hold {
                    ControlCommand::Hold
                } else {
                    ControlCommand::Abort
                };
                if let Some(requests) = &self.requests {
                    let _ = requests.send(command);
                }
            }
            InjectedFault::WithheldTouchdown => {
                self.withheld = self.feet.iter().position(|foot| foot.airborne);
            }
        }
    }
}

impl<R: RobotIo> RobotIo for FaultInjector<R> {
    type Error = R::Error;

    fn joint_count(&self) -> usize {
        self.robot.joint_count()
    }

    fn read(&mut self, sample: &mut SensorSample) {
        self.robot.read(sample);
        self.watch_feet(sample);
        let due = self
            .since_lift_off_s
            .is_some_and(|since| since >= self.plan.delay_s);
        if due && !self.fired {
            self.fire(sample);
        }
        if let Some(foot) = self.withheld {
            sample.wrenches[foot] = [0.0; 6];
        }
        if self.dropout_s > 0.0 {
            sample.wrenches = [[0.0; 6]; 4];
        }
    }

    fn write(&mut self, q_des: &[f64], qd_des: &[f64], dt: f64) -> Result<(), R::Error> {
        if let Some(since) = &mut self.since_lift_off_s {
            *since += dt;
        }
        self.dropout_s = (self.dropout_s - dt).max(0.0);
        self.dt = dt;
        self.robot.write(q_des, qd_des, dt)
    }
}

/// Connects to walkd's control service (waiting for walkd to create it), then sends each
/// request that comes at once; a failure is logged (the evaluation then sees no stop and fails
/// the run).
fn send_requests(names: &ServiceNames, requests: &Receiver<ControlCommand>) {
    let ports = loop {
        match ClientPorts::connect(names, "walk-sim-inject") {
            Ok(ports) => break ports,
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    };
    while let Ok(command) = requests.recv() {
        match ports.control(command, Duration::from_secs(2)) {
            Ok(_) => tracing::info!(command = command.name(), "fault injection: sent"),
            Err(error) => tracing::error!(%error, "fault injection: request failed"),
        }
    }
}
