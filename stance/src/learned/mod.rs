//! Stance sequences learned from real human demonstrations (issue 7; the paper's stance source):
//! readers for motion-capture files ([`c3d`], [`npy`], gaitkit JSON in [`demo`]) that refuse
//! implausible trials at load time (`validate`: wrong axes or `forward`, no steps), segmentation
//! into stances with taxonomy labels ([`mod@segment`]), an n-gram model over stance tokens
//! ([`model`]) with a hand-support part ([`hands`]), its query by distance and affordances
//! ([`query`]), retargeting of the generated stances to a robot ([`retarget`]), realism
//! against a held-out walker ([`realism`]), the gait law of step length and timing over walking
//! speed stored in the model ([`gait_law`]), the paper's Fig. 4 ([`coverage`]) and the source
//! choice shared by the commands that generate ([`source`]). See `docs/learning.md`.

pub mod c3d;
mod cluster;
pub mod coverage;
pub mod demo;
pub mod error;
pub mod gait_law;
pub mod hands;
pub mod model;
pub mod npy;
pub mod pace;
pub mod query;
pub mod realism;
pub mod retarget;
pub mod segment;
pub mod source;
mod validate;

pub use demo::{Demonstration, EventKind, GaitEvent, load_folder};
pub use error::LearnError;
pub use gait_law::{GaitLaw, StepGait, WalkerGait};
pub use model::{NgramModel, TrainOptions};
pub use pace::{RobotGait, SpeedRequest};
pub use query::{Generated, Query, Search, generate_tokens};
pub use realism::{Comparison, Distribution, Measure, WalkStatistics};
pub use retarget::{LearnedOptions, Retargeted, generate_learned};
pub use segment::{Keyframe, SegmentOptions, Segmentation, foot_events, segment, taxonomy_label};
pub use source::{SourceArgs, SourceError, SourceKind, Sourced, StanceSource};
