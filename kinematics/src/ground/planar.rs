//! Planar (x, y, yaw) frames on the ground: the heading of a pose, the mean frame of some poses,
//! and the alignment that puts a stance sequence onto the feet standing now.
//!
//! The controller aligns every sequence with [`sequence_alignment`] when a walk begins, and the
//! evaluation aligns its targets the same way, so both must use this one definition.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// Yaw of a rotation: the heading of its x axis projected on the xy plane.
pub fn yaw(rotation: &UnitQuaternion<f64>) -> f64 {
    let x = rotation * Vector3::x();
    x.y.atan2(x.x)
}

/// The planar frame of some poses: their mean x and y on the ground (z = 0) and their mean yaw;
/// the identity when there are none.
pub fn planar_frame<'a>(poses: impl IntoIterator<Item = &'a Isometry3<f64>>) -> Isometry3<f64> {
    let (mut x, mut y, mut sin, mut cos, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for pose in poses {
        let heading = yaw(&pose.rotation);
        x += pose.translation.x;
        y += pose.translation.y;
        sin += heading.sin();
        cos += heading.cos();
        n += 1.0;
    }
    if n == 0.0 {
        return Isometry3::identity();
    }
    Isometry3::from_parts(
        Translation3::new(x / n, y / n, 0.0),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), sin.atan2(cos)),
    )
}

/// Where a sequence lands when a walk begins: the planar (x, y, yaw) transform that takes the
/// first stance's contact feet onto the same feet standing on the ground now. Feet `[left,
/// right]`; only feet in contact in both count (all standing feet if none is shared). The
/// controller aligns a sequence with it, and the evaluation aligns its targets the same way.
pub fn sequence_alignment(
    first: &[Isometry3<f64>; 2],
    first_contacts: [bool; 2],
    standing: &[Isometry3<f64>; 2],
    standing_contacts: [bool; 2],
) -> Isometry3<f64> {
    let mut shared = [0, 1].map(|f| first_contacts[f] && standing_contacts[f]);
    if !shared.iter().any(|s| *s) {
        shared = standing_contacts;
    }
    let frame = |poses: &[Isometry3<f64>; 2]| {
        planar_frame(poses.iter().zip(shared).filter_map(|(p, s)| s.then_some(p)))
    };
    frame(standing) * frame(first).inverse()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alignment_uses_the_feet_in_contact_in_both() {
        let pose = |x: f64, y: f64, yaw: f64| {
            Isometry3::from_parts(
                Translation3::new(x, y, 0.0),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw),
            )
        };
        let standing = [pose(0.0, 0.1, 0.0), pose(0.0, -0.1, 0.0)];
        // The first stance stands on its right foot only, turned and elsewhere; its left foot
        // is in the air and must not count.
        let first = [pose(5.0, 5.0, 1.0), pose(1.0, -0.1, 0.3)];
        let to_world = sequence_alignment(&first, [false, true], &standing, [true, true]);
        let right = to_world * first[1];
        assert!((right.translation.vector - standing[1].translation.vector).norm() < 1e-12);
        assert!(right.rotation.angle_to(&standing[1].rotation) < 1e-12);
        // Both feet shared: the midpoints and mean headings coincide.
        let both = [pose(2.0, 0.1, 0.0), pose(2.0, -0.1, 0.0)];
        let to_world = sequence_alignment(&both, [true, true], &standing, [true, true]);
        assert!((to_world.translation.vector - Vector3::new(-2.0, 0.0, 0.0)).norm() < 1e-12);
    }
}
