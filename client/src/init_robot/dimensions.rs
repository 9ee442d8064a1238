//! The few numbers of a robot the derivation rules need ([`RobotDimensions`]), as measured from
//! a model or written by hand from published figures for a robot without a public model
//! (`walkctl init-robot --dimensions FILE`). The file is a small TOML table, one key a line;
//! unknown keys, missing required keys and numbers that are not finite and positive are refused
//! with the file and the key named.
//!
//! ```toml
//! name = "hrp4"
//! mass_kg = 39.0                 # total mass
//! com_height_m = 0.78            # standing CoM above the soles
//! leg_length_m = 0.63            # standing hip(-pitch axis) height above the soles
//! pelvis_height_m = 0.70         # standing base-link height above the soles
//! hip_width_m = 0.17             # lateral distance between the hip joints
//! stance_width_m = 0.17          # lateral distance between the standing sole centres
//! sole_length_m = 0.224
//! sole_width_m = 0.13
//! ankle_roll_range_rad = 0.5     # optional: ankle roll's smaller side from standing
//! ankle_pitch_room_rad = 0.8     # optional: ankle pitch's room towards further bending
//! leg_effort_min_nm = 40.0       # optional: smallest leg joint effort limit
//! leg_velocity_min_rad_s = 5.0   # optional: smallest leg joint velocity limit
//! torso_velocity_min_rad_s = 2.0 # optional: smallest torso joint velocity limit
//! ```

use std::path::Path;

use anyhow::Context;
use serde::{Deserialize, Serialize};

/// A robot's size as the derivation rules see it (metres, kilograms, radians).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RobotDimensions {
    /// The robot's name (config `name`, service prefix `walk/<name>`).
    pub name: String,
    /// Total mass m (kg).
    pub mass_kg: f64,
    /// Standing CoM height above the soles z_c (m): the pendulum length.
    pub com_height_m: f64,
    /// Leg length l (m): standing height of the hip(-pitch) axis above the soles.
    pub leg_length_m: f64,
    /// Standing height of the base link above the soles (m): the stance generator scales the
    /// human walk by it.
    pub pelvis_height_m: f64,
    /// Lateral distance between the two hip joints (m).
    pub hip_width_m: f64,
    /// Lateral distance between the two sole centres when standing (m).
    pub stance_width_m: f64,
    /// Sole length (m).
    pub sole_length_m: f64,
    /// Sole width (m).
    pub sole_width_m: f64,
    /// The ankle roll's range from its standing angle, on its smaller side (rad); absent: no
    /// ankle roll joint, or not known (then it limits nothing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ankle_roll_range_rad: Option<f64>,
    /// The ankle pitch's range from its standing angle towards further bending, where a foot
    /// behind the hip turns it (rad); absent: not known (then it limits nothing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ankle_pitch_room_rad: Option<f64>,
    /// Smallest effort limit of the leg joints (N·m); reported, no rule uses it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub leg_effort_min_nm: Option<f64>,
    /// Smallest velocity limit of the leg joints (rad/s): it bounds how fast a swing leg sweeps
    /// its foot forward, so the dynamic step; absent: not known (then it limits nothing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub leg_velocity_min_rad_s: Option<f64>,
    /// Smallest velocity limit of the torso joints (rad/s): it bounds the torso task's gain;
    /// absent: no torso joint, or not known (then it limits nothing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torso_velocity_min_rad_s: Option<f64>,
}

impl RobotDimensions {
    /// Every number with its key, for checks and printing.
    pub fn numbers(&self) -> Vec<(&'static str, Option<f64>)> {
        vec![
            ("mass_kg", Some(self.mass_kg)),
            ("com_height_m", Some(self.com_height_m)),
            ("leg_length_m", Some(self.leg_length_m)),
            ("pelvis_height_m", Some(self.pelvis_height_m)),
            ("hip_width_m", Some(self.hip_width_m)),
            ("stance_width_m", Some(self.stance_width_m)),
            ("sole_length_m", Some(self.sole_length_m)),
            ("sole_width_m", Some(self.sole_width_m)),
            ("ankle_roll_range_rad", self.ankle_roll_range_rad),
            ("ankle_pitch_room_rad", self.ankle_pitch_room_rad),
            ("leg_effort_min_nm", self.leg_effort_min_nm),
            ("leg_velocity_min_rad_s", self.leg_velocity_min_rad_s),
            ("torso_velocity_min_rad_s", self.torso_velocity_min_rad_s),
        ]
    }

    /// Refuses a number that is not finite and positive, a sole the `[robot]` section would
    /// refuse and a name that cannot be a service name; `origin` names the source in the error.
    pub fn check(&self, origin: &str) -> anyhow::Result<()> {
        Self::check_name(&self.name, origin)?;
        for (key, value) in self.numbers() {
            if let Some(value) = value {
                if !(value.is_finite() && value > 0.0) {
                    anyhow::bail!("{origin}: {key} = {value}: must be a finite number above 0");
                }
            }
        }
        for (key, value) in [
            ("sole_length_m", self.sole_length_m),
            ("sole_width_m", self.sole_width_m),
        ] {
            if !(0.01..=1.0).contains(&value) {
                anyhow::bail!("{origin}: {key} = {value}: a sole is 0.01 to 1 m ([robot] sole)");
            }
        }
        Ok(())
    }

    /// Refuses a robot name that cannot name the services `walk/<name>`.
    pub fn check_name(name: &str, origin: &str) -> anyhow::Result<()> {
        if name.is_empty()
            || !name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
        {
            anyhow::bail!(
                "{origin}: name = {name:?}: use letters, digits, '_' and '-' (it names the config \
                 and the services walk/<name>)"
            );
        }
        Ok(())
    }

    /// Reads and checks a dimensions file.
    pub fn load(path: &Path) -> anyhow::Result<RobotDimensions> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read dimensions file {}", path.display()))?;
        Self::parse(&text, &path.display().to_string())
    }

    /// Parses and checks dimensions from TOML text; `origin` names it in errors.
    pub fn parse(text: &str, origin: &str) -> anyhow::Result<RobotDimensions> {
        let dimensions: RobotDimensions = toml::from_str(text).map_err(|e| {
            anyhow::anyhow!("{origin}: {}", kinematics::config_file::toml_message(&e))
        })?;
        dimensions.check(origin)?;
        Ok(dimensions)
    }

    /// The dimensions as the TOML [`RobotDimensions::parse`] reads, each number rounded to 0.1 mm
    /// (0.1 mrad, 0.01 kg), with a comment per key.
    pub fn to_toml(&self) -> String {
        let mut text = format!("name = \"{}\"\n", self.name);
        for (key, value) in self.numbers() {
            if let Some(value) = value {
                let rounded = super::frames::round(value, 1e-4);
                text.push_str(&format!(
                    "{:<26} # {}\n",
                    format!("{key} = {}", super::render::number(rounded)),
                    describe(key)
                ));
            }
        }
        text
    }
}

/// What each key means, for the written file.
fn describe(key: &str) -> &'static str {
    match key {
        "mass_kg" => "total mass [kg]",
        "com_height_m" => "standing CoM height above the soles [m]",
        "leg_length_m" => "standing hip(-pitch axis) height above the soles [m]",
        "pelvis_height_m" => "standing base-link height above the soles [m]",
        "hip_width_m" => "lateral distance between the hip joints [m]",
        "stance_width_m" => "lateral distance between the standing sole centres [m]",
        "sole_length_m" => "sole length [m]",
        "sole_width_m" => "sole width [m]",
        "ankle_roll_range_rad" => "ankle roll range from standing, smaller side [rad]",
        "ankle_pitch_room_rad" => "ankle pitch range from standing towards further bending [rad]",
        "leg_effort_min_nm" => "smallest leg joint effort limit [N·m]",
        "leg_velocity_min_rad_s" => "smallest leg joint velocity limit [rad/s]",
        "torso_velocity_min_rad_s" => "smallest torso joint velocity limit [rad/s]",
        _ => "",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::init_robot::reference;

    #[test]
    fn round_trip() {
        let d = reference::jvrc1();
        let back = RobotDimensions::parse(&d.to_toml(), "written").unwrap();
        assert_eq!(back, d);
        let mut bare = d.clone();
        bare.ankle_roll_range_rad = None;
        bare.leg_effort_min_nm = None;
        let text = bare.to_toml();
        assert!(!text.contains("ankle_roll_range_rad"), "{text}");
        assert_eq!(RobotDimensions::parse(&text, "written").unwrap(), bare);
    }

    #[test]
    fn bad_numbers_and_keys_are_refused_by_name() {
        let good = reference::jvrc1().to_toml();
        let cases = [
            (
                "leg_length_m = 0.8227",
                "leg_length_m = nan",
                "leg_length_m",
            ),
            ("mass_kg = 62.4", "mass_kg = -62.4", "mass_kg"),
            (
                "com_height_m = 0.8601",
                "com_height_m = inf",
                "com_height_m",
            ),
            ("sole_width_m = 0.08", "sole_width_m = 2.0", "sole_width_m"),
            ("hip_width_m = 0.192", "hip_width_m = 0.0", "hip_width_m"),
            ("hip_width_m = 0.192", "hip_widht_m = 0.192", "hip_widht_m"),
            (
                "hip_width_m = 0.192",
                "hip_width_m = \"wide\"",
                "hip_width_m",
            ),
            ("name = \"jvrc1\"", "name = \"jvrc 1\"", "name"),
        ];
        for (from, to, key) in cases {
            assert!(good.contains(from), "{from}");
            let text = good.replace(from, to);
            let error = RobotDimensions::parse(&text, "dims.toml")
                .unwrap_err()
                .to_string();
            assert!(
                error.contains("dims.toml") && error.contains(key),
                "{to}: {error}"
            );
        }
        let missing = good.replace("stance_width_m", "# stance_width_m");
        let error = RobotDimensions::parse(&missing, "dims.toml")
            .unwrap_err()
            .to_string();
        assert!(error.contains("stance_width_m"), "{error}");
    }
}
