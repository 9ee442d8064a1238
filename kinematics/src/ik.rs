//! Damped-least-squares inverse kinematics for a set of frame pose targets, within joint limits.
//!
//! Each iteration solves the Levenberg–Marquardt step
//! `(Σ Jᵢᵀ Wᵢ Jᵢ + λ² I + w_p² S) Δν = Σ Jᵢᵀ Wᵢ eᵢ + w_p² S (q_ref − q)`
//! where eᵢ = (p* − p, log(R* Rᵀ)) is the world-frame pose error of target i, Wᵢ its weights, λ the
//! damping and S selects the joint coordinates. The posture attraction w_p is scaled by the
//! current task error, so it shapes the solution while targets are far and vanishes as they are
//! reached (it never biases a converged solution). Joints that would cross a limit are pinned
//! to it and the step is re-solved for the others; the base is free unless
//! [`IkOptions::fixed_base`] is set.

use nalgebra::{Cholesky, DMatrix, DVector, Isometry3, Vector3};

use crate::configuration::Configuration;
use crate::kinematics::Kinematics;
use crate::model::{FrameId, Model};

/// A pose the frame `frame` should reach.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkTarget {
    /// The frame to move.
    pub frame: FrameId,
    /// Its desired world pose.
    pub pose: Isometry3<f64>,
    /// Weight of the position error (0 ignores position).
    pub position_weight: f64,
    /// Weight of the orientation error (0 ignores orientation).
    pub orientation_weight: f64,
}

/// Solver settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkOptions {
    /// Iteration limit.
    pub max_iterations: usize,
    /// Levenberg–Marquardt damping λ (regularises the step near singularities).
    pub damping: f64,
    /// Convergence threshold on every weighted target's position (m) and orientation (rad) error.
    pub tolerance: f64,
    /// Attraction towards the posture reference (scaled by the task error, see module docs).
    pub posture_weight: f64,
    /// Largest change of any coordinate of ν in one iteration (rad or m).
    pub max_step: f64,
    /// Keep the base where `initial` has it and move only the joints.
    pub fixed_base: bool,
}

impl Default for IkOptions {
    fn default() -> Self {
        Self {
            max_iterations: 200,
            damping: 1e-3,
            tolerance: 1e-6,
            posture_weight: 0.1,
            max_step: 0.2,
            fixed_base: false,
        }
    }
}

/// The result of a converged solve.
#[derive(Debug, Clone, PartialEq)]
pub struct IkSolution {
    /// The solution, joints within limits.
    pub configuration: Configuration,
    /// Largest position error over targets with a position weight (m).
    pub position_error: f64,
    /// Largest orientation error over targets with an orientation weight (rad).
    pub orientation_error: f64,
    /// Iterations used.
    pub iterations: usize,
}

/// Why the solver gave no solution.
#[derive(Debug, thiserror::Error)]
pub enum IkError {
    /// `initial` or `posture` has the wrong number of joints.
    #[error("IK: {what} has {got} joints, the model has {expected}")]
    WrongJointCount {
        /// Which input.
        what: &'static str,
        /// Model dof.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// A target pose or weight is not finite, or a weight is negative.
    #[error("IK: target {0} has a non-finite pose or a negative/non-finite weight")]
    InvalidTarget(usize),
    /// An option is out of range.
    #[error("IK: invalid option: {0}")]
    InvalidOptions(&'static str),
    /// The iteration limit was reached; the best configuration found is attached.
    #[error(
        "IK did not converge in {} iterations (position error {:.3e} m, orientation error {:.3e} rad)",
        .0.iterations, .0.position_error, .0.orientation_error
    )]
    NotConverged(Box<IkSolution>),
}

/// Reusable IK workspace: allocates at construction only.
#[derive(Debug, Clone)]
pub struct IkSolver {
    kinematics: Kinematics,
    jacobian: DMatrix<f64>,
    hessian: DMatrix<f64>,
    hessian_copy: DMatrix<f64>,
    gradient: DVector<f64>,
    gradient_copy: DVector<f64>,
    step: DVector<f64>,
    pinned: Vec<bool>,
}

impl IkSolver {
    /// Allocates the workspace for `model`.
    pub fn new(model: &Model) -> Self {
        let nv = model.nv();
        Self {
            kinematics: Kinematics::new(model),
            jacobian: DMatrix::zeros(6, nv),
            hessian: DMatrix::zeros(nv, nv),
            hessian_copy: DMatrix::zeros(nv, nv),
            gradient: DVector::zeros(nv),
            gradient_copy: DVector::zeros(nv),
            step: DVector::zeros(nv),
            pinned: vec![false; model.dof()],
        }
    }

    /// Moves `initial` until every target is reached within `options.tolerance`, joints within
    /// limits, staying close to `posture` (default: `initial`'s joints).
    pub fn solve(
        &mut self,
        model: &Model,
        targets: &[IkTarget],
        initial: &Configuration,
        posture: Option<&DVector<f64>>,
        options: &IkOptions,
    ) -> Result<IkSolution, IkError> {
        validate(model, targets, initial, posture, options)?;
        let posture = posture.unwrap_or(&initial.joints);
        let mut q = initial.clone();
        q.clamp_to_limits(model);
        let mut iterations = 0;
        loop {
            self.kinematics.update(model, &q);
            let (position_error, orientation_error) = self.errors(model, targets);
            let converged =
                position_error <= options.tolerance && orientation_error <= options.tolerance;
            if converged || iterations == options.max_iterations {
                let solution = IkSolution {
                    configuration: q,
                    position_error,
                    orientation_error,
                    iterations,
                };
                return if converged {
                    Ok(solution)
                } else {
                    Err(IkError::NotConverged(Box::new(solution)))
                };
            }
            let task_error = position_error.max(orientation_error);
            self.assemble(model, targets, &q, posture, options, task_error);
            self.solve_step(model, &q, options);
            q.integrate(self.step.as_slice(), 1.0);
            q.clamp_to_limits(model);
            iterations += 1;
        }
    }

    /// Largest position and orientation error over the weighted targets.
    fn errors(&self, model: &Model, targets: &[IkTarget]) -> (f64, f64) {
        let mut position: f64 = 0.0;
        let mut orientation: f64 = 0.0;
        for target in targets {
            let (dp, dr) = pose_error(
                &self.kinematics.frame_pose(model, target.frame),
                &target.pose,
            );
            if target.position_weight > 0.0 {
                position = position.max(dp.norm());
            }
            if target.orientation_weight > 0.0 {
                orientation = orientation.max(dr.norm());
            }
        }
        (position, orientation)
    }

    /// Builds the normal equations of the damped, posture-regularised least-squares step.
    fn assemble(
        &mut self,
        model: &Model,
        targets: &[IkTarget],
        q: &Configuration,
        posture: &DVector<f64>,
        options: &IkOptions,
        task_error: f64,
    ) {
        self.hessian.fill(0.0);
        self.gradient.fill(0.0);
        for target in targets {
            let current = self.kinematics.frame_pose(model, target.frame);
            let (dp, dr) = pose_error(&current, &target.pose);
            self.kinematics
                .frame_jacobian(model, target.frame, &mut self.jacobian);
            let blocks = [
                (target.position_weight, dp),
                (target.orientation_weight, dr),
            ];
            for (block, (weight, error)) in blocks.into_iter().enumerate() {
                for (row, component) in error.iter().enumerate() {
                    let r = 3 * block + row;
                    let weighted_error = weight * component;
                    for c in 0..self.gradient.len() {
                        self.jacobian[(r, c)] *= weight;
                        self.gradient[c] += weighted_error * self.jacobian[(r, c)];
                    }
                }
            }
            self.hessian
                .gemm_tr(1.0, &self.jacobian, &self.jacobian, 1.0);
        }
        let nv = model.nv();
        let damping = options.damping * options.damping;
        let posture_weight = options.posture_weight * options.posture_weight * task_error.min(1.0);
        for i in 0..nv {
            self.hessian[(i, i)] += damping;
        }
        for j in 0..model.dof() {
            self.hessian[(6 + j, 6 + j)] += posture_weight;
            self.gradient[6 + j] += posture_weight * (posture[j] - q.joints[j]);
        }
        if options.fixed_base {
            for i in 0..6 {
                self.pin(i, 0.0);
            }
        }
    }

    /// Fixes coordinate `i` of the step to `value` in the normal equations.
    fn pin(&mut self, i: usize, value: f64) {
        let nv = self.gradient.len();
        for k in 0..nv {
            self.gradient[k] -= self.hessian[(k, i)] * value;
            self.hessian[(k, i)] = 0.0;
            self.hessian[(i, k)] = 0.0;
        }
        self.hessian[(i, i)] = 1.0;
        self.gradient[i] = value;
    }

    /// Solves for the step; joints that would cross a limit are pinned to it and the rest re-solved.
    fn solve_step(&mut self, model: &Model, q: &Configuration, options: &IkOptions) {
        self.pinned.fill(false);
        self.hessian_copy.copy_from(&self.hessian);
        self.gradient_copy.copy_from(&self.gradient);
        for _ in 0..4 {
            self.factor_and_solve();
            let mut newly_pinned = false;
            for (j, limits) in model.joint_limits().iter().enumerate() {
                let target = q.joints[j] + self.step[6 + j];
                if !self.pinned[j] && (target < limits.lower || target > limits.upper) {
                    self.pinned[j] = true;
                    newly_pinned = true;
                }
            }
            if !newly_pinned {
                break;
            }
            self.hessian.copy_from(&self.hessian_copy);
            self.gradient.copy_from(&self.gradient_copy);
            for (j, limits) in model.joint_limits().iter().enumerate() {
                if self.pinned[j] {
                    let to_limit = (q.joints[j] + self.step[6 + j])
                        .clamp(limits.lower, limits.upper)
                        - q.joints[j];
                    self.pin(6 + j, to_limit);
                }
            }
        }
        let largest = self.step.amax();
        if largest > options.max_step {
            self.step *= options.max_step / largest;
        }
    }

    /// step = hessian⁻¹ gradient, reusing the hessian's storage for the factor.
    fn factor_and_solve(&mut self) {
        let matrix = std::mem::replace(&mut self.hessian, DMatrix::zeros(0, 0));
        self.step.copy_from(&self.gradient);
        match Cholesky::new(matrix) {
            Some(factor) => {
                factor.solve_mut(&mut self.step);
                self.hessian = factor.unpack();
            }
            None => {
                // Only possible with zero damping at a singularity: take no step.
                self.step.fill(0.0);
                self.hessian = DMatrix::zeros(self.step.len(), self.step.len());
            }
        }
    }
}

/// (p* − p, log(R* Rᵀ)) in the world frame.
fn pose_error(current: &Isometry3<f64>, target: &Isometry3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let position = target.translation.vector - current.translation.vector;
    let orientation = (target.rotation * current.rotation.inverse()).scaled_axis();
    (position, orientation)
}

fn validate(
    model: &Model,
    targets: &[IkTarget],
    initial: &Configuration,
    posture: Option<&DVector<f64>>,
    options: &IkOptions,
) -> Result<(), IkError> {
    let dof = model.dof();
    if initial.joints.len() != dof {
        return Err(IkError::WrongJointCount {
            what: "initial",
            expected: dof,
            got: initial.joints.len(),
        });
    }
    if let Some(posture) = posture {
        if posture.len() != dof {
            return Err(IkError::WrongJointCount {
                what: "posture",
                expected: dof,
                got: posture.len(),
            });
        }
    }
    for (i, target) in targets.iter().enumerate() {
        let pose_finite = target.pose.translation.vector.iter().all(|x| x.is_finite())
            && target.pose.rotation.coords.iter().all(|x| x.is_finite());
        let weight_ok = |w: f64| w.is_finite() && w >= 0.0;
        if !pose_finite
            || !weight_ok(target.position_weight)
            || !weight_ok(target.orientation_weight)
        {
            return Err(IkError::InvalidTarget(i));
        }
    }
    if !(options.damping.is_finite() && options.damping >= 0.0) {
        return Err(IkError::InvalidOptions("damping must be finite and >= 0"));
    }
    if !(options.tolerance.is_finite() && options.tolerance > 0.0) {
        return Err(IkError::InvalidOptions("tolerance must be finite and > 0"));
    }
    if !(options.posture_weight.is_finite() && options.posture_weight >= 0.0) {
        return Err(IkError::InvalidOptions(
            "posture_weight must be finite and >= 0",
        ));
    }
    if !(options.max_step.is_finite() && options.max_step > 0.0) {
        return Err(IkError::InvalidOptions("max_step must be finite and > 0"));
    }
    Ok(())
}
