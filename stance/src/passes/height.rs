//! Pass 9: swing-foot height.

use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Point3, Vector3};

use crate::derived::{swing_ends, swing_reference};
use crate::environment::Environment;
use crate::poses::{FEET, PoseSequence};

/// Pass 9, `limitSwingFootHeight(h_min, h_max)`: clamps the height of every foot not in contact
/// to `[h_min, h_max]` (`h_min` keeps it clear of the ground, `h_max` removes unnaturally high
/// swings). The height is measured from the higher of the surfaces under the swing's lift-off
/// and landing soles ([`swing_reference`]; on flat ground, the ground under the foot), and the
/// foot also stays `h_min` above every surface the swing passes over (`swing_clearance`: a
/// stair nosing or ramp edge between the two footholds, higher than both), even where that is
/// above `h_max`, and higher by the drop of a pitched sole's heel or toe (`toe_drop`). Feet
/// with no surface to measure from are left as is.
pub fn limit_swing_foot_height(
    poses: &mut PoseSequence,
    environment: &Environment,
    sole_length: f64,
    h_min: f64,
    h_max: f64,
) {
    for i in 0..poses.len() {
        for foot in FEET {
            if poses.in_contact(i, foot) {
                continue;
            }
            let Some(reference) = swing_reference(poses, environment, i, foot) else {
                continue;
            };
            let clearance = swing_clearance(poses, environment, sole_length, i, foot)
                .map_or(reference, |c| c.max(reference));
            let lowest = (clearance - reference) + h_min + toe_drop(poses, i, foot, sole_length);
            let p = &mut poses.end_effectors[i][foot as usize].translation.vector;
            let height = p.z - reference;
            let clamped = height.clamp(lowest, h_max.max(lowest));
            if clamped != height {
                p.z = reference + clamped;
            }
        }
    }
}

/// How far below its centre a sole's heel or toe hangs at the swing's lift-off or landing,
/// whichever more (m): a sole pitched with a ramp (and turning level on the flat, or back) is
/// that much lower at one end, and its swing height counts from there. On a 10° ramp,
/// 0.017 m for a 0.20 m sole (JVRC-1's dynamic swing of 0.02–0.03 m brushed the ramp's top
/// with its heel and tipped).
fn toe_drop(poses: &PoseSequence, i: usize, foot: EndEffector, sole_length: f64) -> f64 {
    swing_ends(poses, i, foot)
        .into_iter()
        .flatten()
        .map(|j| (poses.pose(j, foot).rotation * Vector3::x()).z.abs() * sole_length / 2.0)
        .fold(0.0, f64::max)
}

/// The highest surface a swing of `foot` through stance `i` passes over: under its lift-off
/// sole (heel to toe), the straight line from the lift-off to the landing sole centre, and
/// the landing sole; only the ends it has. `None` without either end or over no surface.
fn swing_clearance(
    poses: &PoseSequence,
    environment: &Environment,
    sole_length: f64,
    i: usize,
    foot: EndEffector,
) -> Option<f64> {
    let [lift, land] = swing_ends(poses, i, foot).map(|end| end.map(|j| poses.pose(j, foot)));
    let sole = |pose: &Isometry3<f64>| {
        [-0.5, 0.5].map(|s| (pose * Point3::new(s * sole_length, 0.0, 0.0)).coords)
    };
    let centres = lift
        .zip(land)
        .map(|(a, b)| [a.translation.vector, b.translation.vector]);
    lift.map(sole)
        .into_iter()
        .chain(land.map(sole))
        .chain(centres)
        .filter_map(|[from, to]| environment.highest_under(&from, &to))
        .max_by(f64::total_cmp)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::environment::SupportSurface;
    use crate::passes::fixtures::{BOTH, LEFT, RIGHT, SOLE, block, rotated, stance, walk};
    use kinematics::robot::EndEffector::{LeftFoot, RightFoot};

    #[test]
    fn swing_heights_are_clamped_and_contacts_untouched() {
        let mut p = walk(&[
            stance([0.0, 0.1, 0.0], [0.2, -0.1, 0.35], LEFT),
            stance([0.1, 0.1, 0.01], [0.2, -0.1, 0.0], RIGHT),
            stance([0.1, 0.1, 0.05], [0.2, -0.1, 0.0], BOTH),
        ]);
        limit_swing_foot_height(&mut p, &Environment::default(), SOLE.length, 0.03, 0.1);
        assert!((p.pose(0, RightFoot).translation.z - 0.1).abs() < 1e-12);
        assert!((p.pose(1, LeftFoot).translation.z - 0.03).abs() < 1e-12);
        assert_eq!(p.pose(2, LeftFoot).translation.z, 0.05);
    }

    #[test]
    fn swing_foot_inside_the_limits_is_untouched() {
        let mut p = walk(&[stance([0.0, 0.1, 0.0], [0.2, -0.1, 0.07], LEFT)]);
        let before = p.clone();
        limit_swing_foot_height(&mut p, &Environment::default(), SOLE.length, 0.03, 0.1);
        assert_eq!(p, before);
    }

    #[test]
    fn a_pitched_sole_swings_higher_by_the_drop_of_its_heel() {
        // The right foot lifts off pitched 10° (as on a ramp) and lands level: its swing is
        // h_min above the ground plus half the sole length times sin 10°.
        let mut p = walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.0, 0.1, 0.0], [0.2, -0.1, 0.0], LEFT),
            stance([0.0, 0.1, 0.0], [0.4, -0.1, 0.0], BOTH),
        ]);
        rotated(&mut p, 0, RightFoot, [0.0, -10f64.to_radians(), 0.0]);
        limit_swing_foot_height(&mut p, &Environment::default(), SOLE.length, 0.03, 0.03);
        let drop = SOLE.length / 2.0 * 10f64.to_radians().sin();
        let z = p.pose(1, RightFoot).translation.z;
        assert!((z - (0.03 + drop)).abs() < 1e-12, "{z}");
    }

    /// Ground, and a block `height` high whose top spans x from `from` to `to`.
    fn with_block(from: f64, to: f64, height: f64) -> Environment {
        Environment {
            surfaces: vec![SupportSurface::ground(), block("block", from, to, height)],
            hand_affordances: Vec::new(),
        }
    }

    #[test]
    fn a_step_up_is_measured_from_the_higher_surface() {
        // The right foot steps from the ground onto a 0.1 m block starting at x = 0.5; mid-swing
        // it is over the ground, 0.08 m high: 0.02 below the block's top.
        let env = with_block(0.5, 1.5, 0.1);
        let mut p = walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.0, 0.1, 0.0], [0.3, -0.1, 0.08], LEFT),
            stance([0.0, 0.1, 0.0], [0.7, -0.1, 0.1], BOTH),
        ]);
        limit_swing_foot_height(&mut p, &env, SOLE.length, 0.03, 0.06);
        assert!((p.pose(1, RightFoot).translation.z - 0.13).abs() < 1e-12);
    }

    #[test]
    fn a_swing_clears_a_surface_higher_than_both_footholds() {
        // A 0.1 m bump between x = 0.3 and 0.4 under a step from x = 0 to 0.7 on the ground.
        let env = with_block(0.3, 0.4, 0.1);
        let mut p = walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.0, 0.1, 0.0], [0.35, -0.1, 0.05], LEFT),
            stance([0.0, 0.1, 0.0], [0.7, -0.1, 0.0], BOTH),
        ]);
        assert_eq!(
            swing_clearance(&p, &env, SOLE.length, 1, RightFoot),
            Some(0.1)
        );
        limit_swing_foot_height(&mut p, &env, SOLE.length, 0.03, 0.06);
        assert!(
            (p.pose(1, RightFoot).translation.z - 0.13).abs() < 1e-12,
            "h_min above the bump, over h_max above the ground"
        );
        // The landing sole's toe (x = 0.8) over the bump's start counts too.
        let env = with_block(0.79, 1.0, 0.1);
        assert_eq!(
            swing_clearance(&p, &env, SOLE.length, 1, RightFoot),
            Some(0.1)
        );
    }
}
