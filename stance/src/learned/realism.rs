//! Realism of generated human-scale sequences: step length, step width and stance duration,
//! measured the same way on generated token sequences and on segmented demonstrations (e.g. a
//! trial held out of training), summarised as distributions.

use nalgebra::{Rotation3, Vector3};

use super::model::NgramModel;
use super::query::Generated;
use super::segment::Keyframe;

/// A stance in the walking frame: contacts, duration, the two feet positions (x along the
/// path, y lateral).
#[derive(Clone, Copy, Debug)]
struct WalkStance {
    contacts: [bool; 4],
    duration: f64,
    feet: [Vector3<f64>; 2],
}

/// Summary of one sample: count, mean, standard deviation, 10th/50th/90th percentiles.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Distribution {
    pub n: usize,
    pub mean: f64,
    pub sd: f64,
    pub p10: f64,
    pub p50: f64,
    pub p90: f64,
}

impl Distribution {
    /// Summarises `values` (all NaN for an empty sample).
    pub fn of(values: &[f64]) -> Self {
        let n = values.len();
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let mean = sorted.iter().sum::<f64>() / n as f64;
        let sd = (sorted.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
        let q = |p: f64| {
            if n == 0 {
                f64::NAN
            } else {
                sorted[((n - 1) as f64 * p).round() as usize]
            }
        };
        Self {
            n,
            mean,
            sd,
            p10: q(0.1),
            p50: q(0.5),
            p90: q(0.9),
        }
    }
}

impl std::fmt::Display for Distribution {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "n {:3}  mean {:.3}  sd {:.3}  p10 {:.3}  p50 {:.3}  p90 {:.3}",
            self.n, self.mean, self.sd, self.p10, self.p50, self.p90
        )
    }
}

/// Step length (m), step width (m) and stance duration (s) of a walk.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct WalkStatistics {
    /// Along-path distance from the supporting foot to the foot that just touched down.
    pub step_length: Distribution,
    /// Lateral distance between the feet in double support.
    pub step_width: Distribution,
    /// Duration of every stance.
    pub stance_duration: Distribution,
}

fn statistics(stances: &[WalkStance]) -> WalkStatistics {
    let mut lengths = Vec::new();
    let mut widths = Vec::new();
    for (k, s) in stances.iter().enumerate() {
        if s.contacts[0] && s.contacts[1] {
            widths.push((s.feet[0].y - s.feet[1].y).abs());
            if k > 0 {
                let before = stances[k - 1].contacts;
                for foot in 0..2 {
                    if !before[foot] && before[1 - foot] {
                        lengths.push(s.feet[foot].x - s.feet[1 - foot].x);
                    }
                }
            }
        }
    }
    let durations: Vec<f64> = stances.iter().map(|s| s.duration).collect();
    WalkStatistics {
        step_length: Distribution::of(&lengths),
        step_width: Distribution::of(&widths),
        stance_duration: Distribution::of(&durations),
    }
}

/// Statistics of a segmented demonstration: keyframes placed by accumulating their root
/// translations and turns, feet expressed in each stance's heading frame.
pub fn of_keyframes(keyframes: &[Keyframe]) -> WalkStatistics {
    let mut root = Vector3::zeros();
    let mut heading = 0.0;
    let stances: Vec<WalkStance> = keyframes
        .iter()
        .map(|k| {
            root += Rotation3::from_axis_angle(&Vector3::z_axis(), heading)
                * Vector3::from(k.translation);
            heading += k.turn;
            let foot = |f: usize| Vector3::from(k.effectors[f].expect("feet are posed").position);
            WalkStance {
                contacts: k.contacts,
                duration: k.duration,
                feet: [foot(0), foot(1)],
            }
        })
        .collect();
    statistics(&stances)
}

/// Statistics of a generated token sequence (human scale, straight path).
pub fn of_generated(model: &NgramModel, generated: &Generated) -> WalkStatistics {
    let stances: Vec<WalkStance> = generated
        .tokens
        .iter()
        .map(|&id| {
            let token = model.token(id);
            let foot =
                |f: usize| Vector3::from(token.effectors[f].expect("feet are posed").position);
            WalkStance {
                contacts: token.contacts,
                duration: token.duration,
                feet: [foot(0), foot(1)],
            }
        })
        .collect();
    statistics(&stances)
}
