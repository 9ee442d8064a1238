//! The `[controller]` section of a robot config: task weights and gains, limits margins,
//! trajectory speeds, tolerances, contact thresholds and timeouts.

use std::path::Path;

use kinematics::bounds::{Bound, Number, first_outside};
use kinematics::config_file::toml_message;
use kinematics::{ConfigFile, ConfigFileError};
use serde::Deserialize;

use super::gait::force_difference_bounds;
use super::sequence::SceneLimits;

/// The section [`ControllerConfig`] is read from.
const SECTION: &str = "controller";

/// `max_slope_rad` of the static gait unless configured: JVRC-1's, which walks the 10° ramp up
/// and down (0.175 rad, with room for round-off).
const STATIC_MAX_SLOPE_RAD: f64 = 0.18;

/// Controller tuning from the `[controller]` section; every key is optional (defaults below suit
/// the vendored humanoids) and an unknown key is an error naming the file and key.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ControllerConfig {
    /// Weight of the CoM x/y task.
    pub com_weight: f64,
    /// Weight of a swinging foot's pose task.
    pub foot_weight: f64,
    /// Weight of a hand's pose task (reaching or holding a hand contact).
    pub hand_weight: f64,
    /// Weight of the upright base-orientation task.
    pub torso_weight: f64,
    /// Weight of the posture task towards the stance's joint angles (low: moves the upper body).
    pub posture_weight: f64,
    /// Replaces `posture_weight` on the torso joints that turn the upper body about the vertical
    /// (their axis within 30° of it standing), unless the dynamic gait's `torso_posture_weight`
    /// replaces it on every torso joint; absent: `posture_weight`. At ARMAR-4's 0.01 the QP
    /// shifted its CoM sideways by swinging the waist round, ±0.8 rad at every static step on
    /// the flat (its ankle roll cannot shift it); at 0.03 its static stairs walk 10/10 up and
    /// down (docs/controller.md, "Waist yaw").
    pub torso_yaw_posture_weight: Option<f64>,
    /// λ of the λ‖ν‖² regulariser that keeps P positive definite.
    pub regularization: f64,
    /// Proportional gain of the CoM task (1/s).
    pub com_gain: f64,
    /// Proportional gain of the foot and hand pose tasks (1/s).
    pub pose_gain: f64,
    /// Proportional gain of the upright task (1/s).
    pub torso_gain: f64,
    /// Proportional gain of the posture task (1/s).
    pub posture_gain: f64,
    /// Joints are kept this far inside their position limits (rad).
    pub joint_limit_margin_rad: f64,
    /// Fraction of each joint's URDF velocity limit the QP may use.
    pub velocity_limit_scale: f64,
    /// Bound on each base velocity component (m/s, rad/s).
    pub max_base_speed: f64,
    /// Bound on the base's roll and pitch rates (world x and y components of ω, rad/s; the
    /// smaller of this and `max_base_speed` applies). A pelvis that tilts fast pushes the stance
    /// sole over its edge by reaction; robots that shift the CoM by tilting the pelvis (little
    /// ankle roll) need this well below `max_base_speed`.
    pub max_base_tilt_speed: f64,
    /// Bound on the speed at which a foot in contact is pulled back to its anchor (m/s). The
    /// correction `pose_gain · (anchor − pose)` removes drift; after a touchdown on a tilted robot
    /// the error is millimetres and correcting it at the full gain kicks the robot.
    pub max_anchor_correction_speed: f64,
    /// The same for the foot's orientation (rad/s).
    pub max_anchor_correction_angular_speed: f64,
    /// The CoM ground projection stays this far inside the support polygon (m).
    pub support_margin_m: f64,
    /// Rate at which the CoM may approach the shrunk support polygon's edge (1/s).
    pub support_gain: f64,
    /// Average CoM speed of a CoM shift (m/s).
    pub com_speed: f64,
    /// Average foot/hand speed of a swing or reach (m/s).
    pub swing_speed: f64,
    /// Average angular speed of a swing or reach (rad/s).
    pub swing_angular_speed: f64,
    /// Shortest duration of any trajectory (s).
    pub min_motion_s: f64,
    /// Height of the vertical lift after unloading a foot (m).
    pub lift_height_m: f64,
    /// The swing ends this far above the next contact pose before lowering (m).
    pub approach_height_m: f64,
    /// Speed of the final descent onto the contact (m/s).
    pub lower_speed: f64,
    /// How far below the contact pose the descent target goes until touchdown is confirmed (m).
    pub lower_overshoot_m: f64,
    /// How far the unloading foot is raised while its load drops (m).
    pub unload_lift_m: f64,
    /// CoM position tolerance (m).
    pub com_tolerance_m: f64,
    /// End-effector position tolerance (m).
    pub position_tolerance_m: f64,
    /// End-effector orientation tolerance (rad).
    pub orientation_tolerance_rad: f64,
    /// Position tolerance of a swing's via pose (the stance's swing pose, not a contact) (m).
    pub via_position_tolerance_m: f64,
    /// Orientation tolerance of a swing's via pose (rad).
    pub via_orientation_tolerance_rad: f64,
    /// Position tolerance of a hand contact (the kinematic simulator models no hand support) (m).
    pub hand_position_tolerance_m: f64,
    /// Orientation tolerance of a hand contact (rad).
    pub hand_orientation_tolerance_rad: f64,
    /// A foot is released when its FT normal force drops below this fraction of the weight.
    pub release_force_fraction: f64,
    /// A touchdown is confirmed when the FT normal force exceeds this fraction of the weight ...
    pub touchdown_force_fraction: f64,
    /// ... for this long without a break (s); a time, not a count of ticks, so a touchdown is
    /// confirmed as fast at 1 kHz as at 500 Hz. It was 3 ticks, 6 ms at 500 Hz; JVRC-1 up the
    /// 0.15 m stairs at 1 kHz, in process, seeds 0–29: 21/30 at 3 ms, 26/30 at 6 ms.
    pub touchdown_debounce_s: f64,
    /// While a walk executes, the feet together must carry at least this fraction of the
    /// weight, but for moments of up to `unloaded_max_s`; longer is a measurement fault (a
    /// force-torque dropout: a walking robot always stands on a foot).
    pub support_force_min_fraction: f64,
    /// The longest moment the feet may carry less than that (s). MuJoCo's ARMAR-4 reads no foot
    /// force for up to 16 ms at a time while it walks dynamically (its soles chatter).
    pub unloaded_max_s: f64,
    /// Time allowed beyond a phase's planned duration before it is a fault (s).
    pub phase_timeout_s: f64,
    /// Longest step between consecutive contacts of one foot that a sequence may ask for (m).
    pub max_step_m: f64,
    /// Highest step up the static gait takes: a landing this far above the other foot's sole
    /// at most (m, the stair's riser); a sequence with a higher one is refused (docs/scenes.md,
    /// "Step heights"). JVRC-1's standing knee lifts it up a 0.10 m stair in 1 of 4 walks and
    /// tips it in the others.
    pub max_step_up_m: f64,
    /// Highest step down the static gait takes (m): JVRC-1 cannot reach a 0.10 m stair's tread
    /// 0.29 m ahead with its CoM over the standing foot (its steps are taken back).
    pub max_step_down_m: f64,
    /// Steepest surface the static gait stands on: a sole in contact tilted more than this from
    /// horizontal is refused (rad; docs/scenes.md, "Step heights").
    pub max_slope_rad: f64,
    /// Whether the static gait walks with a hand holding a railing: off, a sequence whose scene
    /// has railings and whose stances hold a hand is refused (docs/scenes.md, "Hands on
    /// railings"). JVRC-1 walks `railing.toml` holding it 40/40 (MuJoCo); ARMAR-4 fell.
    pub hold_railings: bool,
    /// How far the integrated joint command may lead the measured angle (rad). The command is
    /// integrated from the previous command, so a loaded joint keeps the servo offset that holds
    /// its load; this bound stops the integral from winding up when a joint is blocked.
    pub command_lead_max_rad: f64,
    /// Task weight of a foot while it unloads: out of the contact set but still on the ground,
    /// so it must rise straight up rather than slide (usually well above `foot_weight`).
    pub unload_foot_weight: f64,
    /// The robot is tipping when the IMU's base tilt and the leg-odometry estimate's differ
    /// by more than this angle (rad; the angle between their vertical axes, so yaw does not
    /// count): the stance feet are no longer flat on the ground. Only checked when the
    /// measurement has an IMU.
    pub tipping_detection_rad: f64,
    /// With a foot in the air (the static gait), a disagreement beyond this smaller angle (rad)
    /// already puts that foot down at once (a catch step) and ends the walk in the tipping
    /// fault: a robot tipping over its stance foot's edge mid-swing falls before the feet roll
    /// by `tipping_detection_rad`. Must stay above the stance sole's ordinary roll.
    pub catch_tilt_rad: f64,
    /// How deep (m) the standing leg may lower the body under the whole weight while a foot is
    /// in the air (the static gait): a landing that needs more (the CoM's sink below its height
    /// at the release plus what the foot still has to descend, once the sink passes half of
    /// this) is beyond reach, and the step is taken back: the foot returns to where it lifted
    /// off and the walk ends in the `step_out_of_reach` fault. A robot's knees set it (JVRC-1's
    /// gave way 8 cm down; ARMAR-4 lands steps 11 cm down).
    pub standing_crouch_max_m: f64,
    /// How fast leg odometry's heading is turned onto the IMU's (rad/s; 0: leg odometry alone).
    /// Odometry cannot see the feet turning together on the ground (down a stair, a touchdown
    /// turns both by up to 0.01 rad, always the same way when the same foot leads), and the walk
    /// curves off its footholds. Only the yaw is taken from the IMU: its tilt would fight the
    /// anchored feet (docs/controller.md, "Floating base").
    pub heading_correction_speed: f64,
    /// Whether a hand that lets go is carried along with the pelvis, as it held, until its next
    /// reach, instead of being left to the posture task. Returning to the posture at once
    /// twists the torso back abruptly (JVRC-1 turns its waist ~0.3 rad to hold a railing), which
    /// makes the stance foot slip about its vertical axis; a robot with heavy arms and little
    /// ankle roll (ARMAR-4) cannot balance with the arm left out to the side.
    pub carry_released_hands: bool,
    /// How high (m) a hand's reach arcs above the straight line to its contact, at its middle:
    /// it comes down onto the top of a railing instead of sweeping into it from below.
    pub hand_approach_height_m: f64,
    /// How far (m) a hand that holds nothing keeps its palm from the surface of a railing of the
    /// walk's scene (`hand_clearance`): a free palm that swings into a rail, or under it, hooks
    /// the robot to it (JVRC-1's hanging palm is 7 cm from a rail 0.45 m beside its path).
    pub hand_clearance_m: f64,
    /// Fastest a free hand's target moves out of a railing's way (m/s): a hand let go on the
    /// rail lifts off it at this speed.
    pub hand_clearance_speed: f64,
    /// The vertical force (N) a held hand presses on its support with, measured at its wrist:
    /// enough to know it is there, little enough not to unload a foot the balance does not
    /// expect to be unloaded (`hand_press`).
    pub hand_force_n: f64,
    /// Admittance of a held hand's target along the vertical (m/s per N of force error): how
    /// fast it rises when the hand presses harder than `hand_force_n` and sinks when softer.
    pub hand_admittance: f64,
    /// Fastest the admittance moves a held hand's target (m/s).
    pub hand_press_speed: f64,
    /// Farthest the admittance moves a held hand's target from its planned pose, either way (m):
    /// a hand that finds no support sinks this far at most.
    pub hand_press_depth_m: f64,
    /// Farthest the admittance moves a held hand's target sideways (m): the arm gives way to a
    /// body leaning over its hand instead of pushing it back through the grasp, which on a round
    /// rail slides the palm off it.
    pub hand_press_slide_m: f64,
    /// The share of the robot's weight each held hand is asked to carry in the static gait
    /// (`hand_support`): the CoM may lean that far towards the railing, out of the feet's
    /// polygon. The touch (`hand_force_n`) when smaller; 0 keeps the hands a touch.
    pub hand_support_share: f64,
    /// How fast a held hand's force asked rises to its share and falls back before it lets go
    /// (shares of the weight per second).
    pub hand_support_rate: f64,
    /// A joint measured this far beyond its URDF limits is an invalid measurement (an encoder
    /// or calibration fault): the controller faults, naming the joint (rad).
    pub joint_limit_tolerance_rad: f64,
    /// Every target of a sequence lies within this horizontal distance of where its first
    /// stance stands (m).
    pub workspace_radius_m: f64,
    /// ... no lower than this below the first stance's soles (m; a staircase of ten 18.5 cm
    /// risers walked down descends 1.85 m) ...
    pub workspace_depth_m: f64,
    /// ... and no higher than this above them (m).
    pub workspace_height_m: f64,
    /// An end-effector's target moves at most this far from one stance to the next (m): a
    /// swing, a step or a reach, never a jump across the room.
    pub max_target_step_m: f64,
    /// Longest planned duration of one phase (s); with `phase_timeout_s` it bounds every phase.
    pub max_phase_s: f64,
    /// The static gait's force-difference control in double support (m/s per N; 0: off): the
    /// feet move vertically against each other until their normal forces split as the CoM
    /// set-point asks. It damps the robot's rocking from foot to foot, which stiff friction
    /// does not (docs/controller.md, "Force difference in the static gait").
    pub force_difference_gain: f64,
    /// Fastest the force difference moves the feet against each other (m/s).
    pub force_difference_max_speed: f64,
}

impl Default for ControllerConfig {
    fn default() -> Self {
        Self {
            com_weight: 10.0,
            foot_weight: 10.0,
            hand_weight: 1.0,
            torso_weight: 1.0,
            posture_weight: 1e-2,
            torso_yaw_posture_weight: None,
            regularization: 1e-5,
            com_gain: 10.0,
            pose_gain: 20.0,
            torso_gain: 10.0,
            posture_gain: 2.0,
            joint_limit_margin_rad: 0.02,
            velocity_limit_scale: 0.5,
            max_base_speed: 1.0,
            max_base_tilt_speed: 1.0,
            max_anchor_correction_speed: 1.0,
            max_anchor_correction_angular_speed: 10.0,
            support_margin_m: 0.02,
            support_gain: 20.0,
            com_speed: 0.05,
            swing_speed: 0.15,
            swing_angular_speed: 0.5,
            min_motion_s: 0.3,
            lift_height_m: 0.03,
            approach_height_m: 0.02,
            lower_speed: 0.02,
            lower_overshoot_m: 0.003,
            unload_lift_m: 0.002,
            com_tolerance_m: 0.005,
            position_tolerance_m: 0.005,
            orientation_tolerance_rad: 0.05,
            via_position_tolerance_m: 0.03,
            via_orientation_tolerance_rad: 0.2,
            hand_position_tolerance_m: 0.03,
            hand_orientation_tolerance_rad: 0.1,
            release_force_fraction: 0.1,
            touchdown_force_fraction: 0.1,
            support_force_min_fraction: 0.1,
            unloaded_max_s: 0.05,
            touchdown_debounce_s: 0.006,
            phase_timeout_s: 5.0,
            max_step_m: 0.5,
            max_step_up_m: 0.06,
            max_step_down_m: 0.06,
            max_slope_rad: STATIC_MAX_SLOPE_RAD,
            hold_railings: true,
            command_lead_max_rad: 0.05,
            unload_foot_weight: 100.0,
            tipping_detection_rad: 0.25,
            catch_tilt_rad: 0.1,
            standing_crouch_max_m: 0.09,
            heading_correction_speed: 0.05,
            carry_released_hands: false,
            hand_approach_height_m: 0.08,
            hand_clearance_m: 0.05,
            hand_clearance_speed: 0.2,
            hand_force_n: 10.0,
            hand_admittance: 5e-4,
            hand_press_speed: 0.05,
            hand_press_depth_m: 0.01,
            hand_press_slide_m: 0.1,
            hand_support_share: 0.165,
            hand_support_rate: 0.1,
            joint_limit_tolerance_rad: 0.03,
            workspace_radius_m: 100.0,
            workspace_depth_m: 3.0,
            workspace_height_m: 3.0,
            max_target_step_m: 1.0,
            max_phase_s: 60.0,
            force_difference_gain: 1e-5,
            force_difference_max_speed: 0.02,
        }
    }
}

/// Why a section of a robot config (`[controller]`, `[gait]`, ...) could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The config file could not be read or parsed.
    #[error(transparent)]
    File(#[from] ConfigFileError),
    /// The section is missing, has an unknown key or a badly typed value.
    #[error("{origin}: [{section}]: {message}")]
    Section {
        /// File (or "<table>") the section came from.
        origin: String,
        /// The section's name (`controller`, `gait.dynamic`, ...).
        section: &'static str,
        /// What is wrong, naming the key.
        message: String,
    },
    /// A value is out of its documented range.
    #[error("{origin}: [{section}] {key} = {}: {requirement}", Number(*value))]
    Value {
        /// File (or "<table>") the section came from.
        origin: String,
        /// The section's name.
        section: &'static str,
        /// The offending key.
        key: &'static str,
        /// Its value.
        value: f64,
        /// What it must satisfy.
        requirement: String,
    },
}

impl ControllerConfig {
    /// The scene the static gait takes (`max_step_up_m`, `max_step_down_m`, `max_slope_rad`,
    /// `hold_railings`).
    pub fn scene_limits(&self) -> SceneLimits {
        SceneLimits {
            up: self.max_step_up_m,
            down: self.max_step_down_m,
            slope: self.max_slope_rad,
            hold_railings: self.hold_railings,
            section: "[controller]",
        }
    }

    /// Reads the `[controller]` section of the robot config file at `path`.
    pub fn from_config_file(path: &Path) -> Result<Self, ConfigError> {
        Self::from_config(&ConfigFile::load(path)?)
    }

    /// Reads the `[controller]` section of a loaded robot config.
    pub fn from_config(file: &ConfigFile) -> Result<Self, ConfigError> {
        let origin = file.origin();
        let section = file.section(SECTION).ok_or_else(|| ConfigError::Section {
            origin: origin.clone(),
            section: SECTION,
            message: "section missing".to_owned(),
        })?;
        let config: Self =
            section
                .clone()
                .try_into()
                .map_err(|e: toml::de::Error| ConfigError::Section {
                    origin: origin.clone(),
                    section: SECTION,
                    message: toml_message(&e),
                })?;
        config.validate(&origin)?;
        Ok(config)
    }

    /// Checks every value against its documented range (docs/controller.md, "[controller]");
    /// `origin` names the file in the error.
    pub fn validate(&self, origin: &str) -> Result<(), ConfigError> {
        check(&self.bounds(), origin, SECTION)
    }

    /// The section's table: every numeric key, its value and its range, one line a key.
    pub fn bounds(&self) -> Vec<Bound> {
        let mut bounds = vec![
            Bound::new("com_weight", self.com_weight, 1e-6, 1e6),
            Bound::new("foot_weight", self.foot_weight, 1e-6, 1e6),
            Bound::new("hand_weight", self.hand_weight, 1e-6, 1e6),
            Bound::new("torso_weight", self.torso_weight, 1e-6, 1e6),
            Bound::new("posture_weight", self.posture_weight, 1e-6, 1e6),
            Bound::optional(
                "torso_yaw_posture_weight",
                self.torso_yaw_posture_weight,
                1e-6,
                1e6,
            ),
            Bound::new("unload_foot_weight", self.unload_foot_weight, 1e-6, 1e6),
            Bound::new("regularization", self.regularization, 1e-12, 1.0),
            Bound::new("com_gain", self.com_gain, 0.01, 1000.0),
            Bound::new("pose_gain", self.pose_gain, 0.01, 1000.0),
            Bound::new("torso_gain", self.torso_gain, 0.01, 1000.0),
            Bound::new("posture_gain", self.posture_gain, 0.01, 1000.0),
            Bound::new("support_gain", self.support_gain, 0.01, 1000.0),
            Bound::new(
                "joint_limit_margin_rad",
                self.joint_limit_margin_rad,
                0.0,
                0.5,
            ),
            Bound::new("velocity_limit_scale", self.velocity_limit_scale, 0.01, 1.0),
            Bound::new("max_base_speed", self.max_base_speed, 1e-3, 10.0),
            Bound::new("max_base_tilt_speed", self.max_base_tilt_speed, 1e-3, 10.0),
            Bound::new(
                "max_anchor_correction_speed",
                self.max_anchor_correction_speed,
                1e-4,
                10.0,
            ),
            Bound::new(
                "max_anchor_correction_angular_speed",
                self.max_anchor_correction_angular_speed,
                1e-4,
                100.0,
            ),
            Bound::new("support_margin_m", self.support_margin_m, 0.0, 0.2),
            Bound::new("com_speed", self.com_speed, 1e-3, 2.0),
            Bound::new("swing_speed", self.swing_speed, 1e-3, 5.0),
            Bound::new("swing_angular_speed", self.swing_angular_speed, 1e-3, 20.0),
            Bound::new("min_motion_s", self.min_motion_s, 0.01, 10.0),
            Bound::new("lift_height_m", self.lift_height_m, 1e-3, 0.5),
            Bound::new("approach_height_m", self.approach_height_m, 0.0, 0.5),
            Bound::new("lower_speed", self.lower_speed, 1e-3, 1.0),
            Bound::new("lower_overshoot_m", self.lower_overshoot_m, 0.0, 0.1),
            Bound::new("unload_lift_m", self.unload_lift_m, 0.0, 0.1),
            Bound::new("com_tolerance_m", self.com_tolerance_m, 1e-4, 0.5),
            Bound::new("position_tolerance_m", self.position_tolerance_m, 1e-4, 0.5),
            Bound::new(
                "orientation_tolerance_rad",
                self.orientation_tolerance_rad,
                1e-4,
                1.5,
            ),
            Bound::new(
                "via_position_tolerance_m",
                self.via_position_tolerance_m,
                1e-4,
                0.5,
            ),
            Bound::new(
                "via_orientation_tolerance_rad",
                self.via_orientation_tolerance_rad,
                1e-4,
                1.5,
            ),
            Bound::new(
                "hand_position_tolerance_m",
                self.hand_position_tolerance_m,
                1e-4,
                0.5,
            ),
            Bound::new(
                "hand_orientation_tolerance_rad",
                self.hand_orientation_tolerance_rad,
                1e-4,
                1.5,
            ),
            Bound::new(
                "release_force_fraction",
                self.release_force_fraction,
                1e-3,
                1.0,
            ),
            Bound::new(
                "touchdown_force_fraction",
                self.touchdown_force_fraction,
                1e-3,
                1.0,
            ),
            Bound::new("touchdown_debounce_s", self.touchdown_debounce_s, 0.0, 1.0),
            Bound::new(
                "support_force_min_fraction",
                self.support_force_min_fraction,
                1e-3,
                1.0,
            ),
            Bound::new("unloaded_max_s", self.unloaded_max_s, 0.002, 1.0),
            Bound::new("phase_timeout_s", self.phase_timeout_s, 0.01, 60.0),
            Bound::new("max_step_m", self.max_step_m, 0.01, 2.0),
            Bound::new("max_step_up_m", self.max_step_up_m, 0.0, 1.0),
            Bound::new("max_step_down_m", self.max_step_down_m, 0.0, 1.0),
            Bound::new("max_slope_rad", self.max_slope_rad, 0.0, 1.0),
            Bound::new("command_lead_max_rad", self.command_lead_max_rad, 1e-4, 1.0),
            Bound::new(
                "tipping_detection_rad",
                self.tipping_detection_rad,
                0.01,
                1.5,
            ),
            Bound::new("catch_tilt_rad", self.catch_tilt_rad, 0.01, 1.5),
            Bound::new(
                "standing_crouch_max_m",
                self.standing_crouch_max_m,
                0.005,
                1.0,
            ),
            Bound::new(
                "heading_correction_speed",
                self.heading_correction_speed,
                0.0,
                10.0,
            ),
            Bound::new(
                "hand_approach_height_m",
                self.hand_approach_height_m,
                0.0,
                0.5,
            ),
            Bound::new("hand_clearance_m", self.hand_clearance_m, 0.0, 0.5),
            Bound::new(
                "hand_clearance_speed",
                self.hand_clearance_speed,
                0.001,
                2.0,
            ),
            Bound::new("hand_force_n", self.hand_force_n, 0.0, 1000.0),
            Bound::new("hand_admittance", self.hand_admittance, 0.0, 0.01),
            Bound::new("hand_press_speed", self.hand_press_speed, 0.0, 1.0),
            Bound::new("hand_press_depth_m", self.hand_press_depth_m, 0.0, 0.2),
            Bound::new("hand_press_slide_m", self.hand_press_slide_m, 0.0, 0.3),
            Bound::new("hand_support_share", self.hand_support_share, 0.0, 0.45),
            Bound::new("hand_support_rate", self.hand_support_rate, 0.01, 10.0),
            Bound::new(
                "joint_limit_tolerance_rad",
                self.joint_limit_tolerance_rad,
                1e-4,
                0.5,
            ),
            Bound::new("workspace_radius_m", self.workspace_radius_m, 0.1, 1000.0),
            Bound::new("workspace_depth_m", self.workspace_depth_m, 0.01, 10.0),
            Bound::new("workspace_height_m", self.workspace_height_m, 0.01, 10.0),
            Bound::new("max_target_step_m", self.max_target_step_m, 0.01, 10.0),
            Bound::new("max_phase_s", self.max_phase_s, 0.1, 120.0),
        ];
        bounds.extend(force_difference_bounds(
            self.force_difference_gain,
            self.force_difference_max_speed,
        ));
        bounds
    }
}

/// Fails with the first value of `bounds` outside its range, naming the file, the section and
/// the key: the check every table of a robot config section ends in.
pub(crate) fn check(
    bounds: &[Bound],
    origin: &str,
    section: &'static str,
) -> Result<(), ConfigError> {
    match first_outside(bounds) {
        Some(violation) => Err(ConfigError::Value {
            origin: origin.to_owned(),
            section,
            key: violation.key,
            value: violation.value,
            requirement: violation.range.requirement(),
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<ControllerConfig, ConfigError> {
        ControllerConfig::from_config(&ConfigFile::parse(text, Path::new("r.toml")).unwrap())
    }

    #[test]
    fn unknown_key_is_an_error_naming_it() {
        let error = parse("[controller]\ncom_wieght = 1.0\n")
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("r.toml") && error.contains("com_wieght"),
            "{error}"
        );
    }

    #[test]
    fn partial_section_keeps_defaults_and_bad_values_are_named() {
        let config = parse("[controller]\ncom_weight = 3.0\n").unwrap();
        assert_eq!(config.com_weight, 3.0);
        assert_eq!(config.foot_weight, ControllerConfig::default().foot_weight);
        let error = parse("[controller]\nlower_speed = -1.0\n")
            .unwrap_err()
            .to_string();
        assert!(error.contains("lower_speed"), "{error}");
    }
}
