//! What the stabilizer measures: the ZMP and each foot's centre of pressure from the ankle
//! wrenches, and the DCM from the estimated CoM (turned by the IMU's tilt).
//!
//! Wrenches are the force and torque the environment exerts on the robot, at the FT frame origin
//! `o`, in world-aligned axes. On the horizontal plane at height `z` their resultant has no
//! horizontal moment at
//!
//! ```text
//! p_x = Σ (o_x f_z − τ_y − (o_z − z) f_x) / Σ f_z
//! p_y = Σ (o_y f_z + τ_x − (o_z − z) f_y) / Σ f_z
//! ```
//!
//! (the sums over the feet give the ZMP, one term a foot's centre of pressure).

use nalgebra::{UnitQuaternion, Vector2, Vector3};

/// The point on the plane at height `plane_z` where the wrenches' resultant has no horizontal
/// moment; `None` while they press with less than `min_force` (N) in all.
pub(crate) fn pressure_centre<'a>(
    wrenches: impl IntoIterator<Item = (&'a [f64; 6], &'a Vector3<f64>)>,
    plane_z: f64,
    min_force: f64,
) -> Option<Vector2<f64>> {
    let (mut moment, mut normal) = (Vector2::zeros(), 0.0);
    for (w, o) in wrenches {
        let lever = o.z - plane_z;
        moment.x += o.x * w[2] - w[4] - lever * w[0];
        moment.y += o.y * w[2] + w[3] - lever * w[1];
        normal += w[2];
    }
    (normal >= min_force).then(|| moment / normal)
}

/// `com` as the IMU sees it: leg odometry puts the soles flat on their anchors, so a robot
/// rolling over a sole edge looks upright to it. The IMU's base orientation `imu` differs from
/// the estimate `estimated` by that roll; its tilt (the part about horizontal axes) turns the CoM
/// about `pivot` on the ground, where the robot rolls (its measured ZMP).
pub(crate) fn tilted_com(
    com: &Vector3<f64>,
    pivot: &Vector3<f64>,
    imu: &UnitQuaternion<f64>,
    estimated: &UnitQuaternion<f64>,
) -> Vector3<f64> {
    let error = imu * estimated.inverse();
    let up = Vector3::z();
    let tilt = UnitQuaternion::rotation_between(&up, &(error * up)).unwrap_or_default();
    pivot + tilt * (com - pivot)
}

/// The body's tilt rate: the horizontal (world x, y) part of the base's angular velocity, from
/// successive IMU orientations, low-pass filtered.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TiltRate {
    previous: Option<UnitQuaternion<f64>>,
    rate: Vector2<f64>,
}

impl TiltRate {
    /// Starts again (the next update only records the orientation).
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// The tilt rate (rad/s) with the IMU orientation `imu` measured now, `dt` after the last
    /// update, filtered with time constant `filter_s`.
    pub fn update(&mut self, imu: &UnitQuaternion<f64>, dt: f64, filter_s: f64) -> Vector2<f64> {
        if let Some(previous) = self.previous {
            let raw = (imu * previous.inverse()).scaled_axis().xy() / dt;
            self.rate += (raw - self.rate) * (dt / (filter_s + dt));
        }
        self.previous = Some(*imu);
        self.rate
    }
}

/// The measured DCM `ξ = c + ċ / ω`, its CoM velocity from the low-pass filtered finite
/// difference of the CoM over the ticks.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct DcmEstimator {
    previous: Option<Vector2<f64>>,
    velocity: Vector2<f64>,
}

impl DcmEstimator {
    /// Starts again at rest (the next update only records the CoM).
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// The DCM of the CoM `com` measured now, `dt` after the last update, for a pendulum of
    /// natural frequency `omega` and a velocity filter time constant `filter_s`.
    pub fn update(
        &mut self,
        com: Vector2<f64>,
        dt: f64,
        omega: f64,
        filter_s: f64,
    ) -> Vector2<f64> {
        if let Some(previous) = self.previous {
            let raw = (com - previous) / dt;
            let blend = dt / (filter_s + dt);
            self.velocity += (raw - self.velocity) * blend;
        }
        self.previous = Some(com);
        com + self.velocity / omega
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pure_force_presses_where_it_acts() {
        // 300 N at (0.1, 0.05) on the ground, read at a sensor 0.1 m above (0, 0).
        let (force, at) = (
            Vector3::new(10.0, -5.0, 300.0),
            Vector3::new(0.1, 0.05, 0.0),
        );
        let origin = Vector3::new(0.0, 0.0, 0.1);
        let torque = (at - origin).cross(&force);
        let wrench = [force.x, force.y, force.z, torque.x, torque.y, torque.z];
        let cop = pressure_centre([(&wrench, &origin)], 0.0, 1.0).unwrap();
        assert!((cop - at.xy()).norm() < 1e-12, "{cop:?}");
        assert!(pressure_centre([(&wrench, &origin)], 0.0, 400.0).is_none());
        // Two feet: the ZMP is the force-weighted mean of their centres of pressure.
        let other_origin = Vector3::new(0.0, -0.2, 0.1);
        let other_at = Vector3::new(-0.1, -0.2, 0.0);
        let other_force = Vector3::new(0.0, 0.0, 100.0);
        let other_torque = (other_at - other_origin).cross(&other_force);
        let other = [
            0.0,
            0.0,
            100.0,
            other_torque.x,
            other_torque.y,
            other_torque.z,
        ];
        let zmp = pressure_centre([(&wrench, &origin), (&other, &other_origin)], 0.0, 1.0).unwrap();
        let expected = (at.xy() * 300.0 + other_at.xy() * 100.0) / 400.0;
        assert!((zmp - expected).norm() < 1e-12, "{zmp:?}");
    }

    #[test]
    fn a_rolled_robot_has_its_com_turned_about_the_pivot() {
        let com = Vector3::new(0.0, 0.0, 0.8);
        let pivot = Vector3::new(0.0, -0.04, 0.0);
        let roll = UnitQuaternion::from_euler_angles(0.05, 0.0, 0.0);
        let seen = tilted_com(&com, &pivot, &roll, &UnitQuaternion::identity());
        assert!((seen - (pivot + roll * (com - pivot))).norm() < 1e-12);
        // Rolled about +x (left side up): the CoM moves about h·θ to the right.
        assert!((seen.y - (-0.04)).abs() < 1e-3, "{seen:?}");
        // Only the tilt counts: a heading error alone turns nothing.
        let heading = UnitQuaternion::from_euler_angles(0.0, 0.0, 0.3);
        let turned = tilted_com(&com, &pivot, &heading, &UnitQuaternion::identity());
        assert!((turned - com).norm() < 1e-12);
    }

    #[test]
    fn the_tilt_rate_is_the_horizontal_angular_velocity() {
        let mut rate = TiltRate::default();
        let dt = 0.002;
        let mut last = Vector2::zeros();
        for k in 0..200 {
            let t = f64::from(k) * dt;
            // Rolling at 0.1 rad/s and turning about the vertical at 0.5 rad/s.
            let imu = UnitQuaternion::from_euler_angles(0.1 * t, 0.0, 0.5 * t);
            last = rate.update(&imu, dt, 0.01);
        }
        // World frame: the roll axis has turned with the heading (0.2 rad after 0.4 s).
        let heading: f64 = 0.5 * 0.398;
        let expected = Vector2::new(heading.cos(), heading.sin()) * 0.1;
        assert!((last - expected).norm() < 5e-3, "{last:?} vs {expected:?}");
    }

    #[test]
    fn the_dcm_leads_a_moving_com() {
        let mut estimator = DcmEstimator::default();
        let (dt, omega) = (0.002, 3.0);
        let mut dcm = Vector2::zeros();
        for k in 0..500 {
            let com = Vector2::new(0.3 * f64::from(k) * dt, 0.0);
            dcm = estimator.update(com, dt, omega, 0.01);
        }
        // ξ = c + ċ/ω: 0.3 m/s / 3 = 0.1 m ahead.
        let com = Vector2::new(0.3 * 499.0 * dt, 0.0);
        assert!(
            (dcm - com - Vector2::new(0.1, 0.0)).norm() < 1e-9,
            "{dcm:?}"
        );
    }
}
