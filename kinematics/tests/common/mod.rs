//! Helpers shared by the integration tests: vendored model paths and seeded random configurations.
#![allow(dead_code)]

use std::path::PathBuf;

use kinematics::{Configuration, Isometry3, Model, Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Path of a file relative to the workspace root.
pub fn workspace_path(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

/// The vendored ARMAR-4 URDF.
pub fn armar4_urdf() -> PathBuf {
    workspace_path("configs/robots/armar4/armar4_fixed_hands.urdf")
}

/// The vendored JVRC-1 URDF.
pub fn jvrc1_urdf() -> PathBuf {
    workspace_path("configs/robots/jvrc1/jvrc1.urdf")
}

/// A deterministic random generator.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// A random rigid transform with translation in [-1, 1]³ and a uniformly random rotation.
pub fn random_pose(rng: &mut ChaCha8Rng) -> Isometry3<f64> {
    let t = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let q = nalgebra::Quaternion::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    Isometry3::from_parts(Translation3::from(t), UnitQuaternion::from_quaternion(q))
}

/// A random configuration: random base pose, joints uniform within their limits.
pub fn random_configuration(model: &Model, rng: &mut ChaCha8Rng) -> Configuration {
    let mut q = Configuration::neutral(model);
    q.base = random_pose(rng);
    for (value, limits) in q.joints.iter_mut().zip(model.joint_limits()) {
        let (lower, upper) = (limits.lower.max(-3.0), limits.upper.min(3.0));
        *value = if upper > lower {
            rng.random_range(lower..upper)
        } else {
            lower
        };
    }
    q
}
