//! Link transforms: every link's pose from the measured joint angles and the controller's
//! estimated floating base, as the transform tree a viewer draws the robot with.
//!
//! The tree is the URDF's: `world` → the root link (the estimated base pose), then each link
//! relative to its parent link, then the configured end-effector and FT frames relative to their
//! links. The poses come from the `kinematics` crate the controller uses, so a sole frame composed
//! along this tree equals the controller's estimate of it for the same sample.

use std::sync::Arc;

use kinematics::configuration::Configuration;
use kinematics::kinematics::Kinematics;
use kinematics::model::{FrameId, LinkId};
use kinematics::robot::{EndEffector, Robot};
use nalgebra::Isometry3;

/// The fixed frame every transform tree hangs from.
pub const WORLD_FRAME: &str = "world";

/// One edge of the transform tree: `child`'s pose in `parent`'s frame.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkTransform<'a> {
    /// Parent frame name.
    pub parent: &'a str,
    /// Child frame name.
    pub child: &'a str,
    /// The child's pose in the parent frame.
    pub pose: Isometry3<f64>,
}

/// Computes the transform tree of a robot; reuses its buffers between calls.
pub struct LinkPoser {
    robot: Arc<Robot>,
    kinematics: Kinematics,
    configuration: Configuration,
    /// The configured frames (end-effectors, then FT sensors).
    frames: Vec<FrameId>,
}

impl LinkPoser {
    /// A poser for `robot`.
    pub fn new(robot: Arc<Robot>) -> Self {
        let frames = EndEffector::ALL
            .iter()
            .map(|&e| robot.frame(e))
            .chain(robot.ft_sensors)
            .collect();
        Self {
            kinematics: Kinematics::new(&robot.model),
            configuration: robot.standing.clone(),
            frames,
            robot,
        }
    }

    /// The robot posed.
    pub fn robot(&self) -> &Arc<Robot> {
        &self.robot
    }

    /// Poses the robot at joint angles `q` (model order) with its floating base at `base`, and
    /// passes every edge of the tree to `each`, parents before children. Fails if `q` has the
    /// wrong length.
    pub fn pose(
        &mut self,
        q: &[f64],
        base: &Isometry3<f64>,
        mut each: impl FnMut(LinkTransform<'_>),
    ) -> anyhow::Result<()> {
        let model = &self.robot.model;
        anyhow::ensure!(
            q.len() == model.dof(),
            "{} joint angles for a robot with {} joints",
            q.len(),
            model.dof()
        );
        self.configuration.joints.copy_from_slice(q);
        self.configuration.base = *base;
        self.kinematics.update(model, &self.configuration);
        for link in model.link_ids() {
            let pose = self.kinematics.link_pose(link);
            let (parent, relative) = match model.link_parent(link) {
                None => (WORLD_FRAME, *pose),
                Some(parent) => (
                    model.link_name(parent),
                    self.kinematics.link_pose(parent).inverse() * pose,
                ),
            };
            each(LinkTransform {
                parent,
                child: model.link_name(link),
                pose: relative,
            });
        }
        for &frame in &self.frames {
            each(LinkTransform {
                parent: model.link_name(model.frame_link(frame)),
                child: model.frame_name(frame),
                pose: *model.frame_offset(frame),
            });
        }
        Ok(())
    }

    /// World pose of `link` at the last [`pose`](Self::pose).
    pub fn link_pose(&self, link: LinkId) -> &Isometry3<f64> {
        self.kinematics.link_pose(link)
    }

    /// World pose of `frame` at the last [`pose`](Self::pose).
    pub fn frame_pose(&self, frame: FrameId) -> Isometry3<f64> {
        self.kinematics.frame_pose(&self.robot.model, frame)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn robot(name: &str) -> Arc<Robot> {
        Arc::new(Robot::vendored(name))
    }

    /// Composing the tree's edges from `world` gives every link's forward-kinematics pose.
    #[test]
    fn the_tree_composes_to_the_forward_kinematics() {
        for name in ["armar4", "jvrc1"] {
            let robot = robot(name);
            let mut poser = LinkPoser::new(Arc::clone(&robot));
            let mut q = robot.standing.joints.clone();
            for (j, value) in q.iter_mut().enumerate() {
                *value += 0.05 * (j as f64).sin();
            }
            let base = Isometry3::translation(0.3, -0.1, 0.9)
                * nalgebra::UnitQuaternion::from_euler_angles(0.05, -0.02, 0.4);
            let mut world: HashMap<String, Isometry3<f64>> = HashMap::new();
            world.insert(WORLD_FRAME.to_owned(), Isometry3::identity());
            let mut edges = 0;
            poser
                .pose(q.as_slice(), &base, |t| {
                    let parent = world[t.parent];
                    world.insert(t.child.to_owned(), parent * t.pose);
                    edges += 1;
                })
                .unwrap();
            assert_eq!(edges, robot.model.link_count() + 6, "{name}");
            let left = robot.frame(EndEffector::LeftFoot);
            let composed = world[robot.model.frame_name(left)];
            let direct = poser.frame_pose(left);
            assert!(
                (composed.translation.vector - direct.translation.vector).norm() < 1e-12,
                "{name}"
            );
            assert!(
                composed.rotation.angle_to(&direct.rotation) < 1e-12,
                "{name}"
            );
        }
    }

    #[test]
    fn a_wrong_joint_count_is_refused() {
        let robot = robot("jvrc1");
        let mut poser = LinkPoser::new(robot);
        let error = poser
            .pose(&[0.0; 3], &Isometry3::identity(), |_| {})
            .unwrap_err();
        assert!(error.to_string().contains("3 joint angles"), "{error}");
    }
}
