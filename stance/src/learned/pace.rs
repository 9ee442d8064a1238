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

/// Over how many of its median steps a paced walk gets up to its stride, and comes to rest: a
/// person starting from standing takes a shorter first step and lengthens the next.
pub(crate) const RAMP_STEPS: f64 = 2.0;

/// How a token sequence is laid out and timed for the robot.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pace {
    /// Factor on the human path's forward lengths (root progress and the effectors' forward
    /// offsets).
    pub stretch: f64,
    /// Human path metres at the start and at the end over which the stretch grows from half and
    /// shrinks to half ([`PathStretch`]): [`RAMP_STEPS`] median steps of a paced walk, none
    /// otherwise.
    pub ramp: f64,
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
            ramp: 0.0,
            time: [scale.sqrt(); 2],
            limits: [[0.0, f64::INFINITY]; 2],
        }
    }

    /// The pace that walks `generated` (laid out at `scale`, post-processed with
    /// `request.scf`) at `request.speed` with `gait`'s single and double supports: the supports
    /// are retimed so that their medians over the walk's complete steps are the gait's (each
    /// stance within the robot's limits for its kind), then the path is stretched, with a ramp
    /// of [`RAMP_STEPS`] median steps at each end, so that the walk's length over its stances'
    /// total time (first and last stance left out: the gait starts and ends with its own
    /// standing phases) is the speed.
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
        let step = measured.step_length.si.p50;
        let known = medians
            .iter()
            .chain([&step])
            .all(|m| m.is_finite() && *m > 0.0);
        if !known || human_length <= 0.0 {
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
            ramp: RAMP_STEPS * step,
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
        let length = PathStretch::new(1.0, pace.ramp, human_length).covered();
        pace.stretch = request.speed.m_s * time / (length * scale * request.scf);
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

/// The map from the human path's along-path coordinate to the robot's (before the size scale):
/// lengths × `factor`, but over the first and the last `ramp` metres the factor grows linearly
/// from half of it and shrinks back to half, so that the walk starts and stops with shorter
/// steps, as people do (before the start and after the end: half of it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PathStretch {
    factor: f64,
    ramp: f64,
    end: f64,
}

impl PathStretch {
    /// The identity.
    pub const NONE: Self = Self {
        factor: 1.0,
        ramp: 0.0,
        end: 0.0,
    };

    /// `factor` over a path of `end` human metres, with ramps of `ramp` metres (at most half
    /// the path each).
    pub fn new(factor: f64, ramp: f64, end: f64) -> Self {
        Self {
            factor,
            ramp: ramp.clamp(0.0, end.max(0.0) / 2.0),
            end,
        }
    }

    /// The robot's along-path coordinate of human coordinate `x`: the factor integrated from 0.
    pub fn map(&self, x: f64) -> f64 {
        let (k, r, d) = (self.factor, self.ramp, self.end);
        if r <= 0.0 {
            return k * x;
        }
        // Through a ramp of length r the factor goes from k/2 to k: its integral over the first
        // u metres is k (u/2 + u²/(4r)), 3kr/4 over the whole ramp.
        let ramp = |u: f64| k * (u / 2.0 + u * u / (4.0 * r));
        let covered = k * (d - r / 2.0);
        if x <= 0.0 {
            k * x / 2.0
        } else if x <= r {
            ramp(x)
        } else if x <= d - r {
            ramp(r) + k * (x - r)
        } else if x <= d {
            covered - ramp(d - x)
        } else {
            covered + k * (x - d) / 2.0
        }
    }

    /// The robot length of the human path from 0 to its end.
    pub fn covered(&self) -> f64 {
        self.map(self.end) - self.map(0.0)
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
    fn a_path_stretch_starts_and_ends_at_half_its_factor_and_is_continuous() {
        let path = PathStretch::new(2.0, 1.0, 10.0);
        // Half the factor at the ends, the whole factor between the ramps.
        let slope = |x: f64| (path.map(x + 1e-6) - path.map(x - 1e-6)) / 2e-6;
        for (x, expected) in [(0.0, 1.0), (0.5, 1.5), (5.0, 2.0), (9.5, 1.5), (10.0, 1.0)] {
            assert!(
                (slope(x) - expected).abs() < 1e-5,
                "slope at {x}: {}",
                slope(x)
            );
        }
        assert!((path.map(1.0) - 1.5).abs() < 1e-12);
        assert!((path.covered() - 2.0 * 9.5).abs() < 1e-12);
        // A first step of one ramp is three quarters of a middle step of the same human length.
        let first = path.map(1.0) - path.map(0.0);
        let middle = path.map(5.0) - path.map(4.0);
        assert!((first / middle - 0.75).abs() < 1e-12);
        // Without a ramp, a plain factor; a ramp longer than half the path is cut to it.
        assert_eq!(PathStretch::new(2.0, 0.0, 10.0).map(3.0), 6.0);
        assert!((PathStretch::new(1.0, 8.0, 4.0).covered() - 3.0).abs() < 1e-12);
        assert_eq!(PathStretch::NONE.map(3.0), 3.0);
    }

    #[test]
    fn a_similar_pace_scales_time_by_the_square_root_of_size() {
        let pace = Pace::similar(0.81);
        assert_eq!(pace.stretch, 1.0);
        let single = token([true, false, false, false], 0.4);
        assert!((pace.duration(&single) - 0.36).abs() < 1e-12);
    }
}
