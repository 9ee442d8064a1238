//! Stance sequences: data model, file format, human-like source and post-processing
//! (Algorithm 1 of Grimm, Kheddar, Asfour; DESIGN.md §3–4).
//!
//! - [`Stance`], [`RawSequence`], [`PostProcessedSequence`], [`Environment`]: the data model,
//!   validated on construction and read/written as versioned JSON ([`format`]).
//! - [`PoseSequence`]: world poses of root and end-effectors per stance, the passes' working form.
//! - [`passes`]: Algorithm 1's nine passes, the terrain pass and the hand pass, each a function;
//!   [`PostProcessor`] runs FK + all passes with reusable buffers.
//! - [`generate()`]: a human-like, impeded stance source; `learned` (feature `learned`): the
//!   n-gram model trained on human demonstrations.
//! - [`Scene`] ([`scene`]): a versioned TOML scene file (surfaces, railings, start and goal),
//!   validated strictly into an [`Environment`] and the walk's start and goal.
//! - [`walk`]: a walk of a given distance (generated for `distance / scf`, then post-processed).
//! - [`timing`]: timed stances' durations kept consistent with the steps the passes change.
//! - [`derived`]: step sizes, swing heights, orthogonal foot distances.
//! - `plot` (feature `plot`): SVG figures of sequences.
//!
//! Conventions: world z up, metres, radians; quaternions `[x, y, z, w]` in files; end-effector
//! arrays are indexed by `kinematics::robot::EndEffector as usize`.

pub mod derived;
pub mod environment;
pub mod error;
pub mod format;
pub mod generate;
pub mod geometry;
mod json_path;
#[cfg(feature = "learned")]
pub mod learned;
pub mod params;
pub mod passes;
mod pipeline;
#[cfg(feature = "plot")]
pub mod plot;
pub mod poses;
pub mod scene;
pub mod sequence;
mod stance_ik;
pub mod timing;
pub mod walk;

pub use environment::{Environment, HandAffordance, SupportSurface};
pub use error::{FormatError, Location};
pub use generate::{
    AffordanceSet, GenerateError, GenerateOptions, generate, generate_with_railing,
};
pub use geometry::PathFrame;
pub use params::{ContactUnification, Gait, GaitUnavailable, ParamsError, PostProcessParams};
pub use pipeline::PostProcessor;
pub use poses::PoseSequence;
pub use scene::{BeyondPath, Scene, SceneError};
pub use sequence::{NoRailing, PostProcessedSequence, RawSequence, Stance, StanceSequence};
pub use walk::{WalkRequest, WalkingSpeed, synthetic_walk, walk_in};
