//! The drawn `/scene/*` channels (Foxglove `SceneUpdate`s in the `world` frame): what the 3D
//! panel shows next to the robot.

use foxglove::messages::{
    ArrowPrimitive, Color, CubePrimitive, LinePrimitive, Point3, SceneEntity, SceneUpdate,
    SpherePrimitive, Timestamp, line_primitive,
};
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use shm_types::{SensorSample, Telemetry};

use super::channels::{isometry, pose, vector};
use super::links::WORLD_FRAME;

/// Length of a force arrow carrying the robot's whole weight (m).
const WEIGHT_ARROW_M: f64 = 0.5;
/// Diameter of the balance points (m).
const POINT_DIAMETER: f64 = 0.04;

const fn rgba(r: f64, g: f64, b: f64, a: f64) -> Color {
    Color { r, g, b, a }
}

const SUPPORT: Color = rgba(0.10, 0.75, 0.30, 1.0);
const COM: Color = rgba(0.95, 0.85, 0.10, 1.0);
const COM_TARGET: Color = rgba(0.90, 0.15, 0.15, 1.0);
const ZMP: Color = rgba(0.20, 0.45, 0.95, 1.0);
const DCM: Color = rgba(0.70, 0.25, 0.90, 1.0);
const IN_CONTACT: Color = rgba(0.10, 0.75, 0.30, 0.35);
const MOVING: Color = rgba(0.95, 0.55, 0.10, 0.35);
const FORCE: Color = rgba(0.95, 0.30, 0.10, 1.0);

/// An entity in the world frame that the next update replaces.
fn entity(id: &str, stamp: Timestamp) -> SceneEntity {
    SceneEntity {
        timestamp: Some(stamp),
        frame_id: WORLD_FRAME.to_owned(),
        id: id.to_owned(),
        frame_locked: false,
        ..Default::default()
    }
}

/// A small sphere at (x, y, z).
fn point(x: f64, y: f64, z: f64, color: Color) -> SpherePrimitive {
    SpherePrimitive {
        pose: Some(pose(&Isometry3::translation(x, y, z))),
        size: Some(vector(POINT_DIAMETER, POINT_DIAMETER, POINT_DIAMETER)),
        color: Some(color),
    }
}

/// The support polygon on the ground, the CoM's ground projection, the CoM target and, when the
/// gait provides them, the reference and measured ZMP and DCM.
pub fn balance(telemetry: &Telemetry, stamp: Timestamp) -> SceneUpdate {
    let mut e = entity("balance", stamp);
    let vertices: Vec<Point3> = telemetry
        .support()
        .iter()
        .map(|v| Point3 {
            x: v[0],
            y: v[1],
            z: 0.0,
        })
        .collect();
    if !vertices.is_empty() {
        e.lines.push(LinePrimitive {
            r#type: line_primitive::Type::LineLoop as i32,
            pose: Some(pose(&Isometry3::identity())),
            thickness: 0.01,
            points: vertices,
            color: Some(SUPPORT),
            ..Default::default()
        });
    }
    let com = telemetry.com;
    e.spheres.push(point(com[0], com[1], 0.0, COM));
    if telemetry.com_target_set.is_set() {
        let [x, y] = telemetry.com_target;
        e.spheres.push(point(x, y, 0.0, COM_TARGET));
    }
    if telemetry.dynamics_valid.is_set() {
        for (p, color) in [
            (telemetry.zmp_reference, ZMP),
            (telemetry.zmp_measured, ZMP),
            (telemetry.dcm_reference, DCM),
            (telemetry.dcm_measured, DCM),
        ] {
            e.spheres.push(point(p[0], p[1], 0.0, color));
        }
    }
    SceneUpdate {
        entities: vec![e],
        ..Default::default()
    }
}

/// A translucent box at each end-effector target: sole-sized for the feet, green while in
/// contact, orange while moving.
pub fn targets(telemetry: &Telemetry, robot: &Robot, stamp: Timestamp) -> SceneUpdate {
    let mut e = entity("targets", stamp);
    for effector in EndEffector::ALL {
        let i = effector as usize;
        if !telemetry.target_set[i].is_set() {
            continue;
        }
        let size = if effector.is_foot() {
            vector(robot.sole.length, robot.sole.width, 0.01)
        } else {
            vector(0.06, 0.06, 0.06)
        };
        let color = if telemetry.contacts[i].is_set() {
            IN_CONTACT
        } else {
            MOVING
        };
        e.cubes.push(CubePrimitive {
            pose: Some(pose(&isometry(&telemetry.targets[i]))),
            size: Some(size),
            color: Some(color),
        });
    }
    SceneUpdate {
        entities: vec![e],
        ..Default::default()
    }
}

/// An arrow per foot along its measured force (world-aligned), from its force-torque frame's
/// world position in `origins` (left, right); [`WEIGHT_ARROW_M`] long for the robot's weight
/// `weight_n`. The hands have no force-torque frame in the model and are not drawn.
pub fn wrenches(
    sample: &SensorSample,
    origins: [Vector3<f64>; 2],
    weight_n: f64,
    stamp: Timestamp,
) -> SceneUpdate {
    let mut e = entity("wrenches", stamp);
    for (w, origin) in sample.wrenches.iter().zip(origins) {
        let force = Vector3::new(w[0], w[1], w[2]);
        let length = WEIGHT_ARROW_M * force.norm() / weight_n;
        if length < 1e-3 {
            continue;
        }
        // An arrow points along its pose's +x axis.
        let rotation = UnitQuaternion::rotation_between(&Vector3::x(), &force)
            .unwrap_or_else(|| UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::PI));
        e.arrows.push(ArrowPrimitive {
            pose: Some(pose(&Isometry3::from_parts(origin.into(), rotation))),
            shaft_length: length * 0.8,
            shaft_diameter: 0.015,
            head_length: length * 0.2,
            head_diameter: 0.04,
            color: Some(FORCE),
        });
    }
    SceneUpdate {
        entities: vec![e],
        ..Default::default()
    }
}
