//! The robot's standing posture as both stance sources retarget from it: where its end-effectors
//! are, which way it faces, and how high its pelvis stands above its soles.

use kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Vector3};

/// The standing posture, measured once per sequence.
pub(crate) struct Standing {
    /// End-effector frame poses in the world, by [`EndEffector`].
    pub poses: [Isometry3<f64>; 4],
    /// Unit walking direction: the feet's mean x axis, horizontal.
    pub forward: Vector3<f64>,
    /// Mean height of the two soles.
    pub sole_z: f64,
    /// Height of the base link above the soles (m): the robot's size a human's is scaled to.
    pub pelvis_height: f64,
}

impl Standing {
    /// Measures `robot` in its standing configuration.
    pub fn measure(robot: &Robot) -> Self {
        let model = &robot.model;
        let mut kinematics = Kinematics::new(model);
        kinematics.update(model, &robot.standing);
        let poses = EndEffector::ALL.map(|e| kinematics.frame_pose(model, robot.frame(e)));
        let [left, right] =
            [EndEffector::LeftFoot, EndEffector::RightFoot].map(|e| poses[e as usize]);
        let heading = left.rotation * Vector3::x() + right.rotation * Vector3::x();
        let sole_z = 0.5 * (left.translation.z + right.translation.z);
        Self {
            poses,
            forward: Vector3::new(heading.x, heading.y, 0.0).normalize(),
            sole_z,
            pelvis_height: kinematics.link_pose(robot.base_link).translation.z - sole_z,
        }
    }

    /// The standing pose of `effector`.
    pub fn pose(&self, effector: EndEffector) -> Isometry3<f64> {
        self.poses[effector as usize]
    }
}
