//! Floating-base estimation by leg odometry: the feet in contact are anchored in the world, so the
//! base pose follows from the measured joint angles.
//!
//! An IMU, when present, sets the initial orientation and, after that, the heading only: the
//! controller turns the world anchors about the vertical so the estimate's yaw follows the IMU's
//! ([`BaseEstimator::heading_error`]), which catches the feet turning together on the ground,
//! the one motion leg odometry cannot see. Roll and pitch come from the anchored feet: the QP
//! holds those feet at their anchors, and an estimate that saw a stance foot tipped (the IMU's
//! view when a compliant foot rolls a little on its edge) would make the anchor correction turn
//! the joints to flatten the foot, which rolls the robot further the same way. Measured under
//! MuJoCo: with the IMU orientation JVRC-1 toppled in 3 of 3 5 m walks, with leg odometry alone
//! it finished all three.

use kinematics::configuration::Configuration;
use kinematics::kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use kinematics::ground::{sole_corners, yaw};

/// Feet closer than this to the lowest sole when the world frame is set up count as standing (m).
const STANDING_TOLERANCE: f64 = 2e-3;

/// Estimates the base pose from anchored feet; holds no state besides the last estimate.
#[derive(Debug, Clone)]
pub(crate) struct BaseEstimator {
    base: Isometry3<f64>,
}

impl BaseEstimator {
    pub fn new(initial: Isometry3<f64>) -> Self {
        Self { base: initial }
    }

    /// Sets up the world frame on the first measurement: the configured standing base pose (its
    /// orientation from the IMU if any), lowered or raised so the lowest sole corner is on the
    /// ground z = 0. Returns which feet stand (within a tolerance of the lowest sole).
    pub fn initialise(
        &mut self,
        robot: &Robot,
        kinematics: &mut Kinematics,
        configuration: &mut Configuration,
        imu: Option<UnitQuaternion<f64>>,
    ) -> [bool; 2] {
        configuration.base = robot.standing.base;
        if let Some(orientation) = imu {
            configuration.base.rotation = orientation;
        }
        kinematics.update(&robot.model, configuration);
        let lowest = [EndEffector::LeftFoot, EndEffector::RightFoot].map(|foot| {
            let pose = kinematics.frame_pose(&robot.model, robot.frame(foot));
            sole_corners(&pose, &robot.sole)
                .iter()
                .map(|c| c.z)
                .fold(f64::INFINITY, f64::min)
        });
        let ground = lowest[0].min(lowest[1]);
        configuration.base.translation.vector.z -= ground;
        kinematics.update(&robot.model, configuration);
        self.base = configuration.base;
        lowest.map(|z| z - ground <= STANDING_TOLERANCE)
    }

    /// The turn about the vertical (rad, in [−π, π]) that brings the last estimate's heading onto
    /// the IMU's base orientation `imu`. The world's yaw is the IMU's since [`Self::initialise`].
    pub fn heading_error(&self, imu: &UnitQuaternion<f64>) -> f64 {
        let turn = yaw(imu) - yaw(&self.base.rotation);
        turn.sin().atan2(turn.cos())
    }

    /// Estimates the base from the anchored feet (`anchors[i]` for left/right foot, weighted by
    /// `weights`) and updates `kinematics` at the estimate. Returns `false` when no foot is
    /// anchored (the base is then kept).
    pub fn update(
        &mut self,
        robot: &Robot,
        kinematics: &mut Kinematics,
        configuration: &mut Configuration,
        anchors: [Option<&Isometry3<f64>>; 2],
        weights: [f64; 2],
    ) -> bool {
        configuration.base = self.base;
        kinematics.update(&robot.model, configuration);
        let inverse_base = self.base.inverse();
        let mut total_weight = 0.0;
        let mut translation = Vector3::zeros();
        let mut rotation: Option<UnitQuaternion<f64>> = None;
        for (slot, foot) in [EndEffector::LeftFoot, EndEffector::RightFoot]
            .iter()
            .enumerate()
        {
            let Some(anchor) = anchors[slot] else {
                continue;
            };
            let foot_in_base =
                inverse_base * kinematics.frame_pose(&robot.model, robot.frame(*foot));
            let candidate = anchor * foot_in_base.inverse();
            let weight = weights[slot].max(1e-6);
            rotation = Some(match rotation {
                None => candidate.rotation,
                Some(r) => r.nlerp(&candidate.rotation, weight / (total_weight + weight)),
            });
            translation += weight * candidate.translation.vector;
            total_weight += weight;
        }
        let Some(rotation) = rotation.filter(|_| total_weight > 0.0) else {
            return false;
        };
        // Renormalise: composing with inverses assumes unit quaternions, and a norm error would
        // double every tick through the estimate's feedback.
        let mut rotation = rotation;
        rotation.renormalize();
        self.base = Isometry3::from_parts(Translation3::from(translation / total_weight), rotation);
        configuration.base = self.base;
        kinematics.update(&robot.model, configuration);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn turned(yaw: f64) -> UnitQuaternion<f64> {
        // Tilted too: only the heading about the vertical counts.
        UnitQuaternion::from_euler_angles(0.0, 0.0, yaw)
            * UnitQuaternion::from_euler_angles(0.1, -0.2, 0.0)
    }

    #[test]
    fn the_heading_error_is_the_shorter_turn_about_the_vertical() {
        let estimator = BaseEstimator::new(Isometry3::from_parts(
            Translation3::new(1.0, 2.0, 0.8),
            turned(3.1),
        ));
        // Across ±π the shorter way round, not −6.2 rad.
        let across = estimator.heading_error(&turned(-3.1));
        assert!(
            (across - (2.0 * std::f64::consts::PI - 6.2)).abs() < 1e-9,
            "{across}"
        );
        let small = estimator.heading_error(&turned(3.05));
        assert!((small + 0.05).abs() < 1e-9, "{small}");
    }
}
