//! Per-stance inverse kinematics shared by the stance sources (synthetic and learned): end-effector
//! target poses in, a stance (`q_S`, contacts, root translation from the previous stance) out.

use kinematics::Configuration;
use kinematics::ik::{IkError, IkOptions, IkSolver, IkTarget};
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Vector3};

use crate::sequence::Stance;

/// Solves a sequence of stances one after the other, warm-started from the previous solution,
/// and expresses each root as eq. 1's translation from the previous stance.
pub(crate) struct StanceIk<'a> {
    robot: &'a Robot,
    solver: IkSolver,
    options: IkOptions,
    targets: Vec<IkTarget>,
    current: Configuration,
    previous_root: Vector3<f64>,
}

/// One solved stance and the IK's remaining errors.
pub(crate) struct SolvedStance {
    /// The stance, root translation relative to the previous solved stance.
    pub stance: Stance,
    /// Remaining `[position, orientation]` error of the IK (m, rad).
    // Reported by the learned source; the synthetic one poses stances the IK reaches exactly.
    #[cfg_attr(not(feature = "learned"), allow(dead_code))]
    pub errors: [f64; 2],
}

impl<'a> StanceIk<'a> {
    /// Starts from the robot's standing posture, root at the origin.
    pub(crate) fn new(robot: &'a Robot) -> Self {
        Self {
            robot,
            solver: IkSolver::new(&robot.model),
            options: IkOptions {
                max_iterations: 60,
                tolerance: 1e-4,
                damping: 1e-2,
                ..IkOptions::default()
            },
            targets: Vec::with_capacity(EndEffector::ALL.len()),
            current: robot.standing.clone(),
            previous_root: Vector3::zeros(),
        }
    }

    /// The last solution (the standing posture before the first stance): the warm start the
    /// caller adjusts for the next stance.
    pub(crate) fn current(&self) -> &Configuration {
        &self.current
    }

    /// Solves one stance from `initial` towards the end-effector poses given (feet weighted fully
    /// in orientation, hands lightly), pulled towards the standing posture. Best effort: an IK
    /// that does not converge gives its best configuration, as a human demonstration retargeted
    /// by optimisation would.
    pub(crate) fn solve(
        &mut self,
        poses: &[Option<Isometry3<f64>>; 4],
        contacts: [bool; 4],
        initial: &Configuration,
    ) -> Result<SolvedStance, IkError> {
        self.targets.clear();
        for e in EndEffector::ALL {
            if let Some(pose) = poses[e as usize] {
                self.targets.push(IkTarget {
                    frame: self.robot.frame(e),
                    pose,
                    position_weight: 1.0,
                    orientation_weight: if e.is_foot() { 1.0 } else { 0.1 },
                });
            }
        }
        let model = &self.robot.model;
        let posture = Some(&self.robot.standing.joints);
        let solution =
            match self
                .solver
                .solve(model, &self.targets, initial, posture, &self.options)
            {
                Ok(solution) => solution,
                Err(IkError::NotConverged(best)) => *best,
                Err(error) => return Err(error),
            };
        let errors = [solution.position_error, solution.orientation_error];
        self.current = solution.configuration;
        let root = self.current.base.translation.vector;
        let stance = Stance {
            q: self.current.joints.as_slice().to_vec(),
            contacts,
            translation: root - self.previous_root,
            root_orientation: self.current.base.rotation,
            duration_s: None,
        };
        self.previous_root = root;
        Ok(SolvedStance { stance, errors })
    }
}
