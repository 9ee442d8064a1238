//! Free hands keep clear of the walk's railings.
//!
//! A hand that holds nothing follows the posture task, and the posture knows nothing of the
//! scene: walking beside a railing at 0.45 m, JVRC-1's hanging right palm is 7 cm from the rail,
//! and shifting the weight onto the right foot swings it out under the rail, which then holds
//! it down and tips the robot (docs/mujoco.md). So a hand that is neither held nor reaching for
//! a contact keeps its palm at least `radius + palm_radius + hand_clearance_m` from every
//! railing's axis: where its target (or, without one, the hand itself) comes closer, an offset
//! moves it back out, straight away from the axis (up, for a released hand still on top of the
//! rail). The offset follows what is needed no faster than `hand_clearance_speed`, so a hand
//! let go on the rail lifts off it smoothly instead of jumping. Only railings with a radius
//! count: a scene's railings are bodies in the world; the line a stance source generates its
//! hand contacts along (radius 0) is not.
//!
//! Pure and allocation-free: the controller applies it to each tick's targets just before the
//! QP, after the held hands' press.

use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Vector3};
use stance::geometry::nearest_on_segment;

use super::config::ControllerConfig;
use super::machine::{PoseTarget, Targets};

/// A railing's axis (a segment, world or sequence frame) and its radius (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct RailAxis {
    pub start: Vector3<f64>,
    pub end: Vector3<f64>,
    pub radius: f64,
}

impl RailAxis {
    /// The railings of a scene (those with a radius) among `affordances`.
    pub fn of_scene(affordances: &[stance::HandAffordance]) -> Vec<Self> {
        affordances
            .iter()
            .filter(|railing| railing.radius > 0.0)
            .map(|railing| Self {
                start: railing.start,
                end: railing.end,
                radius: railing.radius,
            })
            .collect()
    }

    /// The same railing seen through `frame` (a sequence frame's pose in the world).
    pub fn transformed(&self, frame: &Isometry3<f64>) -> Self {
        Self {
            start: frame.transform_point(&self.start.into()).coords,
            end: frame.transform_point(&self.end.into()).coords,
            ..*self
        }
    }

    /// The point of the axis nearest to `point`.
    fn nearest(&self, point: &Vector3<f64>) -> Vector3<f64> {
        nearest_on_segment(&self.start, &self.end, point)
    }
}

/// The free hands' offsets out of the railings' way (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct HandClearance {
    offsets: [Vector3<f64>; 2],
}

impl HandClearance {
    /// Advances each free hand's offset by `dt` towards what keeps it clear of `railings` (world
    /// frame) and moves its pose task in `targets` by it. `poses` are the estimated end-effector
    /// poses (`EndEffector` order), the base of a hand without a target; `palm_radius` in m. A
    /// held or reaching hand gets no offset.
    pub fn apply(
        &mut self,
        targets: &mut Targets,
        poses: &[Isometry3<f64>; 4],
        railings: impl Iterator<Item = RailAxis> + Clone,
        palm_radius: f64,
        config: &ControllerConfig,
        dt: f64,
    ) {
        for (offset, hand) in self.offsets.iter_mut().zip(EndEffector::HANDS) {
            let h = hand as usize;
            if targets.contacts[h] || targets.reaching[h] {
                *offset = Vector3::zeros();
                continue;
            }
            let base = targets.end_effectors[h].map_or(poses[h], |target| target.pose);
            let wanted = push_out(
                &base.translation.vector,
                railings.clone(),
                palm_radius + config.hand_clearance_m,
            );
            let step = wanted - *offset;
            let reach = config.hand_clearance_speed * dt;
            *offset += if step.norm() > reach {
                step.normalize() * reach
            } else {
                step
            };
            if *offset != Vector3::zeros() {
                let mut pose = base;
                pose.translation.vector += *offset;
                targets.end_effectors[h] = Some(PoseTarget {
                    pose,
                    velocity: [0.0; 6],
                });
            }
        }
    }

    /// The current offsets (m; left hand, right hand).
    #[cfg(test)]
    pub fn offsets(&self) -> [Vector3<f64>; 2] {
        self.offsets
    }
}

/// How far `point` must move to lie at least `clearance` beyond the surface of each of
/// `railings`: straight away from the nearest point of each axis in turn (up from a point on
/// an axis).
fn push_out(
    point: &Vector3<f64>,
    railings: impl Iterator<Item = RailAxis>,
    clearance: f64,
) -> Vector3<f64> {
    let mut moved = *point;
    for railing in railings {
        let distance = railing.radius + clearance;
        let axis = railing.nearest(&moved);
        let away = moved - axis;
        if away.norm() < distance {
            moved = axis + away.try_normalize(1e-9).unwrap_or_else(Vector3::z) * distance;
        }
    }
    moved - point
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `railing.toml`'s rail: 0.45 m right of the path, 0.8 m high, 0.02 m in radius.
    fn rail() -> RailAxis {
        RailAxis {
            start: Vector3::new(-0.5, -0.45, 0.8),
            end: Vector3::new(5.5, -0.45, 0.8),
            radius: 0.02,
        }
    }

    const PALM: f64 = 0.04;
    const RIGHT: usize = EndEffector::RightHand as usize;

    fn poses_with_right_hand_at(position: Vector3<f64>) -> [Isometry3<f64>; 4] {
        let mut poses = [Isometry3::identity(); 4];
        poses[RIGHT] = Isometry3::translation(position.x, position.y, position.z);
        poses
    }

    /// The right hand's target after `ticks` of 2 ms with the hand held at `poses`.
    fn settle(
        clearance: &mut HandClearance,
        targets: &Targets,
        poses: &[Isometry3<f64>; 4],
        ticks: usize,
    ) -> Targets {
        let config = ControllerConfig::default();
        let mut out = *targets;
        for _ in 0..ticks {
            out = *targets;
            clearance.apply(&mut out, poses, [rail()].into_iter(), PALM, &config, 0.002);
        }
        out
    }

    #[test]
    fn a_free_palm_near_the_rail_is_sent_back_out_straight_away_from_the_axis() {
        // Just below the rail's axis and 6 cm inside it: the hook of docs/mujoco.md.
        let poses = poses_with_right_hand_at(Vector3::new(1.0, -0.39, 0.78));
        let mut clearance = HandClearance::default();
        let out = settle(&mut clearance, &Targets::none(), &poses, 1000);
        let target = out.end_effectors[RIGHT]
            .expect("a target")
            .pose
            .translation
            .vector;
        let from_axis = target - Vector3::new(1.0, -0.45, 0.8);
        let wanted = 0.02 + PALM + ControllerConfig::default().hand_clearance_m;
        assert!((from_axis.norm() - wanted).abs() < 1e-12, "{from_axis}");
        let before = Vector3::new(0.0, 0.06, -0.02).normalize();
        assert!(
            (from_axis.normalize() - before).norm() < 1e-12,
            "{from_axis}"
        );
        assert!(out.end_effectors[EndEffector::LeftHand as usize].is_none());
    }

    #[test]
    fn a_hand_let_go_on_top_of_the_rail_lifts_off_it_no_faster_than_the_bound() {
        let config = ControllerConfig::default();
        let mut targets = Targets::none();
        let on_top = Isometry3::translation(2.0, -0.45, 0.8 + 0.02 + PALM);
        targets.end_effectors[RIGHT] = Some(PoseTarget {
            pose: on_top,
            velocity: [0.0; 6],
        });
        let poses = [Isometry3::identity(); 4];
        let mut clearance = HandClearance::default();
        let out = settle(&mut clearance, &targets, &poses, 1);
        let first = out.end_effectors[RIGHT].unwrap().pose.translation.z - on_top.translation.z;
        assert!(
            (first - config.hand_clearance_speed * 0.002).abs() < 1e-12,
            "{first}"
        );
        let out = settle(&mut clearance, &targets, &poses, 1000);
        let target = out.end_effectors[RIGHT].unwrap().pose.translation;
        assert!((target.z - (0.8 + 0.02 + PALM + config.hand_clearance_m)).abs() < 1e-12);
        assert!((target.y + 0.45).abs() < 1e-12);
    }

    #[test]
    fn held_reaching_and_distant_hands_and_lines_without_radius_are_left_alone() {
        let near = poses_with_right_hand_at(Vector3::new(1.0, -0.39, 0.78));
        for (held, reaching) in [(true, false), (false, true)] {
            let mut targets = Targets::none();
            targets.contacts[RIGHT] = held;
            targets.reaching[RIGHT] = reaching;
            let mut clearance = HandClearance::default();
            let out = settle(&mut clearance, &targets, &near, 10);
            assert!(out.end_effectors[RIGHT].is_none());
            assert_eq!(clearance.offsets(), [Vector3::zeros(); 2]);
        }
        let far = poses_with_right_hand_at(Vector3::new(1.0, -0.3, 0.78));
        let mut clearance = HandClearance::default();
        assert!(settle(&mut clearance, &Targets::none(), &far, 10).end_effectors[RIGHT].is_none());
        let line = stance::HandAffordance {
            name: "railing".to_owned(),
            start: rail().start,
            end: rail().end,
            radius: 0.0,
            available: [0.0, 5.0],
        };
        assert!(RailAxis::of_scene(&[line]).is_empty());
    }
}
