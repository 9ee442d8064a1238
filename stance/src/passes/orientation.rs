//! Passes 3 and 5: orientation of contact soles and of the swing foot.

use nalgebra::{Rotation3, UnitQuaternion, Vector3};

use crate::environment::Environment;
use crate::geometry::{PathFrame, roll_pitch_yaw};
use crate::poses::{FEET, PoseSequence};

/// Pass 3, `contactFeetParallelToGroundSurface`: expresses each foot in contact in the frame of
/// its surface and sets its roll and pitch to zero there, keeping its yaw. Feet over no surface
/// are left as is.
pub fn contact_feet_parallel_to_surface(poses: &mut PoseSequence, environment: &Environment) {
    for i in 0..poses.len() {
        for foot in FEET {
            if !poses.in_contact(i, foot) {
                continue;
            }
            let pose = poses.pose(i, foot);
            let Some((surface, _)) = environment.support_at(&pose.translation.vector) else {
                continue;
            };
            if let Some(flat) = flattened(&surface.pose.rotation, &pose.rotation) {
                poses.end_effectors[i][foot as usize].rotation = flat;
            }
        }
    }
}

/// `rotation` with its roll and pitch relative to `surface` removed and its yaw kept: the frame
/// whose z is the surface normal and whose x is the foot's x projected onto the surface plane
/// (trigonometry-free). `None` if the foot's x is along the normal (no yaw to keep).
pub(super) fn flattened(
    surface: &UnitQuaternion<f64>,
    rotation: &UnitQuaternion<f64>,
) -> Option<UnitQuaternion<f64>> {
    let normal = surface * Vector3::z();
    let x = rotation * Vector3::x();
    let x = (x - normal * x.dot(&normal)).try_normalize(1e-12)?;
    let basis = [x, normal.cross(&x), normal];
    Some(UnitQuaternion::from_rotation_matrix(
        &Rotation3::from_basis_unchecked(&basis),
    ))
}

/// Pass 5, `limitSwingFootRotation(α_x, α_y, α_z)`: clamps the rotation of every foot not in
/// contact to `[−α, +α]` about each axis, measured against a reference frame whose z is the
/// normal of the surface below the foot (world z if none) and whose x is the walking direction:
/// roll and pitch relative to the surface, yaw relative to the walking direction. Feet within
/// the limits are not touched.
pub fn limit_swing_foot_rotation(
    poses: &mut PoseSequence,
    environment: &Environment,
    path: &PathFrame,
    alpha: [f64; 3],
) {
    for i in 0..poses.len() {
        for foot in FEET {
            if poses.in_contact(i, foot) {
                continue;
            }
            let pose = poses.pose(i, foot);
            let surface = environment
                .support_at(&pose.translation.vector)
                .map_or_else(UnitQuaternion::identity, |(s, _)| s.pose.rotation);
            let along = surface.inverse() * path.direction();
            let reference = surface
                * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), along.y.atan2(along.x));
            let angles = roll_pitch_yaw(&(reference.inverse() * pose.rotation));
            let clamped: [f64; 3] = std::array::from_fn(|k| angles[k].clamp(-alpha[k], alpha[k]));
            if clamped != angles {
                poses.end_effectors[i][foot as usize].rotation = reference
                    * UnitQuaternion::from_euler_angles(clamped[0], clamped[1], clamped[2]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::environment::SupportSurface;
    use crate::passes::fixtures::{BOTH, LEFT, rotated, stance, walk};
    use kinematics::ground::yaw;
    use kinematics::robot::EndEffector::{LeftFoot, RightFoot};
    use nalgebra::Isometry3;

    #[test]
    fn contact_sole_loses_roll_and_pitch_keeps_yaw() {
        let mut p = walk(&[stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH)]);
        rotated(&mut p, 0, LeftFoot, [0.1, -0.2, 0.3]);
        contact_feet_parallel_to_surface(&mut p, &Environment::default());
        let [r, pitch, y] = roll_pitch_yaw(&p.pose(0, LeftFoot).rotation);
        assert!(r.abs() < 1e-12 && pitch.abs() < 1e-12, "{r} {pitch}");
        let original = UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3);
        assert!((y - yaw(&original)).abs() < 1e-12);
    }

    #[test]
    fn contact_sole_on_a_tilted_surface_becomes_parallel_to_it() {
        let tilt = UnitQuaternion::from_euler_angles(0.0, -0.1, 0.0);
        let env = Environment {
            surfaces: vec![SupportSurface {
                name: "ramp".into(),
                pose: Isometry3::from_parts(Vector3::zeros().into(), tilt),
                polygon: None,
            }],
            hand_affordances: Vec::new(),
        };
        let mut p = walk(&[stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH)]);
        contact_feet_parallel_to_surface(&mut p, &env);
        let normal = p.pose(0, RightFoot).rotation * Vector3::z();
        assert!((normal - tilt * Vector3::z()).norm() < 1e-12);
    }

    #[test]
    fn swing_foot_rotation_is_clamped_relative_to_the_walking_direction() {
        let mut p = walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.0, 0.1, 0.0], [0.3, -0.1, 0.1], LEFT),
        ]);
        rotated(&mut p, 1, RightFoot, [0.5, 0.05, 1.0]);
        let path = PathFrame::new(&Vector3::zeros(), &Vector3::new(0.0, 1.0, 0.0)).unwrap();
        limit_swing_foot_rotation(&mut p, &Environment::default(), &path, [0.1, 0.2, 0.3]);
        let relative = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -path.heading())
            * p.pose(1, RightFoot).rotation;
        let [r, pitch, y] = roll_pitch_yaw(&relative);
        assert!((r - 0.1).abs() < 1e-12 && (pitch - 0.05).abs() < 1e-12);
        assert!(
            (y + 0.3).abs() < 1e-12,
            "yaw 1.0 − π/2 is clamped to −0.3: {y}"
        );
        assert_eq!(
            p.pose(0, RightFoot).rotation,
            UnitQuaternion::identity(),
            "contacts untouched"
        );
    }

    #[test]
    fn swing_foot_inside_the_limits_is_untouched() {
        let mut p = walk(&[stance([0.0, 0.1, 0.0], [0.3, -0.1, 0.1], LEFT)]);
        rotated(&mut p, 0, RightFoot, [0.05, -0.05, 0.05]);
        let before = p.clone();
        let path = PathFrame::new(&Vector3::zeros(), &Vector3::x()).unwrap();
        limit_swing_foot_rotation(&mut p, &Environment::default(), &path, [0.1, 0.1, 0.1]);
        assert_eq!(p, before);
    }
}
