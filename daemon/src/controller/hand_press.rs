//! Held hands press on their support with a bounded force: admittance on each held hand's
//! target along the vertical.
//!
//! A hand on a rigid railing under stiff position control is a very stiff spring: in MuJoCo a
//! JVRC-1 palm target one millimetre below a rail's top pushes 167 N into it, enough to lift a
//! foot off the ground. So a held hand's pose target is not where the plan put it but that pose
//! moved along the vertical by an offset `o` that integrates the force error,
//!
//! ```text
//! ȯ = hand_admittance · (f_z − f_d),  |ȯ| ≤ hand_press_speed,  |o| ≤ hand_press_depth_m,
//! ```
//!
//! with `f_z` the vertical force of the environment on the hand measured at its wrist (upward
//! positive) and `f_d` the force asked of it (`Targets::hand_forces`: the static gait's share of
//! the weight, `hand_support`; never less than the touch, `hand_force_n`): pressing harder than
//! asked raises the target, softer lowers it. A hand that finds
//! nothing sinks `hand_press_depth_m` below its planned pose at most and presses on nothing, so
//! the walk goes on without it. The offset of a hand that is not held returns to zero at once.
//!
//! A reach ends `hand_press_depth_m` above its contact ([`reach_goal`]), and the offset of a hand
//! that has just become held starts there, at `+hand_press_depth_m`: the hand comes down onto its
//! support at no more than `hand_press_speed` and stops where it presses with the force asked (a
//! guarded touch). A reach aimed at the contact itself met JVRC-1's rail with 400 N while the
//! dynamic gait walked on, which lifted the foot on the rail's side off the ground.
//!
//! Pure and allocation-free: the controller applies it to each tick's targets just before the QP.

use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Vector3};

use super::config::ControllerConfig;
use super::machine::Targets;

/// The held hands' target offsets (m, world; see the module docs); `None` for a hand not held.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct HandPress {
    offsets: [Option<Vector3<f64>>; 2],
}

/// Where a reach for a hand contact at `contact` (world) ends: `hand_press_depth_m` above it,
/// where the press takes over and lowers the hand onto its support (see the module docs).
pub(crate) fn reach_goal(contact: &Isometry3<f64>, config: &ControllerConfig) -> Isometry3<f64> {
    let mut goal = *contact;
    goal.translation.z += config.hand_press_depth_m;
    goal
}

impl HandPress {
    /// Advances each held hand's offset by `dt` from its wrist's force in `wrenches`
    /// (`EndEffector` order) and moves its pose task in `targets` by it; a hand without a held
    /// pose task (free, reaching, carried) gets no offset.
    pub fn apply(
        &mut self,
        targets: &mut Targets,
        wrenches: &[[f64; 6]; 4],
        config: &ControllerConfig,
        dt: f64,
    ) {
        for (slot, hand) in self.offsets.iter_mut().zip(EndEffector::HANDS) {
            let h = hand as usize;
            let wanted = Vector3::new(
                0.0,
                0.0,
                targets.hand_force_pressed(hand, config.hand_force_n),
            );
            let (true, Some(task)) = (targets.contacts[h], targets.end_effectors[h].as_mut())
            else {
                *slot = None;
                continue;
            };
            // Just held: from where its reach ended (`reach_goal`).
            let offset =
                slot.get_or_insert_with(|| Vector3::new(0.0, 0.0, config.hand_press_depth_m));
            let force = Vector3::new(wrenches[h][0], wrenches[h][1], wrenches[h][2]);
            let speed = config.hand_press_speed;
            let step = (config.hand_admittance * (force - wanted)).map(|v| v.clamp(-speed, speed));
            *offset += step * dt;
            let depth = config.hand_press_depth_m;
            offset.z = offset.z.clamp(-depth, depth);
            let slide = offset.xy().norm();
            if slide > config.hand_press_slide_m {
                let scale = config.hand_press_slide_m / slide;
                offset.x *= scale;
                offset.y *= scale;
            }
            task.pose.translation.vector += *offset;
        }
    }

    /// The current offsets (m; left hand, right hand).
    #[cfg(test)]
    pub fn offsets(&self) -> [Vector3<f64>; 2] {
        self.offsets.map(Option::unwrap_or_default)
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Isometry3;

    use super::*;
    use crate::controller::machine::PoseTarget;

    fn held_right_hand() -> Targets {
        let mut targets = Targets::none();
        targets.contacts = [true, true, false, true];
        targets.end_effectors[3] = Some(PoseTarget {
            pose: Isometry3::translation(0.0, -0.45, 0.86),
            velocity: [0.0; 6],
        });
        targets
    }

    fn wrench(right_hand_z: f64) -> [[f64; 6]; 4] {
        let mut wrenches = [[0.0; 6]; 4];
        wrenches[3][2] = right_hand_z;
        wrenches
    }

    #[test]
    fn a_hand_just_held_starts_at_its_reach_end_and_moves_no_faster_than_the_bound() {
        let config = ControllerConfig::default();
        let dt = 0.002;
        let depth = config.hand_press_depth_m;
        let mut press = HandPress::default();
        // Just held, touching with the force asked: the target stays where the reach ended,
        // hand_press_depth_m above the contact.
        let mut targets = held_right_hand();
        press.apply(&mut targets, &wrench(config.hand_force_n), &config, dt);
        let z = targets.end_effectors[3].unwrap().pose.translation.z;
        assert!((z - (0.86 + depth)).abs() < 1e-12, "{z}");
        let reach_end = reach_goal(&Isometry3::translation(0.0, -0.45, 0.86), &config);
        assert!((reach_end.translation.z - z).abs() < 1e-12);
        // Nothing under it yet: it comes down at 5e-4 × 10 = 0.005 m/s.
        press.apply(&mut held_right_hand(), &wrench(0.0), &config, dt);
        assert!((press.offsets()[1].z - (depth - 0.005 * dt)).abs() < 1e-12);
        for _ in 1..100 {
            press.apply(&mut held_right_hand(), &wrench(0.0), &config, dt);
        }
        let sunk = depth - 100.0 * 0.005 * dt;
        assert!((press.offsets()[1].z - sunk).abs() < 1e-12);
        // 110 N against 10 N asked: up at 5e-4 × 100 = 0.05 m/s, the speed bound; 2000 N too.
        press.apply(&mut held_right_hand(), &wrench(110.0), &config, dt);
        assert!((press.offsets()[1].z - (sunk + 0.05 * dt)).abs() < 1e-12);
        press.apply(&mut held_right_hand(), &wrench(2000.0), &config, dt);
        assert!((press.offsets()[1].z - (sunk + 0.1 * dt)).abs() < 1e-12);
        // Nothing under the hand: it sinks, at most hand_press_depth_m below the contact.
        for _ in 0..10_000 {
            press.apply(&mut held_right_hand(), &wrench(0.0), &config, dt);
        }
        assert_eq!(press.offsets()[1], Vector3::new(0.0, 0.0, -depth));
    }

    #[test]
    fn the_offset_settles_where_the_hand_presses_with_the_asked_force() {
        // A rail whose top is 1 mm into the planned palm pose (170 N) with a stiffness of
        // 1.7e5 N/m (JVRC-1's arm in MuJoCo): the offset settles where the spring gives
        // hand_force_n.
        let (config, dt, stiffness) = (ControllerConfig::default(), 0.002, 1.7e5);
        let mut press = HandPress::default();
        let mut force = 0.0;
        for _ in 0..5000 {
            let mut targets = held_right_hand();
            press.apply(&mut targets, &wrench(force), &config, dt);
            let palm = targets.end_effectors[3].unwrap().pose.translation.z;
            let penetration = 0.86 + 0.001 - palm;
            force = (stiffness * penetration).max(0.0);
        }
        assert!((force - config.hand_force_n).abs() < 0.1, "{force}");
    }

    #[test]
    fn a_hand_pushed_sideways_gives_way_as_far_as_the_slide_bound() {
        // The rail pushes the palm 100 N towards +y while it presses with the force asked: the
        // target moves +y at 5e-4 × 100 = 0.05 m/s, and no farther than hand_press_slide_m.
        let (config, dt) = (ControllerConfig::default(), 0.002);
        let mut press = HandPress::default();
        let mut sideways = wrench(config.hand_force_n);
        sideways[3][1] = 100.0;
        let mut targets = held_right_hand();
        press.apply(&mut targets, &sideways, &config, dt);
        let offset = press.offsets()[1];
        assert!(
            (offset.y - 0.05 * dt).abs() < 1e-12 && offset.x == 0.0,
            "{offset}"
        );
        assert!(
            (targets.end_effectors[3].unwrap().pose.translation.y - (-0.45 + 0.05 * dt)).abs()
                < 1e-12
        );
        for _ in 0..10_000 {
            let mut targets = held_right_hand();
            press.apply(&mut targets, &sideways, &config, dt);
        }
        assert!((press.offsets()[1].y - config.hand_press_slide_m).abs() < 1e-12);
    }

    #[test]
    fn a_hand_that_is_not_held_has_no_offset() {
        let config = ControllerConfig::default();
        let mut press = HandPress::default();
        let mut targets = held_right_hand();
        press.apply(&mut targets, &wrench(0.0), &config, 0.002);
        assert!(press.offsets()[1].z > 0.0);
        targets.contacts[3] = false;
        let before = targets.end_effectors[3];
        press.apply(&mut targets, &wrench(0.0), &config, 0.002);
        assert_eq!(press.offsets(), [Vector3::zeros(); 2]);
        assert_eq!(targets.end_effectors[3].unwrap().pose, before.unwrap().pose);
        // Held again: from the end of its new reach.
        targets.contacts[3] = true;
        press.apply(&mut targets, &wrench(config.hand_force_n), &config, 0.002);
        assert_eq!(
            press.offsets()[1],
            Vector3::new(0.0, 0.0, config.hand_press_depth_m)
        );
    }
}
