//! A human-like, impeded stance source: until an n-gram generator trained on motion capture
//! exists, this is what the rest of the system is tested on. It plans a human walk scaled to the
//! robot ([`gait`]), injects the execution impediments of DESIGN.md §1 ([`impediments`]),
//! retargets every stance with the robot's IK (`q_S`, root pose) and sinks the whole sequence
//! below the floor. Deterministic for a seed.

mod gait;
mod impediments;
pub(crate) mod standing;

use std::fmt;
use std::str::FromStr;

use kinematics::Configuration;
use kinematics::ik::IkError;
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::environment::{Environment, HandAffordance};
use crate::error::FormatError;
use crate::sequence::{RawSequence, Stance};
use crate::stance_ik::StanceIk;
use gait::{Body, PlannedStance, Railing};
use kinematics::ground::yaw;
use standing::Standing;

/// Pelvis height of the human the statistics describe (metres); the robot's pelvis height over
/// it is the retargeting scale of all lengths.
const HUMAN_PELVIS_HEIGHT: f64 = 0.95;

/// The support affordances a sequence may use (the paper's three evaluation sets).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AffordanceSet {
    /// Only the feet (`feet`).
    Feet,
    /// Feet and the left hand on a railing to the left of the path (`feet+left-hand`).
    FeetLeftHand,
    /// Feet and the right hand on a railing to the right of the path (`feet+right-hand`).
    FeetRightHand,
}

impl AffordanceSet {
    /// All three sets.
    pub const ALL: [AffordanceSet; 3] = [
        AffordanceSet::Feet,
        AffordanceSet::FeetLeftHand,
        AffordanceSet::FeetRightHand,
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            AffordanceSet::Feet => "feet",
            AffordanceSet::FeetLeftHand => "feet+left-hand",
            AffordanceSet::FeetRightHand => "feet+right-hand",
        }
    }

    fn railing(self) -> Railing {
        match self {
            AffordanceSet::Feet => Railing::None,
            AffordanceSet::FeetLeftHand => Railing::Left,
            AffordanceSet::FeetRightHand => Railing::Right,
        }
    }
}

impl fmt::Display for AffordanceSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for AffordanceSet {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|set| set.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown affordance set `{s}` (use feet, feet+left-hand or feet+right-hand)"
                )
            })
    }
}

/// What to generate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GenerateOptions {
    /// Distance to cover along the robot's forward direction (metres, > 0). To cover `l` after
    /// post-processing, ask for `l / scf`.
    pub distance: f64,
    /// Which affordances the walk may use.
    pub affordances: AffordanceSet,
    /// Seed of the deterministic random source.
    pub seed: u64,
}

/// Why no sequence was generated.
#[derive(Debug, thiserror::Error)]
pub enum GenerateError {
    /// The requested distance is not a positive finite number (or absurdly long).
    #[error("distance {0} m: must be a finite number in (0, 10000]")]
    InvalidDistance(f64),
    /// The railing availability interval is not a finite `[from, to]` with `from ≤ to`.
    #[error("railing availability {0:?}: must be finite with from ≤ to")]
    InvalidRailing([f64; 2]),
    /// The robot's IK refused a stance's targets.
    #[error("stance {stance}: retargeting failed: {error}")]
    Ik { stance: usize, error: IkError },
    /// The generated sequence failed validation (a bug).
    #[error("generated sequence is invalid: {0}")]
    Invalid(FormatError),
    /// A walking speed was asked of the synthetic generator, which has no human timing.
    #[error(
        "a walking speed needs the learned source (--model MODEL.json): the synthetic \
         generator has no human timing"
    )]
    SpeedNeedsModel,
}

impl From<FormatError> for GenerateError {
    fn from(error: FormatError) -> Self {
        Self::Invalid(error)
    }
}

/// Generates a raw, impeded stance sequence for `robot`; a railing (if the affordance set has
/// one) may be held along the whole walk.
pub fn generate(robot: &Robot, options: &GenerateOptions) -> Result<RawSequence, GenerateError> {
    generate_with_railing(robot, options, [0.0, options.distance])
}

/// [`generate`] with the railing available only over `available` (metres from the start, in
/// generated coordinates). A railing available over `[a, b]` after post-processing is requested
/// as `[a / scf, b / scf]`, like the distance.
pub fn generate_with_railing(
    robot: &Robot,
    options: &GenerateOptions,
    available: [f64; 2],
) -> Result<RawSequence, GenerateError> {
    if !(options.distance > 0.0 && options.distance <= 10_000.0) {
        return Err(GenerateError::InvalidDistance(options.distance));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let body = measure(robot);
    let railing = options.affordances.railing();
    if !(available[0].is_finite() && available[1].is_finite() && available[0] <= available[1]) {
        return Err(GenerateError::InvalidRailing(available));
    }
    let mut plan = gait::plan(&body, options.distance, railing, available, &mut rng);
    impediments::inject(&mut plan, body.scale, &mut rng);
    let sink = impediments::sink_depth(&mut rng);
    let mut environment = Environment::default();
    if let Some((start, end)) = body.railing(railing, options.distance) {
        environment.hand_affordances.push(HandAffordance {
            name: "railing".to_owned(),
            start,
            end,
            radius: 0.0,
            available,
        });
    }
    let mut stances = retarget(robot, &body, &plan)?;
    stances[0].translation.z -= sink;
    Ok(RawSequence::new(
        robot.name.clone(),
        robot.model.joint_names().to_vec(),
        environment,
        stances,
    )?)
}

/// The robot's proportions in its standing posture.
fn measure(robot: &Robot) -> Body {
    let standing = Standing::measure(robot);
    let (left, right) = (
        standing.pose(EndEffector::LeftFoot),
        standing.pose(EndEffector::RightFoot),
    );
    let (forward, sole_z) = (standing.forward, standing.sole_z);
    let lateral = Vector3::z().cross(&forward);
    let unturn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -forward.y.atan2(forward.x));
    let in_path = |p: Isometry3<f64>| {
        let t = p.translation.vector;
        Isometry3::from_parts(
            Translation3::new(t.dot(&forward), t.dot(&lateral), t.z - sole_z),
            unturn * p.rotation,
        )
    };
    Body {
        scale: standing.pelvis_height / HUMAN_PELVIS_HEIGHT,
        forward,
        half_width: 0.5 * (left.translation.vector - right.translation.vector).dot(&lateral),
        sole_length: robot.sole.length,
        hands: [
            in_path(standing.pose(EndEffector::LeftHand)),
            in_path(standing.pose(EndEffector::RightHand)),
        ],
    }
}

/// Solves every planned stance with the robot's IK, warm-started from the previous stance, and
/// expresses the root as eq. 1's translation from the previous stance.
fn retarget(
    robot: &Robot,
    body: &Body,
    plan: &[PlannedStance],
) -> Result<Vec<Stance>, GenerateError> {
    let mut ik = StanceIk::new(robot);
    let mut stances = Vec::with_capacity(plan.len());
    for (i, planned) in plan.iter().enumerate() {
        let mut initial = ik.current().clone();
        initial.base = initial_base(&robot.standing, body, planned);
        let solved = ik
            .solve(&planned.targets, planned.contacts, &initial)
            .map_err(|error| GenerateError::Ik { stance: i, error })?;
        stances.push(solved.stance);
    }
    Ok(stances)
}

/// The IK's initial root pose: the standing root carried over the planned support point and
/// turned by the feet's mean yaw relative to the walking direction.
fn initial_base(standing: &Configuration, body: &Body, planned: &PlannedStance) -> Isometry3<f64> {
    let heading = body.forward.y.atan2(body.forward.x);
    let feet = [EndEffector::LeftFoot, EndEffector::RightFoot];
    let turn: f64 = feet
        .iter()
        .filter_map(|&f| planned.targets[f as usize])
        .map(|t| wrap(yaw(&t.rotation) - heading))
        .sum::<f64>()
        / 2.0;
    let rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), turn);
    let offset = rotation * standing.base.translation.vector;
    Isometry3::from_parts(
        Translation3::new(
            planned.support.x + offset.x,
            planned.support.y + offset.y,
            offset.z,
        ),
        rotation * standing.base.rotation,
    )
}

/// An angle wrapped into (−π, π].
fn wrap(angle: f64) -> f64 {
    let wrapped = angle.rem_euclid(std::f64::consts::TAU);
    if wrapped > std::f64::consts::PI {
        wrapped - std::f64::consts::TAU
    } else {
        wrapped
    }
}
