//! Post-processing as one call: forward kinematics of the raw stances into world poses, the
//! passes (Algorithm 1's nine and the terrain pass), and the post-processed sequence — with
//! buffers reused across calls.

use kinematics::robot::{EndEffector, Robot};
use kinematics::{Configuration, FrameSet, Kinematics};
use nalgebra::{Isometry3, Translation3, Vector3};

use crate::error::FormatError;
use crate::params::PostProcessParams;
use crate::passes::{ContactGeometry, Pass, run_passes, run_passes_observed};
use crate::poses::PoseSequence;
use crate::sequence::{PostProcessedSequence, RawSequence, Stance};
use crate::timing::{FeetPositions, feet_positions, retime_swings};

/// Reusable post-processing workspace for one robot: once its buffers (and the output's) have
/// grown to the longest sequence seen, [`PostProcessor::process_into`] does not allocate.
pub struct PostProcessor<'r> {
    robot: &'r Robot,
    params: PostProcessParams,
    kinematics: Kinematics,
    /// The links on the four end-effectors' ancestor chains: all that forward kinematics needs.
    effector_links: FrameSet,
    configuration: Configuration,
    poses: PoseSequence,
    /// The feet in every raw stance, before the passes: what the stances were timed for.
    planned_feet: FeetPositions,
    /// The stances' durations after the passes ([`crate::timing`]).
    durations: Vec<Option<f64>>,
}

impl<'r> PostProcessor<'r> {
    /// A workspace for `robot` with Algorithm 1's parameters.
    pub fn new(robot: &'r Robot, params: PostProcessParams) -> Self {
        Self {
            robot,
            params,
            kinematics: Kinematics::new(&robot.model),
            effector_links: FrameSet::new(&robot.model, &EndEffector::ALL.map(|e| robot.frame(e))),
            configuration: robot.standing.clone(),
            poses: PoseSequence::default(),
            planned_feet: FeetPositions::new(),
            durations: Vec::new(),
        }
    }

    /// The parameters in use.
    pub fn params(&self) -> &PostProcessParams {
        &self.params
    }

    /// Fills the workspace's poses with the world pose of the root and of every end-effector in
    /// every stance of `raw` (FK of the stance's `q_S` at its global root pose) and returns them.
    pub fn forward_kinematics(&mut self, raw: &RawSequence) -> Result<&PoseSequence, FormatError> {
        raw.check_robot(self.robot)?;
        let model = &self.robot.model;
        self.poses.clear();
        let mut position = Vector3::zeros();
        for stance in raw.stances() {
            position += stance.translation;
            self.configuration.base =
                Isometry3::from_parts(Translation3::from(position), stance.root_orientation);
            self.configuration
                .joints
                .as_mut_slice()
                .copy_from_slice(&stance.q);
            self.kinematics
                .update_frames(model, &self.configuration, &self.effector_links);
            let poses =
                EndEffector::ALL.map(|e| self.kinematics.frame_pose(model, self.robot.frame(e)));
            self.poses
                .push(self.configuration.base, poses, stance.contacts);
        }
        Ok(&self.poses)
    }

    /// Post-processes `raw` into a new sequence.
    pub fn process(&mut self, raw: &RawSequence) -> Result<PostProcessedSequence, FormatError> {
        let mut out = PostProcessedSequence::empty();
        self.process_into(raw, &mut out)?;
        Ok(out)
    }

    /// Post-processes `raw` into `out`, reusing `out`'s buffers. Refuses a sequence for another
    /// robot.
    pub fn process_into(
        &mut self,
        raw: &RawSequence,
        out: &mut PostProcessedSequence,
    ) -> Result<(), FormatError> {
        self.forward_kinematics(raw)?;
        feet_positions(&self.poses, &mut self.planned_feet);
        run_passes(
            &mut self.poses,
            raw.environment(),
            &self.params,
            &ContactGeometry::of(self.robot),
        );
        self.retime(raw);
        out.assign(raw, &self.poses, &self.durations);
        out.gait = Some(self.params.gait);
        Ok(())
    }

    /// The raw stances' durations, kept consistent with the steps the passes changed.
    fn retime(&mut self, raw: &RawSequence) {
        self.durations.clear();
        self.durations
            .extend(raw.stances().iter().map(|stance| stance.duration_s));
        retime_swings(
            &self.planned_feet,
            &self.poses,
            self.params.scf,
            &mut self.durations,
        );
    }

    /// [`PostProcessor::process`] that also hands the poses after each pass to `after` (Fig. 3).
    pub fn process_observed(
        &mut self,
        raw: &RawSequence,
        after: impl FnMut(Pass, &PoseSequence),
    ) -> Result<PostProcessedSequence, FormatError> {
        self.forward_kinematics(raw)?;
        feet_positions(&self.poses, &mut self.planned_feet);
        run_passes_observed(
            &mut self.poses,
            raw.environment(),
            &self.params,
            &ContactGeometry::of(self.robot),
            after,
        );
        self.retime(raw);
        let mut out = PostProcessedSequence::empty();
        out.assign(raw, &self.poses, &self.durations);
        out.gait = Some(self.params.gait);
        Ok(out)
    }
}

impl PostProcessedSequence {
    /// Overwrites `self` with `raw`'s stances (same `q_S` and contacts, root translations from the
    /// post-processed roots, `durations`) and the post-processed end-effector poses, reusing
    /// buffers.
    fn assign(&mut self, raw: &RawSequence, poses: &PoseSequence, durations: &[Option<f64>]) {
        let sequence = &mut self.sequence;
        if sequence.robot != raw.robot {
            sequence.robot.clone_from(&raw.robot);
        }
        if sequence.joint_names != raw.joint_names {
            sequence.joint_names.clone_from(&raw.joint_names);
        }
        if sequence.environment != raw.environment {
            sequence.environment = raw.environment.clone();
        }
        sequence.stances.truncate(poses.len());
        let mut previous = Vector3::zeros();
        let stances = raw.stances.iter().zip(&poses.roots).zip(durations);
        for (i, ((stance, root), &duration_s)) in stances.enumerate() {
            let translation = root.translation.vector - previous;
            previous = root.translation.vector;
            match sequence.stances.get_mut(i) {
                Some(existing) => {
                    existing.q.clear();
                    existing.q.extend_from_slice(&stance.q);
                    existing.contacts = stance.contacts;
                    existing.translation = translation;
                    existing.root_orientation = stance.root_orientation;
                    existing.duration_s = duration_s;
                }
                None => sequence.stances.push(Stance {
                    translation,
                    duration_s,
                    ..stance.clone()
                }),
            }
        }
        self.targets.clear();
        self.targets.extend_from_slice(&poses.end_effectors);
    }

    /// The sequence's world poses (post-processed roots, targets, contacts), e.g. to check the
    /// passes' invariants or run them again.
    pub fn to_poses(&self) -> PoseSequence {
        let mut poses = PoseSequence::with_capacity(self.len());
        for ((root, targets), stance) in self.root_poses().zip(&self.targets).zip(&self.stances) {
            poses.push(root, *targets, stance.contacts);
        }
        poses
    }
}
