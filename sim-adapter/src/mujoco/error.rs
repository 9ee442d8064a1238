//! What can go wrong building or stepping the MuJoCo model.

use std::path::PathBuf;

/// Errors of the MuJoCo backend, each naming what is wrong and where.
#[derive(Debug, thiserror::Error)]
pub enum MujocoError {
    /// The linked MuJoCo library is not the version mujoco-rs was built for.
    #[error(
        "linked MuJoCo library is version {found}, expected {expected}; run scripts/setup-mujoco.sh and rebuild"
    )]
    LibraryVersion {
        /// Version reported by the library.
        found: String,
        /// Version required.
        expected: &'static str,
    },
    /// The URDF could not be read or parsed.
    #[error("{path}: {message}")]
    Urdf {
        /// The URDF file.
        path: PathBuf,
        /// The reader's message.
        message: String,
    },
    /// The URDF and the kinematic model (or the robot config) disagree.
    #[error("physics model: {0}")]
    ModelMismatch(String),
    /// MuJoCo rejected the generated model.
    #[error("MuJoCo could not compile the generated model: {0}")]
    Compile(String),
    /// A scene that cannot be turned into MuJoCo geometry (only a scene built by hand can be:
    /// `stance::Scene::from_path` validates the rest).
    #[error("terrain: {0}")]
    BadTerrain(String),
    /// Drawing or saving a picture failed (feature `render`).
    #[error("rendering: {0}")]
    Render(String),
    /// An option is out of range.
    #[error("MuJoCo option `{name}` = {}: {requirement}", kinematics::bounds::Number(*value))]
    BadOption {
        /// Field of [`super::MujocoOptions`].
        name: &'static str,
        /// The value given.
        value: f64,
        /// What it must satisfy.
        requirement: String,
    },
    /// A command (or the initial joint vector) has the wrong length or a non-finite entry.
    #[error("{0}")]
    JointVector(#[from] kinematic_sim::JointVectorError),
    /// The initial base pose is not finite.
    #[error("initial base pose is not finite")]
    NonFiniteBase,
    /// The step duration is not positive and finite.
    #[error("time step {0} s is not positive and finite")]
    BadTimeStep(f64),
    /// The simulation diverged (MuJoCo found a non-finite or huge state and reset it).
    #[error("the simulation diverged at t = {time} s (MuJoCo reset the state)")]
    Unstable {
        /// Simulated time of the failure.
        time: f64,
    },
}
