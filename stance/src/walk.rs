//! A walk of a given distance: the paper's rule that a sequence meant to cover `l` metres after
//! post-processing is generated for `l / scf` metres (pass 6 scales the path by `scf`, pass 7
//! shortens long steps), then post-processed with Algorithm 1. Every command that walks a
//! distance (the demo, the evaluation, the benches, the latency report) asks for it here.

use kinematics::robot::Robot;

use crate::environment::SupportSurface;
use crate::error::FormatError;
use crate::generate::{AffordanceSet, GenerateError, GenerateOptions, generate};
use crate::params::PostProcessParams;
use crate::pipeline::PostProcessor;
use crate::sequence::{PostProcessedSequence, RawSequence};

/// A walk to generate: how far it should reach after post-processing, with what, which seed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WalkRequest {
    /// Distance the post-processed walk should cover (m).
    pub distance: f64,
    /// Which affordances it may use.
    pub affordances: AffordanceSet,
    /// Seed of the stance source.
    pub seed: u64,
}

impl WalkRequest {
    /// A forward walk on the feet alone.
    pub fn feet(distance: f64, seed: u64) -> Self {
        Self {
            distance,
            affordances: AffordanceSet::Feet,
            seed,
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
    /// Algorithm 1 refused the raw sequence.
    #[error("post-processing the stance sequence: {0}")]
    PostProcess(FormatError),
}

/// The walk of `request` on flat ground: `source` generates the raw sequence for the options of
/// [`WalkRequest::generate_options`], then it is post-processed with `params`.
pub fn walk_with<E: std::error::Error>(
    robot: &Robot,
    params: &PostProcessParams,
    request: &WalkRequest,
    source: impl FnOnce(&GenerateOptions) -> Result<RawSequence, E>,
) -> Result<PostProcessedSequence, WalkError<E>> {
    walk_on(robot, params, request, &[SupportSurface::ground()], source)
}

/// [`walk_with`] on `surfaces` (a scene's, in the walk's frame: [`crate::Scene::walk_environment`]):
/// the source's flat walk is post-processed onto them.
pub fn walk_on<E: std::error::Error>(
    robot: &Robot,
    params: &PostProcessParams,
    request: &WalkRequest,
    surfaces: &[SupportSurface],
    source: impl FnOnce(&GenerateOptions) -> Result<RawSequence, E>,
) -> Result<PostProcessedSequence, WalkError<E>> {
    let raw = source(&request.generate_options(params)).map_err(WalkError::Source)?;
    PostProcessor::new(robot, params.clone())
        .process(&raw.on_surfaces(surfaces))
        .map_err(WalkError::PostProcess)
}

/// The walk of `request` from the synthetic human-like generator.
pub fn synthetic_walk(
    robot: &Robot,
    params: &PostProcessParams,
    request: &WalkRequest,
) -> Result<PostProcessedSequence, WalkError<GenerateError>> {
    walk_with(robot, params, request, |options| generate(robot, options))
}
