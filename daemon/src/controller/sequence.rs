//! [`PreparedSequence`]: a post-processed stance sequence checked against the robot and the
//! controller's limits, converted to the controller's storage off the real-time path.

use kinematics::robot::{EndEffector, Robot};
use nalgebra::{DVector, Isometry3, Vector3};

use super::config::ControllerConfig;
use super::gait::DynamicPlan;
use super::hand_clearance::RailAxis;

/// Tolerance on the posture's joint limits (rad): `q_S` from IK sits on a limit at most by round-off.
const LIMIT_TOLERANCE: f64 = 1e-6;

/// Tolerance on a step's height against `max_step_up_m` / `max_step_down_m` (m): a stair's riser
/// of exactly the limit passes, whatever the round-off of the soles' placement.
const HEIGHT_TOLERANCE_M: f64 = 1e-4;

/// The scene a gait is set to take: the highest step up and down (m) a foot may land above or
/// below the other foot's sole (a stair's riser), the steepest surface (rad) a sole may stand on,
/// whether a hand may hold a railing, and the config section that sets them (named in a
/// refusal). A stair or ramp a robot's legs cannot take tips it over at the first stair (JVRC-1's
/// dynamic gait up and down 0.185 m stairs, MuJoCo) or lets it fall on the slope (ARMAR-4's
/// static gait on the 10° ramp), and a hand on a railing a gait cannot walk with pulls the robot
/// over (JVRC-1's dynamic gait, ARMAR-4's both), after which a held robot falls: refused before
/// anything moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneLimits {
    /// Highest step up (m).
    pub up: f64,
    /// Highest step down (m).
    pub down: f64,
    /// Steepest sole in contact, its tilt from horizontal (rad).
    pub slope: f64,
    /// Whether a hand may be in contact in a sequence whose scene has railings (the hand then
    /// holds one).
    pub hold_railings: bool,
    /// The section holding `max_step_up_m`, `max_step_down_m`, `max_slope_rad` and
    /// `hold_railings` (`[controller]`, `[gait.dynamic]`).
    pub section: &'static str,
}

/// Tolerance on a sole's tilt against `max_slope_rad` (rad): a level tread's sole is level to
/// round-off, and a ramp of exactly the limit passes.
const SLOPE_TOLERANCE_RAD: f64 = 1e-4;

/// Why a sequence is refused; the message names the stance and field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("sequence refused: {0}")]
pub struct Refusal(pub String);

/// One stance as the controller executes it.
#[derive(Debug, Clone)]
pub(crate) struct PreparedStance {
    /// Posture reference `q_S` (model joint order).
    pub posture: DVector<f64>,
    /// Contact flags by `EndEffector`.
    pub contacts: [bool; 4],
    /// Target poses by `EndEffector`, in the sequence's world frame.
    pub targets: [Isometry3<f64>; 4],
    /// How long the walk stays in this stance (s, from the demonstrations; `None`: untimed). The
    /// dynamic gait times its phases by it within the config's limits.
    pub duration_s: Option<f64>,
}

/// A validated sequence ready for [`super::Controller::start`]; building it may allocate, so it is
/// done off the real-time path (see [`super::Controller::prepare`]).
#[derive(Debug, Clone)]
pub struct PreparedSequence {
    pub(crate) stances: Vec<PreparedStance>,
    /// The dynamic gait's plan; `None` for the static gait.
    pub(crate) dynamic: Option<Box<DynamicPlan>>,
    /// The scene's railings, in the sequence's world frame: free hands keep clear of them
    /// (`hand_clearance`).
    pub(crate) railings: Vec<RailAxis>,
}

impl PreparedSequence {
    /// The gait the sequence is executed with.
    pub fn gait(&self) -> stance::Gait {
        if self.dynamic.is_some() {
            stance::Gait::Dynamic
        } else {
            stance::Gait::Static
        }
    }

    /// Number of stances.
    pub fn len(&self) -> usize {
        self.stances.len()
    }

    /// The scene's railings seen through `to_world` (the sequence frame's pose in the world).
    pub(crate) fn railings_in<'a>(
        &'a self,
        to_world: &'a Isometry3<f64>,
    ) -> impl Iterator<Item = RailAxis> + Clone + 'a {
        self.railings
            .iter()
            .map(|railing| railing.transformed(to_world))
    }

    /// Always false: an empty sequence is refused.
    pub fn is_empty(&self) -> bool {
        self.stances.is_empty()
    }

    /// Checks `seq` against `robot` and `config` and converts it.
    ///
    /// Refused: another robot or joint order, an empty sequence, a non-finite value, a posture
    /// beyond a joint limit, a stance without foot support, a step between consecutive contacts
    /// of one foot longer than `config.max_step_m`, or higher up or down than `scene` allows, a
    /// sole in contact on a slope steeper than it, or a hand held on a railing it does not hold
    /// (the gait's).
    pub fn new(
        robot: &Robot,
        config: &ControllerConfig,
        scene: &SceneLimits,
        seq: &stance::PostProcessedSequence,
    ) -> Result<Self, Refusal> {
        seq.check_robot(robot)
            .map_err(|e| Refusal(format!("wrong robot: {e}")))?;
        if seq.is_empty() {
            return Err(Refusal("the sequence has no stance".to_owned()));
        }
        let limits = robot.model.joint_limits();
        let names = robot.model.joint_names();
        let mut stances = Vec::with_capacity(seq.len());
        for i in 0..seq.len() {
            let posture = seq.posture(i);
            if posture.len() != limits.len() {
                return Err(Refusal(format!(
                    "stance {i}: posture has {} joints, the robot {}",
                    posture.len(),
                    limits.len()
                )));
            }
            for (j, (&q, limit)) in posture.iter().zip(limits).enumerate() {
                if !q.is_finite() {
                    return Err(Refusal(format!(
                        "stance {i}: q[{j}] ({}) is not finite",
                        names[j]
                    )));
                }
                if q < limit.lower - LIMIT_TOLERANCE || q > limit.upper + LIMIT_TOLERANCE {
                    return Err(Refusal(format!(
                        "stance {i}: q[{j}] ({}) = {q:.4} is outside its limits [{:.4}, {:.4}]",
                        names[j], limit.lower, limit.upper
                    )));
                }
            }
            let contacts = seq.contacts(i);
            if !contacts[EndEffector::LeftFoot as usize]
                && !contacts[EndEffector::RightFoot as usize]
            {
                return Err(Refusal(format!("stance {i}: no foot in contact")));
            }
            let targets = *seq.targets(i);
            for (e, target) in EndEffector::ALL.iter().zip(&targets) {
                let finite = target.translation.vector.iter().all(|v| v.is_finite())
                    && target.rotation.coords.iter().all(|v| v.is_finite());
                if !finite {
                    return Err(Refusal(format!(
                        "stance {i}: target {} is not finite",
                        e.name()
                    )));
                }
            }
            stances.push(PreparedStance {
                posture: DVector::from_column_slice(posture),
                contacts,
                targets: targets.map(|t| Isometry3::from_parts(t.translation, t.rotation)),
                duration_s: seq.stances()[i].duration_s,
            });
        }
        check_steps(&stances, config.max_step_m, scene)?;
        check_slopes(&stances, scene)?;
        check_workspace(&stances, config)?;
        let railings = RailAxis::of_scene(&seq.environment().hand_affordances);
        check_held_hands(&stances, &railings, scene)?;
        Ok(Self {
            stances,
            dynamic: None,
            railings,
        })
    }
}

/// Refuses, in a scene with `railings`, a hand in contact (holding one) where
/// `scene.hold_railings` is off: the gait has not been measured to walk with a hand on a railing.
/// Without railings a held hand touches nothing and stays a pose task, which every gait walks.
fn check_held_hands(
    stances: &[PreparedStance],
    railings: &[RailAxis],
    scene: &SceneLimits,
) -> Result<(), Refusal> {
    if railings.is_empty() || scene.hold_railings {
        return Ok(());
    }
    for (i, stance) in stances.iter().enumerate() {
        if let Some(hand) = EndEffector::HANDS
            .into_iter()
            .find(|hand| stance.contacts[*hand as usize])
        {
            return Err(Refusal(format!(
                "stance {i}: {} holds a railing, which {} hold_railings = false refuses: this \
                 gait is not set to walk with a hand on a railing; walk with the feet alone \
                 (--affordances feet) (docs/scenes.md, \"Hands on railings\")",
                hand.name(),
                scene.section
            )));
        }
    }
    Ok(())
}

/// Refuses a foot in contact whose sole is tilted from horizontal more than `scene.slope`: a
/// surface steeper than the gait is set to stand on.
fn check_slopes(stances: &[PreparedStance], scene: &SceneLimits) -> Result<(), Refusal> {
    for (i, stance) in stances.iter().enumerate() {
        for foot in [EndEffector::LeftFoot, EndEffector::RightFoot] {
            if !stance.contacts[foot as usize] {
                continue;
            }
            let normal = stance.targets[foot as usize].rotation * Vector3::z();
            let tilt = normal.angle(&Vector3::z());
            if tilt > scene.slope + SLOPE_TOLERANCE_RAD {
                return Err(Refusal(format!(
                    "stance {i}: {} stands on a slope of {tilt:.3} rad ({:.1}°), more than {} \
                     max_slope_rad = {}, the steepest slope this gait is set to stand on \
                     (docs/scenes.md, \"Step heights\")",
                    foot.name(),
                    tilt.to_degrees(),
                    scene.section,
                    scene.slope
                )));
            }
        }
    }
    Ok(())
}

/// Refuses targets outside the workspace the config allows: beyond `workspace_radius_m`
/// (horizontally) of where the first stance stands, more than `workspace_depth_m` below or
/// `workspace_height_m` above its soles, or more than `max_target_step_m` from the same
/// end-effector's target in the stance before.
fn check_workspace(stances: &[PreparedStance], config: &ControllerConfig) -> Result<(), Refusal> {
    let first = &stances[0];
    let feet: Vec<_> = [EndEffector::LeftFoot, EndEffector::RightFoot]
        .into_iter()
        .filter(|f| first.contacts[*f as usize])
        .map(|f| first.targets[f as usize].translation.vector)
        .collect();
    let centre = feet.iter().sum::<nalgebra::Vector3<f64>>() / feet.len() as f64;
    let ground = feet.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
    for (i, stance) in stances.iter().enumerate() {
        for e in EndEffector::ALL {
            let target = stance.targets[e as usize].translation.vector;
            let (x, y, z) = (target.x, target.y, target.z);
            let distance = (target - centre).xy().norm();
            if distance > config.workspace_radius_m {
                return Err(Refusal(format!(
                    "stance {i}: {} target ({x:.3}, {y:.3}, {z:.3}) lies {distance:.3e} m from where \
                     the walk starts, beyond workspace_radius_m = {}",
                    e.name(),
                    config.workspace_radius_m
                )));
            }
            if z < ground - config.workspace_depth_m || z > ground + config.workspace_height_m {
                return Err(Refusal(format!(
                    "stance {i}: {} target at height {z:.3} m is outside the workspace ({} m below \
                     to {} m above the first stance's soles)",
                    e.name(),
                    config.workspace_depth_m,
                    config.workspace_height_m
                )));
            }
            if i > 0 {
                let previous = stances[i - 1].targets[e as usize].translation.vector;
                let step = (target - previous).norm();
                if step > config.max_target_step_m {
                    return Err(Refusal(format!(
                        "stance {i}: {} target moves {step:.3} m from stance {}, more than \
                         max_target_step_m = {}",
                        e.name(),
                        i - 1,
                        config.max_target_step_m
                    )));
                }
            }
        }
    }
    Ok(())
}

/// Refuses steps (between consecutive contact poses of one foot) longer than `max_step`, or
/// landing higher or lower than `scene` allows above or below the sole of the other foot,
/// the one the robot stands on while this one swings: the step a stair's riser makes, whether
/// the feet go one per stair (a foot then travels two risers) or both on each.
fn check_steps(
    stances: &[PreparedStance],
    max_step: f64,
    scene: &SceneLimits,
) -> Result<(), Refusal> {
    use EndEffector::{LeftFoot, RightFoot};
    for (foot, other) in [(LeftFoot, RightFoot), (RightFoot, LeftFoot)] {
        let mut last_contact: Option<(usize, Isometry3<f64>)> = None;
        for (i, stance) in stances.iter().enumerate() {
            if !stance.contacts[foot as usize] {
                continue;
            }
            let pose = stance.targets[foot as usize];
            if let Some((previous, previous_pose)) = last_contact {
                let step = pose.translation.vector - previous_pose.translation.vector;
                let length = step.norm();
                if length > max_step {
                    return Err(Refusal(format!(
                        "stance {i}: {} steps {length:.3} m from stance {previous}, more than max_step_m = {max_step}",
                        foot.name()
                    )));
                }
                // The stance before the landing: the swing's last, in which the other foot
                // stands (a foot that lands without swinging is measured from its own sole).
                let standing = &stances[i - 1];
                let support = if i > previous + 1 && standing.contacts[other as usize] {
                    standing.targets[other as usize]
                } else {
                    previous_pose
                };
                let rise = pose.translation.z - support.translation.z;
                let (way, height, limit) = if rise >= 0.0 {
                    ("up", rise, scene.up)
                } else {
                    ("down", -rise, scene.down)
                };
                if height > limit + HEIGHT_TOLERANCE_M {
                    return Err(Refusal(format!(
                        "stance {i}: {} steps {way} {height:.3} m from the other foot's sole, more \
                         than {} max_step_{way}_m = {limit}, the highest step this gait is set to \
                         take (docs/scenes.md, \"Step heights\")",
                        foot.name(),
                        scene.section
                    )));
                }
            }
            last_contact = Some((i, pose));
        }
    }
    Ok(())
}
