//! A robot drawn with primitive shapes, for viewers and renderers that lack its meshes.
//!
//! The vendored URDFs reference meshes that are not vendored, so every picture of a robot here is
//! drawn from this one description instead (the observer's `/robot_description` URDF and the
//! visual geoms of the MuJoCo model): a stick figure of capsules along the links, a box per sole
//! and a sphere per hand, each in the frame of the link it belongs to.
//!
//! Rules, in link frames:
//! - a capsule from a link's origin to the origin of each child link, when both weigh more than
//!   [`MIN_LINK_MASS`] (so massless helper links — sensor mounts, a root link on the floor — draw
//!   nothing) and the segment is at least [`MIN_SEGMENT`] long;
//! - a sphere at the centre of mass of a link of at least [`HEAD_MASS`] without a child heavier
//!   than [`MIN_LINK_MASS`] and without an end-effector frame (a head at the end of the neck);
//! - a capsule from each foot link's origin (the ankle) to its sole frame, and a box per foot: the
//!   configured sole rectangle (`[robot] sole`), [`SOLE_THICKNESS`] high,
//!   its bottom face on the sole frame;
//! - a sphere per hand at the palm frame.

use nalgebra::{Isometry3, Translation3, Vector3};

use crate::model::LinkId;
use crate::robot::{EndEffector, Robot};

/// Links lighter than this (kg) are helpers: no segment starts or ends at them.
pub const MIN_LINK_MASS: f64 = 1e-3;
/// Shorter segments (m) are not drawn (coincident joint frames of a multi-axis joint).
pub const MIN_SEGMENT: f64 = 0.01;
/// Radius of the link capsules (m).
pub const LIMB_RADIUS: f64 = 0.03;
/// A leaf link at least this heavy (kg) is drawn as a sphere.
pub const HEAD_MASS: f64 = 1.0;
/// Radius of a leaf link's sphere (m).
pub const HEAD_RADIUS: f64 = 0.09;
/// Radius of a hand's sphere (m).
pub const HAND_RADIUS: f64 = 0.045;
/// Height of a sole box (m).
pub const SOLE_THICKNESS: f64 = 0.02;

/// A primitive shape in the frame of the link it is attached to (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// A cylinder with hemispherical ends around the segment `from`–`to`.
    Capsule {
        /// One end of the axis.
        from: Vector3<f64>,
        /// The other end.
        to: Vector3<f64>,
        /// Radius.
        radius: f64,
    },
    /// A box centred at `pose` with the given half extents along its axes.
    Box {
        /// Pose of the box's centre.
        pose: Isometry3<f64>,
        /// Half extents along the box's x, y and z axes.
        half_extents: Vector3<f64>,
    },
    /// A sphere.
    Sphere {
        /// Centre.
        centre: Vector3<f64>,
        /// Radius.
        radius: f64,
    },
}

/// What a shape depicts (viewers may colour them apart).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// A link segment or a leaf link.
    Limb,
    /// A foot's sole.
    Sole,
    /// A hand.
    Hand,
}

/// One shape of the skeleton and the link it moves with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkShape {
    /// The link whose frame `shape` is expressed in.
    pub link: LinkId,
    /// The shape.
    pub shape: Shape,
    /// What it depicts.
    pub part: Part,
}

/// The shapes that draw `robot` (see the module docs for the rules), in link order.
pub fn skeleton(robot: &Robot) -> Vec<LinkShape> {
    let model = &robot.model;
    let heavy = |link: LinkId| model.link_mass(link) > MIN_LINK_MASS;
    let mut shapes = Vec::new();
    // Links that end a chain of heavy links and carry no end-effector: heads.
    let mut leaf = vec![true; model.link_count()];
    for effector in EndEffector::ALL {
        leaf[model.frame_link(robot.frame(effector)).index()] = false;
    }
    for child in model.link_ids() {
        let Some(parent) = model.link_parent(child) else {
            continue;
        };
        if heavy(child) {
            leaf[parent.index()] = false;
        }
        let to = model.link_origin(child).translation.vector;
        if heavy(parent) && heavy(child) && to.norm() >= MIN_SEGMENT {
            shapes.push(LinkShape {
                link: parent,
                shape: Shape::Capsule {
                    from: Vector3::zeros(),
                    to,
                    radius: LIMB_RADIUS,
                },
                part: Part::Limb,
            });
        }
    }
    for link in model.link_ids() {
        if leaf[link.index()] && model.link_mass(link) >= HEAD_MASS {
            shapes.push(LinkShape {
                link,
                shape: Shape::Sphere {
                    centre: *model.link_com(link),
                    radius: HEAD_RADIUS,
                },
                part: Part::Limb,
            });
        }
    }
    for effector in EndEffector::ALL {
        let frame = robot.frame(effector);
        let link = model.frame_link(frame);
        let offset = model.frame_offset(frame);
        if effector.is_foot() && offset.translation.vector.norm() >= MIN_SEGMENT {
            // The ankle down to the sole.
            shapes.push(LinkShape {
                link,
                shape: Shape::Capsule {
                    from: Vector3::zeros(),
                    to: offset.translation.vector,
                    radius: LIMB_RADIUS,
                },
                part: Part::Limb,
            });
        }
        let (shape, part) = if effector.is_foot() {
            let half = Vector3::new(robot.sole.length, robot.sole.width, SOLE_THICKNESS) / 2.0;
            let shape = Shape::Box {
                pose: offset * Translation3::new(0.0, 0.0, half.z),
                half_extents: half,
            };
            (shape, Part::Sole)
        } else {
            let shape = Shape::Sphere {
                centre: offset.translation.vector,
                radius: HAND_RADIUS,
            };
            (shape, Part::Hand)
        };
        shapes.push(LinkShape { link, shape, part });
    }
    shapes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_robot_is_drawn_with_limbs_soles_and_hands() {
        for name in ["armar4", "jvrc1"] {
            let robot = Robot::vendored(name);
            let shapes = skeleton(&robot);
            let count = |part: Part| shapes.iter().filter(|s| s.part == part).count();
            assert_eq!(count(Part::Sole), 2, "{name}");
            assert_eq!(count(Part::Hand), 2, "{name}");
            assert!(
                count(Part::Limb) >= 20,
                "{name}: {} limbs",
                count(Part::Limb)
            );
            // No segment starts at a massless helper link (ARMAR-4's root on the floor).
            for shape in &shapes {
                if let Shape::Capsule { .. } = shape.shape {
                    assert!(robot.model.link_mass(shape.link) > MIN_LINK_MASS, "{name}");
                }
            }
        }
    }

    #[test]
    fn a_sole_box_lies_on_its_sole_frame() {
        let robot = Robot::vendored("jvrc1");
        let frame = robot.frame(EndEffector::LeftFoot);
        let sole = skeleton(&robot)
            .into_iter()
            .find(|s| s.part == Part::Sole && s.link == robot.model.frame_link(frame))
            .expect("left sole");
        let Shape::Box { pose, half_extents } = sole.shape else {
            panic!("a sole is a box");
        };
        // The box centre, seen from the sole frame, is half a thickness above it.
        let centre = robot.model.frame_offset(frame).inverse() * pose;
        assert!(
            (centre.translation.vector - Vector3::new(0.0, 0.0, half_extents.z)).norm() < 1e-12
        );
        assert!((half_extents.x * 2.0 - robot.sole.length).abs() < 1e-12);
    }
}
