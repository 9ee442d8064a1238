//! A human walk, as footprints and per-stance end-effector targets, retargeted to a robot's size:
//! alternating single and double support, steps of 0.55–0.75 m (human) with variance, an
//! interlocking step width with feet crossing the midline, toe-out yaw, heel-strike / heel-off
//! pitch, swing heights up to about 0.2 m, and hand contacts on a railing where allowed. The
//! plan-level impediments (steps too long or too wide, big-foot collisions) are sampled here.

use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Everything the plan needs to know about the robot, measured in its standing posture.
#[derive(Clone, Debug)]
pub(crate) struct Body {
    /// Human-to-robot length scale (robot pelvis height / human pelvis height).
    pub scale: f64,
    /// Horizontal walking direction (mean heading of the standing soles).
    pub forward: Vector3<f64>,
    /// Half the lateral distance between the standing soles.
    pub half_width: f64,
    /// Sole length.
    pub sole_length: f64,
    /// Standing hand poses in the standing path frame (`s`, `e`, `z` = x, y, z).
    pub hands: [Isometry3<f64>; 2],
}

/// Which hands may hold the railing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Railing {
    None,
    Left,
    Right,
}

/// One planned stance: contact flags, world targets (feet always; hands only in contact), and
/// the point the pelvis should be above (the IK's initial guess).
#[derive(Clone, Debug)]
pub(crate) struct PlannedStance {
    pub contacts: [bool; 4],
    pub targets: [Option<Isometry3<f64>>; 4],
    pub support: Vector3<f64>,
}

/// A footprint in path coordinates.
#[derive(Clone, Copy, Debug)]
struct Footprint {
    along: f64,
    lateral: f64,
    yaw: f64,
}

/// Human walking statistics (metres, radians) before scaling to the robot.
const HUMAN_STEP: (f64, f64, f64, f64) = (0.65, 0.05, 0.55, 0.75); // mean, sd, min, max
const HUMAN_STEP_HALF_WIDTH: (f64, f64) = (0.03, 0.035); // mean, sd: offsets < 0 cross the midline
const TOE_OUT: (f64, f64) = (0.12, 0.05);
const SWING_HEIGHT: (f64, f64) = (0.08, 0.20);
const HEEL_STRIKE_PITCH: (f64, f64) = (0.1, 0.3);
const HEEL_OFF_PITCH: (f64, f64) = (0.1, 0.35);
/// Probabilities of the plan-level impediments per step.
const P_LONG_STEP: f64 = 0.15;
const P_WIDE_STEP: f64 = 0.1;
const P_FEET_CROSSING: f64 = 0.2;
/// How far ahead of the pelvis a hand grasps the railing, and the railing's lateral clearance
/// outside the standing hand (human metres).
const HAND_REACH: f64 = 0.1;
const RAILING_CLEARANCE: f64 = 0.1;
/// How much farther sideways than when standing the railing may be from the foot on the hand's
/// side while the hand holds it (human metres): a walker whose steps wander away from the
/// railing lets go of it rather than overstretch the arm.
const RAILING_REACH_SLACK: f64 = 0.1;

/// A Gaussian sample (Box–Muller).
pub(crate) fn gaussian(rng: &mut ChaCha8Rng, mean: f64, sd: f64) -> f64 {
    let u: f64 = rng.random_range(f64::EPSILON..1.0);
    let v: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    mean + sd * (-2.0 * u.ln()).sqrt() * v.cos()
}

impl Body {
    fn lateral_axis(&self) -> Vector3<f64> {
        Vector3::z().cross(&self.forward)
    }

    fn heading(&self) -> f64 {
        self.forward.y.atan2(self.forward.x)
    }

    /// World point of path coordinates.
    fn point(&self, along: f64, lateral: f64, z: f64) -> Vector3<f64> {
        self.forward * along + self.lateral_axis() * lateral + Vector3::z() * z
    }

    /// World pose of path coordinates and roll/pitch/yaw relative to the walking direction.
    fn pose(&self, along: f64, lateral: f64, z: f64, rpy: [f64; 3]) -> Isometry3<f64> {
        let rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), self.heading())
            * UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]);
        Isometry3::from_parts(Translation3::from(self.point(along, lateral, z)), rotation)
    }

    /// Sole pose of a footprint, pitched about its heel (pitch < 0) or toe (pitch > 0) edge
    /// resting on the ground, so the origin rises by half the sole length times sin|pitch|.
    fn sole(&self, print: &Footprint, pitch: f64) -> Isometry3<f64> {
        let rise = 0.5 * self.sole_length * pitch.abs().sin();
        self.pose(print.along, print.lateral, rise, [0.0, pitch, print.yaw])
    }

    /// The railing a hand holds: a segment along the path outside the standing hand.
    pub fn railing(&self, railing: Railing, distance: f64) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let hand = match railing {
            Railing::None => return None,
            Railing::Left => &self.hands[0],
            Railing::Right => &self.hands[1],
        };
        let side = hand.translation.y.signum();
        let lateral = hand.translation.y + side * RAILING_CLEARANCE * self.scale;
        let z = hand.translation.z;
        Some((
            self.point(-0.5, lateral, z),
            self.point(distance + 0.5, lateral, z),
        ))
    }
}

/// Plans a walk of `distance` metres along the body's forward direction; the railing hand may
/// hold while the walk is inside `available` (metres along the path).
pub(crate) fn plan(
    body: &Body,
    distance: f64,
    railing: Railing,
    available: [f64; 2],
    rng: &mut ChaCha8Rng,
) -> Vec<PlannedStance> {
    let first_swing = usize::from(rng.random_bool(0.5));
    let prints = footprints(body, distance, first_swing, rng);
    let mut stances = Vec::with_capacity(2 * prints.len());
    let mut hands = HandSchedule::new(body, railing, distance, available);
    // prints[0] and prints[1] are the standing left and right footprints; then alternate.
    let mut feet = [prints[0], prints[1]];
    let mut start = standing_still(body, &feet);
    hands.apply(&mut start, None, body);
    stances.push(start);
    for (k, next) in prints[2..].iter().enumerate() {
        let swing = (first_swing + k) % 2;
        let support = 1 - swing;
        let from = feet[swing];
        // Single support: the swing foot half-way, lifted, pitched.
        let mid = Footprint {
            along: 0.5 * (from.along + next.along),
            lateral: 0.5 * (from.lateral + next.lateral),
            yaw: 0.5 * (from.yaw + next.yaw),
        };
        let height = rng.random_range(SWING_HEIGHT.0..SWING_HEIGHT.1) * body.scale;
        let swing_pitch = gaussian(rng, 0.0, 0.15);
        let mut single = PlannedStance {
            contacts: [false; 4],
            targets: [None; 4],
            support: body.point(feet[support].along, 0.6 * feet[support].lateral, 0.0),
        };
        single.contacts[support] = true;
        single.targets[support] = Some(body.sole(&feet[support], 0.0));
        single.targets[swing] =
            Some(body.pose(mid.along, mid.lateral, height, [0.0, swing_pitch, mid.yaw]));
        hands.apply(&mut single, Some(swing), body);
        stances.push(single);
        // Double support: heel strike of the landing foot, heel-off of the trailing foot.
        feet[swing] = *next;
        let strike = -rng.random_range(HEEL_STRIKE_PITCH.0..HEEL_STRIKE_PITCH.1);
        let heel_off = rng.random_range(HEEL_OFF_PITCH.0..HEEL_OFF_PITCH.1);
        let mut double = PlannedStance {
            contacts: [true, true, false, false],
            targets: [None; 4],
            support: body.point(0.5 * (feet[0].along + feet[1].along), 0.0, 0.0),
        };
        double.targets[swing] = Some(body.sole(&feet[swing], strike));
        double.targets[support] = Some(body.sole(&feet[support], heel_off));
        hands.apply(&mut double, None, body);
        stances.push(double);
    }
    // Come to rest: both soles flat.
    let mut rest = standing_still(body, &feet);
    hands.apply(&mut rest, None, body);
    stances.push(rest);
    stances
}

/// Double support with both soles flat on their footprints.
fn standing_still(body: &Body, feet: &[Footprint; 2]) -> PlannedStance {
    PlannedStance {
        contacts: [true, true, false, false],
        targets: [
            Some(body.sole(&feet[0], 0.0)),
            Some(body.sole(&feet[1], 0.0)),
            None,
            None,
        ],
        support: body.point(0.5 * (feet[0].along + feet[1].along), 0.0, 0.0),
    }
}

/// Footprints: standing left, standing right, then alternating steps (starting with foot
/// `first_swing`, 0 = left) until `distance`, closed by the trailing foot stepping alongside.
fn footprints(
    body: &Body,
    distance: f64,
    first_swing: usize,
    rng: &mut ChaCha8Rng,
) -> Vec<Footprint> {
    let standing = |side: f64| Footprint {
        along: 0.0,
        lateral: side * body.half_width,
        yaw: 0.0,
    };
    let mut prints = vec![standing(1.0), standing(-1.0)];
    let mut lead = 0.0;
    let mut side = if first_swing == 0 { 1.0 } else { -1.0 }; // +1 = left foot steps next
    loop {
        let mut step = gaussian(rng, HUMAN_STEP.0, HUMAN_STEP.1).clamp(HUMAN_STEP.2, HUMAN_STEP.3)
            * body.scale;
        if rng.random_bool(P_LONG_STEP) {
            step *= rng.random_range(1.3..1.7);
        }
        let mut half_width =
            gaussian(rng, HUMAN_STEP_HALF_WIDTH.0, HUMAN_STEP_HALF_WIDTH.1) * body.scale;
        if rng.random_bool(P_WIDE_STEP) {
            half_width = rng.random_range(0.2..0.35) * body.scale; // a side-step
        } else if rng.random_bool(P_FEET_CROSSING) {
            half_width = -rng.random_range(0.0..0.06) * body.scale;
        }
        let done = lead + step >= distance;
        lead = if done { distance } else { lead + step };
        let yaw = side * gaussian(rng, TOE_OUT.0, TOE_OUT.1);
        prints.push(Footprint {
            along: lead,
            lateral: side * half_width,
            yaw,
        });
        side = -side;
        if done {
            prints.push(Footprint {
                along: lead,
                lateral: side * body.half_width,
                yaw: 0.0,
            });
            return prints;
        }
    }
}

/// When and where the railing hand grasps: it holds while its stance is inside the railing's
/// available part of the path and the railing is within the arm's reach of the foot on its side,
/// and lets go (to move ahead) while that foot swings.
struct HandSchedule {
    hand: Option<(usize, usize)>, // (end-effector index, foot index on the same side)
    railing: Option<(Vector3<f64>, Vector3<f64>)>,
    available: [f64; 2],
    /// Largest lateral distance between the railing and the foot on the hand's side for a grasp.
    reach: f64,
    grasp: Option<Isometry3<f64>>,
}

impl HandSchedule {
    fn new(body: &Body, railing: Railing, distance: f64, available: [f64; 2]) -> Self {
        let hand = match railing {
            Railing::None => None,
            Railing::Left => Some((EndEffector::LeftHand as usize, 0)),
            Railing::Right => Some((EndEffector::RightHand as usize, 1)),
        };
        let railing = body.railing(railing, distance);
        let reach = match (hand, railing) {
            (Some((_, foot)), Some((start, _))) => {
                let side = if foot == 0 { 1.0 } else { -1.0 };
                let standing_foot = side * body.half_width;
                (body.lateral_axis().dot(&start) - standing_foot).abs()
                    + RAILING_REACH_SLACK * body.scale
            }
            _ => 0.0,
        };
        Self {
            hand,
            railing,
            available,
            reach,
            grasp: None,
        }
    }

    fn apply(&mut self, stance: &mut PlannedStance, swinging_foot: Option<usize>, body: &Body) {
        let (Some((hand, foot)), Some((start, _))) = (self.hand, self.railing) else {
            return;
        };
        let along = stance.support.dot(&body.forward);
        let available = (self.available[0]..=self.available[1]).contains(&along);
        let within_reach = stance.targets[foot].is_some_and(|sole| {
            let lateral = body.lateral_axis().dot(&(start - sole.translation.vector));
            lateral.abs() <= self.reach
        });
        if !available || swinging_foot == Some(foot) || !within_reach {
            self.grasp = None;
            return;
        }
        let standing = &body.hands[hand - EndEffector::LeftHand as usize];
        let grasp = *self.grasp.get_or_insert_with(|| {
            let at = along + HAND_REACH * body.scale;
            let point = start + body.forward * (at - start.dot(&body.forward));
            let rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), body.heading())
                * standing.rotation;
            Isometry3::from_parts(Translation3::from(point), rotation)
        });
        stance.contacts[hand] = true;
        stance.targets[hand] = Some(grasp);
    }
}
