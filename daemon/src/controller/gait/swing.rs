//! The swing foot's trajectory, timed with its single-support phase.
//!
//! Horizontally (x, y) one minimum-jerk motion from the lift-off to the landing position over
//! the whole swing; vertically and in orientation two minimum-jerk halves, up to the apex (the
//! post-processed swing pose's height and orientation) at mid-swing and down to the landing.
//! Minimum-jerk pieces start and end with zero velocity and acceleration, so the foot leaves the
//! ground and lands at rest, and the halves join smoothly at the apex (vertical velocity and
//! acceleration zero there).
//!
//! A step up or down (landing and lift-off more than [`STEP_HEIGHT_M`] apart, a stair or a ramp)
//! moves horizontally over part of the swing only, so the sole is high before it passes an edge:
//! climbing, the foot first rises for [`EDGE_CLEARING_SHARE`] of the swing, so its toe clears
//! the riser in front of it, and it arrives above its landing [`SET_DOWN_SHARE`] before the end,
//! holding the apex's height until then and coming straight down onto the tread, so its heel
//! clears the nosing it lands behind and it touches down at rest, not sliding onto the tread;
//! descending, it arrives above its landing [`EDGE_CLEARING_SHARE`] before the end, so its heel
//! clears the nosing behind the landing while it comes down.

use nalgebra::{Isometry3, Translation3, Vector2};

use crate::controller::machine::STEP_HEIGHT_M;
use crate::controller::trajectory::{PointTrajectory, PoseTrajectory, Profile};

/// The share of a step up's (down's) swing before (after) its horizontal motion.
pub(crate) const EDGE_CLEARING_SHARE: f64 = 0.25;

/// The share of a step up's swing in which the foot comes straight down onto its landing (the
/// 15 cm stairs climbed one foot per stair tipped 10 of 10 walks with the foot sliding onto the
/// tread, docs/controller.md, "Swing").
pub(crate) const SET_DOWN_SHARE: f64 = 0.2;

/// A swing from lift-off to landing.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SwingTrajectory {
    horizontal: PointTrajectory,
    /// When the horizontal motion starts, after lift-off (s).
    horizontal_start: f64,
    /// Up to the apex, from lift-off.
    rise: PoseTrajectory,
    /// Down from the apex, from `descent_start`.
    descent: PoseTrajectory,
    /// When the descent from the apex starts, after lift-off (s); between the rise's end and
    /// then the foot keeps the apex's height and orientation.
    descent_start: f64,
}

impl SwingTrajectory {
    /// A swing lasting `duration` (s, > 0) from `lift_off` through the height and orientation
    /// of `apex` to `landing`.
    pub fn new(
        lift_off: Isometry3<f64>,
        apex: Isometry3<f64>,
        landing: Isometry3<f64>,
        duration: f64,
    ) -> Self {
        let start = lift_off.translation.vector.xy();
        let goal = landing.translation.vector.xy();
        let middle = (start + goal) / 2.0;
        let top = Isometry3::from_parts(
            Translation3::new(middle.x, middle.y, apex.translation.z),
            apex.rotation,
        );
        let half = duration / 2.0;
        let climb = landing.translation.z - lift_off.translation.z;
        let edge_clearing = EDGE_CLEARING_SHARE * duration;
        let (horizontal_start, horizontal_end, descent_duration) = if climb > STEP_HEIGHT_M {
            let set_down = SET_DOWN_SHARE * duration;
            (edge_clearing, duration - set_down, set_down)
        } else if climb < -STEP_HEIGHT_M {
            (0.0, duration - edge_clearing, half)
        } else {
            (0.0, duration, half)
        };
        Self {
            horizontal: PointTrajectory::new(start, goal, horizontal_end - horizontal_start),
            horizontal_start,
            rise: PoseTrajectory::new(lift_off, top, half, Profile::MinimumJerk),
            descent: PoseTrajectory::new(top, landing, descent_duration, Profile::MinimumJerk),
            descent_start: duration - descent_duration,
        }
    }

    /// The landing pose.
    pub fn landing(&self) -> &Isometry3<f64> {
        self.descent.goal()
    }

    /// Pose and world velocity (linear xyz, angular xyz) at time `t` after lift-off; after the
    /// swing, the landing pose at rest.
    pub fn sample(&self, t: f64) -> (Isometry3<f64>, [f64; 6]) {
        let (xy, xy_velocity): (Vector2<f64>, Vector2<f64>) =
            self.horizontal.sample(t - self.horizontal_start);
        let (mut pose, mut velocity) = if t < self.descent_start {
            // After the rise the pose stays at the apex, at rest.
            self.rise.sample(t)
        } else {
            self.descent.sample(t - self.descent_start)
        };
        pose.translation.x = xy.x;
        pose.translation.y = xy.y;
        velocity[0] = xy_velocity.x;
        velocity[1] = xy_velocity.y;
        (pose, velocity)
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::UnitQuaternion;

    use super::*;
    use crate::controller::trajectory::assert_velocity_is_derivative;

    fn swing() -> (
        SwingTrajectory,
        Isometry3<f64>,
        Isometry3<f64>,
        Isometry3<f64>,
    ) {
        let lift_off = Isometry3::translation(0.0, 0.1, 0.0);
        let apex = Isometry3::from_parts(
            Translation3::new(0.12, 0.07, 0.06),
            UnitQuaternion::from_euler_angles(0.0, 0.15, 0.05),
        );
        let landing = Isometry3::from_parts(
            Translation3::new(0.2, 0.1, -0.003),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 0.1),
        );
        (
            SwingTrajectory::new(lift_off, apex, landing, 0.6),
            lift_off,
            apex,
            landing,
        )
    }

    #[test]
    fn the_swing_leaves_and_lands_at_rest() {
        let (swing, lift_off, _, landing) = swing();
        let (start, v0) = swing.sample(0.0);
        let (end, v1) = swing.sample(0.6);
        assert!((start.translation.vector - lift_off.translation.vector).norm() < 1e-12);
        assert!((end.translation.vector - landing.translation.vector).norm() < 1e-12);
        assert!(end.rotation.angle_to(&landing.rotation) < 1e-12);
        assert!(
            v0.iter().chain(&v1).all(|v| v.abs() < 1e-12),
            "{v0:?} {v1:?}"
        );
        // Just before landing the foot is nearly still (minimum jerk: velocity ~ τ²).
        let (_, late) = swing.sample(0.6 - 1e-3);
        assert!(late.iter().all(|v| v.abs() < 1e-3), "{late:?}");
    }

    #[test]
    fn the_apex_is_reached_at_mid_swing_and_is_the_highest_point() {
        let (swing, _, apex, _) = swing();
        let (top, velocity) = swing.sample(0.3);
        assert!((top.translation.z - apex.translation.z).abs() < 1e-12);
        assert!(top.rotation.angle_to(&apex.rotation) < 1e-12);
        assert!(velocity[2].abs() < 1e-12, "vertical velocity at the apex");
        for k in 0..=60 {
            let (pose, _) = swing.sample(f64::from(k) * 0.01);
            assert!(pose.translation.z <= apex.translation.z + 1e-12);
        }
    }

    #[test]
    fn the_velocity_is_the_derivative_of_the_pose() {
        let (swing, ..) = swing();
        for t in [0.1, 0.25, 0.31, 0.45] {
            assert_velocity_is_derivative(|t| swing.sample(t), t);
        }
    }

    /// Whether a sole of half-length `half` swinging one stair up (`up`) or down, over treads
    /// 0.3 m deep with 0.1 m risers, stays above every tread it is over.
    fn clears_the_stairs(up: bool) -> bool {
        let half = 0.112;
        let (rise, apex) = if up { (0.2, 0.23) } else { (-0.2, 0.03) };
        let at = |x: f64, z: f64| Isometry3::translation(x, 0.1, z);
        let swing = SwingTrajectory::new(at(0.0, 0.0), at(0.3, apex), at(0.6, rise), 1.0);
        // Tread k (the lift-off's) spans x < 0.15, k ± 1 up to 0.45, k ± 2 beyond.
        let tread = |x: f64| rise * (((x + 0.15) / 0.3).floor() / 2.0).clamp(0.0, 1.0);
        (0..=1000).all(|k| {
            let (pose, _) = swing.sample(f64::from(k) * 1e-3);
            let (x, z) = (pose.translation.x, pose.translation.z);
            let highest = tread(x - half).max(tread(x + half));
            z >= highest - 1e-9
        })
    }

    #[test]
    fn a_step_up_or_down_clears_the_stair_edges_and_a_plain_swing_would_not() {
        assert!(clears_the_stairs(true), "up");
        assert!(clears_the_stairs(false), "down");
        // The same step up with the horizontal motion over the whole swing hits the riser.
        let at = |x: f64, z: f64| Isometry3::translation(x, 0.1, z);
        let plain = SwingTrajectory::new(at(0.0, 0.0), at(0.3, 0.23), at(0.6, 0.0), 1.0);
        let (early, _) = plain.sample(0.2);
        let shaped = SwingTrajectory::new(at(0.0, 0.0), at(0.3, 0.23), at(0.6, 0.2), 1.0);
        let (delayed, _) = shaped.sample(0.2);
        assert!(delayed.translation.x < early.translation.x - 0.03);
    }

    #[test]
    fn a_step_up_arrives_above_its_landing_then_comes_straight_down() {
        let at = |x: f64, z: f64| Isometry3::translation(x, 0.1, z);
        let swing = SwingTrajectory::new(at(0.0, 0.0), at(0.3, 0.23), at(0.6, 0.2), 1.0);
        let (above, velocity) = swing.sample(1.0 - SET_DOWN_SHARE);
        assert!((above.translation.vector - at(0.6, 0.23).translation.vector).norm() < 1e-12);
        assert!(velocity.iter().all(|v| v.abs() < 1e-12), "{velocity:?}");
        for k in 0..20 {
            let (pose, velocity) = swing.sample(1.0 - SET_DOWN_SHARE + f64::from(k) * 0.01);
            assert!((pose.translation.x - 0.6).abs() < 1e-12);
            assert!(
                velocity[0].abs() < 1e-12 && velocity[2] <= 0.0,
                "{velocity:?}"
            );
        }
        // A step down still moves horizontally until a quarter before the end, coming down
        // from mid-swing.
        let down = SwingTrajectory::new(at(0.0, 0.0), at(0.3, 0.03), at(0.6, -0.2), 1.0);
        let (pose, _) = down.sample(1.0 - SET_DOWN_SHARE);
        assert!((pose.translation.x - 0.6).abs() < 1e-12 && pose.translation.z < 0.0);
    }

    #[test]
    fn a_shaped_swing_has_consistent_velocities() {
        let at = |x: f64, z: f64| Isometry3::translation(x, 0.1, z);
        for landing in [0.2, -0.2] {
            let swing = SwingTrajectory::new(at(0.0, 0.0), at(0.3, 0.23), at(0.6, landing), 1.0);
            for t in [0.1, 0.3, 0.55, 0.8] {
                assert_velocity_is_derivative(|t| swing.sample(t), t);
            }
            let (end, _) = swing.sample(1.0);
            assert!((end.translation.x - 0.6).abs() < 1e-12);
        }
    }
}
