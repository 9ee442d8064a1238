//! The dynamic gait: the post-processed stances walked at human-like speed on a linear inverted
//! pendulum walking pattern, with a stabilizer on force-torque and IMU (`docs/controller.md`,
//! "Dynamic gait").
//!
//! When a sequence is prepared (off the real-time thread), its foot-contact changes become a
//! timed [footstep plan](footsteps) and the plan's ZMP reference its [DCM pattern](dcm) by the
//! closed-form backward recursion. On the control thread the [walker](walker) runs the plan on
//! its clock: [swing](swing) trajectories for the lifted foot, a [toe-off](toe_off) before a
//! step up, FT-confirmed touchdowns, the
//! [stabilizer](stabilizer) turning the measured DCM ([sensing]) into a desired ZMP inside the
//! support and a pendulum-consistent CoM set-point, and the foot [compliance] tracking the
//! desired ZMP's split between the feet. The QP is the static gait's, with the CoM height held
//! and no CoM-in-polygon constraint.

mod compliance;
mod config;
mod dcm;
mod elevation;
mod footsteps;
mod sensing;
mod stabilizer;
mod swing;
mod toe_off;
mod walker;

use kinematics::ground::GRAVITY;
use kinematics::ground::sequence_alignment;
use kinematics::ground::sole_corners;
use kinematics::kinematics::Kinematics;
use kinematics::robot::Robot;

pub(crate) use compliance::{distribute, force_difference_velocities};
pub(crate) use config::force_difference_bounds;
pub use config::{DynamicGaitConfig, GaitConfig, StabilizerConfig};
pub(crate) use walker::{DynamicWalker, Sensors};

use super::sequence::{PreparedStance, Refusal};
use dcm::{DcmPattern, ZmpOffsets};
use footsteps::{FEET, FootstepPlan};

/// Everything the dynamic gait computes for a sequence before it runs.
#[derive(Clone, Debug)]
pub(crate) struct DynamicPlan {
    /// The tuning it was planned with.
    pub config: DynamicGaitConfig,
    /// CoM height above the support (m).
    pub com_height: f64,
    /// The timed phases.
    pub footsteps: FootstepPlan,
    /// The ZMP reference and its DCM (sequence frame until the walk starts).
    pub pattern: DcmPattern,
    /// The fastest the heel may turn in a toe-off (rad/s): [`toe_off::TOE_OFF_SPEED_SHARE`] of
    /// the slowest leg joint's speed bound.
    pub toe_off_speed: f64,
}

impl DynamicPlan {
    /// Plans `stances` (validated, sequence frame) for `robot` standing on both feet, its joints
    /// turning at most `velocity_limit_scale` of their URDF speed.
    pub fn new(
        robot: &Robot,
        stances: &[PreparedStance],
        config: &DynamicGaitConfig,
        velocity_limit_scale: f64,
    ) -> Result<Self, Refusal> {
        let model = &robot.model;
        let mut kinematics = Kinematics::new(model);
        kinematics.update(model, &robot.standing);
        let standing = FEET.map(|f| kinematics.frame_pose(model, robot.frame(f)));
        let sole_height = standing
            .iter()
            .flat_map(|pose| sole_corners(pose, &robot.sole))
            .map(|corner| corner.z)
            .fold(f64::INFINITY, f64::min);
        let com_height = config
            .com_height_m
            .unwrap_or(kinematics.com().z - sole_height);
        // The standing feet in the sequence's frame, as the walk will align them.
        let first = &stances[0];
        let to_standing = sequence_alignment(
            &FEET.map(|f| first.targets[f as usize]),
            FEET.map(|f| first.contacts[f as usize]),
            &standing,
            [true, true],
        );
        let standing = standing.map(|pose| to_standing.inverse() * pose);
        let footsteps = FootstepPlan::new(stances, standing, config)?;
        let inward = config.zmp_inward_offset_m;
        if inward > robot.sole.width / 2.0 {
            return Err(Refusal(format!(
                "[gait.dynamic] zmp_inward_offset_m {inward} m puts the single-support ZMP \
                 outside the {} m wide sole",
                robot.sole.width
            )));
        }
        let forward = config.step_down_zmp_forward_m;
        if forward > robot.sole.length / 2.0 {
            return Err(Refusal(format!(
                "[gait.dynamic] step_down_zmp_forward_m {forward} m puts the single-support ZMP \
                 of a step down outside the {} m long sole",
                robot.sole.length
            )));
        }
        let omega = (GRAVITY / com_height).sqrt();
        let offsets = ZmpOffsets {
            inward,
            step_down_forward: forward,
        };
        let pattern = DcmPattern::new(&footsteps.phases, omega, offsets);
        let limits = model.joint_limits();
        let slowest_leg = robot
            .joint_groups
            .legs
            .iter()
            .map(|&j| limits[j].velocity)
            .fold(f64::INFINITY, f64::min);
        Ok(Self {
            config: *config,
            com_height,
            footsteps,
            pattern,
            toe_off_speed: toe_off::TOE_OFF_SPEED_SHARE * velocity_limit_scale * slowest_leg,
        })
    }
}
