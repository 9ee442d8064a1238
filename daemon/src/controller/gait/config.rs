//! The `[gait]` section of a robot config: the gait a walk uses unless it asks for one, and the
//! dynamic gait's step timing, pendulum height, touchdown bounds and stabilizer
//! (`[gait.dynamic]`, `[gait.dynamic.stabilizer]`). Every key is optional; an unknown key is an
//! error naming the file, the table and the key.

use std::path::{Path, PathBuf};

use serde::Deserialize;
use stance::{Gait, GaitUnavailable};

use kinematics::ConfigFile;
use kinematics::bounds::{Bound, Number, Range};
use kinematics::config_file::toml_message;

use crate::controller::config::{ConfigError, check};
use crate::controller::sequence::SceneLimits;

/// What a robot config says about gaits. Without a `[gait]` section a robot walks statically
/// only.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct GaitConfig {
    /// The gait of a walk that does not ask for one (`[gait] default`, `static` if absent).
    pub default: Gait,
    /// The dynamic gait's tuning; `None` when the config has no `[gait.dynamic]`, and then a
    /// dynamic walk is refused.
    pub dynamic: Option<DynamicGaitConfig>,
    /// The robot config this was read from, named when a dynamic walk is refused (empty for
    /// [`GaitConfig::default`]).
    pub path: PathBuf,
}

/// Timing, pendulum and touchdown parameters of the dynamic gait (`[gait.dynamic]`).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DynamicGaitConfig {
    /// Duration of a single-support phase: lift-off to planned touchdown (s).
    pub single_support_s: f64,
    /// Duration of the single support of a step up or down (landing more than
    /// [`STEP_HEIGHT_M`](crate::controller::machine::STEP_HEIGHT_M) above or below the lift-off:
    /// a stair, a ramp), where the foot travels farther and moves horizontally over part of the
    /// swing only (s); absent: [`STEP_SINGLE_SUPPORT_FACTOR`] × `single_support_s`.
    pub step_single_support_s: Option<f64>,
    /// Duration of a double-support phase between two steps: the ZMP crosses to the next
    /// stance foot (s).
    pub double_support_s: f64,
    /// Duration of a double support next to a step up or down (after its touchdown or before
    /// its lift-off), where the CoM crosses to a foot it then stands on for the longer
    /// `step_single_support_s` (s); absent: [`STEP_DOUBLE_SUPPORT_FACTOR`] ×
    /// `double_support_s`.
    pub step_double_support_s: Option<f64>,
    /// Duration of the single support of a stair climbed (a step up from a level sole to a
    /// level one), in place of `step_single_support_s` (s); absent:
    /// [`CLIMB_SINGLE_SUPPORT_FACTOR`] × `single_support_s`.
    pub climb_single_support_s: Option<f64>,
    /// Duration of the single support of a stair climbed past the other foot, one foot per
    /// stair (from the tread below the standing foot's to the one above it: two risers, two
    /// treads), in place of `climb_single_support_s` (s); absent:
    /// [`CLIMB_PAST_SINGLE_SUPPORT_FACTOR`] × `single_support_s`.
    pub climb_past_single_support_s: Option<f64>,
    /// Duration of the single support of a stair descended past the other foot, one foot per
    /// stair (from the tread above the standing foot's to the one below it), in place of
    /// `step_single_support_s` (s); absent: [`DESCENT_PAST_SINGLE_SUPPORT_FACTOR`] ×
    /// `single_support_s`.
    pub descent_past_single_support_s: Option<f64>,
    /// Duration of a double support next to a stair climbed with no other step up or down on
    /// its other side, in place of `step_double_support_s` (s); absent:
    /// [`CLIMB_DOUBLE_SUPPORT_FACTOR`] × `double_support_s`.
    pub climb_double_support_s: Option<f64>,
    /// Duration of a double support between two stairs taken past the other foot, one foot per
    /// stair, up or down (or next to one, with a level step on its other side), and of the one
    /// before the first stair climbed past the other foot after one climbed beside it, in place of
    /// `climb_double_support_s` / `step_double_support_s` (s); absent:
    /// [`PAST_DOUBLE_SUPPORT_FACTOR`] × `double_support_s`.
    pub past_double_support_s: Option<f64>,
    /// The double support before the first lift-off: the CoM starts at rest and has to reach
    /// the sway of the first step (s).
    pub initial_double_support_s: f64,
    /// The double support after the last touchdown: the ZMP returns to the centre of the feet
    /// and the CoM comes to rest (s).
    pub final_double_support_s: f64,
    /// The double support that ends a controlled stop: after the step under way lands, the ZMP
    /// crosses to the centre of both feet and the CoM comes to rest (s; docs/safety.md).
    pub stop_double_support_s: f64,
    /// A transition that changes only hand contacts: the hands reach, the feet stay (s).
    pub hand_transition_s: f64,
    /// `[min, max]` of a single support a timed sequence sets (the sum of the durations of the
    /// stances its foot swings through, s); absent: `single_support_s` to
    /// [`TIMED_SINGLE_SUPPORT_MAX_FACTOR`] × `single_support_s`, so a sequence may slow the tuned
    /// gait down but never step faster than the timing the robot was tuned for.
    pub timed_single_support_s: Option<[f64; 2]>,
    /// `[min, max]` of a double support before a lift-off a timed sequence sets (the sum of the
    /// durations of the stances on both feet since the support's previous phase, s); absent:
    /// `double_support_s` to [`TIMED_DOUBLE_SUPPORT_MAX_FACTOR`] × `double_support_s`.
    pub timed_double_support_s: Option<[f64; 2]>,
    /// Height of the CoM above the support surface, the pendulum length `h` of ω² = g / h (m);
    /// absent: the CoM height of the standing posture.
    pub com_height_m: Option<f64>,
    /// The swing ends this far below its contact pose, so the sole presses into the ground and
    /// force-torque confirms the touchdown at the planned instant (m).
    pub landing_depth_m: f64,
    /// A touchdown confirmed by force-torque up to this long before the planned instant is
    /// accepted (the foot is anchored where it landed); contact readings before that are ignored
    /// as spikes (s).
    pub early_touchdown_s: f64,
    /// Up to this long after the planned instant the foot keeps descending at
    /// `late_descent_speed` and the plan waits at the touchdown instant; past it the missing
    /// touchdown is a fault (s).
    pub late_touchdown_max_s: f64,
    /// Descent speed of a foot that has not touched down at the planned instant (m/s).
    pub late_descent_speed: f64,
    /// A foot still loaded at its planned lift-off keeps its contact, and the plan waits, up to
    /// this long; then it lifts (s).
    pub late_lift_off_max_s: f64,
    /// Replaces `[controller] hand_weight` in the dynamic gait: a hand held at its contact pose
    /// while the body walks on at speed drags the torso round and the stance foot slips about its
    /// vertical axis; absent: the `[controller]` value.
    pub hand_weight: Option<f64>,
    /// Replaces `[controller] com_gain` in the dynamic gait: the commanded pendulum is a motion
    /// the support can produce, but the joints are position-controlled and the robot lags it
    /// (a knee at its torque limit, a landing short of its foothold); closing a few centimetres
    /// of lag at the static gait's gain asks for an acceleration whose ZMP lies past the heel or
    /// toe, and the stance sole rolls over its edge. Absent: the `[controller]` value.
    pub com_gain: Option<f64>,
    /// In single support the ZMP reference sits this far from the stance sole's centre towards
    /// the other foot, along the sole's lateral axis (m; 0: on the centre). A robot whose ankle
    /// roll range is small cannot tilt its legs far enough to sway the CoM out to the sole
    /// centres; a ZMP nearer the midline shrinks the lateral sway by the same fraction.
    pub zmp_inward_offset_m: f64,
    /// In a single support whose swing lands lower than the stance sole (a step down: a stair,
    /// a ramp), the ZMP reference sits this far ahead of the stance sole's centre, along the
    /// sole (m; 0: on the centre). The standing knee lowers the body bent ahead of the ankle;
    /// a ZMP ahead of the ankle shortens the knee's lever (docs/controller.md, "Swing").
    pub step_down_zmp_forward_m: f64,
    /// Replaces `[controller] posture_weight` on the torso joints (`[robot.joint_groups] torso`)
    /// in the dynamic gait. At the posture weight the QP keeps a held hand in place largely with
    /// the waist, whose long lever makes it cheap: the upper body swung round and sideways while
    /// the body walked on, the stance sole rolled onto a corner and turned about it, and walks
    /// with a held hand fell. Absent: the `[controller]` value.
    pub torso_posture_weight: Option<f64>,
    /// Highest step up the dynamic gait takes: a landing this far above the other foot's sole
    /// at most (m, the stair's riser, one foot per stair or both on each); a sequence with a
    /// higher one is refused (docs/scenes.md, "Step heights"). With toe-off,
    /// JVRC-1 climbs 0.15 m stairs 10/10 under MuJoCo and tips on 0.185 m ones.
    pub max_step_up_m: f64,
    /// Highest step down the dynamic gait takes (m): JVRC-1 walks down the 0.185 m stairs 10/10
    /// under MuJoCo (both feet on each, with `step_down_speed`).
    pub max_step_down_m: f64,
    /// A step down (other than a stair descended past the other foot) lasts at least its drop
    /// over this speed in single support (m/s), and no less than `step_single_support_s`: the
    /// standing knee lowers the body through the drop. JVRC-1 went down the 0.185 m stairs 1/4 at
    /// the 1.1 s of the 0.15 m ones, 10/10 at 1.2 and 1.3 s.
    pub step_down_speed: f64,
    /// A stair climbed past the other foot lasts at least its riser (the landing's height above
    /// the standing sole) over this speed in single support (m/s), and no less than
    /// `climb_past_single_support_s`: the standing knee lifts the body through the riser.
    /// JVRC-1 up the 0.15 m stairs one foot per stair (in process, seeds 0–29): 1.0 s 12/30,
    /// 1.1 s 28/30, 1.2 s and 1.25 s 30/30, 1.3 s 28/30.
    pub climb_past_speed: f64,
    /// A stair descended past the other foot lasts at least its riser (the landing's depth below
    /// the standing sole) over this speed in single support (m/s), and no less than
    /// `descent_past_single_support_s`: the standing knee lowers the body through the riser.
    /// JVRC-1 down the 0.15 m stairs one foot per stair (in process, seeds 0–29): 1.0 s 0/10,
    /// 1.2 s 28/30, 1.25 s 29/30, 1.3 s 30/30.
    pub descent_past_speed: f64,
    /// Steepest surface the dynamic gait stands on: a sole in contact tilted more than this
    /// from horizontal is refused (rad; docs/scenes.md, "Step heights"). JVRC-1 walks up and down
    /// the 15° ramp 10/10 under MuJoCo.
    pub max_slope_rad: f64,
    /// Whether the dynamic gait walks with a hand holding a railing: off (the default), a
    /// sequence whose scene has railings and whose stances hold a hand is refused
    /// (docs/scenes.md, "Hands on railings"). Holding the rail of `railing.toml`, JVRC-1 and
    /// ARMAR-4 fell in 4 of 4 walks (MuJoCo, 1 m): the held hand, reached at the gait's low
    /// `hand_weight`, meets the rail from below and the rail holds it down.
    pub hold_railings: bool,
    /// The heel of a foot about to swing up a step rises about its toe by this pitch at the end
    /// of the double support before (rad; 0: the sole stays flat), so the trailing leg reaches
    /// farther (docs/scenes.md, "Toe-off").
    pub toe_off_rad: f64,
    /// How long before the lift-off the heel starts to rise (s; at most the double support).
    pub toe_off_s: f64,
    /// The stabilizer closing the loop on force-torque and IMU.
    #[serde(skip)]
    pub stabilizer: StabilizerConfig,
}

/// A step up or down's single support, relative to a flat step's, unless configured: the stance
/// knee lifts or lowers the body under the whole weight, the swing foot travels farther, and
/// its horizontal motion has three quarters of the swing. JVRC-1 (1.1 s) walks down a 0.10 m
/// stair 10/10 under MuJoCo with its URDF torque limits; at 1.5 (0.825 s) its knee saturated and
/// it tipped, 0/4.
pub const STEP_SINGLE_SUPPORT_FACTOR: f64 = 2.0;

/// A double support next to a step up or down, relative to a flat step's, unless configured.
/// The linear pendulum has to bring the CoM nearly to rest over the foot it stands on through
/// the step's long single support, so the whole step's travel falls into the double support
/// before it: JVRC-1 crossed it at 0.6 m/s in 0.25 s and tipped at a ramp's top, 0/4 under
/// MuJoCo; with 0.55 s it walks the 10 degree ramp up and down. With friction that does not
/// creep (MuJoCo `impratio` 20) the 0.15 m descent's trailing knee saturated lowering the robot
/// onto the lower stair in 0.55 s, 7/10; with 0.8 s it walks 10/10.
pub const STEP_DOUBLE_SUPPORT_FACTOR: f64 = 3.2;

/// `max_slope_rad` unless configured: JVRC-1's, which walks the 15° ramp up and down 10/10
/// under MuJoCo (0.262 rad, with room for round-off).
const DYNAMIC_MAX_SLOPE_RAD: f64 = 0.27;

/// A stair climbed's single support, relative to a flat step's, unless configured: with its
/// trailing heel rising first (toe-off) the climb needs less time than a descent, whose stance
/// knee lowers the whole weight. JVRC-1 (0.75 s, with 1.8 × `double_support_s` next to it) climbs
/// the 0.10 m and 0.15 m stairs both feet on each 10/10 under MuJoCo; at 0.65 s and 1.4 × 1/10
/// and 0/10.
pub const CLIMB_SINGLE_SUPPORT_FACTOR: f64 = 0.75 / 0.55;

/// A stair climbed past the other foot (one foot per stair), relative to a flat step's single
/// support, unless configured: the swing goes two treads and two risers. JVRC-1 climbs the 0.10 m
/// stairs one foot per stair under MuJoCo (in process, seeds 0–29, toe-off over 0.25 s) 30/30 at
/// 0.8, 0.85 and 0.9 s with 0.3–0.4 s of double support between (0.8 s with 0.3 s: 12/30); at
/// 0.75 s 3–4 of 10.
pub const CLIMB_PAST_SINGLE_SUPPORT_FACTOR: f64 = 0.85 / 0.55;

/// A stair descended past the other foot (one foot per stair), relative to a flat step's single
/// support, unless configured. JVRC-1 down the 0.10 m stairs under MuJoCo (in process, with the
/// ZMP 0.03 m ahead, [`STEP_DOWN_ZMP_FORWARD_M`]): 0.95 s 50/50 (seeds 0–49), 0.9 s 77/80,
/// 1.0 s 10/10; without the ZMP ahead 0.9 s 0/10, and at the step's 1.1 s a knee held its torque
/// limit for twice as long.
pub const DESCENT_PAST_SINGLE_SUPPORT_FACTOR: f64 = 0.95 / 0.55;

/// `step_down_zmp_forward_m` unless configured: JVRC-1's. Its descents of the 0.10 m stairs at
/// 0.9 s of single support (in process, seeds 0–9) walked 10/10 at 0.02–0.04 m, 8/10 at 0.05 m and
/// 0/10 at 0; the same offset climbing (the swing landing higher) failed the 0.10 m climb, 0/10,
/// an ankle at its torque limit, so it is for steps down only.
pub const STEP_DOWN_ZMP_FORWARD_M: f64 = 0.03;

/// A double support between two stairs taken past the other foot (one foot per stair, up or
/// down), relative to a flat step's, unless configured: JVRC-1's 0.35 s. Climbing, with 0.85 s of
/// single support (see [`CLIMB_PAST_SINGLE_SUPPORT_FACTOR`]), 1.2 s a stair; toe-off takes the
/// last `toe_off_s` of it: over 0.3 s of a 0.35 s support the climb walked 7/10, over 0.25 s
/// 30/30. Descending the 0.10 m stairs with the step's 1.1 s single support (in process, seeds
/// 0–9) 10/10 at 0.3, 0.4, 0.5 and 0.6 s (the step's 0.8 s before), 4/10 at 0.2 s. Before the
/// first stair climbed past the other foot too (the climb's 0.45 s before): 60/60 up the 0.10 m
/// stairs, 1.20 s a stair (median over the processes, 1.21–1.22 s before).
pub const PAST_DOUBLE_SUPPORT_FACTOR: f64 = 0.35 / 0.25;

/// A double support next to a stair climbed, relative to a flat step's, unless configured
/// (see [`CLIMB_SINGLE_SUPPORT_FACTOR`]).
pub const CLIMB_DOUBLE_SUPPORT_FACTOR: f64 = 1.8;

/// The dynamic gait's CoM task gain (1/s) unless configured (`com_gain`). At the static gait's 10,
/// JVRC-1 walked the flat matrix 59/60 in process and climbed the 0.10 m stairs 8/10, its
/// stance soles rolling over an edge at a transition; at 3, 60/60 and 10/10.
pub const DYNAMIC_COM_GAIN: f64 = 3.0;

/// The longest single support a timed sequence gets unless configured, relative to
/// `single_support_s`: a human-paced step slows the gait down at most this much.
pub const TIMED_SINGLE_SUPPORT_MAX_FACTOR: f64 = 3.0;

/// The longest double support a timed sequence gets unless configured, relative to
/// `double_support_s` (a pause on both feet between steps).
pub const TIMED_DOUBLE_SUPPORT_MAX_FACTOR: f64 = 4.0;

/// The tuning that walks JVRC-1 under MuJoCo (configs/jvrc1.toml, 0.26 m/s), so an empty
/// `[gait.dynamic]` walks an HRP-class robot; `walkctl init-robot` derives a robot's own.
impl Default for DynamicGaitConfig {
    fn default() -> Self {
        Self {
            single_support_s: 0.55,
            step_single_support_s: None,
            double_support_s: 0.25,
            step_double_support_s: None,
            climb_single_support_s: None,
            climb_past_single_support_s: None,
            descent_past_single_support_s: None,
            climb_double_support_s: None,
            past_double_support_s: None,
            initial_double_support_s: 1.0,
            final_double_support_s: 1.0,
            stop_double_support_s: 0.6,
            hand_transition_s: 0.5,
            timed_single_support_s: None,
            timed_double_support_s: None,
            com_height_m: None,
            landing_depth_m: 0.001,
            early_touchdown_s: 0.1,
            late_touchdown_max_s: 0.2,
            late_descent_speed: 0.05,
            late_lift_off_max_s: 0.2,
            hand_weight: Some(0.02),
            com_gain: Some(DYNAMIC_COM_GAIN),
            zmp_inward_offset_m: 0.0,
            step_down_zmp_forward_m: STEP_DOWN_ZMP_FORWARD_M,
            torso_posture_weight: Some(1.0),
            max_step_up_m: 0.15,
            max_step_down_m: 0.19,
            step_down_speed: 0.15,
            climb_past_speed: 0.125,
            descent_past_speed: 0.115,
            max_slope_rad: DYNAMIC_MAX_SLOPE_RAD,
            hold_railings: false,
            toe_off_rad: 0.5,
            toe_off_s: 0.25,
            stabilizer: StabilizerConfig::default(),
        }
    }
}

/// The stabilizer's parts, each with its switch, so its effect can be measured
/// (`[gait.dynamic.stabilizer]`).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StabilizerConfig {
    /// The commanded ZMP is kept this far inside the support polygon (m).
    pub zmp_margin_m: f64,
    /// DCM feedback on the measured CoM: the commanded ZMP moves by `dcm_gain` times the DCM
    /// error. Off, the commanded pendulum follows the reference open loop.
    pub dcm_feedback: bool,
    /// `K` of `p_d = p_ref + K (ξ − ξ_ref)`; above 1, the error decays at `ω (K − 1)`.
    pub dcm_gain: f64,
    /// The measured CoM is turned by the IMU's tilt relative to leg odometry about the measured
    /// ZMP: a robot rolling over a sole edge shows in its DCM (leg odometry assumes the soles
    /// flat).
    pub imu_tilt: bool,
    /// Time constant of the low-pass filter on the measured CoM velocity (s).
    pub velocity_filter_s: f64,
    /// Integrates the error between the measured and the commanded ZMP into an estimate of the
    /// CoM model error and shifts the commanded CoM by it.
    pub zmp_offset: bool,
    /// Time constant of that integrator (s).
    pub zmp_offset_time_constant_s: f64,
    /// Bound on the estimated offset (m).
    pub zmp_offset_max_m: f64,
    /// Foot damping: each foot in contact turns so its measured centre of pressure tracks the
    /// desired one (rate = gain · normal force · CoP error).
    pub foot_damping: bool,
    /// Foot damping gain (rad/s per N·m).
    pub foot_damping_gain: f64,
    /// Bound on the foot damping's angular velocity (rad/s).
    pub foot_damping_max_speed: f64,
    /// Time constant of the leak of the foot damping's accumulated rotation (s).
    pub foot_damping_leak_s: f64,
    /// Force-difference control in double support: the feet move vertically against each other
    /// until their normal forces split as the desired ZMP asks.
    pub force_difference: bool,
    /// Force-difference gain (m/s per N).
    pub force_difference_gain: f64,
    /// Bound on the force-difference velocity (m/s).
    pub force_difference_max_speed: f64,
    /// Internal-force control in double support: the feet give way horizontally, against each
    /// other, to the force they push each other with (docs/controller.md, "Internal force").
    pub internal_force: bool,
    /// Internal-force gain (m/s per N).
    pub internal_force_gain: f64,
    /// Bound on the internal-force velocity (m/s).
    pub internal_force_max_speed: f64,
    /// Tilt damping: the ankles of the feet in contact turn against the body's tilt rate (IMU),
    /// damping its rocking on the compliant soles.
    pub tilt_damping: bool,
    /// `K_d` of the ankle rotation `−K_d θ̇` (s).
    pub tilt_damping_s: f64,
    /// Time constant of the low-pass filter on the tilt rate (s).
    pub tilt_rate_filter_s: f64,
    /// Bound on the tilt damping's ankle rotation (rad).
    pub tilt_damping_max_rad: f64,
}

/// JVRC-1's stabilizer: DCM feedback, IMU tilt and the ZMP offset off (each made walks fall,
/// docs/controller.md "Stabilizer"), foot damping, force difference, internal force and tilt
/// damping on.
impl Default for StabilizerConfig {
    fn default() -> Self {
        Self {
            zmp_margin_m: 0.01,
            dcm_feedback: false,
            dcm_gain: 3.0,
            imu_tilt: false,
            velocity_filter_s: 0.01,
            zmp_offset: false,
            zmp_offset_time_constant_s: 1.0,
            zmp_offset_max_m: 0.03,
            foot_damping: true,
            foot_damping_gain: 5e-4,
            foot_damping_max_speed: 0.2,
            foot_damping_leak_s: 1.0,
            force_difference: true,
            force_difference_gain: 1e-5,
            force_difference_max_speed: 0.02,
            internal_force: true,
            internal_force_gain: 1e-4,
            internal_force_max_speed: 0.02,
            tilt_damping: true,
            tilt_damping_s: 0.03,
            tilt_rate_filter_s: 0.01,
            tilt_damping_max_rad: 0.01,
        }
    }
}

const GAIT: &str = "gait";
const DYNAMIC: &str = "gait.dynamic";
const STABILIZER: &str = "gait.dynamic.stabilizer";

impl GaitConfig {
    /// Reads the `[gait]` section of the robot config file at `path`.
    pub fn from_config_file(path: &Path) -> Result<Self, ConfigError> {
        Self::from_config(&ConfigFile::load(path)?)
    }

    /// Reads the `[gait]` section of a loaded robot config.
    pub fn from_config(file: &ConfigFile) -> Result<Self, ConfigError> {
        let default = Gait::configured_default(file).map_err(|e| ConfigError::Section {
            origin: file.origin(),
            section: GAIT,
            message: e.to_string(),
        })?;
        Ok(Self {
            path: file.path().to_owned(),
            ..Self::from_section(file.section(GAIT), default, &file.origin())?
        })
    }

    /// The dynamic gait's tuning, or why a dynamic walk cannot be executed on this robot (the
    /// client's up-front refusal, `stance::Gait::available_in`, says the same).
    pub fn dynamic(&self) -> Result<&DynamicGaitConfig, GaitUnavailable> {
        self.dynamic.as_ref().ok_or_else(|| GaitUnavailable {
            path: self.path.clone(),
        })
    }

    fn from_section(
        section: Option<&toml::Value>,
        default: Gait,
        origin: &str,
    ) -> Result<Self, ConfigError> {
        let Some(section) = section else {
            return Ok(Self::default());
        };
        let mut section = sub_table(section, origin, GAIT)?;
        let dynamic = section.remove("dynamic");
        // `default` is read by `Gait::configured_default` (the client needs it too).
        section.remove("default");
        let GaitSection {} = deserialize(section, origin, GAIT)?;
        let mut config = Self {
            default,
            ..Self::default()
        };
        if let Some(dynamic) = dynamic {
            let mut dynamic = sub_table(&dynamic, origin, DYNAMIC)?;
            let stabilizer = dynamic.remove("stabilizer");
            let mut parsed: DynamicGaitConfig = deserialize(dynamic, origin, DYNAMIC)?;
            if let Some(stabilizer) = stabilizer {
                parsed.stabilizer = deserialize(
                    sub_table(&stabilizer, origin, STABILIZER)?,
                    origin,
                    STABILIZER,
                )?;
            }
            parsed.validate(origin)?;
            config.dynamic = Some(parsed);
        }
        if config.default == Gait::Dynamic && config.dynamic.is_none() {
            return Err(ConfigError::Section {
                origin: origin.to_owned(),
                section: GAIT,
                message: "default = \"dynamic\" needs a [gait.dynamic] section (the dynamic \
                          gait's tuning); add one, or keep default = \"static\""
                    .to_owned(),
            });
        }
        Ok(config)
    }
}

/// The keys of `[gait]` itself besides `default` and `dynamic`: none (so any other is refused).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GaitSection {}

fn sub_table(
    value: &toml::Value,
    origin: &str,
    section: &'static str,
) -> Result<toml::Table, ConfigError> {
    value
        .as_table()
        .cloned()
        .ok_or_else(|| ConfigError::Section {
            origin: origin.to_owned(),
            section,
            message: "must be a table".to_owned(),
        })
}

fn deserialize<T: serde::de::DeserializeOwned>(
    table: toml::Table,
    origin: &str,
    section: &'static str,
) -> Result<T, ConfigError> {
    toml::Value::Table(table)
        .try_into()
        .map_err(|e: toml::de::Error| ConfigError::Section {
            origin: origin.to_owned(),
            section,
            message: toml_message(&e),
        })
}

impl DynamicGaitConfig {
    /// The scene the dynamic gait takes (`max_step_up_m`, `max_step_down_m`, `max_slope_rad`,
    /// `hold_railings`).
    pub fn scene_limits(&self) -> SceneLimits {
        SceneLimits {
            up: self.max_step_up_m,
            down: self.max_step_down_m,
            slope: self.max_slope_rad,
            hold_railings: self.hold_railings,
            section: "[gait.dynamic]",
        }
    }

    /// The single support of a step up or down (`step_single_support_s` or its default).
    pub fn step_single_support(&self) -> f64 {
        self.step_single_support_s
            .unwrap_or(STEP_SINGLE_SUPPORT_FACTOR * self.single_support_s)
    }

    /// The double support next to a step up or down (`step_double_support_s` or its default).
    pub fn step_double_support(&self) -> f64 {
        self.step_double_support_s
            .unwrap_or(STEP_DOUBLE_SUPPORT_FACTOR * self.double_support_s)
    }

    /// The single support of a step up or down, not a stair taken past the other foot, landing
    /// `drop` (m) below its lift-off (negative: above):
    /// [`step_single_support`](Self::step_single_support), and down no shorter than the drop at
    /// `step_down_speed`.
    pub fn step_down_single_support(&self, drop: f64) -> f64 {
        self.step_single_support().max(drop / self.step_down_speed)
    }

    /// The single support of a stair climbed (`climb_single_support_s` or its default).
    pub fn climb_single_support(&self) -> f64 {
        self.climb_single_support_s
            .unwrap_or(CLIMB_SINGLE_SUPPORT_FACTOR * self.single_support_s)
    }

    /// The single support of a stair climbed past the other foot whose riser (its landing's
    /// height above the standing sole) is `riser` (m): `climb_past_single_support_s` or its
    /// default, and no shorter than the riser at `climb_past_speed`.
    pub fn climb_past_single_support(&self, riser: f64) -> f64 {
        self.climb_past_single_support_s
            .unwrap_or(CLIMB_PAST_SINGLE_SUPPORT_FACTOR * self.single_support_s)
            .max(riser / self.climb_past_speed)
    }

    /// The single support of a stair descended past the other foot whose riser (its landing's
    /// depth below the standing sole) is `riser` (m): `descent_past_single_support_s` or its
    /// default, and no shorter than the riser at `descent_past_speed`.
    pub fn descent_past_single_support(&self, riser: f64) -> f64 {
        self.descent_past_single_support_s
            .unwrap_or(DESCENT_PAST_SINGLE_SUPPORT_FACTOR * self.single_support_s)
            .max(riser / self.descent_past_speed)
    }

    /// The double support next to a stair climbed (`climb_double_support_s` or its default).
    pub fn climb_double_support(&self) -> f64 {
        self.climb_double_support_s
            .unwrap_or(CLIMB_DOUBLE_SUPPORT_FACTOR * self.double_support_s)
    }

    /// The double support between stairs taken past the other foot (`past_double_support_s` or
    /// its default).
    pub fn past_double_support(&self) -> f64 {
        self.past_double_support_s
            .unwrap_or(PAST_DOUBLE_SUPPORT_FACTOR * self.double_support_s)
    }

    /// The limits of a single support timed by the sequence (`timed_single_support_s` or its
    /// default).
    pub fn timed_single_support(&self) -> [f64; 2] {
        self.timed_single_support_s.unwrap_or([
            self.single_support_s,
            TIMED_SINGLE_SUPPORT_MAX_FACTOR * self.single_support_s,
        ])
    }

    /// The limits of a double support timed by the sequence (`timed_double_support_s` or its
    /// default).
    pub fn timed_double_support(&self) -> [f64; 2] {
        self.timed_double_support_s.unwrap_or([
            self.double_support_s,
            TIMED_DOUBLE_SUPPORT_MAX_FACTOR * self.double_support_s,
        ])
    }

    /// Checks every value against its documented range (docs/controller.md, "Dynamic gait");
    /// `origin` names the file in the error.
    pub fn validate(&self, origin: &str) -> Result<(), ConfigError> {
        check(&self.bounds(), origin, DYNAMIC)?;
        check(&self.stabilizer.bounds(), origin, STABILIZER)?;
        for (key, limits, range) in self.timed_limits() {
            check_limits(key, limits, range, origin)?;
        }
        if self.early_touchdown_s >= self.single_support_s {
            return Err(ConfigError::Value {
                origin: origin.to_owned(),
                section: DYNAMIC,
                key: "early_touchdown_s",
                value: self.early_touchdown_s,
                requirement: "must be shorter than single_support_s".to_owned(),
            });
        }
        Ok(())
    }

    /// The `[min, max]` keys of `[gait.dynamic]`: each key, its limits and the range each limit
    /// must lie in (not in [`Self::bounds`], whose keys are single numbers).
    fn timed_limits(&self) -> [(&'static str, Option<[f64; 2]>, Range); 2] {
        [
            (
                "timed_single_support_s",
                self.timed_single_support_s,
                Range::new(0.1, 10.0),
            ),
            (
                "timed_double_support_s",
                self.timed_double_support_s,
                Range::new(0.01, 10.0),
            ),
        ]
    }

    /// The `[gait.dynamic]` table: every numeric key, its value and its range, one line a key.
    pub fn bounds(&self) -> Vec<Bound> {
        vec![
            Bound::new("single_support_s", self.single_support_s, 0.1, 5.0),
            Bound::optional(
                "step_single_support_s",
                self.step_single_support_s,
                0.1,
                5.0,
            ),
            Bound::new("double_support_s", self.double_support_s, 0.01, 5.0),
            Bound::optional(
                "step_double_support_s",
                self.step_double_support_s,
                0.01,
                5.0,
            ),
            Bound::optional(
                "climb_single_support_s",
                self.climb_single_support_s,
                0.1,
                5.0,
            ),
            Bound::optional(
                "climb_past_single_support_s",
                self.climb_past_single_support_s,
                0.1,
                5.0,
            ),
            Bound::optional(
                "descent_past_single_support_s",
                self.descent_past_single_support_s,
                0.1,
                5.0,
            ),
            Bound::optional(
                "climb_double_support_s",
                self.climb_double_support_s,
                0.01,
                5.0,
            ),
            Bound::optional(
                "past_double_support_s",
                self.past_double_support_s,
                0.01,
                5.0,
            ),
            Bound::new(
                "initial_double_support_s",
                self.initial_double_support_s,
                0.1,
                10.0,
            ),
            Bound::new(
                "final_double_support_s",
                self.final_double_support_s,
                0.1,
                10.0,
            ),
            Bound::new(
                "stop_double_support_s",
                self.stop_double_support_s,
                0.1,
                10.0,
            ),
            Bound::new("hand_transition_s", self.hand_transition_s, 0.05, 10.0),
            Bound::optional("com_height_m", self.com_height_m, 0.1, 3.0),
            Bound::new("landing_depth_m", self.landing_depth_m, 0.0, 0.05),
            Bound::new("early_touchdown_s", self.early_touchdown_s, 0.0, 1.0),
            Bound::new("late_touchdown_max_s", self.late_touchdown_max_s, 0.0, 2.0),
            Bound::new("late_descent_speed", self.late_descent_speed, 1e-3, 1.0),
            Bound::new("late_lift_off_max_s", self.late_lift_off_max_s, 0.0, 2.0),
            Bound::optional("hand_weight", self.hand_weight, 1e-6, 1e6),
            Bound::optional("com_gain", self.com_gain, 0.01, 1000.0),
            Bound::new("zmp_inward_offset_m", self.zmp_inward_offset_m, 0.0, 0.2),
            Bound::new(
                "step_down_zmp_forward_m",
                self.step_down_zmp_forward_m,
                0.0,
                0.2,
            ),
            Bound::optional("torso_posture_weight", self.torso_posture_weight, 1e-6, 1e6),
            Bound::new("max_step_up_m", self.max_step_up_m, 0.0, 1.0),
            Bound::new("max_step_down_m", self.max_step_down_m, 0.0, 1.0),
            Bound::new("step_down_speed", self.step_down_speed, 0.01, 10.0),
            Bound::new("climb_past_speed", self.climb_past_speed, 0.01, 10.0),
            Bound::new("descent_past_speed", self.descent_past_speed, 0.01, 10.0),
            Bound::new("max_slope_rad", self.max_slope_rad, 0.0, 1.0),
            Bound::new("toe_off_rad", self.toe_off_rad, 0.0, 0.8),
            Bound::new("toe_off_s", self.toe_off_s, 0.01, 5.0),
        ]
    }
}

/// A `[min, max]` key of `[gait.dynamic]`, if given, holds min ≤ max, both in `range` (so
/// finite and positive).
fn check_limits(
    key: &str,
    limits: Option<[f64; 2]>,
    range: Range,
    origin: &str,
) -> Result<(), ConfigError> {
    let Some([min, max]) = limits else {
        return Ok(());
    };
    if range.contains(min) && range.contains(max) && min <= max {
        return Ok(());
    }
    Err(ConfigError::Section {
        origin: origin.to_owned(),
        section: DYNAMIC,
        message: format!(
            "{key} = [{}, {}]: must be [min, max] with min ≤ max, each in {range} (s)",
            Number(min),
            Number(max)
        ),
    })
}

impl StabilizerConfig {
    /// The `[gait.dynamic.stabilizer]` table: every numeric key, its value and its range.
    pub fn bounds(&self) -> Vec<Bound> {
        let mut bounds = vec![
            Bound::new("zmp_margin_m", self.zmp_margin_m, 0.0, 0.1),
            Bound::new("dcm_gain", self.dcm_gain, 0.1, 20.0),
            Bound::new("velocity_filter_s", self.velocity_filter_s, 1e-4, 1.0),
            Bound::new(
                "zmp_offset_time_constant_s",
                self.zmp_offset_time_constant_s,
                0.01,
                100.0,
            ),
            Bound::new("zmp_offset_max_m", self.zmp_offset_max_m, 0.0, 0.2),
            Bound::new("foot_damping_gain", self.foot_damping_gain, 0.0, 0.1),
            Bound::new(
                "foot_damping_max_speed",
                self.foot_damping_max_speed,
                0.0,
                10.0,
            ),
            Bound::new("foot_damping_leak_s", self.foot_damping_leak_s, 0.01, 100.0),
            Bound::new("tilt_damping_s", self.tilt_damping_s, 0.0, 1.0),
            Bound::new("tilt_rate_filter_s", self.tilt_rate_filter_s, 1e-4, 1.0),
            Bound::new("tilt_damping_max_rad", self.tilt_damping_max_rad, 0.0, 0.5),
            Bound::new("internal_force_gain", self.internal_force_gain, 0.0, 0.01),
            Bound::new(
                "internal_force_max_speed",
                self.internal_force_max_speed,
                0.0,
                1.0,
            ),
        ];
        bounds.extend(force_difference_bounds(
            self.force_difference_gain,
            self.force_difference_max_speed,
        ));
        bounds
    }
}

/// The ranges of a force-difference gain (m/s per N) and its bound (m/s): the same keys in
/// `[gait.dynamic.stabilizer]` and, for the static gait, `[controller]`.
pub(crate) fn force_difference_bounds(gain: f64, max_speed: f64) -> [Bound; 2] {
    [
        Bound::new("force_difference_gain", gain, 0.0, 0.01),
        Bound::new("force_difference_max_speed", max_speed, 0.0, 1.0),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<GaitConfig, ConfigError> {
        GaitConfig::from_config(&ConfigFile::parse(text, Path::new("robot.toml")).unwrap())
    }

    #[test]
    fn without_a_gait_section_the_robot_walks_statically_only() {
        let file = ConfigFile::parse("[controller]\n", Path::new("robot.toml")).unwrap();
        let config = GaitConfig::from_config(&file).unwrap();
        assert_eq!(config.default, Gait::Static);
        // walkd refuses a dynamic walk as the client does up front: the file, section and fix.
        let refusal = config.dynamic().unwrap_err();
        assert_eq!(refusal, Gait::Dynamic.available_in(&file).unwrap_err());
        assert_eq!(refusal.path, Path::new("robot.toml"));
    }

    #[test]
    fn an_empty_dynamic_section_takes_the_defaults() {
        // The refusal's fix says so.
        let config = parse("[gait.dynamic]\n").unwrap();
        assert_eq!(config.dynamic().unwrap(), &DynamicGaitConfig::default());
    }

    #[test]
    fn a_dynamic_default_without_its_section_is_refused_naming_the_file_and_the_section() {
        let error = parse("[gait]\ndefault = \"dynamic\"\n")
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("robot.toml") && error.contains("[gait.dynamic]"),
            "{error}"
        );
    }

    #[test]
    fn partial_tables_keep_the_defaults() {
        let config = parse(
            "[gait]\ndefault = \"dynamic\"\n[gait.dynamic]\nsingle_support_s = 0.6\n\
             [gait.dynamic.stabilizer]\nfoot_damping = false\n",
        )
        .unwrap();
        assert_eq!(config.default, Gait::Dynamic);
        let dynamic = config.dynamic().unwrap();
        assert_eq!(dynamic.single_support_s, 0.6);
        assert_eq!(
            dynamic.double_support_s,
            DynamicGaitConfig::default().double_support_s
        );
        assert!(!dynamic.stabilizer.foot_damping);
        assert!(dynamic.stabilizer.tilt_damping);
    }

    /// An empty `[gait.dynamic]` walks: its defaults are the tuning that walks JVRC-1 under
    /// MuJoCo, and the stabilizer options docs/controller.md measured as harmful are off.
    #[test]
    fn the_defaults_are_the_tuning_that_walks_jvrc1() {
        let jvrc1 = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/jvrc1.toml");
        let tuned = GaitConfig::from_config_file(&jvrc1).unwrap();
        assert_eq!(tuned.dynamic().unwrap(), &DynamicGaitConfig::default());
        let empty = parse("[gait.dynamic]\n").unwrap();
        let stabilizer = empty.dynamic().unwrap().stabilizer;
        assert!(!stabilizer.dcm_feedback && !stabilizer.imu_tilt && !stabilizer.zmp_offset);
    }

    #[test]
    fn unknown_keys_name_their_table() {
        for (text, table, key) in [
            ("[gait]\ndefualt = \"static\"\n", "[gait]", "defualt"),
            (
                "[gait.dynamic]\nsingle_support = 0.6\n",
                "[gait.dynamic]",
                "single_support",
            ),
            (
                "[gait.dynamic.stabilizer]\ndcm_gian = 2.0\n",
                "[gait.dynamic.stabilizer]",
                "dcm_gian",
            ),
        ] {
            let error = parse(text).unwrap_err().to_string();
            assert!(error.contains(table) && error.contains(key), "{error}");
        }
        let error = parse("[gait]\ndefault = \"fast\"\n")
            .unwrap_err()
            .to_string();
        assert!(error.contains("fast"), "{error}");
    }

    #[test]
    fn durations_and_gains_have_upper_bounds() {
        for (table, key) in [
            ("gait.dynamic", "single_support_s"),
            ("gait.dynamic", "step_single_support_s"),
            ("gait.dynamic", "double_support_s"),
            ("gait.dynamic", "step_double_support_s"),
            ("gait.dynamic", "climb_single_support_s"),
            ("gait.dynamic", "climb_past_single_support_s"),
            ("gait.dynamic", "descent_past_single_support_s"),
            ("gait.dynamic", "climb_double_support_s"),
            ("gait.dynamic", "past_double_support_s"),
            ("gait.dynamic", "initial_double_support_s"),
            ("gait.dynamic", "final_double_support_s"),
            ("gait.dynamic", "stop_double_support_s"),
            ("gait.dynamic", "late_touchdown_max_s"),
            ("gait.dynamic", "late_lift_off_max_s"),
            ("gait.dynamic.stabilizer", "dcm_gain"),
            ("gait.dynamic.stabilizer", "zmp_offset_time_constant_s"),
        ] {
            let error = parse(&format!("[{table}]\n{key} = 1e9\n"))
                .expect_err(key)
                .to_string();
            assert!(error.contains(&format!("[{table}] {key}")), "{error}");
        }
    }

    #[test]
    fn timed_limits_default_to_slowing_the_tuned_gait_down_only() {
        let config =
            parse("[gait.dynamic]\nsingle_support_s = 0.6\ndouble_support_s = 0.2\n").unwrap();
        let dynamic = config.dynamic().unwrap();
        assert_eq!(dynamic.timed_single_support(), [0.6, 3.0 * 0.6]);
        assert_eq!(dynamic.timed_double_support(), [0.2, 4.0 * 0.2]);
        let config = parse(
            "[gait.dynamic]\ntimed_single_support_s = [0.4, 1.2]\n\
             timed_double_support_s = [0.1, 0.5]\n",
        )
        .unwrap();
        let dynamic = config.dynamic().unwrap();
        assert_eq!(dynamic.timed_single_support(), [0.4, 1.2]);
        assert_eq!(dynamic.timed_double_support(), [0.1, 0.5]);
    }

    #[test]
    fn bad_timed_limits_are_refused_naming_the_key() {
        for key in ["timed_single_support_s", "timed_double_support_s"] {
            for limits in [
                "[0.9, 0.5]",
                "[nan, 1.0]",
                "[0.5, inf]",
                "[-0.5, 1.0]",
                "[0.5, 1e9]",
            ] {
                let error = parse(&format!("[gait.dynamic]\n{key} = {limits}\n"))
                    .expect_err(limits)
                    .to_string();
                assert!(
                    error.contains("robot.toml") && error.contains(&format!("{key} = [")),
                    "{error}"
                );
            }
            for malformed in ["0.5", "[0.5]", "[0.5, 1.0, 2.0]"] {
                let error = parse(&format!("[gait.dynamic]\n{key} = {malformed}\n"))
                    .expect_err(malformed)
                    .to_string();
                assert!(error.contains(key), "{error}");
            }
        }
    }

    #[test]
    fn bad_values_are_named() {
        let error = parse("[gait.dynamic]\ndouble_support_s = 0.0\n")
            .unwrap_err()
            .to_string();
        assert!(error.contains("double_support_s"), "{error}");
        let error = parse("[gait.dynamic]\nzmp_inward_offset_m = -0.01\n")
            .unwrap_err()
            .to_string();
        assert!(error.contains("zmp_inward_offset_m"), "{error}");
        let error = parse("[gait.dynamic.stabilizer]\ndcm_gain = -1.0\n")
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("[gait.dynamic.stabilizer] dcm_gain"),
            "{error}"
        );
    }
}
