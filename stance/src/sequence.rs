//! The stance data model (the paper's eq. 1) and the two sequences built from it: the raw
//! sequence a stance source produces and the post-processed sequence the controller executes.
//! Both are validated on construction, so a value of either type is always well-formed.

use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use crate::environment::Environment;
use crate::error::{FormatError, Location};
use crate::params::Gait;
use crate::poses::HANDS;

/// One stance `S = { q_S, c_S(lf), c_S(rf), c_S(lh), c_S(rh), t_S }`.
#[derive(Clone, Debug, PartialEq)]
pub struct Stance {
    /// Joint angles `q_S` of the whole robot, in the model's joint order.
    pub q: Vec<f64>,
    /// Contact flags indexed by [`EndEffector`] (`contacts[EndEffector::LeftFoot as usize]`).
    pub contacts: [bool; 4],
    /// Translation `t_S` of the root from the previous stance (from the world origin for the
    /// first stance).
    pub translation: Vector3<f64>,
    /// Orientation of the root in the world. Eq. 1 has none (the identity is its default in the
    /// file); a retargeted stance needs it to reproduce the end-effector poses it was solved for.
    pub root_orientation: UnitQuaternion<f64>,
    /// How long the walk stays in this stance, from reaching it until it moves on (s): a timed
    /// stance, its duration from the demonstrations. `None`: untimed, the gait's configured
    /// timing applies (every file of format version 1).
    pub duration_s: Option<f64>,
}

impl Stance {
    /// Whether `end_effector` is in contact in this stance.
    pub fn in_contact(&self, end_effector: EndEffector) -> bool {
        self.contacts[end_effector as usize]
    }
}

/// What both kinds of sequence hold, with its accessors: the robot and joint order it is for, its
/// environment, and its stances. [`RawSequence`] and [`PostProcessedSequence`] dereference to it.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct StanceSequence {
    pub(crate) robot: String,
    pub(crate) joint_names: Vec<String>,
    pub(crate) environment: Environment,
    pub(crate) stances: Vec<Stance>,
}

/// A sequence as a stance source delivers it, impediments included.
#[derive(Clone, Debug, PartialEq)]
pub struct RawSequence {
    pub(crate) sequence: StanceSequence,
}

/// A sequence after Algorithm 1: the raw stances (`q_S` and contact flags unchanged, root
/// translations following the passes' moves) plus explicit world-frame target poses for every
/// end-effector in every stance. This is what the controller executes.
#[derive(Clone, Debug, PartialEq)]
pub struct PostProcessedSequence {
    pub(crate) sequence: StanceSequence,
    pub(crate) targets: Vec<[Isometry3<f64>; 4]>,
    /// The gait whose limits post-processed it, and which walks it; `None` (a file that does
    /// not say): the robot config's `[gait] default`.
    pub(crate) gait: Option<Gait>,
}

impl StanceSequence {
    /// A validated sequence (see [`FormatError`] for what is refused).
    fn new(
        robot: String,
        joint_names: Vec<String>,
        environment: Environment,
        stances: Vec<Stance>,
    ) -> Result<Self, FormatError> {
        validate(&robot, &joint_names, &environment, &stances)?;
        Ok(Self {
            robot,
            joint_names,
            environment,
            stances,
        })
    }

    /// Name of the robot the sequence is for.
    pub fn robot(&self) -> &str {
        &self.robot
    }

    /// Joint names, the order of every `q_S`.
    pub fn joint_names(&self) -> &[String] {
        &self.joint_names
    }

    /// Support surfaces and hand affordances.
    pub fn environment(&self) -> &Environment {
        &self.environment
    }

    /// The stances (`q_S`, contact flags, root translations).
    pub fn stances(&self) -> &[Stance] {
        &self.stances
    }

    /// Number of stances (≥ 1 once validated).
    pub fn len(&self) -> usize {
        self.stances.len()
    }

    /// False for a validated sequence (only [`PostProcessedSequence::empty`] has no stance).
    pub fn is_empty(&self) -> bool {
        self.stances.is_empty()
    }

    /// Global root pose `GP_S` of every stance (accumulated translations, root orientation).
    pub fn root_poses(&self) -> impl Iterator<Item = Isometry3<f64>> + '_ {
        accumulate_roots(&self.stances)
    }

    /// Refuses the sequence if it is not for `robot` (name, joint names and order).
    pub fn check_robot(&self, robot: &Robot) -> Result<(), FormatError> {
        check_robot(&self.robot, &self.joint_names, robot)
    }
}

impl std::ops::Deref for RawSequence {
    type Target = StanceSequence;

    fn deref(&self) -> &StanceSequence {
        &self.sequence
    }
}

impl std::ops::Deref for PostProcessedSequence {
    type Target = StanceSequence;

    fn deref(&self) -> &StanceSequence {
        &self.sequence
    }
}

/// Accumulates the stance translations into global root poses `GP_S`.
fn accumulate_roots(stances: &[Stance]) -> impl Iterator<Item = Isometry3<f64>> + '_ {
    stances.iter().scan(Vector3::zeros(), |position, stance| {
        *position += stance.translation;
        Some(Isometry3::from_parts(
            Translation3::from(*position),
            stance.root_orientation,
        ))
    })
}

impl RawSequence {
    /// A validated raw sequence (see [`FormatError`] for what is refused).
    pub fn new(
        robot: String,
        joint_names: Vec<String>,
        environment: Environment,
        stances: Vec<Stance>,
    ) -> Result<Self, FormatError> {
        Ok(Self {
            sequence: StanceSequence::new(robot, joint_names, environment, stances)?,
        })
    }

    /// The same walk in another environment (a scene's, in the walk's frame:
    /// [`crate::Scene::walk_environment`]): its surfaces, and its railings as the hand
    /// affordances in place of the stance source's own. A stance source generates on flat
    /// ground; post-processing puts the walk onto these surfaces and its held hands onto these
    /// railings. Refused if a hand is held in some stance and the environment has no railing on
    /// that hand's side ([`crate::HandAffordance::is_on_the_side_of`]).
    pub fn in_environment(mut self, environment: Environment) -> Result<Self, NoRailing> {
        let railing_for = |hand| {
            environment
                .hand_affordances
                .iter()
                .any(|railing| railing.is_on_the_side_of(hand))
        };
        let held = self.stances.iter().enumerate().find_map(|(stance, s)| {
            HANDS
                .into_iter()
                .find(|&hand| s.in_contact(hand) && !railing_for(hand))
                .map(|hand| NoRailing { hand, stance })
        });
        if let Some(refusal) = held {
            return Err(refusal);
        }
        self.sequence.environment = environment;
        Ok(self)
    }
}

/// Why a walk cannot be put in an environment ([`RawSequence::in_environment`]): a hand holds a
/// railing in the walk and the environment has none on its side to hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "the sequence holds a hand on a railing ({} from stance {stance}) but the scene has none on \
     that side of the path (a [[railing]] whose middle is {} of the line from start to goal)",
    hand.name(),
    if *hand == EndEffector::LeftHand { "left" } else { "right" }
)]
pub struct NoRailing {
    /// The first held hand.
    pub hand: EndEffector,
    /// The first stance it is held in.
    pub stance: usize,
}

impl PostProcessedSequence {
    /// A validated post-processed sequence; `targets` holds one pose per end-effector per stance.
    pub fn new(
        robot: String,
        joint_names: Vec<String>,
        environment: Environment,
        stances: Vec<Stance>,
        targets: Vec<[Isometry3<f64>; 4]>,
    ) -> Result<Self, FormatError> {
        validate_targets(&targets, stances.len())?;
        Ok(Self {
            sequence: StanceSequence::new(robot, joint_names, environment, stances)?,
            targets,
            gait: None,
        })
    }

    /// An empty value to be filled by [`crate::PostProcessor::process_into`] (reused buffers).
    pub fn empty() -> Self {
        Self {
            sequence: StanceSequence::default(),
            targets: Vec::new(),
            gait: None,
        }
    }

    /// The gait the sequence asks to be walked with (`None`: the robot's default).
    pub fn gait(&self) -> Option<Gait> {
        self.gait
    }

    /// The sequence asking for `gait` (`None`: the robot's default), e.g. a client's
    /// `--gait` choice for a file post-processed earlier.
    pub fn with_gait(mut self, gait: Option<Gait>) -> Self {
        self.gait = gait;
        self
    }

    /// Ends the walk at its first stance with both feet in contact whose soles' mean lies
    /// `distance` or more along +x: the goal of a walk on a scene's surfaces, in the walk's
    /// frame (start at the origin, heading +x). A walk that never gets there is kept whole.
    /// Returns whether it got there.
    pub fn end_at(&mut self, distance: f64) -> bool {
        let (left, right) = (
            EndEffector::LeftFoot as usize,
            EndEffector::RightFoot as usize,
        );
        let reached = (0..self.len()).find(|&i| {
            let contacts = self.contacts(i);
            let middle =
                (self.targets[i][left].translation.x + self.targets[i][right].translation.x) / 2.0;
            contacts[left] && contacts[right] && middle >= distance
        });
        if let Some(last) = reached {
            self.sequence.stances.truncate(last + 1);
            self.targets.truncate(last + 1);
        }
        reached.is_some()
    }

    /// Contact flags of stance `i`, indexed by [`EndEffector`]. Panics if `i >= len()`.
    pub fn contacts(&self, i: usize) -> [bool; 4] {
        self.stances[i].contacts
    }

    /// World-frame target pose of `end_effector` in stance `i` (a contact pose where the flag is
    /// set, the swing/free pose otherwise). Panics if `i >= len()`.
    pub fn target(&self, i: usize, end_effector: EndEffector) -> Isometry3<f64> {
        self.targets[i][end_effector as usize]
    }

    /// All four targets of stance `i`, indexed by [`EndEffector`].
    pub fn targets(&self, i: usize) -> &[Isometry3<f64>; 4] {
        &self.targets[i]
    }

    /// The posture reference `q_S` of stance `i` (model joint order). Panics if `i >= len()`.
    pub fn posture(&self, i: usize) -> &[f64] {
        &self.stances[i].q
    }
}

/// Unit-norm tolerance for quaternions read from files.
const QUATERNION_TOLERANCE: f64 = 1e-6;

fn check_robot(name: &str, joint_names: &[String], robot: &Robot) -> Result<(), FormatError> {
    if name != robot.name {
        return Err(FormatError::RobotMismatch {
            found: name.to_owned(),
            expected: robot.name.clone(),
        });
    }
    let expected = robot.model.joint_names();
    if expected.len() != joint_names.len() {
        return Err(FormatError::JointNameCount {
            robot: robot.name.clone(),
            expected: expected.len(),
            found: joint_names.len(),
        });
    }
    match expected.iter().zip(joint_names).position(|(a, b)| a != b) {
        Some(index) => Err(FormatError::JointName {
            index,
            expected: expected[index].clone(),
            found: joint_names[index].clone(),
        }),
        None => Ok(()),
    }
}

fn finite(values: &[f64], location: impl FnOnce() -> Location) -> Result<(), FormatError> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(FormatError::NonFinite {
            location: location(),
        })
    }
}

pub(crate) fn check_rotation(
    rotation: &UnitQuaternion<f64>,
    location: impl Fn() -> Location,
) -> Result<(), FormatError> {
    finite(rotation.coords.as_slice(), &location)?;
    let norm = rotation.coords.norm();
    if (norm - 1.0).abs() > QUATERNION_TOLERANCE {
        return Err(FormatError::NonUnitQuaternion {
            location: location(),
            norm,
        });
    }
    Ok(())
}

pub(crate) fn check_pose(
    pose: &Isometry3<f64>,
    location: impl Fn() -> Location,
) -> Result<(), FormatError> {
    finite(pose.translation.vector.as_slice(), &location)?;
    check_rotation(&pose.rotation, location)
}

fn validate(
    robot: &str,
    joint_names: &[String],
    environment: &Environment,
    stances: &[Stance],
) -> Result<(), FormatError> {
    if robot.is_empty() {
        return Err(FormatError::Invalid {
            location: Location::file("robot"),
            message: "empty robot name".into(),
        });
    }
    for (index, name) in joint_names.iter().enumerate() {
        if name.is_empty() || joint_names[..index].contains(name) {
            return Err(FormatError::BadJointName {
                index,
                name: name.clone(),
            });
        }
    }
    validate_environment(environment)?;
    if stances.is_empty() {
        return Err(FormatError::EmptySequence);
    }
    for (i, stance) in stances.iter().enumerate() {
        if stance.q.len() != joint_names.len() {
            return Err(FormatError::JointCount {
                stance: i,
                expected: joint_names.len(),
                found: stance.q.len(),
            });
        }
        if let Some(j) = stance.q.iter().position(|v| !v.is_finite()) {
            return Err(FormatError::NonFinite {
                location: Location::stance(i, format!("q[{j}]")),
            });
        }
        finite(stance.translation.as_slice(), || {
            Location::stance(i, "translation")
        })?;
        check_rotation(&stance.root_orientation, || {
            Location::stance(i, "root_orientation")
        })?;
        if !stance.in_contact(EndEffector::LeftFoot) && !stance.in_contact(EndEffector::RightFoot) {
            return Err(FormatError::NoFootSupport { stance: i });
        }
        check_duration(stance.duration_s, i)?;
    }
    Ok(())
}

/// The longest stance duration accepted (s): a stance of a walk, not a pause.
pub const MAX_STANCE_DURATION_S: f64 = 60.0;

/// A stance duration, if any, is a finite number in (0, [`MAX_STANCE_DURATION_S`]].
fn check_duration(duration_s: Option<f64>, stance: usize) -> Result<(), FormatError> {
    let Some(duration) = duration_s else {
        return Ok(());
    };
    if !duration.is_finite() {
        return Err(FormatError::NonFinite {
            location: Location::stance(stance, "duration_s"),
        });
    }
    if !(duration > 0.0 && duration <= MAX_STANCE_DURATION_S) {
        return Err(FormatError::Invalid {
            location: Location::stance(stance, "duration_s"),
            message: format!("{duration} s: must be in (0, {MAX_STANCE_DURATION_S}] s"),
        });
    }
    Ok(())
}

fn validate_targets(targets: &[[Isometry3<f64>; 4]], stances: usize) -> Result<(), FormatError> {
    if targets.len() != stances {
        return Err(FormatError::Invalid {
            location: Location::file("stances"),
            message: format!("{} target sets for {stances} stances", targets.len()),
        });
    }
    for (i, poses) in targets.iter().enumerate() {
        for e in EndEffector::ALL {
            check_pose(&poses[e as usize], || {
                Location::stance(i, format!("targets.{}", e.name()))
            })?;
        }
    }
    Ok(())
}

fn validate_environment(environment: &Environment) -> Result<(), FormatError> {
    if environment.surfaces.is_empty() {
        return Err(FormatError::Invalid {
            location: Location::file("environment.surfaces"),
            message: "no support surface (the default is the ground plane z = 0)".into(),
        });
    }
    for (k, surface) in environment.surfaces.iter().enumerate() {
        let field = |f: &str| Location::file(format!("environment.surfaces[{k}].{f}"));
        check_pose(&surface.pose, || field("pose"))?;
        if let Some(polygon) = &surface.polygon {
            if polygon.len() < 3 {
                return Err(FormatError::Invalid {
                    location: field("polygon"),
                    message: format!("{} vertices, a polygon needs at least 3", polygon.len()),
                });
            }
            finite(polygon.as_flattened(), || field("polygon"))?;
        }
    }
    for (k, affordance) in environment.hand_affordances.iter().enumerate() {
        let field = |f: &str| Location::file(format!("environment.hand_affordances[{k}].{f}"));
        finite(affordance.start.as_slice(), || field("start"))?;
        finite(affordance.end.as_slice(), || field("end"))?;
        finite(&affordance.available, || field("available"))?;
        finite(&[affordance.radius], || field("radius"))?;
        if affordance.radius < 0.0 {
            return Err(FormatError::Invalid {
                location: field("radius"),
                message: format!("{} m: a radius is ≥ 0", affordance.radius),
            });
        }
        if affordance.available[0] > affordance.available[1] {
            return Err(FormatError::Invalid {
                location: field("available"),
                message: "interval start after its end".into(),
            });
        }
    }
    Ok(())
}
