//! URDF → floating-base model: forward kinematics, frame and CoM Jacobians, inverse kinematics.
//!
//! # Conventions
//! - World frame: z up, gravity −z, metres, radians, right-handed; quaternions `[x, y, z, w]`.
//! - The floating base is the URDF's root link; [`Configuration::base`] is its pose in the world.
//! - Generalized velocity ν ∈ R^(6+n) = (v, ω, q̇): v is the linear velocity of the base-link
//!   origin in the world frame, ω the base angular velocity in the world frame, q̇ the joint
//!   velocities in model order.
//! - A frame Jacobian (6 × (6+n)) maps ν to (linear velocity of the frame origin; angular velocity
//!   of the frame), both in the world frame: rows 0..3 linear, 3..6 angular.
//!   (Pinocchio's `LOCAL_WORLD_ALIGNED` output; its free-flyer input is in the base frame instead.)
//! - The CoM Jacobian (3 × (6+n)) maps ν to ċ in the world frame.
//! - Mimic joints are treated as fixed at their offset; they are not in the joint vector.

pub mod bounds;
pub mod config_file;
pub mod configuration;
pub mod ground;
pub mod ik;
pub mod kinematics;
pub mod model;
pub mod robot;
pub mod skeleton;

pub use nalgebra::{DMatrix, DVector, Isometry3, Translation3, UnitQuaternion, Vector3};

pub use config_file::{ConfigFile, ConfigFileError};
pub use configuration::Configuration;
pub use ik::{IkError, IkOptions, IkSolution, IkSolver, IkTarget};
pub use kinematics::{FrameSet, Kinematics};
pub use model::{FrameId, JointLimits, LinkId, Model, ModelError};
pub use robot::{EndEffector, JointGroups, Robot, RobotError, SoleRectangle};
pub use skeleton::{LinkShape, Part, Shape};
