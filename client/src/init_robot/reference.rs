//! The calibration of the derivation rules: JVRC-1's dimensions as [`super::measure`] measures
//! them from the hand-tuned `configs/jvrc1.toml` (its frames, sole and standing posture), and
//! that config's hand-tuned values that the derived configs keep or scale. A test checks both
//! against the file, so a retuned JVRC-1 shows here.

use super::dimensions::RobotDimensions;

/// Gravity (m/s²), as the dynamic gait's pendulum uses it.
pub const GRAVITY: f64 = 9.81;

/// JVRC-1 measured from `configs/jvrc1.toml` (rounded to 0.1 mm, 0.1 mrad).
pub fn jvrc1() -> RobotDimensions {
    RobotDimensions {
        name: "jvrc1".to_owned(),
        mass_kg: 62.4,
        com_height_m: 0.8601,
        leg_length_m: 0.8227,
        pelvis_height_m: 0.8227,
        hip_width_m: 0.192,
        stance_width_m: 0.192,
        sole_length_m: 0.2,
        sole_width_m: 0.08,
        ankle_roll_range_rad: Some(0.6109),
        ankle_pitch_room_rad: Some(1.1035),
        leg_effort_min_nm: Some(100.0),
        leg_velocity_min_rad_s: Some(8.9012),
        torso_velocity_min_rad_s: Some(8.9012),
    }
}

/// One key of a hand-tuned section and its value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tuned {
    /// A number.
    Number(f64),
    /// A switch.
    Switch(bool),
}

/// `configs/jvrc1.toml` `[controller]`, in its order.
pub const CONTROLLER: [(&str, Tuned); 46] = [
    ("com_weight", Tuned::Number(10.0)),
    ("foot_weight", Tuned::Number(10.0)),
    ("unload_foot_weight", Tuned::Number(10.0)),
    ("hand_weight", Tuned::Number(1.0)),
    ("torso_weight", Tuned::Number(1.0)),
    ("posture_weight", Tuned::Number(0.01)),
    ("regularization", Tuned::Number(1e-5)),
    ("com_gain", Tuned::Number(10.0)),
    ("pose_gain", Tuned::Number(20.0)),
    ("torso_gain", Tuned::Number(10.0)),
    ("posture_gain", Tuned::Number(2.0)),
    ("joint_limit_margin_rad", Tuned::Number(0.02)),
    ("velocity_limit_scale", Tuned::Number(0.5)),
    ("max_base_speed", Tuned::Number(1.0)),
    ("support_margin_m", Tuned::Number(0.02)),
    ("support_gain", Tuned::Number(20.0)),
    ("com_speed", Tuned::Number(0.05)),
    ("swing_speed", Tuned::Number(0.15)),
    ("swing_angular_speed", Tuned::Number(0.5)),
    ("min_motion_s", Tuned::Number(0.3)),
    ("lift_height_m", Tuned::Number(0.03)),
    ("approach_height_m", Tuned::Number(0.02)),
    ("lower_speed", Tuned::Number(0.02)),
    ("lower_overshoot_m", Tuned::Number(0.003)),
    ("unload_lift_m", Tuned::Number(0.002)),
    ("com_tolerance_m", Tuned::Number(0.005)),
    ("position_tolerance_m", Tuned::Number(0.005)),
    ("orientation_tolerance_rad", Tuned::Number(0.05)),
    ("via_position_tolerance_m", Tuned::Number(0.03)),
    ("via_orientation_tolerance_rad", Tuned::Number(0.2)),
    ("hand_position_tolerance_m", Tuned::Number(0.03)),
    ("hand_orientation_tolerance_rad", Tuned::Number(0.1)),
    ("release_force_fraction", Tuned::Number(0.1)),
    ("touchdown_force_fraction", Tuned::Number(0.1)),
    ("touchdown_debounce_s", Tuned::Number(0.006)),
    ("phase_timeout_s", Tuned::Number(5.0)),
    ("max_step_m", Tuned::Number(0.65)),
    ("max_step_up_m", Tuned::Number(0.06)),
    ("max_step_down_m", Tuned::Number(0.06)),
    ("max_slope_rad", Tuned::Number(0.18)),
    ("hold_railings", Tuned::Switch(true)),
    ("command_lead_max_rad", Tuned::Number(0.05)),
    ("tipping_detection_rad", Tuned::Number(0.25)),
    ("catch_tilt_rad", Tuned::Number(0.1)),
    ("standing_crouch_max_m", Tuned::Number(0.09)),
    ("carry_released_hands", Tuned::Switch(true)),
];

/// `configs/jvrc1.toml` `[gait.dynamic]`, in its order.
pub const GAIT_DYNAMIC: [(&str, Tuned); 24] = [
    ("single_support_s", Tuned::Number(0.55)),
    ("double_support_s", Tuned::Number(0.25)),
    ("initial_double_support_s", Tuned::Number(1.0)),
    ("final_double_support_s", Tuned::Number(1.0)),
    ("stop_double_support_s", Tuned::Number(0.6)),
    ("hand_transition_s", Tuned::Number(0.5)),
    ("landing_depth_m", Tuned::Number(0.001)),
    ("early_touchdown_s", Tuned::Number(0.1)),
    ("late_touchdown_max_s", Tuned::Number(0.2)),
    ("late_descent_speed", Tuned::Number(0.05)),
    ("late_lift_off_max_s", Tuned::Number(0.2)),
    ("hand_weight", Tuned::Number(0.02)),
    ("com_gain", Tuned::Number(3.0)),
    ("torso_posture_weight", Tuned::Number(1.0)),
    ("max_step_up_m", Tuned::Number(0.15)),
    ("max_step_down_m", Tuned::Number(0.19)),
    ("step_down_speed", Tuned::Number(0.15)),
    ("climb_past_speed", Tuned::Number(0.125)),
    ("descent_past_speed", Tuned::Number(0.115)),
    ("max_slope_rad", Tuned::Number(0.27)),
    ("hold_railings", Tuned::Switch(false)),
    ("toe_off_rad", Tuned::Number(0.5)),
    ("toe_off_s", Tuned::Number(0.25)),
    ("step_down_zmp_forward_m", Tuned::Number(0.03)),
];

/// `configs/jvrc1.toml` `[gait.dynamic.stabilizer]`, in its order.
pub const STABILIZER: [(&str, Tuned); 22] = [
    ("zmp_margin_m", Tuned::Number(0.01)),
    ("dcm_feedback", Tuned::Switch(false)),
    ("dcm_gain", Tuned::Number(3.0)),
    ("imu_tilt", Tuned::Switch(false)),
    ("velocity_filter_s", Tuned::Number(0.01)),
    ("zmp_offset", Tuned::Switch(false)),
    ("zmp_offset_time_constant_s", Tuned::Number(1.0)),
    ("zmp_offset_max_m", Tuned::Number(0.03)),
    ("foot_damping", Tuned::Switch(true)),
    ("foot_damping_gain", Tuned::Number(5e-4)),
    ("foot_damping_max_speed", Tuned::Number(0.2)),
    ("foot_damping_leak_s", Tuned::Number(1.0)),
    ("force_difference", Tuned::Switch(true)),
    ("force_difference_gain", Tuned::Number(1e-5)),
    ("force_difference_max_speed", Tuned::Number(0.02)),
    ("internal_force", Tuned::Switch(true)),
    ("internal_force_gain", Tuned::Number(1e-4)),
    ("internal_force_max_speed", Tuned::Number(0.02)),
    ("tilt_damping", Tuned::Switch(true)),
    ("tilt_damping_s", Tuned::Number(0.03)),
    ("tilt_rate_filter_s", Tuned::Number(0.01)),
    ("tilt_damping_max_rad", Tuned::Number(0.01)),
];

/// JVRC-1's `[postprocess]` (static gait) values the rules scale.
pub mod postprocess {
    /// `s_max` (m).
    pub const S_MAX: f64 = 0.24;
    /// `scf`.
    pub const SCF: f64 = 0.16;
    /// `h_min`, `h_max` (m).
    pub const H: (f64, f64) = (0.03, 0.08);
    /// `alpha_x`, `alpha_y`, `alpha_z` (rad).
    pub const ALPHA: (f64, f64, f64) = (0.05, 0.15, 0.15);
}

/// JVRC-1's `[postprocess.dynamic]` values the rules scale.
pub mod dynamic {
    /// `s_max` (m).
    pub const S_MAX: f64 = 0.48;
    /// `scf`.
    pub const SCF: f64 = 0.46;
    /// `h_min`, `h_max` (m).
    pub const H: (f64, f64) = (0.02, 0.03);
    /// `alpha_y` (rad).
    pub const ALPHA_Y: f64 = 0.05;
    /// `rise_weight`.
    pub const RISE_WEIGHT: f64 = 3.5;
    /// `stair_s_max` (m).
    pub const STAIR_S_MAX: f64 = 0.68;
}

/// ARMAR-4's hand-tuned values (`configs/armar4.toml`) that calibrate the rules for a robot
/// with little ankle roll or slow joints, which JVRC-1 cannot calibrate. A test checks them
/// against the file.
pub mod armar4 {
    use super::Tuned;

    /// Total mass (kg), measured from its model.
    pub const MASS_KG: f64 = 72.04;
    /// `[gait.dynamic]` `single_support_s`.
    pub const SINGLE_SUPPORT_S: f64 = 0.4;
    /// `[postprocess.dynamic]` `s_max` (m).
    pub const S_MAX_DYNAMIC: f64 = 0.2;
    /// `[controller]` `torso_gain` (1/s).
    pub const TORSO_GAIN: f64 = 1.0;
    /// `[gait.dynamic.stabilizer]` `foot_damping_gain` (rad/s per N·m).
    pub const FOOT_DAMPING_GAIN: f64 = 2e-3;
    /// `[controller]` bounds of a robot that sways on its pelvis because its ankle roll is
    /// small (docs/controller.md, "Pelvis tilt rate").
    pub const ROLL_LIMITED_BOUNDS: [(&str, Tuned); 3] = [
        ("max_base_tilt_speed", Tuned::Number(0.2)),
        ("max_anchor_correction_speed", Tuned::Number(0.01)),
        ("max_anchor_correction_angular_speed", Tuned::Number(0.1)),
    ];
    /// `[controller]` `carry_released_hands` (absent from its config: the default): with heavy
    /// arms and little ankle roll it cannot balance with a released arm carried out to the side.
    pub const CARRY_RELEASED_HANDS: bool = false;
}

/// The value of `key` in one of the tables above.
pub fn tuned(table: &[(&str, Tuned)], key: &str) -> Tuned {
    table
        .iter()
        .find(|(k, _)| *k == key)
        .map(|(_, v)| *v)
        .unwrap_or_else(|| panic!("no hand-tuned value for {key}"))
}

/// The number of `key` in one of the tables above.
pub fn number(table: &[(&str, Tuned)], key: &str) -> f64 {
    match tuned(table, key) {
        Tuned::Number(x) => x,
        Tuned::Switch(_) => panic!("{key} is a switch"),
    }
}
