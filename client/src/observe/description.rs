//! The robot description an observer publishes on `/robot_description`: the robot's URDF with
//! its meshes (not vendored) replaced by primitive shapes, so a viewer draws it without any other
//! file.
//!
//! Links, joints, origins, axes, limits and inertials are the vendored URDF's, unchanged, so the
//! link frames match the observer's transform tree; each link's visuals are the shapes
//! [`kinematics::skeleton`] gives it (capsules become cylinders, as URDF has no capsule), and the
//! collision geometry is dropped.

use anyhow::Context;
use kinematics::robot::Robot;
use kinematics::skeleton::{self, Part, Shape};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use urdf_rs::{Color, Geometry, Material, Pose, Vec3, Vec4, Visual};

/// The colour of each part (RGBA).
fn material(part: Part) -> Material {
    let (name, rgba) = match part {
        Part::Limb => ("limb", [0.62, 0.66, 0.72, 1.0]),
        Part::Sole => ("sole", [0.20, 0.22, 0.25, 1.0]),
        Part::Hand => ("hand", [0.93, 0.55, 0.18, 1.0]),
    };
    Material {
        name: name.to_owned(),
        color: Some(Color { rgba: Vec4(rgba) }),
        texture: None,
    }
}

/// The URDF text of `robot`'s description (see the module docs).
pub fn description_urdf(robot: &Robot) -> anyhow::Result<String> {
    let mut urdf = urdf_rs::read_file(&robot.urdf)
        .with_context(|| format!("reading {}", robot.urdf.display()))?;
    let shapes = skeleton::skeleton(robot);
    urdf.materials = [Part::Limb, Part::Sole, Part::Hand]
        .into_iter()
        .map(material)
        .collect();
    for link in &mut urdf.links {
        link.collision.clear();
        link.visual.clear();
        let Some(id) = robot.model.link_index(&link.name) else {
            continue;
        };
        for shape in shapes.iter().filter(|s| s.link == id) {
            let (pose, geometry) = urdf_geometry(&shape.shape);
            link.visual.push(Visual {
                name: None,
                origin: urdf_pose(&pose),
                geometry,
                // A reference to the robot-level material of the part.
                material: Some(Material {
                    name: material(shape.part).name,
                    color: None,
                    texture: None,
                }),
            });
        }
    }
    urdf_rs::write_to_string(&urdf).context("writing the description URDF")
}

/// A shape as a URDF geometry and its origin in the link frame.
fn urdf_geometry(shape: &Shape) -> (Isometry3<f64>, Geometry) {
    match *shape {
        Shape::Capsule { from, to, radius } => {
            let axis = to - from;
            // A URDF cylinder lies along its z axis, centred on its origin.
            let rotation =
                UnitQuaternion::rotation_between(&Vector3::z(), &axis).unwrap_or_else(|| {
                    UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.0)
                });
            let centre = Translation3::from((from + to) / 2.0);
            (
                Isometry3::from_parts(centre, rotation),
                Geometry::Cylinder {
                    radius,
                    length: axis.norm(),
                },
            )
        }
        Shape::Box { pose, half_extents } => (
            pose,
            Geometry::Box {
                size: Vec3((half_extents * 2.0).into()),
            },
        ),
        Shape::Sphere { centre, radius } => (
            Isometry3::from_parts(Translation3::from(centre), UnitQuaternion::identity()),
            Geometry::Sphere { radius },
        ),
    }
}

/// A pose as URDF `xyz` + `rpy` (fixed-axis roll, pitch, yaw).
fn urdf_pose(pose: &Isometry3<f64>) -> Pose {
    let (roll, pitch, yaw) = pose.rotation.euler_angles();
    Pose {
        xyz: Vec3(pose.translation.vector.into()),
        rpy: Vec3([roll, pitch, yaw]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The description loads as a model with the same links and joints, references no file, and
    /// draws every shape of the skeleton.
    #[test]
    fn the_description_is_the_same_model_without_meshes() {
        for name in ["armar4", "jvrc1"] {
            let robot = Robot::vendored(name);
            let text = description_urdf(&robot).unwrap();
            assert!(
                !text.contains("filename"),
                "{name}: the description references a file"
            );
            let model = kinematics::model::Model::from_urdf_str(&text).unwrap();
            assert_eq!(model.link_names(), robot.model.link_names(), "{name}");
            assert_eq!(model.joint_names(), robot.model.joint_names(), "{name}");
            for link in model.link_ids() {
                let a = model.link_origin(link);
                let b = robot.model.link_origin(link);
                assert!(
                    (a.translation.vector - b.translation.vector).norm() < 1e-9,
                    "{name}"
                );
                assert!(a.rotation.angle_to(&b.rotation) < 1e-9, "{name}");
            }
            let parsed = urdf_rs::read_from_string(&text).unwrap();
            let visuals: usize = parsed.links.iter().map(|l| l.visual.len()).sum();
            assert_eq!(visuals, skeleton::skeleton(&robot).len(), "{name}");
        }
    }

    #[test]
    fn a_cylinder_spans_its_capsule() {
        let from = Vector3::new(0.0, 0.1, 0.0);
        let to = Vector3::new(0.0, 0.1, -0.4);
        let (pose, geometry) = urdf_geometry(&Shape::Capsule {
            from,
            to,
            radius: 0.03,
        });
        let Geometry::Cylinder { length, .. } = geometry else {
            panic!("a capsule is drawn as a cylinder");
        };
        let end = pose * nalgebra::Point3::new(0.0, 0.0, length / 2.0);
        assert!((end.coords - to).norm() < 1e-12);
    }
}
