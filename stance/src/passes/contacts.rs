//! Pass 2: remove jumping contacts.

use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Quaternion, UnitQuaternion, Vector3};

use crate::params::ContactUnification;
use crate::poses::PoseSequence;

/// Pass 2, `unifyContacts`: while an end-effector stays in contact over consecutive stances
/// (a contact run) its pose must not change (eq. 2). Every stance of a run gets the run's first
/// pose ([`ContactUnification::First`], the paper's choice) or the mean of the run's poses
/// ([`ContactUnification::Mean`]). Applies to all four end-effectors.
pub fn unify_contacts(poses: &mut PoseSequence, mode: ContactUnification) {
    for e in EndEffector::ALL {
        let mut start = 0;
        while start < poses.len() {
            if !poses.in_contact(start, e) {
                start += 1;
                continue;
            }
            let mut end = start + 1;
            while end < poses.len() && poses.in_contact(end, e) {
                end += 1;
            }
            let pose = match mode {
                ContactUnification::First => *poses.pose(start, e),
                ContactUnification::Mean => mean_pose(poses, e, start, end),
            };
            for stance in &mut poses.end_effectors[start..end] {
                stance[e as usize] = pose;
            }
            start = end;
        }
    }
}

/// Mean of `e`'s poses over stances `start..end`: mean translation and the normalised sum of the
/// quaternions (each flipped into the first one's hemisphere), exact for equal rotations.
fn mean_pose(poses: &PoseSequence, e: EndEffector, start: usize, end: usize) -> Isometry3<f64> {
    let first = poses.pose(start, e).rotation.coords;
    let mut translation = Vector3::zeros();
    let mut rotation = Quaternion::new(0.0, 0.0, 0.0, 0.0);
    for i in start..end {
        let pose = poses.pose(i, e);
        translation += pose.translation.vector;
        let q = pose.rotation.coords;
        let q = if q.dot(&first) < 0.0 { -q } else { q };
        rotation.coords += q;
    }
    let count = (end - start) as f64;
    Isometry3::from_parts(
        (translation / count).into(),
        UnitQuaternion::from_quaternion(rotation),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::passes::fixtures::{BOTH, LEFT, RIGHT, stance, walk};
    use kinematics::robot::EndEffector::{LeftFoot, RightFoot};

    fn jumping() -> PoseSequence {
        walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.02, 0.1, 0.0], [0.2, -0.1, 0.1], LEFT),
            stance([0.04, 0.12, 0.0], [0.4, -0.1, 0.0], BOTH),
            stance([0.5, 0.1, 0.1], [0.42, -0.1, 0.0], RIGHT),
        ])
    }

    #[test]
    fn first_pose_of_each_run_wins_including_runs_at_start_and_end() {
        let mut p = jumping();
        let original = p.clone();
        unify_contacts(&mut p, ContactUnification::First);
        for i in 0..3 {
            assert_eq!(p.pose(i, LeftFoot), original.pose(0, LeftFoot));
        }
        assert_eq!(
            p.pose(3, LeftFoot),
            original.pose(3, LeftFoot),
            "swing untouched"
        );
        assert_eq!(p.pose(0, RightFoot), original.pose(0, RightFoot));
        assert_eq!(
            p.pose(3, RightFoot),
            original.pose(2, RightFoot),
            "run at the end"
        );
        assert_eq!(p.contacts, original.contacts);
    }

    #[test]
    fn mean_variant_averages_the_run() {
        let mut p = jumping();
        unify_contacts(&mut p, ContactUnification::Mean);
        let x = p.pose(0, LeftFoot).translation.x;
        assert!((x - 0.02).abs() < 1e-12);
        assert_eq!(p.pose(2, LeftFoot), p.pose(0, LeftFoot));
    }

    #[test]
    fn single_stance_is_unchanged() {
        let mut p = walk(&[stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH)]);
        let before = p.clone();
        unify_contacts(&mut p, ContactUnification::First);
        assert_eq!(p, before);
    }
}
