//! Passes 1 and 4: bring stances and contact soles onto their support surfaces.

use nalgebra::Vector3;

use crate::environment::Environment;
use crate::poses::{FEET, PoseSequence};

/// Pass 1, `moveStancesUp`: translates each stance along z so that its lowest foot in contact
/// (lowest relative to the surface it stands on) is exactly at that surface's elevation. Whole
/// stances move, so this removes a sequence sunk below (or floating above) the floor without
/// changing any stance's shape. Stances whose contact feet are over no surface are left as is.
pub fn move_stances_up(poses: &mut PoseSequence, environment: &Environment) {
    for i in 0..poses.len() {
        let lowest = FEET
            .iter()
            .filter(|&&foot| poses.in_contact(i, foot))
            .filter_map(|&foot| {
                let p = poses.pose(i, foot).translation.vector;
                environment.support_at(&p).map(|(_, z)| p.z - z)
            })
            .min_by(f64::total_cmp);
        if let Some(height) = lowest
            && height != 0.0
        {
            poses.translate_stance(i, &Vector3::new(0.0, 0.0, -height));
        }
    }
}

/// Pass 4, `contactFeetToSurfaceElevation`: puts every foot in contact exactly on the elevation
/// of its surface (after pass 1 only the lowest one is; in double support the other may hover).
/// Feet over no surface are left as is.
pub fn contact_feet_to_surface_elevation(poses: &mut PoseSequence, environment: &Environment) {
    for i in 0..poses.len() {
        for foot in FEET {
            if !poses.in_contact(i, foot) {
                continue;
            }
            let p = poses.pose(i, foot).translation.vector;
            if let Some((_, z)) = environment.support_at(&p) {
                poses.end_effectors[i][foot as usize].translation.vector.z = z;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::passes::fixtures::{BOTH, LEFT, stance, walk};
    use kinematics::robot::EndEffector::{LeftFoot, LeftHand, RightFoot};

    #[test]
    fn sunken_sequence_rises_to_the_ground() {
        let mut p = walk(&[
            stance([0.0, 0.1, -0.3], [0.0, -0.1, -0.25], BOTH),
            stance([0.0, 0.1, -0.3], [0.3, -0.1, -0.1], LEFT),
        ]);
        let hand_before = p.pose(0, LeftHand).translation.z;
        move_stances_up(&mut p, &Environment::default());
        assert_eq!(p.pose(0, LeftFoot).translation.z, 0.0);
        assert!((p.pose(0, RightFoot).translation.z - 0.05).abs() < 1e-12);
        assert!((p.pose(0, LeftHand).translation.z - hand_before - 0.3).abs() < 1e-12);
        assert!(
            (p.pose(1, RightFoot).translation.z - 0.2).abs() < 1e-12,
            "swing foot moves with its stance"
        );
    }

    #[test]
    fn stance_already_on_the_ground_is_untouched() {
        let mut p = walk(&[stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.04], BOTH)]);
        let before = p.clone();
        move_stances_up(&mut p, &Environment::default());
        assert_eq!(p, before);
    }

    #[test]
    fn hovering_contact_sole_is_put_down_and_swing_foot_is_not() {
        let mut p = walk(&[stance([0.0, 0.1, 0.0], [0.2, -0.1, 0.04], LEFT)]);
        let mut q = walk(&[stance([0.0, 0.1, 0.0], [0.2, -0.1, 0.04], BOTH)]);
        contact_feet_to_surface_elevation(&mut p, &Environment::default());
        contact_feet_to_surface_elevation(&mut q, &Environment::default());
        assert_eq!(p.pose(0, RightFoot).translation.z, 0.04);
        assert_eq!(q.pose(0, RightFoot).translation.z, 0.0);
    }
}
