//! Pass 9: swing-foot height.

use crate::environment::Environment;
use crate::poses::{FEET, PoseSequence};

/// Pass 9, `limitSwingFootHeight(h_min, h_max)`: clamps the height of every foot not in contact
/// above the surface below it to `[h_min, h_max]` (`h_min` keeps it clear of the ground, `h_max`
/// removes unnaturally high swings). Feet over no surface are left as is.
pub fn limit_swing_foot_height(
    poses: &mut PoseSequence,
    environment: &Environment,
    h_min: f64,
    h_max: f64,
) {
    for i in 0..poses.len() {
        for foot in FEET {
            if poses.in_contact(i, foot) {
                continue;
            }
            let p = &mut poses.end_effectors[i][foot as usize].translation.vector;
            if let Some((_, z)) = environment.support_at(p) {
                let height = p.z - z;
                let clamped = height.clamp(h_min, h_max);
                if clamped != height {
                    p.z = z + clamped;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::passes::fixtures::{BOTH, LEFT, RIGHT, stance, walk};
    use kinematics::robot::EndEffector::{LeftFoot, RightFoot};

    #[test]
    fn swing_heights_are_clamped_and_contacts_untouched() {
        let mut p = walk(&[
            stance([0.0, 0.1, 0.0], [0.2, -0.1, 0.35], LEFT),
            stance([0.1, 0.1, 0.01], [0.2, -0.1, 0.0], RIGHT),
            stance([0.1, 0.1, 0.05], [0.2, -0.1, 0.0], BOTH),
        ]);
        limit_swing_foot_height(&mut p, &Environment::default(), 0.03, 0.1);
        assert!((p.pose(0, RightFoot).translation.z - 0.1).abs() < 1e-12);
        assert!((p.pose(1, LeftFoot).translation.z - 0.03).abs() < 1e-12);
        assert_eq!(p.pose(2, LeftFoot).translation.z, 0.05);
    }

    #[test]
    fn swing_foot_inside_the_limits_is_untouched() {
        let mut p = walk(&[stance([0.0, 0.1, 0.0], [0.2, -0.1, 0.07], LEFT)]);
        let before = p.clone();
        limit_swing_foot_height(&mut p, &Environment::default(), 0.03, 0.1);
        assert_eq!(p, before);
    }
}
