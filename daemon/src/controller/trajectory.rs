//! Set-point trajectories for the tasks: smooth (minimum-jerk) or constant-speed interpolation
//! of a pose or a ground point, sampled with their feed-forward velocity.

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector2, Vector3};

/// How the interpolation parameter advances with time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Profile {
    /// s(τ) = 10τ³ − 15τ⁴ + 6τ⁵: zero velocity and acceleration at both ends.
    MinimumJerk,
    /// s(τ) = τ: constant speed (the final descent onto a contact).
    Linear,
}

impl Profile {
    /// (s, ds/dt) at time `t` of a motion lasting `duration`.
    pub fn sample(self, t: f64, duration: f64) -> (f64, f64) {
        if t >= duration {
            return (1.0, 0.0);
        }
        let tau = (t / duration).max(0.0);
        match self {
            Self::MinimumJerk => {
                let t2 = tau * tau;
                let s = t2 * tau * (10.0 - 15.0 * tau + 6.0 * t2);
                let ds = 30.0 * t2 * (1.0 - 2.0 * tau + t2) / duration;
                (s, ds)
            }
            Self::Linear => (tau, 1.0 / duration),
        }
    }
}

/// A pose interpolated from `start` to `goal`: translation on the straight line, raised by an
/// arc of height `lift` at its middle ([`PoseTrajectory::lifted`]), rotation about one fixed
/// world axis.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PoseTrajectory {
    start: Isometry3<f64>,
    goal: Isometry3<f64>,
    rotation_axis_angle: Vector3<f64>,
    duration: f64,
    profile: Profile,
    lift: f64,
}

impl PoseTrajectory {
    /// A motion from `start` to `goal` lasting `duration` (> 0).
    pub fn new(
        start: Isometry3<f64>,
        goal: Isometry3<f64>,
        duration: f64,
        profile: Profile,
    ) -> Self {
        Self {
            start,
            goal,
            rotation_axis_angle: (goal.rotation * start.rotation.inverse()).scaled_axis(),
            duration,
            profile,
            lift: 0.0,
        }
    }

    /// The same motion over an arc: `lift` · 4s(1 − s) above the straight line (`lift` at its
    /// middle), so it ends coming down onto the goal, as a hand onto the top of a railing it
    /// would otherwise sweep through from below.
    pub fn lifted(self, lift: f64) -> Self {
        Self { lift, ..self }
    }

    /// A motion that stays at `pose`.
    pub fn hold(pose: Isometry3<f64>) -> Self {
        Self::new(pose, pose, 1.0, Profile::Linear)
    }

    /// The final pose.
    pub fn goal(&self) -> &Isometry3<f64> {
        &self.goal
    }

    /// Planned duration (s).
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// Pose and world velocity (linear xyz, angular xyz) at time `t`.
    pub fn sample(&self, t: f64) -> (Isometry3<f64>, [f64; 6]) {
        let (s, ds) = self.profile.sample(t, self.duration);
        let delta = self.goal.translation.vector - self.start.translation.vector;
        let arc = Vector3::z() * self.lift * 4.0;
        let translation = self.start.translation.vector + delta * s + arc * s * (1.0 - s);
        let rotation =
            UnitQuaternion::from_scaled_axis(self.rotation_axis_angle * s) * self.start.rotation;
        let v = (delta + arc * (1.0 - 2.0 * s)) * ds;
        let w = self.rotation_axis_angle * ds;
        (
            Isometry3::from_parts(Translation3::from(translation), rotation),
            [v.x, v.y, v.z, w.x, w.y, w.z],
        )
    }
}

/// A ground-plane point (the CoM x/y target) interpolated with a minimum-jerk profile.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PointTrajectory {
    start: Vector2<f64>,
    goal: Vector2<f64>,
    duration: f64,
}

impl PointTrajectory {
    /// A minimum-jerk motion from `start` to `goal` lasting `duration` (> 0).
    pub fn new(start: Vector2<f64>, goal: Vector2<f64>, duration: f64) -> Self {
        Self {
            start,
            goal,
            duration,
        }
    }

    /// The final point.
    pub fn goal(&self) -> Vector2<f64> {
        self.goal
    }

    /// Planned duration (s).
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// Point and velocity at time `t`.
    pub fn sample(&self, t: f64) -> (Vector2<f64>, Vector2<f64>) {
        let (s, ds) = Profile::MinimumJerk.sample(t, self.duration);
        let delta = self.goal - self.start;
        (self.start + delta * s, delta * ds)
    }
}

/// Test support: asserts that at time `t` the velocity `sample` gives (linear, angular) is the
/// central finite difference of its poses.
#[cfg(test)]
pub(crate) fn assert_velocity_is_derivative(
    sample: impl Fn(f64) -> (Isometry3<f64>, [f64; 6]),
    t: f64,
) {
    let h = 1e-6;
    let (a, _) = sample(t - h);
    let (b, _) = sample(t + h);
    let (_, v) = sample(t);
    let linear = (b.translation.vector - a.translation.vector) / (2.0 * h);
    let angular = (b.rotation * a.rotation.inverse()).scaled_axis() / (2.0 * h);
    for k in 0..3 {
        assert!((linear[k] - v[k]).abs() < 1e-6, "t {t} linear {k}");
        assert!((angular[k] - v[3 + k]).abs() < 1e-6, "t {t} angular {k}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimum_jerk_starts_and_ends_at_rest_and_velocity_matches_finite_difference() {
        let start = Isometry3::translation(0.0, 0.0, 0.0);
        let goal = Isometry3::from_parts(
            Translation3::new(0.3, -0.1, 0.05),
            UnitQuaternion::from_euler_angles(0.0, 0.1, 0.4),
        );
        let trajectory = PoseTrajectory::new(start, goal, 1.5, Profile::MinimumJerk);
        let (p0, v0) = trajectory.sample(0.0);
        let (p1, v1) = trajectory.sample(2.0);
        assert!((p0.translation.vector - start.translation.vector).norm() < 1e-12);
        assert!((p1.translation.vector - goal.translation.vector).norm() < 1e-12);
        assert!(p1.rotation.angle_to(&goal.rotation) < 1e-12);
        assert!(v0.iter().chain(&v1).all(|v| v.abs() < 1e-12));
        assert_velocity_is_derivative(|t| trajectory.sample(t), 0.6);
    }

    #[test]
    fn a_lifted_motion_arcs_over_the_straight_line_and_comes_down_onto_the_goal() {
        let start = Isometry3::translation(0.0, -0.25, 0.77);
        let goal = Isometry3::translation(0.0, -0.45, 0.86);
        let trajectory = PoseTrajectory::new(start, goal, 1.0, Profile::MinimumJerk).lifted(0.08);
        let middle = trajectory.sample(0.5).0.translation.vector;
        let straight = (start.translation.vector + goal.translation.vector) / 2.0;
        assert!(
            (middle - straight - Vector3::z() * 0.08).norm() < 1e-12,
            "{middle}"
        );
        assert!(
            (trajectory.sample(1.0).0.translation.vector - goal.translation.vector).norm() < 1e-12
        );
        // Near its end it moves down onto the goal, from above it.
        let (near, velocity) = trajectory.sample(0.9);
        assert!(near.translation.z > goal.translation.z && velocity[2] < 0.0);
        assert_velocity_is_derivative(|t| trajectory.sample(t), 0.3);
    }
}
