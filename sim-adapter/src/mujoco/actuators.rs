//! How hard the simulated motors work: each joint's actuator torque against its URDF effort limit
//! (which the model enforces: `mjcf` gives each joint an `actuatorfrcrange`, MuJoCo clamps the
//! servo's torque there) and its speed against its URDF velocity limit. Kept per joint: the peak
//! fractions and the longest stretch spent at the torque limit, so a run report can say whether a
//! walk asked more of a motor than it has.
//!
//! The peak torque is that of |τ| low-passed over [`TORQUE_FILTER_S`]: the stiff servos (kp
//! 1e5 N·m/rad) and contact impacts drive a joint to its limit for single physics steps (on
//! ARMAR-4 the arms at the first step, the ankles when the soles chatter), so the raw peak reads
//! 1.0 on nearly every joint and says nothing about the load a walk puts on a motor. The time at
//! the limit is counted on the raw torque.

use kinematics::robot::Robot;
use shm_types::ActuatorLoad;

/// A joint counts as at its torque limit while its torque is at least this fraction of it
/// (MuJoCo clamps to the limit exactly; the margin absorbs rounding).
const AT_LIMIT_FRACTION: f64 = 0.99;

/// Time constant of the low-pass filter on |τ| whose peak is reported (s).
const TORQUE_FILTER_S: f64 = 0.02;

/// The actuator record of a simulated robot; see the module docs. Allocation-free after
/// construction.
#[derive(Clone, Debug)]
pub(crate) struct ActuatorRecord {
    /// Effort and velocity limit of each joint (N·m or N, rad/s or m/s; infinite or 0: none in
    /// the URDF), model order.
    effort_limits: Vec<f64>,
    velocity_limits: Vec<f64>,
    /// The index in `JointGroups::named` (the load's array index) of each joint's group, if it
    /// has one.
    groups: Vec<Option<usize>>,
    /// How long each joint has been at its torque limit now (s).
    at_limit_s: Vec<f64>,
    /// |τ| / limit low-passed over [`TORQUE_FILTER_S`].
    filtered_torque: Vec<f64>,
    /// What is reported; per joint, the longest stretch at the limit is only kept for the
    /// longest of all.
    load: ActuatorLoad,
}

impl ActuatorRecord {
    /// A record for `robot`'s joints, nothing seen yet.
    pub fn new(robot: &Robot) -> Self {
        let limits = robot.model.joint_limits();
        let named = robot.joint_groups.named();
        let groups = (0..limits.len())
            .map(|j| named.iter().position(|(_, joints)| joints.contains(&j)))
            .collect();
        Self {
            effort_limits: limits.iter().map(|l| l.effort).collect(),
            velocity_limits: limits.iter().map(|l| l.velocity).collect(),
            groups,
            at_limit_s: vec![0.0; limits.len()],
            filtered_torque: vec![0.0; limits.len()],
            load: ActuatorLoad::ZERO,
        }
    }

    /// Takes the joints' actuator torques and speeds (model order) after a physics step of `dt`
    /// seconds.
    pub fn observe(
        &mut self,
        torques: impl Iterator<Item = f64>,
        speeds: impl Iterator<Item = f64>,
        dt: f64,
    ) {
        for (j, (torque, speed)) in torques.zip(speeds).enumerate() {
            let torque_fraction = fraction(torque, self.effort_limits[j]);
            let filtered = &mut self.filtered_torque[j];
            *filtered += (torque_fraction - *filtered) * dt / (TORQUE_FILTER_S + dt);
            if let Some(group) = self.groups[j] {
                let load = &mut self.load;
                load.peak_torque_fraction[group] = load.peak_torque_fraction[group].max(*filtered);
                load.peak_speed_fraction[group] =
                    load.peak_speed_fraction[group].max(fraction(speed, self.velocity_limits[j]));
            }
            if torque_fraction < AT_LIMIT_FRACTION {
                self.at_limit_s[j] = 0.0;
                continue;
            }
            self.at_limit_s[j] += dt;
            if self.at_limit_s[j] > self.load.longest_at_torque_limit_s {
                self.load.longest_at_torque_limit_s = self.at_limit_s[j];
                self.load.longest_at_torque_limit_joint = j as u32;
            }
        }
    }

    /// What the motors have done so far.
    pub fn load(&self) -> &ActuatorLoad {
        &self.load
    }
}

/// `|value| / limit`, 0 without a limit (infinite, or 0 as URDFs write "unknown").
fn fraction(value: f64, limit: f64) -> f64 {
    if limit.is_finite() && limit > 0.0 {
        value.abs() / limit
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three joints in the legs, arms and torso: limits 100, 50 and none.
    fn record() -> ActuatorRecord {
        ActuatorRecord {
            effort_limits: vec![100.0, 50.0, f64::INFINITY],
            velocity_limits: vec![2.0, 4.0, 0.0],
            groups: vec![Some(0), Some(1), Some(2)],
            at_limit_s: vec![0.0; 3],
            filtered_torque: vec![0.0; 3],
            load: ActuatorLoad::ZERO,
        }
    }

    #[test]
    fn peaks_and_the_longest_stretch_at_the_limit_are_kept() {
        let mut record = record();
        for (torques, speeds) in [
            ([10.0, 50.0, 1e6], [1.0, 0.0, 9.0]),
            ([-99.5, 49.9, 0.0], [-3.0, 1.0, 0.0]),
            ([-50.0, 20.0, 0.0], [0.0, 0.0, 0.0]),
            ([30.0, 50.0, 0.0], [0.0, 2.0, 0.0]),
        ] {
            record.observe(torques.into_iter(), speeds.into_iter(), 0.001);
        }
        let load = record.load();
        assert_eq!(load.peak_speed_fraction, [1.5, 0.5, 0.0, 0.0]);
        // Joint 1: 50, 49.9 (at the limit: within 1 %), 20 (off), 50: two steps in a row. Joint
        // 0 was at its limit (0.995) for one step only.
        assert_eq!(load.longest_at_torque_limit_joint, 1);
        assert!((load.longest_at_torque_limit_s - 0.002).abs() < 1e-12);
    }

    #[test]
    fn the_peak_torque_is_the_sustained_one() {
        let mut record = record();
        let dt = 0.001;
        // One step at the limit: a spike, not a load.
        record.observe([100.0, 0.0, 0.0].into_iter(), [0.0; 3].into_iter(), dt);
        let spike = record.load().peak_torque_fraction[0];
        assert!(spike < 0.1, "{spike}");
        // Half the limit for ten time constants: the peak settles there.
        for _ in 0..200 {
            record.observe([-50.0, 0.0, 0.0].into_iter(), [0.0; 3].into_iter(), dt);
        }
        let held = record.load().peak_torque_fraction[0];
        assert!((held - 0.5).abs() < 1e-3, "{held}");
    }

    #[test]
    fn a_robot_below_its_limits_reports_no_joint() {
        let mut record = record();
        record.observe([10.0, 10.0, 10.0].into_iter(), [0.1; 3].into_iter(), 0.001);
        assert_eq!(
            record.load().longest_at_torque_limit_joint,
            ActuatorLoad::NO_JOINT
        );
        assert_eq!(record.load().longest_at_torque_limit_s, 0.0);
    }
}
