//! The CoM stabilizer: DCM feedback to a desired ZMP kept inside the support polygon, realised
//! by a commanded pendulum the QP's CoM task tracks, and the ZMP-offset integrator that learns the
//! CoM model error from the measured ZMP.
//!
//! Joints are position-controlled: the ZMP is not commanded, it follows from how the CoM
//! moves. So the stabilizer commands a CoM that moves like the LIPM driven by the desired ZMP
//! `p_d`, stepped exactly over each tick (for constant `p_d`, with `e = e^{ω dt}`):
//!
//! ```text
//! ξ ← p_d + (ξ − p_d) e          c ← p_d + (c − p_d)/e + (ξ₀ − p_d)(e − 1/e)/2
//! ```
//!
//! `p_d = clamp(p_ref + K (ξ_c − ξ_ref) + K (ξ_m − ξ̃_c))`, `K > 1`, clamped into the support
//! polygon shrunk by a margin: every commanded CoM motion is one the support can produce (the
//! static gait's CoM-in-polygon constraint is not needed). The first term keeps the commanded
//! pendulum `ξ_c` on the reference (its errors decay at `ω (K − 1)`). The second is the DCM
//! feedback: `ξ_m` is the measured DCM and `ξ̃_c` the commanded one through the same velocity
//! filter, so only what the robot does differently from the command counts (a robot tipping over
//! a sole edge, a push), not the filter's lag (compared with `ξ_c` itself, the lag of a DCM moving
//! at 0.5 m/s would read as centimetres of error). Off, the command is blind to the robot.
//!
//! ZMP offset: a CoM that is not where the model puts it (mass distribution, a load) shows as a
//! steady error between the measured ZMP and `p_d`. Integrating it, `δ̇ = (p_m − p_d) / τ`,
//! estimates `δ`, the true CoM minus the model's. The pendulum is the model's CoM, so it is
//! driven by `p_d − δ` (the true ZMP is then `p_d`) and every DCM compared with the reference
//! is the pendulum's plus `δ`. The pendulum absorbs the offset through its own dynamics: shifting
//! the QP's CoM target by `δ` instead would move the ZMP the wrong way first (the LIPM is not
//! minimum phase) and the integrator would run away.

use kinematics::ground::SupportPolygon;
use nalgebra::Vector2;

use super::config::StabilizerConfig;
use super::dcm::PatternSample;
use super::sensing::DcmEstimator;

/// The commanded linear inverted pendulum: its CoM and DCM (ground plane).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pendulum {
    /// CoM (m).
    pub com: Vector2<f64>,
    /// DCM (m).
    pub dcm: Vector2<f64>,
}

impl Pendulum {
    /// A pendulum at rest with its CoM at `com`.
    pub fn at_rest(com: Vector2<f64>) -> Self {
        Self { com, dcm: com }
    }

    /// Steps the pendulum exactly over `dt` with the ZMP held at `zmp`.
    pub fn step(&mut self, zmp: Vector2<f64>, omega: f64, dt: f64) {
        let grow = (omega * dt).exp();
        let dcm = self.dcm - zmp;
        self.com = zmp + (self.com - zmp) / grow + dcm * (grow - 1.0 / grow) / 2.0;
        self.dcm = zmp + dcm * grow;
    }

    /// CoM velocity `ω (ξ − c)`.
    pub fn velocity(&self, omega: f64) -> Vector2<f64> {
        omega * (self.dcm - self.com)
    }
}

/// What the stabilizer asks for this tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ComCommand {
    /// CoM set-point of the QP (model CoM, m) and its feed-forward velocity (m/s).
    pub com: Vector2<f64>,
    pub com_velocity: Vector2<f64>,
    /// The desired ZMP, inside the support (m).
    pub zmp: Vector2<f64>,
}

/// The measurements the stabilizer closes its loops on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Measured {
    /// DCM of the estimated (model) CoM, its velocity filtered with `velocity_filter_s`.
    pub dcm: Vector2<f64>,
    /// ZMP from the ankle wrenches (`None` without enough load).
    pub zmp: Option<Vector2<f64>>,
}

/// The stabilizer's state: the commanded pendulum, its DCM as the sensors would see it, and the
/// ZMP offset.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stabilizer {
    config: StabilizerConfig,
    omega: f64,
    pendulum: Pendulum,
    commanded: DcmEstimator,
    zmp_offset: Vector2<f64>,
}

impl Stabilizer {
    /// A stabilizer at rest at the origin.
    pub fn new(config: StabilizerConfig, omega: f64) -> Self {
        Self {
            config,
            omega,
            pendulum: Pendulum::at_rest(Vector2::zeros()),
            commanded: DcmEstimator::default(),
            zmp_offset: Vector2::zeros(),
        }
    }

    /// Starts a walk: tuning and ω from its plan, the pendulum at rest at the CoM `com`.
    pub fn reset(&mut self, config: StabilizerConfig, omega: f64, com: Vector2<f64>) {
        *self = Self::new(config, omega);
        self.pendulum = Pendulum::at_rest(com);
    }

    /// One tick: the desired ZMP from the reference and the measurement, clamped into `support`,
    /// and the commanded CoM after `dt`.
    pub fn update(
        &mut self,
        reference: &PatternSample,
        measured: &Measured,
        support: &SupportPolygon,
        dt: f64,
    ) -> ComCommand {
        let c = &self.config;
        let commanded =
            self.commanded
                .update(self.pendulum.com, dt, self.omega, c.velocity_filter_s);
        let mut error = self.pendulum.dcm + self.zmp_offset - reference.dcm;
        if c.dcm_feedback {
            error += measured.dcm - commanded;
        }
        let wanted = reference.zmp + c.dcm_gain * error;
        let zmp = Vector2::from(support.nearest_inside([wanted.x, wanted.y], c.zmp_margin_m));
        if let (true, Some(measured_zmp)) = (c.zmp_offset, measured.zmp) {
            self.zmp_offset += (measured_zmp - zmp) * (dt / c.zmp_offset_time_constant_s);
            let norm = self.zmp_offset.norm();
            if norm > c.zmp_offset_max_m {
                self.zmp_offset *= c.zmp_offset_max_m / norm;
            }
        }
        self.pendulum.step(zmp - self.zmp_offset, self.omega, dt);
        ComCommand {
            com: self.pendulum.com,
            com_velocity: self.pendulum.velocity(self.omega),
            zmp,
        }
    }

    /// The commanded pendulum.
    pub fn pendulum(&self) -> &Pendulum {
        &self.pendulum
    }

    /// The estimated CoM model error (true minus model, m).
    pub fn zmp_offset(&self) -> Vector2<f64> {
        self.zmp_offset
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controller::gait::sensing::DcmEstimator;

    const OMEGA: f64 = 3.4;

    fn foot() -> SupportPolygon {
        SupportPolygon::from_points(&[[0.1, 0.04], [-0.1, 0.04], [-0.1, -0.04], [0.1, -0.04]])
    }

    fn still(at: Vector2<f64>) -> PatternSample {
        PatternSample {
            zmp: at,
            zmp_velocity: Vector2::zeros(),
            dcm: at,
            dcm_velocity: Vector2::zeros(),
        }
    }

    #[test]
    fn the_exact_step_solves_the_lipm() {
        let mut pendulum = Pendulum {
            com: Vector2::new(0.02, -0.01),
            dcm: Vector2::new(0.05, 0.01),
        };
        let zmp = Vector2::new(0.01, 0.0);
        let mut fine = pendulum;
        pendulum.step(zmp, OMEGA, 0.1);
        for _ in 0..100_000 {
            // c̈ = ω² (c − p) by semi-implicit Euler.
            let velocity = fine.velocity(OMEGA) + OMEGA * OMEGA * (fine.com - zmp) * 1e-6;
            fine.com += velocity * 1e-6;
            fine.dcm = fine.com + velocity / OMEGA;
        }
        assert!(
            (pendulum.com - fine.com).norm() < 1e-5,
            "{pendulum:?} vs {fine:?}"
        );
        assert!((pendulum.dcm - fine.dcm).norm() < 1e-5);
    }

    #[test]
    fn the_desired_zmp_is_clamped_into_the_support() {
        let config = StabilizerConfig {
            dcm_feedback: true,
            zmp_offset: true,
            ..Default::default()
        };
        let mut stabilizer = Stabilizer::new(config, OMEGA);
        stabilizer.reset(config, OMEGA, Vector2::zeros());
        // A large DCM error to the left would ask for a ZMP far outside the foot.
        let measured = Measured {
            dcm: Vector2::new(0.0, 0.2),
            zmp: None,
        };
        let command = stabilizer.update(&still(Vector2::zeros()), &measured, &foot(), 0.002);
        let edge = 0.04 - config.zmp_margin_m;
        assert!(
            (command.zmp - Vector2::new(0.0, edge)).norm() < 1e-12,
            "{:?}",
            command.zmp
        );
        assert!(
            foot().signed_distance([command.zmp.x, command.zmp.y]) >= config.zmp_margin_m - 1e-12
        );
        // A DCM error inside the margin passes unclamped: p_d = p_ref + K (ξ − ξ_ref).
        let small = Measured {
            dcm: Vector2::new(0.005, 0.0),
            zmp: None,
        };
        let command = stabilizer.update(&still(Vector2::zeros()), &small, &foot(), 0.002);
        assert!((command.zmp.x - config.dcm_gain * 0.005).abs() < 1e-12);
    }

    #[test]
    fn dcm_feedback_moves_the_zmp_towards_what_the_robot_does_differently() {
        let config = StabilizerConfig {
            zmp_offset: false,
            ..Default::default()
        };
        let run = |offset: f64, feedback: bool, ticks: usize| {
            let config = StabilizerConfig {
                dcm_feedback: feedback,
                ..config
            };
            let mut stabilizer = Stabilizer::new(config, OMEGA);
            stabilizer.reset(config, OMEGA, Vector2::zeros());
            let mut sensed = DcmEstimator::default();
            let mut command = None;
            for _ in 0..ticks {
                // The robot follows the command, `offset` further forward (rolling over its toes,
                // say).
                let robot = stabilizer.pendulum().com + Vector2::new(offset, 0.0);
                let measured = Measured {
                    dcm: sensed.update(robot, 0.002, OMEGA, config.velocity_filter_s),
                    zmp: None,
                };
                command =
                    Some(stabilizer.update(&still(Vector2::zeros()), &measured, &foot(), 0.002));
            }
            command.unwrap().zmp
        };
        // Following the command exactly reads as no error.
        assert!(run(0.0, true, 50).norm() < 1e-9);
        // A robot ahead of its command: the ZMP moves forward by K times the error to hold it
        // back, and the command is drawn back with it.
        let ahead = run(0.01, true, 1);
        assert!(
            (ahead.x - config.dcm_gain * 0.01).abs() < 1e-9 && ahead.y == 0.0,
            "{ahead:?}"
        );
        // Without the feedback the command ignores it.
        assert!(run(0.01, false, 50).norm() < 1e-9);
    }

    #[test]
    fn the_zmp_offset_learns_a_com_model_error() {
        let config = StabilizerConfig {
            dcm_feedback: true,
            zmp_offset: true,
            ..Default::default()
        };
        let mut stabilizer = Stabilizer::new(config, OMEGA);
        stabilizer.reset(config, OMEGA, Vector2::zeros());
        let error = Vector2::new(0.01, -0.005);
        // The robot moves exactly as commanded, but its true CoM is `error` further than the
        // model's: its measured ZMP is the pendulum's plus `error`.
        let mut pendulum_zmp = Vector2::zeros();
        for _ in 0..10_000 {
            let measured = Measured {
                dcm: stabilizer.pendulum().dcm,
                zmp: Some(pendulum_zmp + error),
            };
            let command = stabilizer.update(&still(Vector2::zeros()), &measured, &foot(), 0.002);
            pendulum_zmp = command.zmp - stabilizer.zmp_offset();
        }
        assert!(
            (stabilizer.zmp_offset() - error).norm() < 1e-4,
            "{:?}",
            stabilizer.zmp_offset()
        );
        let robot = stabilizer.pendulum();
        assert!(
            (robot.com + error).norm() < 1e-4,
            "the true CoM ends on the reference"
        );
    }
}
