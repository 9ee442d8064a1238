//! [`Controller::telemetry`]: the estimate and set-points of the last tick as plain `Copy` data,
//! for observers (the runtime publishes it on `telemetry` after each tick's command).

use kinematics::ground::SupportPolygon;
use kinematics::robot::EndEffector;
use stance::Gait;

use super::machine::Targets;
use super::status::{ControllerState, ControllerStatus};
use super::{Controller, pose_array};

/// What the controller estimated and aimed at in its last tick (world frame; poses as
/// `[x, y, z, qx, qy, qz, qw]`, end-effectors in `EndEffector` order): its status and what the
/// status leaves out.
#[derive(Clone, Copy, Debug)]
pub struct ControllerTelemetry {
    /// The status after the tick (state, phase, progress, CoM, contacts, balance readings).
    pub status: ControllerStatus,
    /// The gait walked (the balance readings of the status are the dynamic gait's).
    pub gait: Gait,
    /// Estimated floating-base pose.
    pub base: [f64; 7],
    /// Estimated end-effector frame poses.
    pub end_effectors: [[f64; 7]; 4],
    /// Each end-effector's target: its anchor while in contact, else its pose task's set-point,
    /// `None` without either.
    pub targets: [Option<[f64; 7]>; 4],
    /// The CoM x/y set-point while executing (moved towards the held hands by the weight they
    /// carry, `hand_support`).
    pub com_target: Option<[f64; 2]>,
    /// Support polygon of the feet in contact, as the CoM constraint uses it: moved towards the
    /// held hands by the weight they carry.
    pub support: SupportPolygon,
    /// The vertical force (N) each held hand's press tracks (left, right; 0 for a hand not
    /// held): the desired split of the weight between the hands and the feet.
    pub hand_forces_desired: [f64; 2],
}

impl Controller {
    /// The estimate and set-points of the last tick. Plain data; no allocation.
    pub fn telemetry(&self) -> ControllerTelemetry {
        let status = &self.status;
        let targets = self.machine.targets();
        let mut target_poses = [None; 4];
        for e in EndEffector::ALL {
            let i = e as usize;
            target_poses[i] = if targets.contacts[i] {
                Some(pose_array(&targets.anchors[i]))
            } else {
                targets.end_effectors[i].map(|t| pose_array(&t.pose))
            };
        }
        let executing = matches!(
            status.state,
            ControllerState::Executing | ControllerState::ControlledStop
        );
        ControllerTelemetry {
            status: *status,
            gait: self.machine.gait(),
            base: pose_array(&self.configuration.base),
            end_effectors: self.poses.map(|pose| pose_array(&pose)),
            targets: target_poses,
            com_target: executing.then(|| {
                let com = targets.hand_load.com_of(targets.com);
                [com.x, com.y]
            }),
            support: self.support_polygon(targets),
            hand_forces_desired: EndEffector::HANDS
                .map(|hand| targets.hand_force_pressed(hand, self.config.hand_force_n)),
        }
    }

    /// The support polygon the QP's CoM constraint uses ([`Targets::com_support`]).
    fn support_polygon(&self, targets: &Targets) -> SupportPolygon {
        let mut support = SupportPolygon::empty();
        targets.com_support(&self.robot.sole, &mut support);
        support
    }
}
