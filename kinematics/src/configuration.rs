//! A robot configuration: floating-base pose plus the actuated joint vector.

use nalgebra::{DVector, Isometry3, Translation3, UnitQuaternion, Vector3};

use crate::model::Model;

/// Base pose in the world and joint positions in model order (see [`Model::joint_names`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Configuration {
    /// Pose of the floating-base link (the URDF root) in the world frame.
    pub base: Isometry3<f64>,
    /// Actuated joint positions in model order.
    pub joints: DVector<f64>,
}

impl Configuration {
    /// Identity base pose, every joint at zero clamped into its limits.
    pub fn neutral(model: &Model) -> Self {
        let joints = DVector::from_iterator(
            model.dof(),
            model
                .joint_limits()
                .iter()
                .map(|l| 0.0_f64.clamp(l.lower, l.upper)),
        );
        Self {
            base: Isometry3::identity(),
            joints,
        }
    }

    /// Moves along the generalized velocity `nu` = (v, ω, q̇) for `dt` seconds.
    ///
    /// v and ω are the base's linear and angular velocity in the world frame, so the base
    /// translation advances by v·dt and its rotation becomes exp(ω·dt)·R.
    ///
    /// # Panics
    /// If `nu.len() != 6 + joints.len()`.
    pub fn integrate(&mut self, nu: &[f64], dt: f64) {
        assert_eq!(
            nu.len(),
            6 + self.joints.len(),
            "integrate: nu has the wrong length"
        );
        let v = Vector3::new(nu[0], nu[1], nu[2]);
        let w = Vector3::new(nu[3], nu[4], nu[5]);
        self.base.translation = Translation3::from(self.base.translation.vector + v * dt);
        self.base.rotation = UnitQuaternion::from_scaled_axis(w * dt) * self.base.rotation;
        for (q, qd) in self.joints.iter_mut().zip(&nu[6..]) {
            *q += qd * dt;
        }
    }

    /// Clamps every joint into its position limits.
    pub fn clamp_to_limits(&mut self, model: &Model) {
        for (q, limits) in self.joints.iter_mut().zip(model.joint_limits()) {
            *q = q.clamp(limits.lower, limits.upper);
        }
    }

    /// Position of the joint called `name`, if the model has it.
    pub fn joint(&self, model: &Model, name: &str) -> Option<f64> {
        model.joint_index(name).map(|i| self.joints[i])
    }

    /// Sets the joint called `name`; returns `false` if the model has no such joint.
    pub fn set_joint(&mut self, model: &Model, name: &str, value: f64) -> bool {
        match model.joint_index(name) {
            Some(i) => {
                self.joints[i] = value;
                true
            }
            None => false,
        }
    }
}
