//! How hard a walk worked the simulated motors, as both matrix commands report it: per joint
//! group, the peak sustained torque (|τ| low-passed over 20 ms) and the peak speed as fractions of the URDF's effort and velocity limits, and the
//! joint that stayed longest at its torque limit. MuJoCo applies the effort limits (the motors
//! saturate), so a walk that needs more torque than a motor has shows here, and one that leans
//! on a saturated motor for longer than [`AT_LIMIT_WARNING_S`] is flagged in the run's row.

use std::fmt::Write;

use kinematics::robot::Robot;
use serde::{Serialize, Serializer};
use shm_types::ActuatorLoad;

/// A joint at its torque limit for longer than this is flagged (s). Impacts saturate a motor for
/// a few milliseconds; a tenth of a second is a motor that cannot carry what the walk asks.
pub const AT_LIMIT_WARNING_S: f64 = 0.1;

/// A walk's [`ActuatorLoad`] with the robot's names.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ActuatorReport {
    /// Per joint group with joints (`legs`, `arms`, `torso`, `head`): peak sustained
    /// |τ| / effort limit.
    #[serde(serialize_with = "as_map")]
    pub peak_torque_fraction: Vec<(&'static str, f64)>,
    /// Per joint group with joints: peak |q̇| / velocity limit.
    #[serde(serialize_with = "as_map")]
    pub peak_speed_fraction: Vec<(&'static str, f64)>,
    /// The longest stretch one joint spent at its torque limit (s).
    pub longest_at_torque_limit_s: f64,
    /// That joint, if one reached its limit.
    pub longest_at_torque_limit_joint: Option<String>,
}

impl ActuatorReport {
    /// `load` measured on `robot`.
    pub fn new(load: &ActuatorLoad, robot: &Robot) -> Self {
        let named = robot.joint_groups.named();
        let by_group = |values: &[f64; 4]| {
            named
                .iter()
                .zip(values)
                .filter(|((_, joints), _)| !joints.is_empty())
                .map(|((group, _), &value)| (*group, value))
                .collect()
        };
        Self {
            peak_torque_fraction: by_group(&load.peak_torque_fraction),
            peak_speed_fraction: by_group(&load.peak_speed_fraction),
            longest_at_torque_limit_s: load.longest_at_torque_limit_s,
            longest_at_torque_limit_joint: robot
                .model
                .joint_names()
                .get(load.longest_at_torque_limit_joint as usize)
                .cloned(),
        }
    }

    /// Whether a joint stayed at its torque limit longer than [`AT_LIMIT_WARNING_S`].
    pub fn saturated(&self) -> bool {
        self.longest_at_torque_limit_s > AT_LIMIT_WARNING_S
    }

    /// `torque legs 0.62 arms 0.10 …`, and the saturated joint when there is one.
    pub fn describe(&self) -> String {
        let mut out = String::from("torque");
        for (group, fraction) in &self.peak_torque_fraction {
            let _ = write!(out, " {group} {fraction:.2}");
        }
        if self.saturated() {
            let joint = self.longest_at_torque_limit_joint.as_deref().unwrap_or("?");
            let _ = write!(
                out,
                " SATURATED: {joint} at its torque limit for {:.2} s",
                self.longest_at_torque_limit_s
            );
        }
        out
    }

    /// The larger of each group's peaks in `self` and `other` (a matrix's worst walk per group),
    /// and the longer saturation.
    pub fn worst(mut self, other: &Self) -> Self {
        for (mine, theirs) in [
            (&mut self.peak_torque_fraction, &other.peak_torque_fraction),
            (&mut self.peak_speed_fraction, &other.peak_speed_fraction),
        ] {
            for ((_, a), (_, b)) in mine.iter_mut().zip(theirs) {
                *a = a.max(*b);
            }
        }
        if other.longest_at_torque_limit_s > self.longest_at_torque_limit_s {
            self.longest_at_torque_limit_s = other.longest_at_torque_limit_s;
            self.longest_at_torque_limit_joint = other.longest_at_torque_limit_joint.clone();
        }
        self
    }
}

/// Group → fraction as a JSON object, in the groups' order.
fn as_map<S: Serializer>(groups: &[(&'static str, f64)], serializer: S) -> Result<S::Ok, S::Error> {
    serializer.collect_map(groups.iter().map(|(group, fraction)| (*group, *fraction)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(legs: f64, longest_s: f64) -> ActuatorReport {
        ActuatorReport {
            peak_torque_fraction: vec![("legs", legs), ("arms", 0.1)],
            peak_speed_fraction: vec![("legs", 0.3), ("arms", 0.2)],
            longest_at_torque_limit_s: longest_s,
            longest_at_torque_limit_joint: (longest_s > 0.0).then(|| "R_KNEE".to_owned()),
        }
    }

    #[test]
    fn a_long_saturation_is_flagged_with_its_joint() {
        assert_eq!(report(0.62, 0.0).describe(), "torque legs 0.62 arms 0.10");
        assert!(!report(1.0, 0.05).saturated());
        let long = report(1.0, 0.25);
        assert!(long.saturated());
        assert_eq!(
            long.describe(),
            "torque legs 1.00 arms 0.10 SATURATED: R_KNEE at its torque limit for 0.25 s"
        );
    }

    #[test]
    fn the_worst_of_two_walks_takes_each_peak() {
        let worst = report(0.5, 0.0).worst(&report(0.7, 0.02));
        assert_eq!(
            worst.peak_torque_fraction,
            vec![("legs", 0.7), ("arms", 0.1)]
        );
        assert_eq!(
            worst.longest_at_torque_limit_joint.as_deref(),
            Some("R_KNEE")
        );
    }

    #[test]
    fn groups_and_the_joint_come_from_the_robot() {
        let robot = Robot::vendored("jvrc1");
        let mut load = ActuatorLoad::ZERO;
        load.peak_torque_fraction = [0.5, 0.2, 0.1, 0.05];
        load.longest_at_torque_limit_joint = 3;
        load.longest_at_torque_limit_s = 0.01;
        let report = ActuatorReport::new(&load, &robot);
        assert_eq!(
            report.peak_torque_fraction,
            vec![("legs", 0.5), ("arms", 0.2), ("torso", 0.1), ("head", 0.05)]
        );
        assert_eq!(
            report.longest_at_torque_limit_joint.as_deref(),
            Some(robot.model.joint_names()[3].as_str())
        );
        let none = ActuatorReport::new(&ActuatorLoad::ZERO, &robot);
        assert_eq!(none.longest_at_torque_limit_joint, None);
    }
}
