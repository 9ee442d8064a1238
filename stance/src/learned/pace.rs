//! The pace of a retargeted walk: how long each stance lasts and how long its steps are.
//!
//! Without a speed request a stance lasts its token's human duration scaled to the robot by
//! dynamic similarity (equal Froude number: time ∝ √length, so × √(robot / human pelvis height)),
//! and the steps keep the human's proportions. With a request for a walking speed V (m/s, of the
//! walk after post-processing) the model's gait law ([`super::gait_law`]) gives, at the robot's
//! dimensionless speed V / √(g L) (L its standing pelvis height, the leg length the law uses),
//! the single- and double-support times of a person walking that way. The generated walk's
//! supports are retimed so that their medians are those times, each stance kept within the
//! robot's timing limits (walkd's, which would otherwise change it), and the walk is stretched
//! along the path so that its length over its time is V once post-processing has shortened every
//! step by `scf`. Its steps are then as long as the speed needs at that timing (they include the
//! walk's stances that are not steps), not the law's own step length, which is reported beside.

use kinematics::ground::GRAVITY;

use super::error::LearnError;
use super::gait_law::froude_speed;
use super::model::{NgramModel, Token};
use super::query::Generated;
use super::realism::of_generated;
use crate::walk::WalkingSpeed;

/// A walking speed asked of a learned walk, and the post-processing it is planned for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedRequest {
    /// The speed and the robot's timing limits.
    pub speed: WalkingSpeed,
    /// The post-processing's sequence scaling factor, which shortens every step by it.
    pub scf: f64,
}

/// What a speed request asks of the robot, from the model's gait law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotGait {
    /// The robot's dimensionless speed V / √(g L).
    pub froude_speed: f64,
    /// Step length after post-processing (m).
    pub step_length: f64,
    /// Single-support time (s).
    pub single_support: f64,
    /// Double-support time (s).
    pub double_support: f64,
    /// Whether the dimensionless speed lies outside the speeds the law was fitted on.
    pub extrapolated: bool,
}

impl RobotGait {
    /// The gait the model's law gives a robot of leg length `leg_length` (m) at `speed` (m/s).
    pub fn of(model: &NgramModel, leg_length: f64, speed: f64) -> Result<Self, LearnError> {
        if !(speed.is_finite() && speed > 0.0) {
            return Err(LearnError::Query(format!(
                "speed {speed} m/s: a walking speed is a positive number"
            )));
        }
        let law = model.gait_law.as_ref().ok_or_else(|| {
            LearnError::Query(
                "the model has no gait law, so it cannot walk at a requested speed: train it on \
                 walkers at two or more speeds (walkctl learn)"
                    .into(),
            )
        })?;
        let froude_speed = froude_speed(speed, leg_length);
        let step = law.at(froude_speed);
        let time = (leg_length / GRAVITY).sqrt();
        let [low, high] = law.speed_range();
        Ok(Self {
            froude_speed,
            step_length: step.step_length * leg_length,
            single_support: step.single_support * time,
            double_support: step.double_support * time,
            extrapolated: !(low..=high).contains(&froude_speed),
        })
    }
}

impl RobotGait {
    /// One line for reports, e.g. `gait law at v̂ 0.043 (outside its walkers' speeds:
    /// extrapolated): step 0.090 m, single support 0.46 s, double support 0.32 s (…)`.
    pub fn describe(&self) -> String {
        format!(
            "gait law at v̂ {:.3}{}: step {:.3} m, single support {:.2} s, double support {:.2} s \
             (each support then kept within the robot's timed limits)",
            self.froude_speed,
            if self.extrapolated {
                " (outside its walkers' speeds: extrapolated)"
            } else {
                ""
            },
            self.step_length,
            self.single_support,
            self.double_support
        )
    }
}

/// How a token sequence is laid out and timed for the robot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pace {
    /// Factor on the human path's forward lengths (root progress and the effectors' forward
    /// offsets).
    pub stretch: f64,
    /// Factors from a token's human duration to the robot stance's: single, double support.
    time: [f64; 2],
    /// The limits `[min, max]` of a robot stance of each kind (s): single, double support.
    limits: [[f64; 2]; 2],
}

impl Pace {
    /// The human walk at the robot's size: lengths as they are, times × √`scale`.
    pub fn similar(scale: f64) -> Self {
        Self {
            stretch: 1.0,
            time: [scale.sqrt(); 2],
            limits: [[0.0, f64::INFINITY]; 2],
        }
    }

    /// The pace that walks `generated` (laid out at `scale`, post-processed with
    /// `request.scf`) at `request.speed` with `gait`'s single and double supports: the supports
    /// are retimed so that their medians over the walk's complete steps are the gait's (each
    /// stance within the robot's limits for its kind), then the path is stretched
    /// so that the walk's length over its stances' total time (first and last stance left out:
    /// the gait starts and ends with its own standing phases) is the speed.
    pub fn for_speed(
        model: &NgramModel,
        generated: &Generated,
        gait: &RobotGait,
        request: SpeedRequest,
        scale: f64,
    ) -> Result<Self, LearnError> {
        let measured = of_generated(model, std::slice::from_ref(generated));
        let medians = [
            measured.single_support.si.p50,
            measured.double_support.si.p50,
        ];
        let human_length = generated.progress.last().copied().unwrap_or(0.0);
        if medians.iter().any(|m| !(m.is_finite() && *m > 0.0)) || human_length <= 0.0 {
            return Err(LearnError::Query(
                "the generated walk has no complete step to set its pace by: ask for a longer \
                 distance"
                    .into(),
            ));
        }
        let limits = request.speed.support_limits_s;
        let within = |duration: f64, [min, max]: [f64; 2]| duration.clamp(min, max);
        let mut pace = Self {
            stretch: 1.0,
            time: [
                within(gait.single_support, limits[0]) / medians[0],
                within(gait.double_support, limits[1]) / medians[1],
            ],
            limits,
        };
        let tokens = &generated.tokens;
        let moving = tokens.get(1..tokens.len().saturating_sub(1)).unwrap_or(&[]);
        let time: f64 = moving
            .iter()
            .map(|&id| pace.duration(model.token(id)))
            .sum();
        pace.stretch = request.speed.m_s * time / (human_length * scale * request.scf);
        Ok(pace)
    }

    /// The same walking speed with the path stretched by `stretch` instead: every duration
    /// changes by the ratio of the stretches.
    pub fn at_stretch(self, stretch: f64) -> Self {
        let ratio = stretch / self.stretch;
        Self {
            stretch,
            time: self.time.map(|t| t * ratio),
            ..self
        }
    }

    /// The robot stance's duration (s) for `token`.
    pub fn duration(&self, token: &Token) -> f64 {
        let kind = usize::from(token.contacts[0] && token.contacts[1]);
        let [min, max] = self.limits[kind];
        (token.duration * self.time[kind]).clamp(min, max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn token(contacts: [bool; 4], duration: f64) -> Token {
        Token {
            label: "t".into(),
            contacts,
            count: 1,
            duration,
            root_height: 0.9,
            translation: [0.3, 0.0, 0.0],
            effectors: [None; 4],
        }
    }

    #[test]
    fn a_similar_pace_scales_time_by_the_square_root_of_size() {
        let pace = Pace::similar(0.81);
        assert_eq!(pace.stretch, 1.0);
        let single = token([true, false, false, false], 0.4);
        assert!((pace.duration(&single) - 0.36).abs() < 1e-12);
    }
}
