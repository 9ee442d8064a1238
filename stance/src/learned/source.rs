//! The stance source choice shared by every command that generates a raw sequence
//! (`walkctl generate`, `walkd bench`): the synthetic human-like generator or a learned n-gram
//! model, selected by the same `--source` / `--model` / `--beam` options everywhere.

use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use kinematics::robot::Robot;

use super::error::LearnError;
use super::model::NgramModel;
use super::pace::{RobotGait, SpeedRequest};
use super::query::Search;
use super::retarget::{LearnedOptions, generate_learned};
use crate::environment::Environment;
use crate::generate::{GenerateError, GenerateOptions, generate_with_railing};
use crate::params::PostProcessParams;
use crate::sequence::{PostProcessedSequence, RawSequence};
use crate::walk::{WalkError, WalkRequest, walk_in, walk_with};

/// Which generator a command uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SourceKind {
    /// The hand-written human-like generator ([`crate::generate()`]).
    Synthetic,
    /// A trained n-gram model, retargeted ([`generate_learned`]).
    Learned,
}

impl FromStr for SourceKind {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "synthetic" => Ok(Self::Synthetic),
            "learned" => Ok(Self::Learned),
            _ => Err(format!("unknown source `{s}` (use learned or synthetic)")),
        }
    }
}

impl fmt::Display for SourceKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Synthetic => "synthetic",
            Self::Learned => "learned",
        })
    }
}

/// The stance source options (flatten into a command's arguments).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct SourceArgs {
    /// Stance source: `learned` (n-gram model, the default when --model is given) or
    /// `synthetic` (the default without --model).
    #[arg(long, value_name = "SOURCE")]
    pub source: Option<SourceKind>,
    /// Trained n-gram model (see `walkctl learn`), e.g. data/models/default-ngram.json.
    #[arg(long, value_name = "MODEL.json")]
    pub model: Option<PathBuf>,
    /// With a model: the most probable sequence (beam search of this width, 1-1000) instead of
    /// a sequence sampled with the seed.
    #[arg(
        long,
        value_name = "WIDTH",
        value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=1000)
    )]
    pub beam: Option<usize>,
}

/// Why the source options cannot be used or the source generated nothing. Messages are complete
/// in themselves (the cause is part of the text, not a separate `source()`), so an error chain
/// prints each cause once.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    /// `--source learned` without a model file.
    #[error("--source learned needs --model MODEL.json")]
    MissingModel,
    /// A model file with `--source synthetic`.
    #[error("--model with --source synthetic: the synthetic source uses no model")]
    ModelWithSynthetic,
    /// A beam width for the synthetic source.
    #[error("--beam needs the learned source: give --model MODEL.json")]
    BeamWithoutModel,
    /// The beam width is zero.
    #[error("--beam 0: the beam width must be at least 1")]
    ZeroBeam,
    /// The model could not be loaded, queried or retargeted.
    #[error("{0}")]
    Learned(LearnError),
    /// The synthetic generator failed.
    #[error("{0}")]
    Synthetic(GenerateError),
}

impl From<LearnError> for SourceError {
    fn from(error: LearnError) -> Self {
        Self::Learned(error)
    }
}

impl From<GenerateError> for SourceError {
    fn from(error: GenerateError) -> Self {
        Self::Synthetic(error)
    }
}

/// A ready stance source.
#[derive(Clone, Debug)]
pub enum StanceSource {
    /// The synthetic generator.
    Synthetic,
    /// A loaded model and how to pick its sequence (`None`: sampled with the seed).
    Learned {
        /// The model.
        model: Box<NgramModel>,
        /// Where it was loaded from (for reports).
        path: PathBuf,
        /// Beam width for the most probable sequence; `None` samples with the seed.
        beam: Option<usize>,
    },
}

/// A generated raw sequence and, for the learned source, the IK's largest remaining
/// `[position (m), orientation (rad)]` error over its stances.
#[derive(Clone, Debug)]
pub struct Sourced {
    /// The raw robot sequence.
    pub raw: RawSequence,
    /// Largest retargeting residual (learned source only).
    pub largest_ik_error: Option<[f64; 2]>,
    /// With a speed request: what the gait law asked of the robot.
    pub gait: Option<RobotGait>,
}

impl SourceArgs {
    /// Checks the option combination and loads the model, if any.
    pub fn load(&self) -> Result<StanceSource, SourceError> {
        match (self.source, &self.model) {
            (Some(SourceKind::Synthetic), Some(_)) => Err(SourceError::ModelWithSynthetic),
            (Some(SourceKind::Synthetic), None) | (None, None) => match self.beam {
                Some(_) => Err(SourceError::BeamWithoutModel),
                None => Ok(StanceSource::Synthetic),
            },
            (Some(SourceKind::Learned), None) => Err(SourceError::MissingModel),
            (Some(SourceKind::Learned) | None, Some(path)) => {
                StanceSource::learned(path, self.beam)
            }
        }
    }
}

impl StanceSource {
    /// The learned source with the model at `path`, sampled (`beam` `None`) or most probable.
    pub fn learned(path: &Path, beam: Option<usize>) -> Result<Self, SourceError> {
        if beam == Some(0) {
            return Err(SourceError::ZeroBeam);
        }
        Ok(Self::Learned {
            model: Box::new(NgramModel::from_path(path)?),
            path: path.to_path_buf(),
            beam,
        })
    }

    /// A one-line description for reports, e.g. `learned (model.json, sampled, seed 3)`.
    pub fn describe(&self, seed: u64) -> String {
        match self {
            Self::Synthetic => format!("synthetic (seed {seed})"),
            Self::Learned {
                path,
                beam: Some(width),
                ..
            } => format!("learned ({}, beam {width})", path.display()),
            Self::Learned {
                path, beam: None, ..
            } => format!("learned ({}, sampled, seed {seed})", path.display()),
        }
    }

    /// The walk of `request` from this source, post-processed with `params` (the railing, if
    /// any, available along the whole walk).
    pub fn walk(
        &self,
        robot: &Robot,
        params: &PostProcessParams,
        request: &WalkRequest,
    ) -> Result<PostProcessedSequence, WalkError<SourceError>> {
        walk_with(robot, params, request, |options| {
            Ok(self
                .generate(robot, options, None, speed_request(request, params))?
                .raw)
        })
    }

    /// [`StanceSource::walk`] through `environment` ([`walk_in`]: a scene's, in the walk's frame).
    pub fn walk_in(
        &self,
        robot: &Robot,
        params: &PostProcessParams,
        request: &WalkRequest,
        environment: &Environment,
    ) -> Result<PostProcessedSequence, WalkError<SourceError>> {
        walk_in(robot, params, request, environment, |options| {
            Ok(self
                .generate(robot, options, None, speed_request(request, params))?
                .raw)
        })
    }

    /// Generates a raw sequence covering `options.distance` (raw-scale metres: divide by scf
    /// first to cover a distance after post-processing), the railing available over `railing`
    /// (same scale; `None` = the whole walk), paced for `speed` if asked (learned source only).
    pub fn generate(
        &self,
        robot: &Robot,
        options: &GenerateOptions,
        railing: Option<[f64; 2]>,
        speed: Option<SpeedRequest>,
    ) -> Result<Sourced, SourceError> {
        let railing = railing.unwrap_or([0.0, options.distance]);
        match self {
            Self::Synthetic if speed.is_some() => Err(GenerateError::SpeedNeedsModel.into()),
            Self::Synthetic => Ok(Sourced {
                raw: generate_with_railing(robot, options, railing)?,
                largest_ik_error: None,
                gait: None,
            }),
            Self::Learned { model, beam, .. } => {
                let learned = LearnedOptions {
                    distance: options.distance,
                    affordances: options.affordances,
                    railing: Some(railing),
                    search: beam.map_or(Search::Sample(options.seed), Search::Beam),
                    speed,
                };
                let retargeted = generate_learned(robot, model, &learned)?;
                let largest = retargeted
                    .ik_errors
                    .iter()
                    .fold([0.0f64; 2], |w, e| [w[0].max(e[0]), w[1].max(e[1])]);
                Ok(Sourced {
                    raw: retargeted.raw,
                    largest_ik_error: Some(largest),
                    gait: retargeted.gait,
                })
            }
        }
    }
}

/// The speed `request` asks for, with the `scf` its post-processing will shorten the steps by.
fn speed_request(request: &WalkRequest, params: &PostProcessParams) -> Option<SpeedRequest> {
    request.speed.map(|speed| SpeedRequest {
        speed,
        scf: params.scf,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(source: Option<&str>, model: Option<&str>, beam: Option<usize>) -> SourceArgs {
        SourceArgs {
            source: source.map(|s| s.parse().unwrap()),
            model: model.map(PathBuf::from),
            beam,
        }
    }

    #[test]
    fn option_combinations_are_checked() {
        assert!(matches!(
            args(None, None, None).load(),
            Ok(StanceSource::Synthetic)
        ));
        assert!(matches!(
            args(Some("synthetic"), None, None).load(),
            Ok(StanceSource::Synthetic)
        ));
        assert!(matches!(
            args(Some("learned"), None, None).load(),
            Err(SourceError::MissingModel)
        ));
        assert!(matches!(
            args(Some("synthetic"), Some("m.json"), None).load(),
            Err(SourceError::ModelWithSynthetic)
        ));
        assert!(matches!(
            args(None, None, Some(4)).load(),
            Err(SourceError::BeamWithoutModel)
        ));
        assert!(matches!(
            args(None, Some("m.json"), Some(0)).load(),
            Err(SourceError::ZeroBeam)
        ));
        assert!("learnt".parse::<SourceKind>().is_err());
    }

    #[test]
    fn a_missing_model_file_is_named_once() {
        let error = args(None, Some("/nonexistent/model.json"), None)
            .load()
            .unwrap_err();
        // What `{:#}` of an error chain (anyhow) prints: every cause in turn.
        let mut chain = error.to_string();
        let mut cause = std::error::Error::source(&error);
        while let Some(next) = cause {
            chain = format!("{chain}: {next}");
            cause = next.source();
        }
        assert!(chain.contains("/nonexistent/model.json"), "{chain}");
        assert_eq!(chain.matches("No such file").count(), 1, "{chain}");
    }
}
