//! The derivation rules: a robot's dimensions → the `[postprocess]`, `[controller]`, `[gait]` and
//! `[runtime]` sections of a starting config, calibrated on the hand-tuned JVRC-1 (the
//! reference, [`reference::jvrc1`]) and, for robots with little ankle roll, on ARMAR-4. A pure
//! function; docs/new-robot.md states every rule with the calibration numbers.
//!
//! With r = l / l_ref (leg lengths) and t = √r (dynamic similarity: the same Froude number, so
//! lengths scale with r, times and speeds with t):
//!
//! - dynamic gait timing: `single_support_s` = 0.55 s·t, `double_support_s` = 0.25 s·t (times k,
//!   below); `max_step_up_m`, `max_step_down_m` = (0.15, 0.19) m·r; `step_down_speed`,
//!   `climb_past_speed`, `descent_past_speed` = (0.15, 0.125, 0.115) m/s·t;
//!   `step_down_zmp_forward_m` = 0.03 m × sole length / 0.20 m (JVRC-1's share of its
//!   sole);
//! - `[postprocess]` (static gait): `s_max` = min(0.24 m·r, 1.2 × sole length); `h_min`,
//!   `h_max` = (0.03, 0.08) m·r; `scf` keeps JVRC-1's mapping of the human stride onto about
//!   0.8 `s_max`: the stance generator already scales the human walk by the pelvis height P,
//!   so `scf` = 0.16 × (s_max / 0.24 m) × (P_ref / P) — which is 0.16 for a robot scaled
//!   uniformly from JVRC-1 (not 0.16·r, which maps the stride onto 0.8 s_max·r);
//! - `[postprocess.dynamic]`: `s_max` = 0.48 m·r·k, at most 4 l sin(ankle pitch room − margin)
//!   (a foot a quarter stride behind the hip tilts the leg by asin(s_max / 4l), which the ankle
//!   pitch has to follow) and at most [`SWING_SWEEP_SHARE`] × ω l × `single_support_s`, with ω
//!   the slowest leg joint's commanded speed limit (`velocity_limit_scale` × URDF velocity): the
//!   swing foot crosses about two steps in single support, and a leg swept at ω moves its foot
//!   at most ω l (ARMAR-4's short steps); `scf` = 0.46 × (s_max / 0.48 m) × (P_ref / P);
//!   `h_min`, `h_max` = (0.02, 0.03) m·r; `alpha_y` 0.05 rad;
//! - lateral foot distance: `o_min` = max(0.78 × hip width, sole width + 0.05 m), `o_max` =
//!   max(1.25 × hip width, `o_min` + 0.02 m);
//! - little ankle roll: the linear inverted pendulum (ω = √(g/z_c)) walking periodically with its
//!   single-support ZMP at b from the midline sways the CoM by a = b (1 − sech(ωT/2)),
//!   T = single + double support; tilting the legs on the ankle rolls moves it by at most
//!   c = l sin(roll range − joint margin). When a > [`ROLL_SWAY_RATIO`]·c (with b = o_min / 2 at
//!   the Froude timing), the robot is *roll-limited*: its feet stay at the standing width
//!   (`o_min` = the stance width rounded down to the cm, `o_max` = `o_min` + 0.01 m, both gaits),
//!   its swing foot level and straight (`alpha_x` 0.01, `alpha_y`/`alpha_z` 0.05 rad), and
//!   `zmp_inward_offset_m` = o_min/2 − b with b solving a = ratio·c, within [0, sole width/2 −
//!   `zmp_margin_m`]; if that is not enough, T shrinks (single and double support alike, by the
//!   factor k, not below [`MIN_PERIOD_FRACTION`] of the Froude value) and the dynamic step with it
//!   (the walking speed stays the Froude speed);
//! - `[controller]`: JVRC-1's values but `max_step_m` = max(0.5 m·r, dynamic s_max + 0.02 m,
//!   `stair_s_max` = 0.68 / 0.48 × dynamic s_max),
//!   `lift_height_m`, `approach_height_m` ·r and `com_speed`, `swing_speed`, `lower_speed` ·t;
//!   `torso_gain` at most the slowest torso joint's commanded speed limit over
//!   [`TORSO_SATURATION_RAD`] (ARMAR-4's 0.4 rad/s torso pitch); roll-limited, ARMAR-4's bounds
//!   on the pelvis tilt rate and the anchor correction, and a released hand left to the posture
//!   (`carry_released_hands` off);
//! - `[gait.dynamic.stabilizer]`: JVRC-1's switches and values but `foot_damping_gain` = 5e-4 ×
//!   m_ref/m (roll-limited: ARMAR-4's 2e-3 × m_ARMAR/m) and `force_difference_gain` = 1e-5 ×
//!   m_ref/m (the CoP torque and the force difference grow with the weight);
//! - `[gait]` `default = "static"`; `[runtime]` JVRC-1's with `service_prefix = "walk/<name>"`.

use super::dimensions::RobotDimensions;
use super::frames::round;
use super::reference::{self, GRAVITY, Tuned};

/// The largest share of the ankle-roll sway c that the pendulum's sway a may take: ARMAR-4's
/// hand-tuned gait (0.4/0.15 s, ZMP 0.05 m inside 0.17 m apart feet) sways a = 0.0107 m of
/// c = 0.0338 m, a ratio of 0.32 (see the test `armar4_hand_tuned_sway_ratio`).
pub const ROLL_SWAY_RATIO: f64 = 0.32;
/// The step period is not shortened below this fraction of its Froude value.
pub const MIN_PERIOD_FRACTION: f64 = 0.6;
/// The longest dynamic step as a share of ω l T_ss, how far a leg swept at its slowest joint's
/// commanded speed ω moves its foot in single support: ARMAR-4's hand-tuned 0.2 m step in 0.4 s
/// at 0.5 × 1.71 rad/s with l = 0.834 m is 0.70 of it (the test `armar4_hand_tuned_swing_share`);
/// its derived 0.33 m step (the ankle-pitch rule alone) walked 3 of 60 MuJoCo walks.
pub const SWING_SWEEP_SHARE: f64 = 0.70;
/// The torso task's error (rad) at which its command reaches the slowest torso joint's commanded
/// speed: ARMAR-4's torso pitch (0.5 × 0.4 rad/s) with its hand-tuned gain 1. At JVRC-1's gain
/// 10 it saturated at 0.02 rad, and its static walks with a hand tipped.
pub const TORSO_SATURATION_RAD: f64 = 0.2;

/// One value of a derived section.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A number written plainly (`0.55`).
    Number(f64),
    /// A number written in exponent form (`5e-4`).
    Exponent(f64),
    /// A whole number.
    Integer(i64),
    /// A switch.
    Switch(bool),
    /// A string.
    Text(String),
}

/// One line of a derived section.
#[derive(Debug, Clone, PartialEq)]
pub enum Line {
    /// A comment line.
    Comment(String),
    /// `# key = value  # rule`: a key left out, shown for the user to set.
    Commented {
        /// The key.
        key: &'static str,
        /// Its suggested value.
        value: Value,
        /// What it does.
        rule: String,
    },
    /// `key = value  # rule`.
    Key {
        /// The key.
        key: &'static str,
        /// Its value.
        value: Value,
        /// The rule that gave it, or what it is.
        rule: String,
    },
}

/// One `[table]` of the config.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    /// The table's name (`gait.dynamic`).
    pub table: &'static str,
    /// Its lines.
    pub lines: Vec<Line>,
}

/// The lateral sway check of a robot with an ankle roll.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RollCheck {
    /// c: how far tilting the legs on the ankle rolls moves the CoM (m).
    pub reach_m: f64,
    /// a at the Froude timing with the ZMP at the sole centres (m).
    pub froude_sway_m: f64,
    /// a with the derived timing and ZMP (m).
    pub sway_m: f64,
    /// Whether a > ratio·c at the Froude timing: the roll-limited rules apply.
    pub limited: bool,
}

/// The key derived values, for reports and tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Summary {
    /// l / l_ref.
    pub scale: f64,
    /// Dynamic gait single support (s).
    pub single_support_s: f64,
    /// Dynamic gait double support (s).
    pub double_support_s: f64,
    /// k: the step period's fraction of its Froude value.
    pub period_fraction: f64,
    /// Static `s_max` (m).
    pub s_max: f64,
    /// Static `scf`.
    pub scf: f64,
    /// Dynamic `s_max` (m).
    pub s_max_dynamic: f64,
    /// Dynamic `scf`.
    pub scf_dynamic: f64,
    /// Static `o_min`, `o_max` (m).
    pub o: (f64, f64),
    /// Dynamic `o_min`, `o_max` (m).
    pub o_dynamic: (f64, f64),
    /// `zmp_inward_offset_m`.
    pub zmp_inward_offset_m: f64,
    /// `max_step_m`.
    pub max_step_m: f64,
    /// The sway check, for robots with an ankle roll.
    pub roll: Option<RollCheck>,
}

/// What [`derive`] gives: the sections, the key values and what the user should know.
#[derive(Debug, Clone, PartialEq)]
pub struct DerivedSections {
    /// `[postprocess]` … `[runtime]`, in the order of the config files.
    pub sections: Vec<Section>,
    /// The key values.
    pub summary: Summary,
    /// Remarks on the derivation (roll limits, shortened periods).
    pub notes: Vec<String>,
}

impl DerivedSections {
    /// The value of `table`.`key`, if it is a number.
    pub fn number(&self, table: &str, key: &str) -> Option<f64> {
        self.sections
            .iter()
            .filter(|s| s.table == table)
            .flat_map(|s| &s.lines)
            .find_map(|line| match line {
                Line::Key {
                    key: k,
                    value: Value::Number(x) | Value::Exponent(x),
                    ..
                } if *k == key => Some(*x),
                Line::Key {
                    key: k,
                    value: Value::Integer(i),
                    ..
                } if *k == key => Some(*i as f64),
                _ => None,
            })
    }
}

/// The LIPM's lateral CoM sway a = b (1 − sech(ωT/2)) for a single-support ZMP at `b` from the
/// midline, step period `period`, ω = √(g / `com_height`).
pub fn sway(b: f64, period: f64, com_height: f64) -> f64 {
    let omega = (GRAVITY / com_height).sqrt();
    b * (1.0 - 1.0 / (omega * period / 2.0).cosh())
}

/// c = l sin(roll range − margin): how far the CoM moves when the legs tilt on the ankle rolls.
pub fn ankle_reach(leg_length: f64, roll_range: f64, margin: f64) -> f64 {
    leg_length * (roll_range - margin).max(0.0).sin()
}

/// Two significant digits.
fn significant(x: f64) -> f64 {
    if x == 0.0 {
        return 0.0;
    }
    let step = 10f64.powf(x.abs().log10().floor() - 1.0);
    round(x, step)
}

fn key(key: &'static str, value: f64, rule: impl Into<String>) -> Line {
    Line::Key {
        key,
        value: Value::Number(value),
        rule: rule.into(),
    }
}

fn comment(text: impl Into<String>) -> Line {
    Line::Comment(text.into())
}

fn kept(table: &[(&'static str, Tuned)], name: &'static str, rule: &str) -> Line {
    let value = match reference::tuned(table, name) {
        Tuned::Number(x) if x != 0.0 && x.abs() < 1e-3 => Value::Exponent(x),
        Tuned::Number(x) => Value::Number(x),
        Tuned::Switch(b) => Value::Switch(b),
    };
    Line::Key {
        key: name,
        value,
        rule: rule.to_owned(),
    }
}

/// The lateral and sway rules' outcome.
struct Lateral {
    o: (f64, f64),
    o_dynamic: Option<(f64, f64)>,
    offset: f64,
    period_fraction: f64,
    roll: Option<RollCheck>,
    lines: Vec<Line>,
    notes: Vec<String>,
}

/// Applies the derivation rules to `d`.
pub fn derive(d: &RobotDimensions) -> DerivedSections {
    let reference = reference::jvrc1();
    let l = d.leg_length_m;
    let r = l / reference.leg_length_m;
    let t = r.sqrt();
    let pelvis = reference.pelvis_height_m / d.pelvis_height_m;
    let weight = reference.mass_kg / d.mass_kg;
    let margin = reference::number(&reference::CONTROLLER, "joint_limit_margin_rad");
    let speed_scale = reference::number(&reference::CONTROLLER, "velocity_limit_scale");
    let l_is = format!("l = {l:.3} m");
    let lateral = lateral(d, t, margin);
    let k = lateral.period_fraction;

    let single = round(0.55 * t * k, 0.01);
    let double = round(0.25 * t * k, 0.01);
    let period_rule = |base: f64| {
        if k < 1.0 {
            format!("{base} s × √(l/l_ref) × {k:.2} (roll-limited, see above), {l_is}")
        } else {
            format!("{base} s × √(l/l_ref), {l_is}")
        }
    };

    // Static gait.
    let s_max_scaled = reference::postprocess::S_MAX * r;
    let sole_cap = 1.2 * d.sole_length_m;
    let s_max = round(s_max_scaled.min(sole_cap), 0.001);
    let s_max_rule = if s_max_scaled <= sole_cap {
        format!("0.24 m × l/l_ref (≤ 1.2 × sole length {sole_cap:.3} m), {l_is}")
    } else {
        format!("1.2 × sole length (0.24 m × l/l_ref = {s_max_scaled:.3} m is longer)")
    };
    let scf = round(
        reference::postprocess::SCF * s_max / reference::postprocess::S_MAX * pelvis,
        0.01,
    );
    let scf_rule = format!(
        "0.16 × (s_max/0.24 m) × (P_ref/P), pelvis height P = {:.3} m: the human stride onto \
         ~0.8 s_max",
        d.pelvis_height_m
    );

    // Dynamic gait.
    let s_dyn_froude = reference::dynamic::S_MAX * r * k;
    let pitch_cap = d
        .ankle_pitch_room_rad
        .map(|room| 4.0 * l * (room - margin).max(0.0).sin());
    let swing_speed = d.leg_velocity_min_rad_s.map(|v| speed_scale * v);
    let sweep_cap = swing_speed.map(|omega| SWING_SWEEP_SHARE * omega * l * single);
    let s_max_dynamic = round(
        s_dyn_froude
            .min(pitch_cap.unwrap_or(f64::INFINITY))
            .min(sweep_cap.unwrap_or(f64::INFINITY)),
        0.001,
    );
    let froude_rule = format!(
        "0.48 m × l/l_ref{} = {s_dyn_froude:.3} m",
        if k < 1.0 { " × k" } else { "" }
    );
    let s_dyn_rule = match (pitch_cap, sweep_cap) {
        (_, Some(cap)) if cap < s_dyn_froude && pitch_cap.is_none_or(|p| cap <= p) => format!(
            "{SWING_SWEEP_SHARE} ω l T_ss = {SWING_SWEEP_SHARE} × {:.3} × {l:.3} × {single}: the \
             swing leg at its slowest joint's commanded speed ω ({froude_rule} is longer)",
            swing_speed.unwrap_or_default()
        ),
        (Some(cap), _) if cap < s_dyn_froude => format!(
            "4 l sin(ankle pitch room − margin) = 4 × {l:.3} × sin({:.3} − {margin}): a foot \
             s_max/4 behind the hip ({froude_rule} is longer)",
            d.ankle_pitch_room_rad.unwrap_or_default(),
        ),
        _ if k < 1.0 => format!("0.48 m × l/l_ref × {k:.2} (the period's fraction), {l_is}"),
        _ => format!("0.48 m × l/l_ref, {l_is}"),
    };
    let scf_dynamic = round(
        reference::dynamic::SCF * s_max_dynamic / reference::dynamic::S_MAX * pelvis,
        0.01,
    );
    let stair_s_max = round(
        reference::dynamic::STAIR_S_MAX * s_max_dynamic / reference::dynamic::S_MAX,
        0.001,
    );
    let max_step = round((0.5 * r).max(s_max_dynamic + 0.02).max(stair_s_max), 0.001);

    let postprocess = vec![
        comment(
            "Algorithm 1 (stance crate, docs/stance.md); derived (docs/new-robot.md), not tuned.",
        ),
        key("scf", scf, scf_rule),
        key("s_max", s_max, s_max_rule),
        key("o_min", lateral.o.0, lateral_rule(d, lateral.roll, "o_min")),
        key("o_max", lateral.o.1, lateral_rule(d, lateral.roll, "o_max")),
        key("alpha_x", reference::postprocess::ALPHA.0, "JVRC-1's"),
        key("alpha_y", reference::postprocess::ALPHA.1, "JVRC-1's"),
        key("alpha_z", reference::postprocess::ALPHA.2, "JVRC-1's"),
        key(
            "h_min",
            round(reference::postprocess::H.0 * r, 0.001),
            "0.03 m × l/l_ref",
        ),
        key(
            "h_max",
            round(reference::postprocess::H.1 * r, 0.001),
            "0.08 m × l/l_ref",
        ),
    ];

    let mut dynamic = vec![
        comment("Overrides of [postprocess] for the dynamic gait."),
        key("s_max", s_max_dynamic, s_dyn_rule),
        key(
            "scf",
            scf_dynamic,
            "0.46 × (s_max/0.48 m) × (P_ref/P): JVRC-1's stride mapping",
        ),
        key(
            "h_min",
            round(reference::dynamic::H.0 * r, 0.001),
            "0.02 m × l/l_ref",
        ),
        key(
            "h_max",
            round(reference::dynamic::H.1 * r, 0.001),
            "0.03 m × l/l_ref",
        ),
    ];
    if let Some((o_min, o_max)) = lateral.o_dynamic {
        dynamic.push(comment(
            "Roll-limited (see [gait.dynamic]): the feet stay at the standing width (narrower, \
             every ankle rolls before the CoM moves) and the swing foot level and straight (a \
             rolled or turned foot takes ankle roll), as configs/armar4.toml.",
        ));
        dynamic.push(key(
            "o_min",
            o_min,
            "the stance width, rounded down to the cm",
        ));
        dynamic.push(key("o_max", o_max, "o_min + 0.01 m"));
        dynamic.push(key("alpha_x", 0.01, "roll-limited: the swing foot level"));
        dynamic.push(key("alpha_y", 0.05, "roll-limited"));
        dynamic.push(key(
            "alpha_z",
            0.05,
            "roll-limited: the swing foot straight",
        ));
    } else {
        dynamic.push(key("alpha_y", reference::dynamic::ALPHA_Y, "JVRC-1's"));
    }
    dynamic.push(key(
        "rise_weight",
        reference::dynamic::RISE_WEIGHT,
        "JVRC-1's: shorter steps up and down stairs",
    ));
    dynamic.push(key(
        "stair_s_max",
        stair_s_max,
        format!(
            "{} × s_max / {}: one foot per stair where two treads are a step this long (JVRC-1's \
             ratio, measured on its 0.10 m and 0.15 m stairs)",
            reference::dynamic::STAIR_S_MAX,
            reference::dynamic::S_MAX
        ),
    ));

    let roll_limited = lateral.roll.is_some_and(|c| c.limited);
    let torso_gain = d
        .torso_velocity_min_rad_s
        .map(|v| speed_scale * v)
        .map(|speed| (significant(speed / TORSO_SATURATION_RAD), speed))
        .filter(|&(gain, _)| gain < reference::number(&reference::CONTROLLER, "torso_gain"));
    let controller = controller(
        Scales { r, t },
        ControllerRules {
            max_step,
            s_max_dynamic,
            torso_gain,
            roll_limited,
        },
    );

    // JVRC-1's measured value of `name` times `factor`, the rule naming the scale.
    let scaled = |name: &'static str, factor: f64, scale: &str| {
        let base = reference::number(&reference::GAIT_DYNAMIC, name);
        key(
            name,
            round(base * factor, 0.001),
            format!("{base} {scale} (JVRC-1's, measured)"),
        )
    };
    let jvrc1_sole = reference::jvrc1().sole_length_m;
    let mut gait_dynamic = lateral.lines.clone();
    for (name, _) in reference::GAIT_DYNAMIC.iter() {
        gait_dynamic.push(match *name {
            "single_support_s" => key(name, single, period_rule(0.55)),
            "double_support_s" => key(name, double, period_rule(0.25)),
            "max_step_up_m" | "max_step_down_m" => {
                scaled(name, r, "× l/l_ref: higher steps are refused")
            }
            "step_down_speed" | "climb_past_speed" | "descent_past_speed" => {
                scaled(name, t, "m/s × t")
            }
            "step_down_zmp_forward_m" => scaled(
                name,
                d.sole_length_m / jvrc1_sole,
                &format!("× sole length / {jvrc1_sole} m"),
            ),
            _ => kept(&reference::GAIT_DYNAMIC, name, "JVRC-1's"),
        });
    }
    gait_dynamic.push(key(
        "zmp_inward_offset_m",
        lateral.offset,
        if lateral.offset > 0.0 {
            "single-support ZMP this far inside the sole centre [m]: the sway rule above"
        } else {
            "single-support ZMP at the sole centre [m]: the ankle roll is not limiting"
        },
    ));

    let mut stabilizer = vec![comment(
        "JVRC-1's stabilizer; the two force gains scale with 1/m (the CoP torque and the force \
         difference grow with the weight).",
    )];
    for (name, _) in reference::STABILIZER.iter() {
        stabilizer.push(match *name {
            "foot_damping_gain" if roll_limited => Line::Key {
                key: name,
                value: Value::Exponent(significant(
                    reference::armar4::FOOT_DAMPING_GAIN * reference::armar4::MASS_KG / d.mass_kg,
                )),
                rule: format!(
                    "roll-limited: ARMAR-4's 2e-3 × m_ARMAR/m, m = {:.2} kg [rad/s per N·m]",
                    d.mass_kg
                ),
            },
            "foot_damping_gain" => Line::Key {
                key: name,
                value: Value::Exponent(significant(5e-4 * weight)),
                rule: format!("5e-4 × m_ref/m, m = {:.2} kg [rad/s per N·m]", d.mass_kg),
            },
            "force_difference_gain" => Line::Key {
                key: name,
                value: Value::Exponent(significant(1e-5 * weight)),
                rule: format!("1e-5 × m_ref/m, m = {:.2} kg [m/s per N]", d.mass_kg),
            },
            _ => kept(&reference::STABILIZER, name, "JVRC-1's"),
        });
    }

    let sections = vec![
        Section {
            table: "postprocess",
            lines: postprocess,
        },
        Section {
            table: "postprocess.dynamic",
            lines: dynamic,
        },
        Section {
            table: "controller",
            lines: controller,
        },
        Section {
            table: "gait",
            lines: vec![
                comment(
                    "Which gait a walk uses unless it asks for one (daemon::controller::GaitConfig; \
                     docs/controller.md, \"Dynamic gait\"). Unknown keys are errors.",
                ),
                Line::Key {
                    key: "default",
                    value: Value::Text("static".to_owned()),
                    rule: "the quasi-static gait until the dynamic one is tried".to_owned(),
                },
            ],
        },
        Section {
            table: "gait.dynamic",
            lines: gait_dynamic,
        },
        Section {
            table: "gait.dynamic.stabilizer",
            lines: stabilizer,
        },
        runtime(&d.name),
    ];
    DerivedSections {
        sections,
        summary: Summary {
            scale: r,
            single_support_s: single,
            double_support_s: double,
            period_fraction: k,
            s_max,
            scf,
            s_max_dynamic,
            scf_dynamic,
            o: lateral.o,
            o_dynamic: lateral.o_dynamic.unwrap_or(lateral.o),
            zmp_inward_offset_m: lateral.offset,
            max_step_m: max_step,
            roll: lateral.roll,
        },
        notes: lateral.notes,
    }
}

/// The comment of a static lateral limit.
fn lateral_rule(d: &RobotDimensions, roll: Option<RollCheck>, which: &str) -> String {
    if roll.is_some_and(|c| c.limited) {
        return match which {
            "o_min" => format!(
                "roll-limited: the stance width {:.3} m rounded down to the cm",
                d.stance_width_m
            ),
            _ => "roll-limited: o_min + 0.01 m".to_owned(),
        };
    }
    match which {
        "o_min" => format!(
            "max(0.78 × hip width, sole width + 0.05 m), hips {:.3} m, sole {:.3} m",
            d.hip_width_m, d.sole_width_m
        ),
        _ => "max(1.25 × hip width, o_min + 0.02 m)".to_owned(),
    }
}

/// The lateral limits, the sway check and what it sets (see the module docs).
fn lateral(d: &RobotDimensions, t: f64, margin: f64) -> Lateral {
    let o_min = round((0.78 * d.hip_width_m).max(d.sole_width_m + 0.05), 0.001);
    let o_max = round((1.25 * d.hip_width_m).max(o_min + 0.02), 0.001);
    let froude_period = 0.8 * t;
    let z = d.com_height_m;
    let omega = (GRAVITY / z).sqrt();
    let mut result = Lateral {
        o: (o_min, o_max),
        o_dynamic: None,
        offset: 0.0,
        period_fraction: 1.0,
        roll: None,
        lines: Vec::new(),
        notes: Vec::new(),
    };
    let Some(range) = d.ankle_roll_range_rad else {
        result.lines.push(comment(
            "No ankle roll range known: the lateral sway is not checked (docs/new-robot.md).",
        ));
        return result;
    };
    let c = ankle_reach(d.leg_length_m, range, margin);
    let allowed = ROLL_SWAY_RATIO * c;
    let froude_sway = sway(o_min / 2.0, froude_period, z);
    let limited = froude_sway > allowed;
    let mut check = RollCheck {
        reach_m: c,
        froude_sway_m: froude_sway,
        sway_m: froude_sway,
        limited,
    };
    if !limited {
        result.roll = Some(check);
        result.lines.push(comment(format!(
            "Lateral sway (LIPM, ω = √(g/z_c) = {omega:.2} /s, z_c = {z:.3} m): a = b (1 − \
             sech(ωT/2)) = {froude_sway:.4} m with b = o_min/2 = {:.3} m, T = {froude_period:.2} s; \
             the ankle rolls reach c = l sin({range:.3} − {margin}) = {c:.4} m; a ≤ {ROLL_SWAY_RATIO} c: \
             the ankle roll does not limit the gait.",
            o_min / 2.0
        )));
        return result;
    }
    let o_min_dynamic = (d.stance_width_m / 0.01 + 1e-9).floor() * 0.01;
    let o_min_dynamic = round(o_min_dynamic, 0.001);
    let o_dynamic = (o_min_dynamic, round(o_min_dynamic + 0.01, 0.001));
    let half = o_dynamic.0 / 2.0;
    let zmp_margin = reference::number(&reference::STABILIZER, "zmp_margin_m");
    // Whole millimetres: the offset rounded up (the sway stays within the share), its bound
    // rounded down (the ZMP stays inside the sole's margin).
    let offset_max = ((d.sole_width_m / 2.0 - zmp_margin).max(0.0) * 1000.0).floor() / 1000.0;
    let factor = 1.0 - 1.0 / (omega * froude_period / 2.0).cosh();
    let wanted_b = allowed / factor;
    let offset = round(
        (((half - wanted_b) * 1000.0 - 1e-6).ceil() / 1000.0).clamp(0.0, offset_max),
        0.001,
    );
    let b = half - offset;
    let mut k = 1.0;
    if sway(b, froude_period, z) > allowed * (1.0 + 1e-9) {
        // a = b (1 − sech(ωT/2)) = allowed  ⇒  T = (2/ω) acosh(1 / (1 − allowed/b)).
        let needed = if allowed < b {
            2.0 / omega * (1.0 / (1.0 - allowed / b)).acosh()
        } else {
            froude_period
        };
        // Whole percent, rounded down so the sway stays within the share.
        k = ((needed / froude_period * 100.0 + 1e-9).floor() / 100.0)
            .clamp(MIN_PERIOD_FRACTION, 1.0);
        if needed / froude_period < MIN_PERIOD_FRACTION {
            result.notes.push(format!(
                "roll-limited: even at {:.0} % of the Froude step period the sway ({:.4} m) \
                 exceeds {ROLL_SWAY_RATIO} × c = {allowed:.4} m; the gait is likely to run the \
                 ankle rolls into their limits",
                MIN_PERIOD_FRACTION * 100.0,
                sway(b, froude_period * k, z)
            ));
        }
        result.notes.push(format!(
            "roll-limited: step period shortened to {:.0} % of its Froude value ({:.2} s of \
             {froude_period:.2} s), the dynamic step with it",
            k * 100.0,
            froude_period * k
        ));
    }
    check.sway_m = sway(b, froude_period * k, z);
    result.notes.insert(
        0,
        format!(
            "roll-limited (ankle roll ±{range:.3} rad): sway {froude_sway:.4} m > {ROLL_SWAY_RATIO} \
             × c = {allowed:.4} m; zmp_inward_offset_m = {offset:.3}, feet {:.2}–{:.2} m apart, \
             sway now {:.4} m",
            o_dynamic.0, o_dynamic.1, check.sway_m
        ),
    );
    result.lines.push(comment(format!(
        "Roll-limited: the legs tilt on the ankle rolls (±{range:.3} rad, less the {margin} rad \
         margin) to sway the CoM sideways, reaching c = l sin(range − margin) = {c:.4} m. The \
         pendulum (LIPM, ω = √(g/z_c) = {omega:.2} /s, z_c = {z:.3} m) sways a = b (1 − \
         sech(ωT/2)): {froude_sway:.4} m at the Froude period {froude_period:.2} s with the ZMP at \
         the sole centres (b = {half:.3} m), more than {ROLL_SWAY_RATIO} c = {allowed:.4} m \
         (ARMAR-4's hand-tuned share). The single-support ZMP moves inwards to b = {b:.3} m{}: \
         a = {:.4} m.",
        if k < 1.0 {
            format!(
                " (at most sole width/2 − zmp_margin_m = {offset_max:.3} m inwards) and the \
                 period shrinks to {:.2} s",
                froude_period * k
            )
        } else {
            String::new()
        },
        check.sway_m
    )));
    result.o = o_dynamic;
    result.o_dynamic = Some(o_dynamic);
    result.offset = offset;
    result.period_fraction = k;
    result.roll = Some(check);
    result
}

/// The size ratios: r = l / l_ref and t = √r.
struct Scales {
    r: f64,
    t: f64,
}

/// What `[controller]` takes from the other rules.
struct ControllerRules {
    max_step: f64,
    s_max_dynamic: f64,
    /// The torso gain and the torso's commanded speed limit, when that limit lowers the gain.
    torso_gain: Option<(f64, f64)>,
    roll_limited: bool,
}

/// `[controller]`: JVRC-1's, with the scaled lengths and speeds.
fn controller(Scales { r, t }: Scales, rules: ControllerRules) -> Vec<Line> {
    let ControllerRules {
        max_step,
        s_max_dynamic,
        torso_gain,
        roll_limited,
    } = rules;
    let mut lines = vec![comment(
        "QP controller and stance state machine (daemon::controller; docs/controller.md). \
         Unknown keys are errors. JVRC-1's values; lengths scale with l/l_ref, speeds with \
         √(l/l_ref).",
    )];
    for (name, _) in reference::CONTROLLER.iter() {
        if let Some(heading) = controller_heading(name) {
            lines.push(comment(heading));
        }
        let scaled = |factor: f64, unit: &str| {
            let base = reference::number(&reference::CONTROLLER, name);
            let rule = if unit == "r" {
                format!("{base} × l/l_ref")
            } else {
                format!("{base} × √(l/l_ref)")
            };
            key(name, round(base * factor, 0.001), rule)
        };
        lines.push(match *name {
            "max_step_m" => key(
                name,
                max_step,
                format!(
                    "max(0.5 m × l/l_ref, dynamic s_max {s_max_dynamic:.3} + 0.02 m, \
                     stair_s_max): longer steps are refused"
                ),
            ),
            "lift_height_m"
            | "approach_height_m"
            | "max_step_up_m"
            | "max_step_down_m"
            | "standing_crouch_max_m" => scaled(r, "r"),
            "com_speed" | "swing_speed" | "lower_speed" => scaled(t, "t"),
            "torso_gain" => match torso_gain {
                Some((gain, speed)) => key(
                    name,
                    gain,
                    format!(
                        "the torso's commanded speed {speed:.3} rad/s at a \
                         {TORSO_SATURATION_RAD} rad error (JVRC-1's 10 is faster)"
                    ),
                ),
                None => kept(&reference::CONTROLLER, name, ""),
            },
            "carry_released_hands" if roll_limited => Line::Key {
                key: name,
                value: Value::Switch(reference::armar4::CARRY_RELEASED_HANDS),
                rule: "roll-limited: ARMAR-4's; a released arm carried out to the side tipped its \
                       static walks with a hand"
                    .to_owned(),
            },
            _ => kept(&reference::CONTROLLER, name, ""),
        });
        if *name == "max_base_speed" && roll_limited {
            for (bound, _) in &reference::armar4::ROLL_LIMITED_BOUNDS {
                lines.push(kept(
                    &reference::armar4::ROLL_LIMITED_BOUNDS,
                    bound,
                    "roll-limited: ARMAR-4's (docs/controller.md, \"Pelvis tilt rate\")",
                ));
            }
        }
    }
    lines
}

/// The group comments of `[controller]`, as configs/jvrc1.toml has them.
fn controller_heading(key: &str) -> Option<&'static str> {
    Some(match key {
        "com_weight" => "QP task weights (dimensionless) and the λ‖ν‖² regulariser",
        "com_gain" => "task gains (1/s): desired velocity = feed-forward + gain · error",
        "joint_limit_margin_rad" => {
            "limits: joints stay this far inside their limits, at this fraction of their URDF speed"
        }
        "support_margin_m" => "the CoM ground projection stays this far inside the support polygon",
        "com_speed" => {
            "trajectories: CoM shift and swing speeds, lift / approach heights, final descent"
        }
        "com_tolerance_m" => "tolerances: contacts (feet), swing apex (via), hand contacts",
        "release_force_fraction" => {
            "FT contact detection: fractions of the robot's weight, and how long a touchdown must hold [s]"
        }
        "phase_timeout_s" => {
            "a phase may overrun its planned duration by this much before it is a fault"
        }
        "command_lead_max_rad" => {
            "the joint command is integrated from the previous command and may lead the measured \
             angle by at most this much (rad)"
        }
        "tipping_detection_rad" => {
            "fault (and hold) when the IMU and leg odometry disagree on the base orientation by \
             more than this (rad)"
        }
        "max_step_up_m" => {
            "... or landing higher or lower than this above or below the other foot in the static \
             gait (docs/scenes.md, \"Step heights\")"
        }
        "max_slope_rad" => "... or with a sole standing on a slope steeper than this (rad)",
        "hold_railings" => {
            "... or with a hand holding a railing, unless this is on (docs/scenes.md, \"Hands on \
             railings\")"
        }
        "standing_crouch_max_m" => {
            "with a foot in the air (static gait), take the step back when landing it would need \
             the standing leg to lower the body deeper than this (m)"
        }
        "catch_tilt_rad" => {
            "with a foot in the air (static gait), put it down at once and end the walk in the \
             tipping fault when the IMU and leg odometry disagree by more than this (rad)"
        }
        "carry_released_hands" => {
            "a hand that lets go of the railing is carried along with the pelvis until its next grasp"
        }
        _ => return None,
    })
}

/// `[runtime]`: JVRC-1's, with the robot's own service prefix.
fn runtime(name: &str) -> Section {
    let line = |key: &'static str, value: Value, rule: &str| Line::Key {
        key,
        value,
        rule: rule.to_owned(),
    };
    Section {
        table: "runtime",
        lines: vec![
            comment(
                "walkd and its adapters (shm-types::RuntimeConfig; docs/ipc.md). Unknown keys are \
                 errors.",
            ),
            line(
                "service_prefix",
                Value::Text(format!("walk/{name}")),
                "iceoryx2 services: <prefix>/sensors, commands, status, stances, control",
            ),
            line(
                "rate_hz",
                Value::Number(500.0),
                "control rate of walkd = sample rate of the adapter",
            ),
            line(
                "watchdog_periods",
                Value::Integer(10),
                "no fresh sample (walkd) / command (adapter) for this many periods → hold",
            ),
            line(
                "lockstep_timeout_ms",
                Value::Integer(500),
                "the same in lockstep mode, in wall time",
            ),
            line(
                "status_rate_hz",
                Value::Number(20.0),
                "rate of the status service",
            ),
            comment(
                "Submissions are bounded inside walkd, before they are parsed (docs/safety.md).",
            ),
            line(
                "max_submission_bytes",
                Value::Integer(16_777_216),
                "16 MiB of JSON",
            ),
            line("max_stances", Value::Integer(10_000), ""),
            comment(
                "Real-time options of walkd's control thread; each degrades to a warning when not \
                 permitted.",
            ),
            Line::Commented {
                key: "fifo_priority",
                value: Value::Integer(80),
                rule: "SCHED_FIFO priority 1..=99".to_owned(),
            },
            Line::Commented {
                key: "cpu",
                value: Value::Integer(1),
                rule: "pin the control thread to this CPU".to_owned(),
            },
            line(
                "lock_memory",
                Value::Switch(true),
                "mlockall(MCL_CURRENT | MCL_FUTURE)",
            ),
            line(
                "spin_us",
                Value::Integer(100),
                "with fifo_priority: busy-poll ±100 µs around each expected sample (docs/ipc.md \
                 \"Latency\")",
            ),
        ],
    }
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use kinematics::ConfigFile;

    use super::*;
    use crate::init_robot::measure::tests::hand_tuned;

    fn config(name: &str) -> ConfigFile {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../configs")
            .join(format!("{name}.toml"));
        ConfigFile::load(&path).expect("config")
    }

    /// `table.key` of a config file as a number (`None` when absent or not a number).
    fn configured(file: &ConfigFile, table: &str, key: &str) -> Option<f64> {
        let mut parts = table.split('.');
        let mut value = file.section(parts.next()?)?;
        for part in parts {
            value = value.get(part)?;
        }
        let value = value.get(key)?;
        value
            .as_float()
            .or_else(|| value.as_integer().map(|i| i as f64))
    }

    fn numbers(derived: &DerivedSections) -> Vec<(&'static str, &'static str, f64)> {
        derived
            .sections
            .iter()
            .flat_map(|s| {
                s.lines.iter().filter_map(|line| match line {
                    Line::Key { key, .. } => {
                        derived.number(s.table, key).map(|x| (s.table, *key, x))
                    }
                    _ => None,
                })
            })
            .collect()
    }

    /// Uniformly scaled JVRC-1: lengths × `f`, mass × f³.
    fn scaled_jvrc1(f: f64) -> RobotDimensions {
        let mut d = reference::jvrc1();
        d.mass_kg *= f.powi(3);
        for x in [
            &mut d.com_height_m,
            &mut d.leg_length_m,
            &mut d.pelvis_height_m,
            &mut d.hip_width_m,
            &mut d.stance_width_m,
            &mut d.sole_length_m,
            &mut d.sole_width_m,
        ] {
            *x *= f;
        }
        d
    }

    #[test]
    fn jvrc1_reproduces_its_hand_tuned_config() {
        let derived = derive(&reference::jvrc1());
        let file = config("jvrc1");
        let mut compared = 0;
        for (table, key, value) in numbers(&derived) {
            if let Some(tuned) = configured(&file, table, key) {
                assert!(
                    (value - tuned).abs() <= 1e-9 + 0.005 * tuned.abs(),
                    "[{table}] {key}: derived {value}, configs/jvrc1.toml {tuned}"
                );
                compared += 1;
            }
        }
        assert!(compared >= 70, "only {compared} keys compared");
        let s = derived.summary;
        assert_eq!((s.single_support_s, s.double_support_s), (0.55, 0.25));
        assert_eq!(
            (s.s_max, s.scf, s.s_max_dynamic, s.scf_dynamic),
            (0.24, 0.16, 0.48, 0.46)
        );
        assert_eq!(
            (s.o, s.zmp_inward_offset_m, s.max_step_m),
            ((0.15, 0.24), 0.0, 0.68)
        );
        assert!(!s.roll.unwrap().limited);
    }

    #[test]
    fn every_key_of_jvrc1_is_written_with_its_value() {
        let derived = derive(&reference::jvrc1());
        let file = config("jvrc1");
        for table in [
            "postprocess",
            "postprocess.dynamic",
            "controller",
            "gait",
            "gait.dynamic",
            "gait.dynamic.stabilizer",
            "runtime",
        ] {
            let mut parts = table.split('.');
            let mut section = file.section(parts.next().unwrap()).unwrap();
            for part in parts {
                section = section.get(part).unwrap();
            }
            let written: Vec<&Line> = derived
                .sections
                .iter()
                .filter(|s| s.table == table)
                .flat_map(|s| &s.lines)
                .collect();
            for (key, value) in section.as_table().unwrap() {
                if value.is_table() {
                    continue;
                }
                let line = written.iter().find_map(|line| match line {
                    Line::Key { key: k, value, .. } if k == key => Some(value),
                    _ => None,
                });
                let Some(derived) = line else {
                    panic!("[{table}] {key} is not written");
                };
                let same = match (derived, value) {
                    (Value::Number(x) | Value::Exponent(x), v) => v
                        .as_float()
                        .or(v.as_integer().map(|i| i as f64))
                        .is_some_and(|v| (v - x).abs() <= 0.005 * v.abs()),
                    (Value::Integer(i), v) => v.as_integer() == Some(*i),
                    (Value::Switch(b), v) => v.as_bool() == Some(*b),
                    (Value::Text(t), v) => v.as_str() == Some(t.as_str()),
                };
                assert!(
                    same,
                    "[{table}] {key}: derived {derived:?}, configs/jvrc1.toml {value}"
                );
            }
        }
    }

    #[test]
    fn armar4_hand_tuned_sway_ratio() {
        // configs/armar4.toml's tuned gait on its measured dimensions: a / c.
        let d = hand_tuned("armar4");
        let file = config("armar4");
        let get = |table, key| configured(&file, table, key).expect(key);
        let period =
            get("gait.dynamic", "single_support_s") + get("gait.dynamic", "double_support_s");
        let b =
            get("postprocess.dynamic", "o_min") / 2.0 - get("gait.dynamic", "zmp_inward_offset_m");
        let a = sway(b, period, d.com_height_m);
        let c = ankle_reach(d.leg_length_m, d.ankle_roll_range_rad.unwrap(), 0.02);
        assert!(
            (a - 0.0108).abs() < 2e-4 && (c - 0.0335).abs() < 2e-4,
            "a {a}, c {c}"
        );
        assert!((a / c - ROLL_SWAY_RATIO).abs() < 0.005, "a/c = {}", a / c);
    }

    #[test]
    fn armar4_hand_tuned_swing_share() {
        // configs/armar4.toml's dynamic step on its measured dimensions: s_max / (ω l T_ss).
        let d = hand_tuned("armar4");
        let file = config("armar4");
        let get = |table, key| configured(&file, table, key).expect(key);
        let omega = get("controller", "velocity_limit_scale") * d.leg_velocity_min_rad_s.unwrap();
        let share = get("postprocess.dynamic", "s_max")
            / (omega * d.leg_length_m * get("gait.dynamic", "single_support_s"));
        assert!((share - SWING_SWEEP_SHARE).abs() < 0.005, "share {share}");
        // The torso: 0.5 × 0.4 rad/s at 0.2 rad is the hand-tuned gain.
        let torso = get("controller", "velocity_limit_scale") * d.torso_velocity_min_rad_s.unwrap()
            / TORSO_SATURATION_RAD;
        assert_eq!(torso, get("controller", "torso_gain"));
    }

    #[test]
    fn armar4_reference_values_are_its_config() {
        use reference::armar4;
        let file = config("armar4");
        let get = |table, key| configured(&file, table, key).expect(key);
        assert_eq!(
            get("gait.dynamic", "single_support_s"),
            armar4::SINGLE_SUPPORT_S
        );
        assert_eq!(get("postprocess.dynamic", "s_max"), armar4::S_MAX_DYNAMIC);
        assert_eq!(get("controller", "torso_gain"), armar4::TORSO_GAIN);
        assert_eq!(
            get("gait.dynamic.stabilizer", "foot_damping_gain"),
            armar4::FOOT_DAMPING_GAIN
        );
        for (key, _) in armar4::ROLL_LIMITED_BOUNDS {
            assert_eq!(
                get("controller", key),
                reference::number(&armar4::ROLL_LIMITED_BOUNDS, key),
                "{key}"
            );
        }
        let controller = daemon::controller::ControllerConfig::from_config(&file).unwrap();
        assert_eq!(
            controller.carry_released_hands,
            armar4::CARRY_RELEASED_HANDS
        );
        assert!((hand_tuned("armar4").mass_kg - armar4::MASS_KG).abs() < 0.005);
    }

    #[test]
    fn armar4_is_roll_limited_with_an_inward_zmp_and_a_shorter_step() {
        let d = hand_tuned("armar4");
        let derived = derive(&d);
        let s = derived.summary;
        let roll = s.roll.expect("ARMAR-4 has ankle rolls");
        assert!(roll.limited && roll.froude_sway_m > ROLL_SWAY_RATIO * roll.reach_m);
        assert!(
            roll.sway_m <= ROLL_SWAY_RATIO * roll.reach_m * 1.001,
            "{roll:?}"
        );
        // Non-zero offset, near the hand-tuned 0.05 m; a period near the hand-tuned 0.55 s.
        assert!(
            s.zmp_inward_offset_m > 0.03 && s.zmp_inward_offset_m <= 0.052,
            "{s:?}"
        );
        let period = s.single_support_s + s.double_support_s;
        assert!(
            s.period_fraction < 1.0 && (period - 0.55).abs() < 0.05,
            "{s:?}"
        );
        // A shorter dynamic step than JVRC-1's and than its own Froude scaling gives.
        let froude = 0.48 * s.scale;
        assert!(
            s.s_max_dynamic < 0.48 && s.s_max_dynamic < froude * 0.8,
            "{s:?}"
        );
        assert!(
            (s.s_max_dynamic - 0.2).abs() < 0.03,
            "hand-tuned 0.2 m: {s:?}"
        );
        // Feet at the standing width (0.176 m), as configured: 0.17–0.18 m.
        assert_eq!(s.o_dynamic, (0.17, 0.18));
        assert_eq!(derived.number("postprocess.dynamic", "alpha_x"), Some(0.01));
        assert!(!derived.notes.is_empty());
        // ARMAR-4's own bounds, damping and torso gain.
        let file = config("armar4");
        for (table, key) in [
            ("controller", "max_base_tilt_speed"),
            ("controller", "max_anchor_correction_speed"),
            ("controller", "max_anchor_correction_angular_speed"),
            ("controller", "torso_gain"),
            ("gait.dynamic.stabilizer", "foot_damping_gain"),
        ] {
            assert_eq!(
                derived.number(table, key),
                configured(&file, table, key),
                "[{table}] {key}"
            );
        }
        assert!(
            derived
                .sections
                .iter()
                .flat_map(|s| &s.lines)
                .any(|line| matches!(
                    line,
                    Line::Key {
                        key: "carry_released_hands",
                        value: Value::Switch(false),
                        ..
                    }
                ))
        );
    }

    #[test]
    fn slow_legs_shorten_the_dynamic_step() {
        // JVRC-1 with ARMAR-4's 1.71 rad/s legs: 0.70 × 0.855 rad/s × 0.823 m × 0.55 s.
        let mut d = reference::jvrc1();
        d.leg_velocity_min_rad_s = Some(1.7104);
        let derived = derive(&d);
        let want = round(
            SWING_SWEEP_SHARE * 0.5 * 1.7104 * d.leg_length_m * 0.55,
            0.001,
        );
        assert_eq!(derived.summary.s_max_dynamic, want);
        assert!(want < 0.3, "{want}");
        // Without a known limit, JVRC-1's step.
        d.leg_velocity_min_rad_s = None;
        assert_eq!(derive(&d).summary.s_max_dynamic, 0.48);
    }

    #[test]
    fn a_slow_torso_lowers_the_torso_gain() {
        let mut d = reference::jvrc1();
        d.torso_velocity_min_rad_s = Some(1.0);
        assert_eq!(derive(&d).number("controller", "torso_gain"), Some(2.5));
        for fast in [None, Some(50_000.0)] {
            d.torso_velocity_min_rad_s = fast;
            assert_eq!(derive(&d).number("controller", "torso_gain"), Some(10.0));
        }
    }

    #[test]
    fn scaling_is_monotonic() {
        let sizes = [0.5, 0.7, 1.0, 1.4, 2.0];
        let derived: Vec<DerivedSections> =
            sizes.iter().map(|&f| derive(&scaled_jvrc1(f))).collect();
        let increasing = [
            ("gait.dynamic", "single_support_s"),
            ("gait.dynamic", "double_support_s"),
            ("postprocess", "s_max"),
            ("postprocess", "h_max"),
            ("postprocess.dynamic", "s_max"),
            ("postprocess.dynamic", "h_max"),
            ("controller", "max_step_m"),
            ("controller", "lift_height_m"),
            ("controller", "com_speed"),
            ("controller", "swing_speed"),
        ];
        let values = |table: &str, key: &str| -> Vec<f64> {
            derived
                .iter()
                .map(|d| d.number(table, key).unwrap())
                .collect()
        };
        for (table, key) in increasing {
            let values = values(table, key);
            assert!(
                values.windows(2).all(|w| w[0] < w[1]),
                "[{table}] {key}: {values:?}"
            );
        }
        let decreasing = [
            ("gait.dynamic.stabilizer", "foot_damping_gain"),
            ("gait.dynamic.stabilizer", "force_difference_gain"),
        ];
        for (table, key) in decreasing {
            let values = values(table, key);
            assert!(
                values.windows(2).all(|w| w[0] > w[1]),
                "[{table}] {key}: {values:?}"
            );
        }
        // Times with the square root of the size, lengths with the size.
        let single: Vec<f64> = derived.iter().map(|d| d.summary.single_support_s).collect();
        assert!((single[4] / single[0] - 2.0).abs() < 0.05, "{single:?}");
        let step: Vec<f64> = derived.iter().map(|d| d.summary.s_max_dynamic).collect();
        assert!((step[4] / step[0] - 4.0).abs() < 0.05, "{step:?}");
        // A uniformly scaled robot maps the (pelvis-scaled) human stride alike: scf unchanged.
        for d in &derived {
            assert_eq!((d.summary.scf, d.summary.scf_dynamic), (0.16, 0.46));
        }
    }

    #[test]
    fn the_human_stride_maps_onto_the_same_share_of_s_max() {
        // The generator scales the human walk (2 × 0.65 m strides) by P / 0.95 m; scf then
        // shrinks it: JVRC-1's configs map it onto 0.75 s_max (static), 1.06 s_max (dynamic).
        let share = |d: &RobotDimensions, scf: f64, s_max: f64| {
            2.0 * 0.65 * d.pelvis_height_m / 0.95 * scf / s_max
        };
        let reference = reference::jvrc1();
        let want = (share(&reference, 0.16, 0.24), share(&reference, 0.46, 0.48));
        assert!((want.0 - 0.75).abs() < 0.01, "{want:?}");
        let mut icub_like = scaled_jvrc1(0.57);
        icub_like.pelvis_height_m = 0.589; // iCub's root link stands 12 cm above its hips
        for d in [hand_tuned("armar4"), icub_like] {
            let s = derive(&d).summary;
            let got = (
                share(&d, s.scf, s.s_max),
                share(&d, s.scf_dynamic, s.s_max_dynamic),
            );
            assert!(
                (got.0 / want.0 - 1.0).abs() < 0.05,
                "{}: {got:?} vs {want:?}",
                d.name
            );
            assert!(
                (got.1 / want.1 - 1.0).abs() < 0.05,
                "{}: {got:?} vs {want:?}",
                d.name
            );
        }
    }

    #[test]
    fn the_period_is_not_shortened_below_its_floor() {
        let mut d = reference::jvrc1();
        d.ankle_roll_range_rad = Some(0.03);
        d.sole_width_m = 0.05;
        let derived = derive(&d);
        let s = derived.summary;
        assert_eq!(s.period_fraction, MIN_PERIOD_FRACTION);
        assert_eq!(s.single_support_s, round(0.55 * MIN_PERIOD_FRACTION, 0.01));
        assert!(
            derived.notes.iter().any(|n| n.contains("even at 60 %")),
            "{:?}",
            derived.notes
        );
    }

    #[test]
    fn without_an_ankle_roll_range_nothing_is_limited() {
        let mut d = reference::jvrc1();
        d.ankle_roll_range_rad = None;
        let s = derive(&d).summary;
        assert_eq!(
            (s.roll, s.zmp_inward_offset_m, s.period_fraction),
            (None, 0.0, 1.0)
        );
    }
}
