//! The controller in closed loop with a simulator, in one process, and the tools built on it.
//!
//! - [`closed_loop`]: the one tick loop (measure → `Controller::tick` → simulator step), for the
//!   kinematic simulator and MuJoCo alike.
//! - [`walk`]: a walk to its end against the kinematic simulator; [`command`] is `walk-bench`.
//! - [`sequence`]: where a bench walk comes from (a stance source or a file).
//! - `physics` (feature `mujoco`): a walk under MuJoCo with fall detection, drift and the paper's
//!   Fig. 6 trace.
//!
//! - `matrix` (feature `mujoco`): `physics-matrix`, those walks over affordance sets ×
//!   distances × seeds with config overrides, model error and pushes.
//! - `tune` (feature `mujoco`): `walk-tune`, those matrices over step timing × step length, for
//!   the fastest dynamic gait a robot walks without a fall.
//!
//! Binaries: `walk-bench` (a walk as fast as the machine runs), `physics-matrix` and `walk-tune`
//! (feature `mujoco`) and `latency-report` (latency and deadline misses of the real multi-process
//! system). This crate, not `daemon`, links the
//! simulators: walkd itself links none.

pub mod closed_loop;
pub mod command;
/// `physics-matrix`: in-process MuJoCo walks over a matrix (feature `mujoco`).
#[cfg(feature = "mujoco")]
pub mod matrix;
/// The controller walking under MuJoCo physics, in one process (feature `mujoco`).
#[cfg(feature = "mujoco")]
pub mod physics;
pub mod sequence;
/// `walk-tune`: the fastest dynamic gait that walks without a fall (feature `mujoco`).
#[cfg(feature = "mujoco")]
pub mod tune;
pub mod walk;

pub use closed_loop::{ClosedLoop, Readings, TickError};
pub use walk::{
    Outcome, TickObservation, WalkError, WalkOptions, WalkReport, kinematic_gaits, walk,
};
