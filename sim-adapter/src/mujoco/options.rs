//! Tunable parameters of the MuJoCo model; the defaults suit the vendored humanoids.

use kinematics::bounds::{Bound, first_outside};

use super::MujocoError;

/// How the physics model is built and stepped.
///
/// Joint servos are position + velocity actuators: `τ = kp·(q_des − q) + kv·(q̇_des − q̇)`, the way
/// a position-controlled robot's joint controller behaves. The velocity term is integrated
/// implicitly (`implicitfast`), the position term explicitly; the joint armature bounds how stiff
/// the servo can be at a given time step (`kp·timestep² / armature` must stay well below 1).
///
/// The default servos are stiff (kp 1e5 N·m/rad, kv 1000 N·m·s/rad): the loaded joints of a
/// stance leg must not yield millimetres under the robot's weight, or the controller's task errors
/// never settle inside its tolerances (with kp 3e4 / kv 300 a JVRC-1 foot lift settled 7.5 mm from
/// its goal). The armature of 0.2 kg·m² keeps them stable at the step: `kp·h²/armature` =
/// 1e5 · 0.25e-6 / 0.2 = 0.125 at 0.5 ms.
///
/// The step is 0.5 ms: at 1 ms (the default until 2026-12-07, `kp·h²/armature` 0.5) the soles'
/// contacts were not converged. JVRC-1's dynamic gait up the 0.15 m stairs (in process, 500 Hz):
/// 28/30 at 1 ms, largest tilt 0.067 rad; 30/30 at 0.5 ms, 0.032 rad; 10/10 at 0.25 ms, 0.032
/// rad; at a 1 kHz control rate 5/10 at 1 ms, 10/10 at 0.5 and 0.25 ms (docs/mujoco.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MujocoOptions {
    /// Physics time step (s); `step(dt)` runs as many of these as fit in `dt`.
    pub timestep: f64,
    /// Servo stiffness kp (N·m/rad for revolute joints, N/m for prismatic ones).
    pub servo_stiffness: f64,
    /// Servo damping kv (N·m·s/rad, N·s/m).
    pub servo_damping: f64,
    /// Rotor inertia added to every joint (kg·m²); keeps stiff servos stable on light links.
    pub armature: f64,
    /// Passive viscous damping of every joint (N·m·s/rad).
    pub joint_damping: f64,
    /// Sliding friction coefficient between the soles and the floor.
    pub friction: f64,
    /// How much stiffer MuJoCo's soft contacts hold tangentially than normally (its
    /// `impratio`, elliptic cones; default 20, MuJoCo's own is 1). At 1 a sole loaded sideways
    /// inside its friction cone creeps, as a rubber sole on a floor does not: each stance of
    /// JVRC-1 walking up the 15° ramp slid 3 mm down it, and at 20 it stays put (the Coulomb
    /// limit `friction` is the same; docs/mujoco.md, "Contacts").
    pub impratio: f64,
    /// Height of the foot collision boxes (m); their bottom face lies on the sole plane.
    pub sole_thickness: f64,
    /// Contact time constant (s) of MuJoCo's soft contacts (`solref`); at least 2 × `timestep`.
    pub contact_time_constant: f64,
    /// The robot has fallen when its base link is below this fraction of its initial height.
    pub fall_height_fraction: f64,
    /// ... or when the base link's z axis tilts more than this from vertical (rad).
    pub fall_tilt: f64,
    /// The FT readings of a `step` are the mean over its physics steps (default) rather than the
    /// last one's. The stiff servos answer each new command with a force transient in the first
    /// physics step after it, so at two steps per control period the last step's reading is
    /// biased (JVRC-1 swaying in double support: 196 / 399 N on the feet in the second step,
    /// 276 / 353 N in the first, their mean the weight); a real sensor's anti-aliasing filter
    /// sees the mean.
    pub average_ft_over_step: bool,
    /// Model error the controller does not know about: every body's mass and inertia are
    /// scaled by this factor (1: the URDF's).
    pub mass_scale: f64,
    /// Model error: the centre of mass of the body holding the configured `base_link` (the
    /// pelvis) is moved by this offset, in that body's frame (m).
    pub pelvis_com_offset: [f64; 3],
    /// Give the model what its pictures need (`mjcf`): visual-only geoms drawing the links
    /// (`kinematics::skeleton`), a floor texture, a sky and an offscreen buffer. They take part in
    /// no collision and no inertia, so the dynamics are bit-identical either way (tested).
    pub visual_geoms: bool,
}

impl Default for MujocoOptions {
    fn default() -> Self {
        Self {
            timestep: 0.0005,
            servo_stiffness: 1.0e5,
            servo_damping: 1000.0,
            armature: 0.2,
            joint_damping: 0.0,
            friction: 1.0,
            impratio: 20.0,
            sole_thickness: 0.02,
            contact_time_constant: 0.005,
            fall_height_fraction: 0.7,
            fall_tilt: 0.6,
            average_ft_over_step: true,
            mass_scale: 1.0,
            pelvis_com_offset: [0.0; 3],
            visual_geoms: true,
        }
    }
}

impl MujocoOptions {
    /// Checks every option against its documented range (docs/mujoco.md, "Options") and the
    /// contact time constant against the time step; the error names the option.
    pub fn check(&self) -> Result<(), MujocoError> {
        if let Some(violation) = first_outside(&self.bounds()) {
            return Err(MujocoError::BadOption {
                name: violation.key,
                value: violation.value,
                requirement: violation.range.requirement(),
            });
        }
        if self.contact_time_constant < 2.0 * self.timestep {
            return Err(MujocoError::BadOption {
                name: "contact_time_constant",
                value: self.contact_time_constant,
                requirement: "must be at least twice the timestep".to_owned(),
            });
        }
        Ok(())
    }

    /// Every numeric option, its value and its range, one line an option.
    pub fn bounds(&self) -> Vec<Bound> {
        let offset = self.pelvis_com_offset;
        vec![
            Bound::new("timestep", self.timestep, 1e-5, 0.01),
            Bound::new("servo_stiffness", self.servo_stiffness, 1.0, 1e7),
            Bound::new("servo_damping", self.servo_damping, 0.0, 1e5),
            Bound::new("armature", self.armature, 0.0, 100.0),
            Bound::new("joint_damping", self.joint_damping, 0.0, 1e4),
            Bound::new("friction", self.friction, 0.0, 10.0),
            Bound::new("impratio", self.impratio, 1.0, 100.0),
            Bound::new("sole_thickness", self.sole_thickness, 1e-3, 0.2),
            Bound::new(
                "contact_time_constant",
                self.contact_time_constant,
                2e-5,
                1.0,
            ),
            Bound::new("fall_height_fraction", self.fall_height_fraction, 0.0, 1.0),
            Bound::new("fall_tilt", self.fall_tilt, 0.01, std::f64::consts::PI),
            Bound::new("mass_scale", self.mass_scale, 0.1, 10.0),
            Bound::new("pelvis_com_offset", offset[0], -0.5, 0.5),
            Bound::new("pelvis_com_offset", offset[1], -0.5, 0.5),
            Bound::new("pelvis_com_offset", offset[2], -0.5, 0.5),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The option that failed and the requirement it broke, or `None` when all pass.
    fn rejection(options: MujocoOptions) -> Option<(&'static str, String)> {
        match options.check() {
            Ok(()) => None,
            Err(MujocoError::BadOption {
                name, requirement, ..
            }) => Some((name, requirement)),
            Err(other) => panic!("unexpected error {other}"),
        }
    }

    #[test]
    fn bad_options_are_rejected_by_name() {
        let defaults = MujocoOptions::default();
        assert_eq!(rejection(defaults), None);
        let zero_damping = MujocoOptions {
            servo_damping: 0.0,
            ..defaults
        };
        assert_eq!(rejection(zero_damping), None);
        for (options, name, requirement) in [
            (
                MujocoOptions {
                    timestep: 0.0,
                    ..defaults
                },
                "timestep",
                "must be in [1e-5, 0.01]",
            ),
            (
                MujocoOptions {
                    friction: f64::NAN,
                    ..defaults
                },
                "friction",
                "must be in [0, 10]",
            ),
            (
                MujocoOptions {
                    impratio: 0.5,
                    ..defaults
                },
                "impratio",
                "must be in [1, 100]",
            ),
            (
                MujocoOptions {
                    mass_scale: 1e9,
                    ..defaults
                },
                "mass_scale",
                "must be in [0.1, 10]",
            ),
            (
                MujocoOptions {
                    pelvis_com_offset: [0.0, f64::INFINITY, 0.0],
                    ..defaults
                },
                "pelvis_com_offset",
                "must be in [-0.5, 0.5]",
            ),
            (
                MujocoOptions {
                    contact_time_constant: defaults.timestep,
                    ..defaults
                },
                "contact_time_constant",
                "must be at least twice the timestep",
            ),
        ] {
            assert_eq!(
                rejection(options),
                Some((name, requirement.to_owned())),
                "{name}"
            );
        }
    }
}
