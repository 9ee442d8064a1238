//! Toe-off: the trailing foot's heel rises about its toe at the end of the double support before
//! it swings up a step, so the trailing leg, stretched between a foot a stair below and a CoM
//! already over the upper foot, reaches farther and the CoM starts the single support higher.
//!
//! The foot stays in the contact set, held by its anchor; the anchor turns about the sole's front
//! edge by a pitch that rises with a minimum-jerk profile to `toe_off_rad` (less where the legs
//! cannot turn the foot that fast: [`reachable_pitch`]) over the last `toe_off_s` of the double
//! support, and the turn's velocity is fed forward to the contact
//! constraint. The pitch is applied relative to the foot's flat anchor, which is recovered each
//! tick from the anchor and the pitch applied last, so anchors moved by the estimate's heading
//! stay consistent.

use kinematics::robot::SoleRectangle;
use nalgebra::{Isometry3, Point3, UnitQuaternion, Vector3};

use crate::controller::trajectory::Profile;

/// The sole frame turned by `pitch` (rad, heel up) about its front edge, in the sole's frame.
fn about_toe(sole: &SoleRectangle, pitch: f64) -> Isometry3<f64> {
    let turn = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), pitch);
    Isometry3::rotation_wrt_point(turn, Point3::new(sole.length / 2.0, 0.0, 0.0))
}

/// The fastest a leg joint may turn for the heel to rise, relative to the slowest leg joint's
/// speed bound in the QP (`velocity_limit_scale` × its URDF speed): the rest is left for the leg's
/// other motion. At JVRC-1's 0.5 rad in 0.3 s the heel turns at 3.1 rad/s at most, 0.7 of its
/// hip's 4.45 rad/s; ARMAR-4's legs, bounded to 0.86 rad/s, made the QP infeasible
/// (`qp_infeasible` at the first stair) at that pitch.
pub(crate) const TOE_OFF_SPEED_SHARE: f64 = 0.75;

/// The peak speed of a minimum-jerk motion over its mean speed (30/16).
const MINIMUM_JERK_PEAK: f64 = 1.875;

/// The pitch (rad) the heel rises to over `duration` (s): `max_pitch`, or less if reaching it
/// would turn the foot faster than `max_speed` (rad/s).
pub(crate) fn reachable_pitch(max_pitch: f64, max_speed: f64, duration: f64) -> f64 {
    max_pitch.min(max_speed * duration / MINIMUM_JERK_PEAK)
}

/// A heel rising about the toe of one foot in contact, or coming back down.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ToeOff {
    /// The pitch applied to the anchor last tick (rad).
    pitch: f64,
    /// The pitch the motion under way starts from and goes to (rad).
    from: f64,
    goal: f64,
    /// When the motion under way started (s, plan clock).
    start_s: f64,
    /// How long a motion up or down lasts (s).
    duration_s: f64,
}

impl ToeOff {
    /// A heel that starts rising at `start_s` (s, plan clock) to `goal` (rad) over
    /// `duration_s` (s, > 0).
    pub fn rise(start_s: f64, goal: f64, duration_s: f64) -> Self {
        Self {
            pitch: 0.0,
            from: 0.0,
            goal,
            start_s,
            duration_s,
        }
    }

    /// From `now` (s) the heel comes back down, from where it is, over as long as it rose (the
    /// lift-off it rose for will not come: a controlled stop).
    pub fn lower(&mut self, now: f64) {
        if self.goal != 0.0 {
            (self.from, self.goal, self.start_s) = (self.pitch, 0.0, now);
        }
    }

    /// The sole is flat again after [`ToeOff::lower`].
    pub fn lowered(&self) -> bool {
        self.goal == 0.0 && self.pitch == 0.0
    }

    /// Turns `anchor` to the pitch of time `now` (s) on the minimum-jerk motion under way;
    /// returns the contact's feed-forward velocity (world, linear xyz of the
    /// sole frame's origin and angular xyz).
    pub fn update(
        &mut self,
        anchor: &mut Isometry3<f64>,
        sole: &SoleRectangle,
        now: f64,
    ) -> [f64; 6] {
        let flat = *anchor * about_toe(sole, self.pitch).inverse();
        let (s, rate) = Profile::MinimumJerk.sample(now - self.start_s, self.duration_s);
        let turn = self.goal - self.from;
        self.pitch = self.from + turn * s;
        *anchor = flat * about_toe(sole, self.pitch);
        let omega = flat.rotation * Vector3::new(0.0, turn * rate, 0.0);
        let toe = flat * Point3::new(sole.length / 2.0, 0.0, 0.0);
        let v = omega.cross(&(anchor.translation.vector - toe.coords));
        [v.x, v.y, v.z, omega.x, omega.y, omega.z]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SOLE: SoleRectangle = SoleRectangle {
        length: 0.2,
        width: 0.08,
    };

    #[test]
    fn the_toe_stays_and_the_heel_rises() {
        let turned = about_toe(&SOLE, 0.3);
        let toe = turned * Point3::new(0.1, 0.03, 0.0);
        assert!((toe - Point3::new(0.1, 0.03, 0.0)).norm() < 1e-12);
        let heel = turned * Point3::new(-0.1, 0.0, 0.0);
        assert!((heel.z - 0.2 * 0.3_f64.sin()).abs() < 1e-12, "{heel}");
    }

    #[test]
    fn the_feed_forward_is_the_anchor_s_velocity() {
        let base = Isometry3::new(Vector3::new(1.0, 0.2, 0.15), Vector3::new(0.0, 0.0, 0.7));
        let mut toe_off = ToeOff::rise(1.0, 0.25, 0.5);
        let mut anchor = base;
        let dt = 1e-4;
        toe_off.update(&mut anchor, &SOLE, 1.2);
        let before = anchor;
        let velocity = toe_off.update(&mut anchor, &SOLE, 1.2 + dt);
        let linear = (anchor.translation.vector - before.translation.vector) / dt;
        let angular = (anchor.rotation * before.rotation.inverse()).scaled_axis() / dt;
        for k in 0..3 {
            assert!(
                (linear[k] - velocity[k]).abs() < 1e-3,
                "{linear} {velocity:?}"
            );
            assert!(
                (angular[k] - velocity[3 + k]).abs() < 1e-3,
                "{angular} {velocity:?}"
            );
        }
        // At the end the pitch is the whole turn and the toe has not moved.
        toe_off.update(&mut anchor, &SOLE, 1.5);
        assert_eq!(toe_off.pitch, 0.25);
        let toe = |pose: &Isometry3<f64>| pose * Point3::new(0.1, 0.0, 0.0);
        assert!((toe(&anchor) - toe(&base)).norm() < 1e-12);
    }

    #[test]
    fn a_pitch_too_fast_for_the_legs_is_lowered_to_what_they_turn() {
        assert_eq!(reachable_pitch(0.5, 4.45, 0.3), 0.5);
        let pitch = reachable_pitch(0.5, 0.64, 0.3);
        assert!(pitch < 0.11, "{pitch}");
        let mut toe_off = ToeOff::rise(0.0, pitch, 0.3);
        let mut anchor = Isometry3::identity();
        let dt = 1e-3;
        let fastest = (1..300)
            .map(|k| toe_off.update(&mut anchor, &SOLE, f64::from(k) * dt)[4])
            .fold(0.0, f64::max);
        assert!((fastest - 0.64).abs() < 1e-3, "{fastest}");
    }

    #[test]
    fn a_heel_lowered_halfway_up_comes_back_to_the_flat_anchor() {
        let base = Isometry3::new(Vector3::new(0.3, -0.1, 0.1), Vector3::new(0.0, 0.0, -0.4));
        let mut toe_off = ToeOff::rise(0.0, 0.5, 0.3);
        let mut anchor = base;
        toe_off.update(&mut anchor, &SOLE, 0.15);
        assert!(toe_off.pitch > 0.1 && toe_off.pitch < 0.4, "{toe_off:?}");
        toe_off.lower(0.15);
        assert!(!toe_off.lowered());
        let mut highest: f64 = 0.0;
        for k in 1..=31 {
            toe_off.update(&mut anchor, &SOLE, 0.15 + f64::from(k) * 0.01);
            highest = highest.max(toe_off.pitch);
        }
        assert!(highest < 0.4, "the heel went on rising: {highest}");
        assert!(toe_off.lowered());
        assert!((anchor.translation.vector - base.translation.vector).norm() < 1e-12);
        assert!(anchor.rotation.angle_to(&base.rotation) < 1e-12);
    }
}
