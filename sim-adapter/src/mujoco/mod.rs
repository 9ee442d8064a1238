//! The MuJoCo physics backend (`walk-sim --physics mujoco`): the robot under rigid-body dynamics
//! with contacts, driven like the kinematic simulator.
//!
//! Built behind the `mujoco` cargo feature; the library is fetched by `scripts/setup-mujoco.sh`
//! (see `docs/mujoco.md`). The model is generated from the URDF's kinematics and inertials plus
//! the `[robot]` section's frames (`mjcf` documents every modelling choice); [`MujocoSim`] steps
//! it with joint servos tracking `q_des` / `q̇_des` and reports the same [`SimMeasurement`]
//! record as `kinematic_sim::KinematicSim`, plus base height and tilt for fall detection.
//! [`MujocoSim::on_terrain`](crate::mujoco::MujocoSim::on_terrain) builds the world of a scene
//! instead of the flat floor ([`Terrain`](crate::mujoco::Terrain): surfaces as boxes, railings as
//! capsules, capsules on the legs) and counts the legs' contacts with it
//! ([`TerrainCollisions`](crate::mujoco::TerrainCollisions)).
//! It is a [`kinematic_sim::Simulator`], so [`crate::SimulatedRobot`] puts it behind
//! [`crate::RobotIo`] for the adapter loop.
//!
//! [`SimMeasurement`]: kinematic_sim::SimMeasurement

mod actuators;
mod bodies;
mod collisions;
mod contact;
mod error;
mod mjcf;
mod options;
#[cfg(feature = "render")]
pub mod render;
mod sim;
mod terrain;
mod visuals;

pub use collisions::{KEPT_EVENTS, TerrainCollision, TerrainCollisions};
pub use error::MujocoError;
pub use options::MujocoOptions;
pub use sim::MujocoSim;
pub use terrain::{DEPTH_BELOW, Terrain};
