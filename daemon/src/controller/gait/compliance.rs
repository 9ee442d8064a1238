//! Foot force and centre-of-pressure compliance for position-controlled joints (Kajita et al.
//! 2010; Caron et al. 2019), as velocities of the feet in contact that the QP's contact
//! constraints add to their hold.
//!
//! The desired ZMP is first split between the feet in contact: in double support by the lever
//! rule along the line between the feet's single-support ZMP points (the sole centres, moved
//! towards each other by `zmp_inward_offset_m`), giving normal-force shares, each foot's centre
//! of pressure (CoP) being its point moved by the desired ZMP's offset from that line, clamped
//! into the sole; in single support the stance foot carries everything at the desired ZMP. So
//! the foot about to lift carries nothing once the ZMP has reached the stance foot's point.
//!
//! - **Foot damping**: a foot turns about the horizontal axes so that its measured CoP moves to
//!   the desired one: `ω_x = −A f_z (cop_d − cop_m)_y`, `ω_y = A f_z (cop_d − cop_m)_x` (A in
//!   rad/s per N·m; the angular velocity pressing the side that should carry more), less `θ/τ`
//!   of the rotation `θ` it has accumulated since the foot landed (a leak: a CoP error that the
//!   ankle cannot remove does not wind it up to its limit). The sole is on the ground, so the
//!   servos turn that into ankle torque.
//! - **Force difference** (double support): the feet move vertically against each other,
//!   `v = K (Δf_d − Δf_m)` with `Δf = f_left − f_right` (K in m/s per N): the left foot by
//!   `−v/2`, the right by `+v/2`, so the foot that should carry more presses down.
//! - **Internal force** (double support): two legs on the ground form a closed chain, and stiff
//!   position servos holding it where the model closes it (their joints sag under load by a
//!   fraction of a milliradian, the feet were anchored under another load) push the feet against
//!   each other: standing after a walk up the stairs, JVRC-1's feet pushed each other with 90 N
//!   and a hip pitch sat at its 100 N·m limit. The part of each foot's horizontal ground force
//!   beyond its share of the total (the share its normal force carries; what moves the CoM)
//!   is internal, `e = f_left − s_left (f_left + f_right)`, and the feet give way to it, the left
//!   by `K e`, the right by `−K e`: their sum, and so the balance, is unchanged.
//! - **Tilt damping**: the robot rocks on its compliant soles (MuJoCo, JVRC-1: about 4 Hz in
//!   pitch, 2 Hz in roll, excited by every lift-off and swing), which leg odometry cannot see and
//!   which swings the ZMP by centimetres. For a body of inertia `I` about the sole on a contact of
//!   rotational stiffness `k`, `I θ̈ = −k (θ − φ) + m g h θ` (θ: body tilt, φ: ankle angle), so an
//!   ankle that turns against the body's tilt rate, `φ = −K_d θ̇` (IMU), adds the damping
//!   `k K_d θ̇`. The feet in contact turn by `K_d θ̇` relative to the body held by the other tasks,
//!   at most by a bound (a rigid, kinematic robot would turn its feet with nothing to damp).

use kinematics::robot::{EndEffector, SoleRectangle};
use nalgebra::{Isometry3, Point3, Vector2};

use super::config::StabilizerConfig;
use super::dcm::stance_zmp;

/// What a foot in contact should carry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FootLoad {
    /// Its share of the total normal force (0..=1).
    pub share: f64,
    /// Its centre of pressure (ground plane, m).
    pub cop: Vector2<f64>,
}

/// Splits the desired ZMP `zmp` between the feet on the ground (`feet`: left, right sole poses,
/// `None` in the air), each CoP kept `margin` inside its sole; the lever's ends are `inward` (m)
/// from the sole centres towards the other foot.
pub(crate) fn distribute(
    zmp: Vector2<f64>,
    feet: [Option<&Isometry3<f64>>; 2],
    sole: &SoleRectangle,
    margin: f64,
    inward: f64,
) -> [Option<FootLoad>; 2] {
    match feet {
        [Some(left), Some(right)] => {
            let a = stance_zmp(left, EndEffector::LeftFoot, inward);
            let b = stance_zmp(right, EndEffector::RightFoot, inward);
            let line = b - a;
            let t = ((zmp - a).dot(&line) / line.norm_squared()).clamp(0.0, 1.0);
            let offset = zmp - (a + line * t);
            [(left, a, 1.0 - t), (right, b, t)].map(|(pose, point, share)| {
                Some(FootLoad {
                    share,
                    cop: clamp_to_sole(point + offset, pose, sole, margin),
                })
            })
        }
        [Some(foot), None] | [None, Some(foot)] => {
            let load = Some(FootLoad {
                share: 1.0,
                cop: clamp_to_sole(zmp, foot, sole, margin),
            });
            if feet[0].is_some() {
                [load, None]
            } else {
                [None, load]
            }
        }
        [None, None] => [None, None],
    }
}

/// The foot damping's angular velocity (world x, y; rad/s) for a foot with normal force `force`
/// (N) whose CoP is `measured` and should be `desired`, having turned by `turned` (rad) so far.
pub(crate) fn foot_damping(
    desired: Vector2<f64>,
    measured: Vector2<f64>,
    force: f64,
    turned: Vector2<f64>,
    config: &StabilizerConfig,
) -> Vector2<f64> {
    let error = desired - measured;
    let rate = config.foot_damping_gain * force.max(0.0);
    let omega = Vector2::new(-rate * error.y, rate * error.x) - turned / config.foot_damping_leak_s;
    bounded(omega, config.foot_damping_max_speed)
}

/// The force-difference velocity `v` (m/s; the left foot moves by `−v/2`, the right by `+v/2`)
/// for desired and measured normal forces (left, right; N), with gain `gain` (m/s per N) and
/// bound `max` (m/s).
fn force_difference(desired: [f64; 2], measured: [f64; 2], gain: f64, max: f64) -> f64 {
    let error = (desired[0] - desired[1]) - (measured[0] - measured[1]);
    (gain * error).clamp(-max, max)
}

/// The vertical velocities (left, right; m/s) of two feet in contact that split their measured
/// normal forces `forces` (N) by the desired `shares`: [`force_difference`] shared between
/// them. Both gaits' force-difference control.
pub(crate) fn force_difference_velocities(
    shares: [f64; 2],
    forces: [f64; 2],
    gain: f64,
    max: f64,
) -> [f64; 2] {
    let total = forces[0] + forces[1];
    let desired = shares.map(|share| share * total);
    let v = force_difference(desired, forces, gain, max);
    [-v / 2.0, v / 2.0]
}

/// The horizontal velocities (left, right; world x, y; m/s) of two feet in contact that relax
/// the force they push each other with: the part of each foot's horizontal ground force
/// (`horizontal`, N) beyond its share of their total, shared by normal force (`normal`, N; a
/// negative reading counts as none), times `gain` (m/s per N), at most `max` (m/s). Zero when the
/// feet carry no normal force.
pub(crate) fn internal_force_velocities(
    horizontal: [Vector2<f64>; 2],
    normal: [f64; 2],
    gain: f64,
    max: f64,
) -> [Vector2<f64>; 2] {
    let [left, right] = normal.map(|n| n.max(0.0));
    let total = left + right;
    if total <= 0.0 {
        return [Vector2::zeros(); 2];
    }
    let left_share = left / total;
    let internal = horizontal[0] - left_share * (horizontal[0] + horizontal[1]);
    let velocity = bounded(gain * internal, max);
    [velocity, -velocity]
}

/// The tilt damping's ankle rotation, kept `K_d θ̇` through the velocity of the feet in contact.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TiltDamping {
    applied: Vector2<f64>,
}

impl TiltDamping {
    /// Starts again with no rotation applied.
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// The angular velocity (world x, y) of the feet in contact that turns them to
    /// `gain · tilt_rate` (`gain` = `K_d`, s), at most `max` (rad), within `dt`.
    pub fn velocity(
        &mut self,
        tilt_rate: Vector2<f64>,
        gain: f64,
        max: f64,
        dt: f64,
    ) -> Vector2<f64> {
        let target = bounded(tilt_rate * gain, max);
        let velocity = (target - self.applied) / dt;
        self.applied = target;
        velocity
    }
}

/// `p` clamped into the sole rectangle at `pose`, shrunk by `margin`.
fn clamp_to_sole(
    p: Vector2<f64>,
    pose: &Isometry3<f64>,
    sole: &SoleRectangle,
    margin: f64,
) -> Vector2<f64> {
    let local = pose.inverse_transform_point(&Point3::new(p.x, p.y, pose.translation.z));
    let (hx, hy) = (
        (sole.length / 2.0 - margin).max(0.0),
        (sole.width / 2.0 - margin).max(0.0),
    );
    let clamped = Point3::new(local.x.clamp(-hx, hx), local.y.clamp(-hy, hy), 0.0);
    (pose * clamped).coords.xy()
}

/// `v` scaled down to at most `max` in norm.
fn bounded(v: Vector2<f64>, max: f64) -> Vector2<f64> {
    let norm = v.norm();
    if norm > max { v * (max / norm) } else { v }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feet_pushing_each_other_give_way_and_a_force_that_moves_the_com_does_not() {
        let (gain, max) = (1e-4, 0.02);
        // Equal loads, the ground pushing the left foot forward and the right back by 90 N: the
        // legs push each other apart; each foot moves along its ground force, 9 mm/s.
        let [left, right] = internal_force_velocities(
            [Vector2::new(90.0, 0.0), Vector2::new(-90.0, 0.0)],
            [300.0, 300.0],
            gain,
            max,
        );
        assert!((left - Vector2::new(0.009, 0.0)).norm() < 1e-12, "{left}");
        assert_eq!(right, -left);
        // 100 N forward shared as the normal forces are (3:1) accelerates the CoM: nothing to
        // relax.
        let moving = internal_force_velocities(
            [Vector2::new(75.0, 0.0), Vector2::new(25.0, 0.0)],
            [450.0, 150.0],
            gain,
            max,
        );
        assert!(moving.iter().all(|v| v.norm() < 1e-12), "{moving:?}");
        // Large forces are bounded; unloaded feet get nothing.
        let [fast, _] = internal_force_velocities(
            [Vector2::new(0.0, 1e4), Vector2::new(0.0, -1e4)],
            [300.0, 300.0],
            gain,
            max,
        );
        assert!((fast.norm() - max).abs() < 1e-12);
        let unloaded = internal_force_velocities(
            [Vector2::new(5.0, 0.0), Vector2::new(-5.0, 0.0)],
            [0.0, 0.0],
            gain,
            max,
        );
        assert_eq!(unloaded, [Vector2::zeros(); 2]);
    }

    const SOLE: SoleRectangle = SoleRectangle {
        length: 0.2,
        width: 0.08,
    };

    fn foot(x: f64, y: f64) -> Isometry3<f64> {
        Isometry3::translation(x, y, 0.0)
    }

    #[test]
    fn double_support_splits_by_the_lever_rule() {
        let (left, right) = (foot(0.0, 0.1), foot(0.2, -0.1));
        let zmp = Vector2::new(0.05, 0.05);
        let [Some(l), Some(r)] = distribute(zmp, [Some(&left), Some(&right)], &SOLE, 0.01, 0.0)
        else {
            panic!("both feet carry");
        };
        assert!((l.share + r.share - 1.0).abs() < 1e-12);
        // The shares and CoPs reproduce the ZMP when nothing is clamped.
        let resultant = l.cop * l.share + r.cop * r.share;
        assert!((resultant - zmp).norm() < 1e-12, "{resultant:?}");
        assert!(l.share > r.share);
    }

    #[test]
    fn with_an_inward_offset_the_stance_point_carries_everything() {
        let (left, right) = (foot(0.0, 0.1), foot(0.2, -0.1));
        let inward = 0.02;
        let feet = [Some(&left), Some(&right)];
        // The ZMP on the right foot's single-support point: the left foot carries nothing.
        let point = Vector2::new(0.2, -0.08);
        let [Some(l), Some(r)] = distribute(point, feet, &SOLE, 0.01, inward) else {
            panic!("both feet carry");
        };
        assert!(l.share.abs() < 1e-12 && (r.share - 1.0).abs() < 1e-12);
        assert!((r.cop - point).norm() < 1e-12, "{:?}", r.cop);
        // Without the offset the lever rule between the centres leaves load on the left foot.
        let [Some(l), _] = distribute(point, feet, &SOLE, 0.01, 0.0) else {
            panic!("both feet carry");
        };
        assert!(l.share > 0.05, "{}", l.share);
        // Between the points the shares and CoPs still reproduce the ZMP.
        let zmp = Vector2::new(0.08, 0.02);
        let [Some(l), Some(r)] = distribute(zmp, feet, &SOLE, 0.01, inward) else {
            panic!("both feet carry");
        };
        let resultant = l.cop * l.share + r.cop * r.share;
        assert!((resultant - zmp).norm() < 1e-12, "{resultant:?}");
    }

    #[test]
    fn single_support_carries_all_at_the_zmp_clamped_into_the_sole() {
        let stance = foot(0.0, -0.1);
        let [None, Some(load)] = distribute(
            Vector2::new(0.0, 0.0),
            [None, Some(&stance)],
            &SOLE,
            0.01,
            0.0,
        ) else {
            panic!("the right foot carries");
        };
        assert_eq!(load.share, 1.0);
        assert!(
            (load.cop - Vector2::new(0.0, -0.07)).norm() < 1e-12,
            "{:?}",
            load.cop
        );
    }

    #[test]
    fn damping_presses_the_side_that_should_carry_more() {
        let config = StabilizerConfig::default();
        // Desired CoP ahead (+x) and to the left (+y) of the measured one.
        let none = Vector2::zeros();
        let turn = foot_damping(Vector2::new(0.01, 0.01), none, 300.0, none, &config);
        assert!(turn.y > 0.0, "turning about +y presses the toes down");
        assert!(turn.x < 0.0, "turning about −x presses the left edge down");
        let fast = foot_damping(Vector2::new(1.0, 0.0), none, 1e6, none, &config);
        assert!((fast.norm() - config.foot_damping_max_speed).abs() < 1e-12);
        // Without a CoP error the accumulated rotation leaks away.
        let back = foot_damping(none, none, 300.0, Vector2::new(0.01, 0.0), &config);
        assert!((back.x + 0.01 / config.foot_damping_leak_s).abs() < 1e-12 && back.y == 0.0);
    }

    #[test]
    fn tilt_damping_turns_the_feet_with_the_tilt_rate() {
        let mut damping = TiltDamping::default();
        let dt = 0.002;
        let mut turned = Vector2::zeros();
        for rate in [0.1, 0.3, -0.2] {
            turned += damping.velocity(Vector2::new(rate, 0.0), 0.03, 0.02, dt) * dt;
            // The feet have turned by K_d θ̇ in all: the ankles by its opposite.
            assert!((turned.x - 0.03 * rate).abs() < 1e-12);
        }
        // Never further than the bound.
        turned += damping.velocity(Vector2::new(10.0, 0.0), 0.03, 0.02, dt) * dt;
        assert!((turned.x - 0.02).abs() < 1e-12);
    }

    #[test]
    fn force_difference_lowers_the_foot_that_should_carry_more() {
        let config = StabilizerConfig::default();
        let (gain, max) = (
            config.force_difference_gain,
            config.force_difference_max_speed,
        );
        let v = force_difference([400.0, 200.0], [300.0, 300.0], gain, max);
        assert!(v > 0.0, "the left foot (−v/2) presses down");
        assert!(force_difference([1e9, 0.0], [0.0, 0.0], gain, max) <= max);
    }
}
