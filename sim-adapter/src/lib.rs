//! `walk-sim`: simulated robots behind the adapter side of the IPC contract.
//!
//! - [`RobotIo`]: what an adapter needs from a robot — read its sensors, write joint setpoints.
//!   A hardware adapter (ARMAR-4, HRP-4) implements only this (see docs/adapter.md).
//! - [`run_adapter`]: the adapter loop shared by every robot: publishes samples through
//!   [`shm_types::AdapterPorts`], applies commands, and holds position when commands go stale.
//! - [`SimulatedRobot`]: [`RobotIo`] over any [`kinematic_sim::Simulator`] (the kinematic
//!   simulator, `--physics kinematic`, or MuJoCo, `--physics mujoco`).
//! - [`GroundTruth`], [`PublishTruth`]: a simulated robot's true state on the `sim-truth`
//!   service, for evaluation (drift of the controller's estimate, fall judgement).
//! - [`inject`]: fault injection for evaluating the controlled stop (`walk-sim --inject`).

mod adapter_loop;
pub mod inject;
mod robot_io;
mod scene_ground;
mod simulated;
mod truth;

/// The MuJoCo physics backend (feature `mujoco`; library from scripts/setup-mujoco.sh).
#[cfg(feature = "mujoco")]
pub mod mujoco;

pub use adapter_loop::{AdapterError, AdapterOptions, AdapterReport, run_adapter};
pub use robot_io::RobotIo;
pub use scene_ground::SceneGround;
pub use simulated::{MotorLoad, SimulatedRobot, TerrainContacts};
pub use truth::{GroundTruth, PublishTruth};
