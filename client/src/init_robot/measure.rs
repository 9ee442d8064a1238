//! [`RobotDimensions`] measured from a loaded robot in its standing posture (soles flat on
//! z = 0, as `Robot::load` places it), with the leg joints' roles from [`super::legs`]:
//!
//! - mass m: the model's total mass; CoM height z_c: the CoM's height above the soles;
//! - leg length l: the hip-pitch joint's height above the soles (the mean of the two legs);
//! - pelvis height: the base link's height (what the stance generator scales the human walk by);
//! - hip width: the lateral distance between the two hips (the origins of their joints least
//!   aligned with the lateral axis); stance width: between the two sole frames;
//! - sole: the `[robot] sole` rectangle;
//! - ankle roll range: over both legs, the smaller distance from the standing angle to a limit;
//! - ankle pitch room: over both legs, the distance from the standing angle to the limit on the
//!   side it already leans to (the side a foot left behind the hip turns it further);
//! - the legs' smallest effort and velocity limits, the torso joints' smallest velocity limit.

use kinematics::{EndEffector, Kinematics, Robot, Vector3};

use super::dimensions::RobotDimensions;
use super::legs::Legs;
use super::model::{Posed, UrdfModel};

/// Measures `robot` (whose model is `urdf`, with legs `legs`).
pub fn measure(robot: &Robot, urdf: &UrdfModel, legs: &Legs) -> RobotDimensions {
    let model = &robot.model;
    let q = &robot.standing;
    let mut kinematics = Kinematics::new(model);
    kinematics.update(model, q);
    let posed = Posed::new(urdf, q);
    let soles = [EndEffector::LeftFoot, EndEffector::RightFoot]
        .map(|foot| kinematics.frame_pose(model, robot.frame(foot)));
    let forward = {
        let x: Vector3<f64> = soles.iter().map(|s| s.rotation * Vector3::x()).sum();
        Vector3::new(x.x, x.y, 0.0).normalize()
    };
    let left = Vector3::z().cross(&forward);
    let hips = legs.both().map(|leg| posed.joint_origin(leg.hip_pitch));
    let hip_centres = legs.both().map(|leg| posed.joint_origin(leg.hip_centre));
    let limits = model.joint_limits();
    let leg_joints: Vec<usize> = legs.both().iter().flat_map(|l| l.joints.clone()).collect();
    let min_over = |values: Vec<f64>| values.into_iter().reduce(f64::min);
    let roll_range = min_over(
        legs.both()
            .iter()
            .filter_map(|leg| leg.ankle_roll)
            .map(|j| (limits[j].upper - q.joints[j]).min(q.joints[j] - limits[j].lower))
            .collect(),
    );
    let pitch_room = min_over(
        legs.both()
            .iter()
            .filter_map(|leg| leg.ankle_pitch)
            .map(|j| {
                let angle = q.joints[j];
                let (up, down) = (limits[j].upper - angle, angle - limits[j].lower);
                if angle > 0.0 {
                    up
                } else if angle < 0.0 {
                    down
                } else {
                    up.min(down)
                }
            })
            .collect(),
    );
    RobotDimensions {
        name: robot.name.clone(),
        mass_kg: model.total_mass(),
        com_height_m: kinematics.com().z,
        leg_length_m: (hips[0].z + hips[1].z) / 2.0,
        pelvis_height_m: kinematics.link_pose(robot.base_link).translation.z,
        hip_width_m: (hip_centres[0] - hip_centres[1]).dot(&left).abs(),
        stance_width_m: (soles[0].translation.vector - soles[1].translation.vector)
            .dot(&left)
            .abs(),
        sole_length_m: robot.sole.length,
        sole_width_m: robot.sole.width,
        ankle_roll_range_rad: roll_range.filter(|r| r.is_finite()),
        ankle_pitch_room_rad: pitch_room.filter(|r| r.is_finite()),
        leg_effort_min_nm: min_over(leg_joints.iter().map(|&j| limits[j].effort).collect())
            .filter(|e| e.is_finite()),
        leg_velocity_min_rad_s: min_over(leg_joints.iter().map(|&j| limits[j].velocity).collect())
            .filter(|v| v.is_finite()),
        torso_velocity_min_rad_s: min_over(
            robot
                .joint_groups
                .torso
                .iter()
                .map(|&j| limits[j].velocity)
                .collect(),
        )
        .filter(|v| v.is_finite()),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use std::path::Path;

    use super::*;
    use crate::init_robot::legs::find_legs;
    use crate::init_robot::reference;

    /// The dimensions of a shipped, hand-tuned config.
    pub(crate) fn hand_tuned(name: &str) -> RobotDimensions {
        let config = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../configs")
            .join(format!("{name}.toml"));
        let robot = Robot::load(&config, None).expect("config loads");
        let urdf = UrdfModel::load(&robot.urdf).expect("URDF loads");
        let legs = find_legs(&urdf, [None, None]).expect("legs");
        measure(&robot, &urdf, &legs)
    }

    #[test]
    fn the_reference_is_jvrc1_as_configured() {
        let measured = hand_tuned("jvrc1");
        let reference = reference::jvrc1();
        assert_eq!(measured.name, reference.name);
        for ((key, got), (_, want)) in measured.numbers().into_iter().zip(reference.numbers()) {
            let (got, want) = (got.expect(key), want.expect(key));
            assert!(
                (got - want).abs() < 1e-4,
                "{key}: measured {got}, reference {want}"
            );
        }
    }

    #[test]
    fn armar4_as_configured() {
        let d = hand_tuned("armar4");
        assert!((d.mass_kg - 72.04).abs() < 1e-3, "{}", d.mass_kg);
        // The configured soles stand 0.176 m apart under hips 0.248 m apart (docs/controller.md).
        assert!((d.hip_width_m - 0.248).abs() < 1e-3, "{}", d.hip_width_m);
        assert!(
            (d.stance_width_m - 0.176).abs() < 1e-3,
            "{}",
            d.stance_width_m
        );
        // ±0.06 rad ankle roll, standing at ~0; ankle pitch 0.41 of 0.49 rad standing.
        assert!((d.ankle_roll_range_rad.unwrap() - 0.06).abs() < 1e-4);
        assert!((d.ankle_pitch_room_rad.unwrap() - (0.4906 - 0.4064)).abs() < 1e-3);
        assert!(d.com_height_m > d.leg_length_m && d.leg_length_m > 0.8);
        // Slow joints: 1.71 rad/s in the legs, 0.4 rad/s at the torso pitch.
        assert!((d.leg_velocity_min_rad_s.unwrap() - 1.7104).abs() < 1e-4);
        assert_eq!(d.torso_velocity_min_rad_s, Some(0.4));
    }
}
