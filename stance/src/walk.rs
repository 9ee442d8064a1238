//! A walk of a given distance: the paper's rule that a sequence meant to cover `l` metres after
//! post-processing is generated for `l / scf` metres (pass 6 scales the path by `scf`, pass 7
//! shortens long steps), then post-processed with Algorithm 1. Every command that walks a
//! distance (the demo, the evaluation, the benches, the latency report) asks for it here.

use kinematics::robot::Robot;

use crate::environment::{Environment, SupportSurface};
use crate::error::FormatError;
use crate::generate::{AffordanceSet, GenerateError, GenerateOptions, generate};
use crate::params::PostProcessParams;
use crate::pipeline::PostProcessor;
use crate::sequence::{NoRailing, PostProcessedSequence, RawSequence};

/// A walk to generate: how far it should reach after post-processing, with what, which seed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WalkRequest {
    /// Distance the post-processed walk should cover (m).
    pub distance: f64,
    /// Which affordances it may use.
    pub affordances: AffordanceSet,
    /// Seed of the stance source.
    pub seed: u64,
    /// The walking speed asked for; `None`: the source's own pace. Only a learned source with a
    /// gait law paces a walk (`stance::learned::pace`).
    pub speed: Option<WalkingSpeed>,
}

/// A walking speed to pace a walk for, within the robot's timing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WalkingSpeed {
    /// The walk's speed after post-processing (m/s).
    pub m_s: f64,
    /// The limits `[min, max]` (s) within which the robot's dynamic gait times a single and a
    /// double support from a sequence: `[gait.dynamic] timed_single_support_s` and
    /// `timed_double_support_s`. A paced walk plans every support within them, so that the
    /// daemon walks it at the pace planned.
    pub support_limits_s: [[f64; 2]; 2],
}

impl WalkRequest {
    /// A forward walk on the feet alone.
    pub fn feet(distance: f64, seed: u64) -> Self {
        Self {
            distance,
            affordances: AffordanceSet::Feet,
            seed,
            speed: None,
        }
    }

    /// What to ask a stance source for: `distance / scf` metres.
    pub fn generate_options(&self, params: &PostProcessParams) -> GenerateOptions {
        GenerateOptions {
            distance: self.distance / params.scf,
            affordances: self.affordances,
            seed: self.seed,
        }
    }
}

/// Why no walk came out; the message includes the cause.
#[derive(Debug, thiserror::Error)]
pub enum WalkError<E: std::error::Error> {
    /// The stance source generated nothing.
    #[error("generating the stance sequence: {0}")]
    Source(E),
    /// The walk holds a railing the scene does not have.
    #[error("putting the walk in the scene: {0}")]
    Scene(NoRailing),
    /// Algorithm 1 refused the raw sequence.
    #[error("post-processing the stance sequence: {0}")]
    PostProcess(FormatError),
}

/// The walk of `request` on flat ground: `source` generates the raw sequence for the options of
/// [`WalkRequest::generate_options`], then it is post-processed with `params` in the source's
/// own environment (the ground, and its railing for a held hand).
pub fn walk_with<E: std::error::Error>(
    robot: &Robot,
    params: &PostProcessParams,
    request: &WalkRequest,
    mut source: impl FnMut(&GenerateOptions) -> Result<RawSequence, E>,
) -> Result<PostProcessedSequence, WalkError<E>> {
    let raw = source(&request.generate_options(params)).map_err(WalkError::Source)?;
    PostProcessor::new(robot, params.clone())
        .process(&raw)
        .map_err(WalkError::PostProcess)
}

/// How many times longer than its path a walk on terrain is generated, in the order tried:
/// the first whose post-processed walk reaches the path's end is ended there
/// ([`PostProcessedSequence::end_at`]). With both feet on every stair the terrain pass takes
/// more footholds per metre than the flat walk has, and it cannot add stances; a longer flat
/// walk than needed would only bring in more of the source's sideways wander. Up and down the
/// 15° ramp JVRC-1's steps are a third of its flat ones (the weighted rise): twice the path
/// ended 1.1–1.5 m short of the goal, on the way down.
pub const TERRAIN_DISTANCE_MARGINS: [f64; 4] = [1.0, 1.5, 2.0, 3.0];

/// [`walk_with`] in `environment`, a scene's in the walk's frame
/// ([`crate::Scene::walk_environment`]): the source's flat walk is put in it
/// ([`RawSequence::in_environment`]: its surfaces, its railings for the held hands) and
/// post-processed onto it; unless its surfaces are the flat ground, it is generated longer
/// ([`TERRAIN_DISTANCE_MARGINS`]) until it reaches `request.distance`, and ended there. Refused
/// ([`WalkError::Scene`]) if the walk holds a hand and the scene has no railing.
pub fn walk_in<E: std::error::Error>(
    robot: &Robot,
    params: &PostProcessParams,
    request: &WalkRequest,
    environment: &Environment,
    mut source: impl FnMut(&GenerateOptions) -> Result<RawSequence, E>,
) -> Result<PostProcessedSequence, WalkError<E>> {
    let options = request.generate_options(params);
    let mut processor = PostProcessor::new(robot, params.clone());
    let mut walk = |margin: f64| {
        let longer = GenerateOptions {
            distance: options.distance * margin,
            ..options
        };
        let raw = source(&longer).map_err(WalkError::Source)?;
        let raw = raw
            .in_environment(environment.clone())
            .map_err(WalkError::Scene)?;
        processor.process(&raw).map_err(WalkError::PostProcess)
    };
    if environment
        .surfaces
        .iter()
        .all(SupportSurface::is_ground_plane)
    {
        return walk(1.0);
    }
    let mut longest = None;
    for margin in TERRAIN_DISTANCE_MARGINS {
        let mut walked = walk(margin)?;
        if walked.end_at(request.distance) {
            return Ok(walked);
        }
        longest = Some(walked);
    }
    Ok(longest.expect("at least one margin"))
}

/// The walk of `request` from the synthetic human-like generator.
pub fn synthetic_walk(
    robot: &Robot,
    params: &PostProcessParams,
    request: &WalkRequest,
) -> Result<PostProcessedSequence, WalkError<GenerateError>> {
    if request.speed.is_some() {
        return Err(WalkError::Source(GenerateError::SpeedNeedsModel));
    }
    walk_with(robot, params, request, |options| generate(robot, options))
}
