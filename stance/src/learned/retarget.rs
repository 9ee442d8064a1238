//! Retargeting generated human stances to a robot (the MMM analogue): human lengths are scaled
//! by the robot's pelvis height over the human's, every stance's end-effector targets are laid
//! out along the robot's walking direction, and a per-stance IK (weighted position and rotation
//! errors, joints within limits, warm-started from the previous stance) gives `q_S` and the root
//! pose. Nothing is cleaned up: the raw sequence keeps the demonstrations' natural impediments
//! (jumping contacts, toe-out, pitched soles, uneven steps) for post-processing to remove.

use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::error::LearnError;
use super::model::NgramModel;
use super::pace::{Pace, PathStretch, RobotGait, SpeedRequest};
use super::query::{Generated, Query, Search, generate_tokens};
use crate::environment::{Environment, HandAffordance};
use crate::generate::AffordanceSet;
use crate::generate::standing::Standing;
use crate::sequence::{RawSequence, Stance};
use crate::stance_ik::StanceIk;

/// Rounds of generating a paced walk and setting its stretch ([`generate_learned`]).
const PACE_ROUNDS: usize = 4;

/// A stretch within this relative difference of the one the walk was generated for is kept.
const PACE_TOLERANCE: f64 = 0.03;

/// What to generate with a learned model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LearnedOptions {
    /// Distance to cover along the robot's forward direction (robot metres; divide by scf first
    /// to cover it after post-processing).
    pub distance: f64,
    /// Which hands may hold the railing.
    pub affordances: AffordanceSet,
    /// Part of the path `[from, to]` (robot metres, same scale as `distance`) along which the
    /// railing is available; `None` = the whole path.
    pub railing: Option<[f64; 2]>,
    /// Beam search (most probable) or seeded sampling.
    pub search: Search,
    /// A walking speed to pace the walk for; `None`: the human pace at the robot's size
    /// ([`super::pace`]).
    pub speed: Option<SpeedRequest>,
}

/// The robot's walking frame and size, measured in its standing posture.
struct RobotFrame {
    /// Human-to-robot length scale.
    scale: f64,
    /// The robot's leg length: its standing pelvis height above the soles (m).
    leg_length: f64,
    /// The human path's forward lengths on the robot's ([`PathStretch`]).
    path: PathStretch,
    /// Unit walking direction (horizontal).
    forward: Vector3<f64>,
    /// Standing hand orientations in the world.
    hand_rotations: [UnitQuaternion<f64>; 2],
}

impl RobotFrame {
    fn measure(robot: &Robot, human_pelvis_height: f64) -> Self {
        let standing = Standing::measure(robot);
        Self {
            scale: standing.pelvis_height / human_pelvis_height,
            leg_length: standing.pelvis_height,
            path: PathStretch::NONE,
            forward: standing.forward,
            hand_rotations: [
                standing.pose(EndEffector::LeftHand).rotation,
                standing.pose(EndEffector::RightHand).rotation,
            ],
        }
    }

    fn heading(&self) -> f64 {
        self.forward.y.atan2(self.forward.x)
    }

    /// World point of human path coordinates (along, lateral, height), scaled (and stretched
    /// along the path).
    fn point(&self, human: Vector3<f64>) -> Vector3<f64> {
        let lateral = Vector3::z().cross(&self.forward);
        (self.forward * self.path.map(human.x) + lateral * human.y + Vector3::z() * human.z)
            * self.scale
    }
}

/// Per-stance world targets (robot scale) of a generated token sequence, and its duration.
struct StanceTargets {
    contacts: [bool; 4],
    targets: [Option<Isometry3<f64>>; 4],
    root: Vector3<f64>,
    duration_s: f64,
}

fn lay_out(
    model: &NgramModel,
    generated: &Generated,
    frame: &RobotFrame,
    pace: &Pace,
) -> Vec<StanceTargets> {
    let heading = frame.heading();
    generated
        .tokens
        .iter()
        .zip(&generated.progress)
        .zip(&generated.hands)
        .map(|((&id, &along), &hands)| {
            let token = model.token(id);
            let root = Vector3::new(along, 0.0, token.root_height);
            let contacts = [token.contacts[0], token.contacts[1], hands[0], hands[1]];
            let mut targets = [None; 4];
            for e in EndEffector::ALL {
                let k = e as usize;
                if !e.is_foot() && !contacts[k] {
                    continue;
                }
                // A grasp the hand-support model added takes that model's mean grasp pose.
                let added = || {
                    let feet = [contacts[0], contacts[1]];
                    model.hand_support(feet, k - 2).and_then(|h| h.pose)
                };
                let pose = match token.effectors[k] {
                    Some(pose) if e.is_foot() || token.contacts[k] => Some(pose),
                    _ => added(),
                };
                let Some(pose) = pose else {
                    continue;
                };
                let position = frame.point(root + Vector3::from(pose.position));
                let rotation = if e.is_foot() {
                    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), heading + pose.yaw)
                        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), pose.pitch)
                } else {
                    frame.hand_rotations[k - 2]
                };
                targets[k] = Some(Isometry3::from_parts(
                    Translation3::from(position),
                    rotation,
                ));
            }
            StanceTargets {
                contacts,
                targets,
                root: frame.point(root),
                duration_s: pace.duration(token),
            }
        })
        .collect()
}

/// Hand availability along the human-scale path for an affordance set and railing interval.
fn hand_intervals(set: AffordanceSet, interval: [f64; 2]) -> [Vec<[f64; 2]>; 2] {
    let all = vec![interval];
    match set {
        AffordanceSet::Feet => [Vec::new(), Vec::new()],
        AffordanceSet::FeetLeftHand => [all, Vec::new()],
        AffordanceSet::FeetRightHand => [Vec::new(), all],
    }
}

/// A retargeted sequence with what it came from and how well the IK met its targets.
#[derive(Clone, Debug)]
pub struct Retargeted {
    /// The raw robot sequence.
    pub raw: RawSequence,
    /// The generated human-scale token sequence.
    pub generated: Generated,
    /// Per stance, the IK's remaining `[position error (m), orientation error (rad)]`.
    pub ik_errors: Vec<[f64; 2]>,
    /// With a speed request: what the gait law asked of the robot.
    pub gait: Option<RobotGait>,
}

/// Generates a raw stance sequence for `robot` from a learned model: query (human scale),
/// pace ([`super::pace`]), lay-out, per-stance IK. The stances carry their durations.
pub fn generate_learned(
    robot: &Robot,
    model: &NgramModel,
    options: &LearnedOptions,
) -> Result<Retargeted, LearnError> {
    let mut frame = RobotFrame::measure(robot, model.human_pelvis_height);
    let railing = options.railing.unwrap_or([0.0, options.distance]);
    // Human path metres before the stretch (and its ramps): the stretched walk covers the
    // distance.
    let query = |stretch: f64, ramp: f64| Query {
        distance: options.distance / frame.scale / stretch + ramp / 2.0,
        hands: hand_intervals(
            options.affordances,
            railing.map(|s| s / frame.scale / stretch),
        ),
        search: options.search,
    };
    let (generated, pace, gait) = match options.speed {
        None => (
            generate_tokens(model, &query(1.0, 0.0))?,
            Pace::similar(frame.scale),
            None,
        ),
        Some(request) => {
            let gait = RobotGait::of(model, frame.leg_length, request.speed.m_s)?;
            // The stretch depends on the walk's own stances, and the walk on the distance it
            // is asked for, which the stretch sets: a few rounds bring them together. The walk
            // is laid out at the stretch it was generated for (so it covers the distance), its
            // times corrected by what is left between the two (so it walks at the speed).
            let (mut stretch, mut ramp) = (1.0, 0.0);
            let mut walk = None;
            for _ in 0..PACE_ROUNDS {
                let generated = generate_tokens(model, &query(stretch, ramp))?;
                let pace = Pace::for_speed(model, &generated, &gait, request, frame.scale)?;
                let settled = (pace.stretch / stretch - 1.0).abs() < PACE_TOLERANCE;
                let next = pace.stretch;
                ramp = pace.ramp;
                walk = Some((generated, pace.at_stretch(stretch)));
                if settled {
                    break;
                }
                stretch = next;
            }
            let (generated, pace) = walk.expect("at least one round");
            (generated, pace, Some(gait))
        }
    };
    let end = generated.progress.last().copied().unwrap_or(0.0);
    frame.path = PathStretch::new(pace.stretch, pace.ramp, end);
    let layout = lay_out(model, &generated, &frame, &pace);
    let (stances, ik_errors) = solve(robot, &layout)?;
    let environment = environment(&layout, options, &frame);
    let raw = RawSequence::new(
        robot.name.clone(),
        robot.model.joint_names().to_vec(),
        environment,
        stances,
    )
    .map_err(|e| LearnError::Retarget(e.to_string()))?;
    Ok(Retargeted {
        raw,
        generated,
        gait,
        ik_errors,
    })
}

/// The ground plus, for a hand set, a railing through the generated grasps (or beside the
/// standing hand if the model generated none), available along the whole path.
fn environment(
    layout: &[StanceTargets],
    options: &LearnedOptions,
    frame: &RobotFrame,
) -> Environment {
    let mut environment = Environment::default();
    let hand = match options.affordances {
        AffordanceSet::Feet => return environment,
        AffordanceSet::FeetLeftHand => 2,
        AffordanceSet::FeetRightHand => 3,
    };
    let grasps: Vec<Vector3<f64>> = layout
        .iter()
        .filter_map(|s| s.targets[hand].map(|t| t.translation.vector))
        .collect();
    let lateral_axis = Vector3::z().cross(&frame.forward);
    let (lateral, height) = if grasps.is_empty() {
        let side = if hand == 2 { 1.0 } else { -1.0 };
        (side * 0.35 * frame.scale, 0.9 * frame.scale)
    } else {
        let n = grasps.len() as f64;
        (
            grasps.iter().map(|g| g.dot(&lateral_axis)).sum::<f64>() / n,
            grasps.iter().map(|g| g.z).sum::<f64>() / n,
        )
    };
    let at = |along: f64| frame.forward * along + lateral_axis * lateral + Vector3::z() * height;
    environment.hand_affordances.push(HandAffordance {
        name: "railing".to_owned(),
        start: at(-0.5),
        end: at(options.distance + 0.5),
        radius: 0.0,
        available: options.railing.unwrap_or([0.0, options.distance]),
    });
    environment
}

/// The stances and the IK's remaining `[position, orientation]` error of each.
fn solve(
    robot: &Robot,
    layout: &[StanceTargets],
) -> Result<(Vec<Stance>, Vec<[f64; 2]>), LearnError> {
    let mut ik = StanceIk::new(robot);
    let mut current_root = Vector3::zeros();
    let mut stances = Vec::with_capacity(layout.len());
    let mut errors = Vec::with_capacity(layout.len());
    for (i, stance) in layout.iter().enumerate() {
        // Warm start: the previous solution carried along with the human root.
        let mut initial = ik.current().clone();
        initial.base.translation.vector.x += stance.root.x - current_root.x;
        initial.base.translation.vector.y += stance.root.y - current_root.y;
        let solved = ik
            .solve(&stance.targets, stance.contacts, &initial)
            .map_err(|error| LearnError::Retarget(format!("stance {i}: {error}")))?;
        errors.push(solved.errors);
        stances.push(Stance {
            duration_s: Some(stance.duration_s),
            ..solved.stance
        });
        current_root = stance.root;
    }
    Ok((stances, errors))
}
