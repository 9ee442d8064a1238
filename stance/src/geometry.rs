//! Small spatial helpers shared by the derived quantities and the passes: roll/pitch/yaw and the
//! straight walking path every along-path / lateral measure is expressed in. (Headings and the
//! planar frame of poses are ground geometry: `kinematics::ground`.)

use nalgebra::{Isometry3, UnitQuaternion, Vector3};

/// Roll, pitch and yaw `[x, y, z]` of a rotation, `R = Rz(yaw) · Ry(pitch) · Rx(roll)` (the
/// convention of [`UnitQuaternion::from_euler_angles`]).
pub fn roll_pitch_yaw(rotation: &UnitQuaternion<f64>) -> [f64; 3] {
    let (roll, pitch, yaw) = rotation.euler_angles();
    [roll, pitch, yaw]
}

/// The point of the segment from `start` to `end` nearest to `point` (`start` for a segment of
/// no length): where a hand reaching for a railing's axis from `point` meets it.
pub fn nearest_on_segment(
    start: &Vector3<f64>,
    end: &Vector3<f64>,
    point: &Vector3<f64>,
) -> Vector3<f64> {
    let axis = end - start;
    let t = (point - start).dot(&axis) / axis.norm_squared();
    // A degenerate segment (start = end) gives NaN: its only point.
    start + axis * if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) }
}

/// The straight walking path of a sequence: an origin on the ground plane and a horizontal unit
/// direction. Along-path distances (step sizes, the scaling of pass 6) and lateral offsets
/// (orthogonal foot distance, pass 8) are measured in it.
///
/// The direction ([`crate::passes::path_of`]) is the line of the root's travel from the first
/// stance to the last, pointing where the feet's contact poses head on average (sole frames
/// have x forward; toe-out cancels between left and right), or that mean heading for a walk
/// whose root does not travel. No pass moves a root across the path, so computing it again on
/// a post-processed sequence gives the same frame. The feet's mean heading alone is off by the walk's toe-out
/// noise and by how long each foot stands (0.2–0.7° on generated walks), and pass 6 keeps the
/// lateral offsets that error builds up over the raw, human-scale walk: post-processed walks
/// veered up to 3° (0.26 m over 5 m) from the direction they were generated in, away from their
/// railing and goal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathFrame {
    origin: Vector3<f64>,
    direction: Vector3<f64>,
    lateral: Vector3<f64>,
}

/// Horizontal vectors shorter than this do not define a direction.
const MIN_DIRECTION_NORM: f64 = 1e-9;

impl PathFrame {
    /// A path from `origin` (its z is ignored) heading along the horizontal part of `direction`;
    /// `None` if that part is (nearly) zero.
    pub fn new(origin: &Vector3<f64>, direction: &Vector3<f64>) -> Option<Self> {
        let horizontal = Vector3::new(direction.x, direction.y, 0.0);
        let norm = horizontal.norm();
        if norm < MIN_DIRECTION_NORM || !norm.is_finite() {
            return None;
        }
        let direction = horizontal / norm;
        Some(Self {
            origin: Vector3::new(origin.x, origin.y, 0.0),
            direction,
            lateral: Vector3::z().cross(&direction),
        })
    }

    /// The walking path from `origin` (its z is ignored) along the mean heading of `feet` (the
    /// contact poses, see the type's documentation); `+x` if they define none.
    pub fn of_walk<'a>(
        origin: &Vector3<f64>,
        feet: impl IntoIterator<Item = &'a Isometry3<f64>>,
    ) -> Self {
        // Unit headings, so that a tilted foot counts like a flat one with the same yaw.
        let heading = |foot: &Isometry3<f64>| {
            let x = foot.rotation * Vector3::x();
            Vector3::new(x.x, x.y, 0.0)
                .try_normalize(MIN_DIRECTION_NORM)
                .unwrap_or_else(Vector3::zeros)
        };
        let mean: Vector3<f64> = feet.into_iter().map(heading).sum();
        Self::new(origin, &mean)
            .or_else(|| Self::new(origin, &Vector3::x()))
            .expect("+x is a valid direction")
    }

    /// Horizontal unit vector of the walking direction.
    pub fn direction(&self) -> &Vector3<f64> {
        &self.direction
    }

    /// Horizontal unit vector pointing left of the walking direction (`z × direction`).
    pub fn lateral_axis(&self) -> &Vector3<f64> {
        &self.lateral
    }

    /// Heading of the walking direction (rotation about world z from +x).
    pub fn heading(&self) -> f64 {
        self.direction.y.atan2(self.direction.x)
    }

    /// Distance of `point` along the path from the origin.
    pub fn along(&self, point: &Vector3<f64>) -> f64 {
        (point - self.origin).dot(&self.direction)
    }

    /// Signed lateral offset of `point` from the path line (positive = left).
    pub fn lateral(&self, point: &Vector3<f64>) -> f64 {
        (point - self.origin).dot(&self.lateral)
    }

    /// The point on the ground plane (z = 0) `along` the path and `lateral` to its left: the
    /// inverse of [`PathFrame::along`] and [`PathFrame::lateral`], e.g. the start of a line
    /// parallel to the path.
    pub fn point(&self, along: f64, lateral: f64) -> Vector3<f64> {
        self.origin + self.direction * along + self.lateral * lateral
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinematics::ground::yaw;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn roll_pitch_yaw_round_trips() {
        let r = UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3);
        let [roll, pitch, yaw_] = roll_pitch_yaw(&r);
        assert!((roll - 0.1).abs() < 1e-12 && (pitch + 0.2).abs() < 1e-12);
        assert!((yaw_ - 0.3).abs() < 1e-12 && (yaw(&r) - 0.3).abs() < 1e-12);
    }

    #[test]
    fn path_frame_measures_along_and_lateral() {
        let toe_out = |yaw: f64| Isometry3::rotation(Vector3::new(0.0, 0.0, yaw));
        let feet = [toe_out(FRAC_PI_2 + 0.2), toe_out(FRAC_PI_2 - 0.2)];
        let frame = PathFrame::of_walk(&Vector3::new(1.0, 1.0, 0.8), &feet);
        assert!((frame.heading() - FRAC_PI_2).abs() < 1e-12);
        let p = Vector3::new(0.5, 2.0, 0.0);
        assert!((frame.along(&p) - 1.0).abs() < 1e-12);
        assert!((frame.lateral(&p) - 0.5).abs() < 1e-12);
        assert!((frame.point(1.0, 0.5) - p).norm() < 1e-12);
    }

    #[test]
    fn path_frame_ignores_roll_and_pitch_and_defaults_to_x() {
        let tilted = Isometry3::rotation(Vector3::new(0.3, 0.4, 0.0))
            * Isometry3::rotation(Vector3::new(0.0, 0.0, 0.5));
        let flat = Isometry3::rotation(Vector3::new(0.0, 0.0, yaw(&tilted.rotation)));
        let a = PathFrame::of_walk(&Vector3::zeros(), [&tilted, &flat]);
        assert!((a.heading() - yaw(&tilted.rotation)).abs() < 1e-12);
        let none: [Isometry3<f64>; 0] = [];
        assert_eq!(PathFrame::of_walk(&Vector3::zeros(), &none).heading(), 0.0);
    }
}
