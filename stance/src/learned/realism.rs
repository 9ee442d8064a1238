//! Realism of generated human-scale stance sequences: the gait measures a clinician would take
//! (step length and width along the walking direction, step time, cadence, single and double
//! support), measured the same way on generated token sequences and on a held-out human walker,
//! in SI units and normalised by leg length, and compared in one table ([`Comparison`]).
//!
//! Only complete steps count: a step runs from one foot's strike to the other foot's next
//! strike, both detected inside the recording, with that other foot's foot-off between them.
//! Stances cut by the start or end of a recording never make a step. See `docs/learning.md`
//! ("Realism against the held-out walker") for the definitions.

use kinematics::ground::GRAVITY as G;
use nalgebra::Vector3;

use super::demo::{Demonstration, EventKind};
use super::error::LearnError;
use super::model::NgramModel;
use super::query::{Generated, Query, Search, generate_tokens};
use super::segment::{SegmentOptions, foot_events, segment};
use super::validate::pelvis_height_above_feet;

/// Human-scale distance (m) of each generated sequence the comparison measures.
const GENERATED_DISTANCE_M: f64 = 10.0;

/// Beam width of the most probable generated sequence.
const BEAM_WIDTH: usize = 8;

/// Number of sampled sequences (seeds 0, 1, …) pooled in the comparison.
const SAMPLES: u64 = 10;

/// A foot strike (`strike`) or foot off of `foot` at `time` (s), with the heel position (m) at
/// a strike (steps use its horizontal part; `gait_law` its height, to tell level walking).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct FootEvent {
    pub(crate) foot: usize,
    pub(crate) strike: bool,
    pub(crate) time: f64,
    pub(crate) heel: Vector3<f64>,
}

/// One complete step, from a strike of one foot to the next strike of the other.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Step {
    /// Step length and width (m) along the walking direction; `None` when no stride around the
    /// step gives a direction.
    along: Option<(f64, f64)>,
    /// Strike to the other foot's strike (s).
    time: f64,
    /// The other foot's foot-off to its strike (s).
    single_support: f64,
    /// Strike to the other foot's foot-off (s).
    double_support: f64,
    /// The walker's leg length (m).
    leg_length: f64,
}

/// The complete steps among `events` of a walker with leg length `leg_length`.
///
/// The walking direction of a step is its striking foot's stride (heel at its previous strike to
/// heel at this one), or where that strike is the first, the stride of the foot it steps past
/// (from the strike opening the step to that foot's next strike).
pub(crate) fn steps(events: &[FootEvent], leg_length: f64) -> Vec<Step> {
    let mut strikes: Vec<&FootEvent> = events.iter().filter(|e| e.strike).collect();
    strikes.sort_by(|a, b| a.time.total_cmp(&b.time));
    let mut steps = Vec::new();
    for i in 1..strikes.len() {
        let (from, to) = (strikes[i - 1], strikes[i]);
        if from.foot == to.foot {
            continue;
        }
        let off = events
            .iter()
            .filter(|e| !e.strike && e.foot == to.foot && (from.time..to.time).contains(&e.time))
            .map(|e| e.time)
            .max_by(f64::total_cmp);
        let Some(off) = off else {
            continue;
        };
        let before = (i >= 2 && strikes[i - 2].foot == to.foot)
            .then(|| (to.heel - strikes[i - 2].heel).xy());
        let after = strikes
            .get(i + 1)
            .filter(|e| e.foot == from.foot)
            .map(|e| (e.heel - from.heel).xy());
        let direction = before.or(after).and_then(|d| d.try_normalize(1e-9));
        let d = (to.heel - from.heel).xy();
        steps.push(Step {
            along: direction.map(|u| (d.dot(&u), (u.x * d.y - u.y * d.x).abs())),
            time: to.time - from.time,
            single_support: to.time - off,
            double_support: off - from.time,
            leg_length,
        });
    }
    steps
}

/// Foot strikes and offs of a demonstration as the segmentation (default thresholds, as
/// training uses) detects them, with the heel at each strike.
pub(crate) fn demonstration_events(demo: &Demonstration) -> Vec<FootEvent> {
    let contacts = segment(demo, &SegmentOptions::default()).contacts;
    foot_events(&contacts, demo.rate)
        .into_iter()
        .map(|e| {
            let frame = ((e.time * demo.rate).round() as usize).min(demo.len() - 1);
            FootEvent {
                foot: e.foot,
                strike: e.kind == EventKind::FootStrike,
                time: e.time,
                heel: demo.feet[e.foot][frame][0],
            }
        })
        .collect()
}

/// A generated stance placed in the world: contacts of the feet, duration (s), foot positions.
#[derive(Clone, Copy, Debug, PartialEq)]
struct PlacedStance {
    feet_down: [bool; 2],
    duration: f64,
    feet: [Vector3<f64>; 2],
}

/// Foot strikes (a foot down that was not in the previous stance) and offs of a stance
/// sequence, at the start of the stance where they happen; the foot position at a strike is the
/// one of that stance.
fn stance_events(stances: &[PlacedStance]) -> Vec<FootEvent> {
    let mut events = Vec::new();
    let mut time = 0.0;
    for pair in stances.windows(2) {
        time += pair[0].duration;
        for foot in 0..2 {
            let (before, now) = (pair[0].feet_down[foot], pair[1].feet_down[foot]);
            if before != now {
                events.push(FootEvent {
                    foot,
                    strike: now,
                    time,
                    heel: pair[1].feet[foot],
                });
            }
        }
    }
    events
}

/// The stances of a generated sequence in the world: roots accumulated from the tokens' root
/// translations (the generated path is straight), feet at their prototype positions (sole
/// midpoints) relative to the root.
fn placed(model: &NgramModel, generated: &Generated) -> Vec<PlacedStance> {
    let mut root = Vector3::zeros();
    generated
        .tokens
        .iter()
        .enumerate()
        .map(|(k, &id)| {
            let token = model.token(id);
            if k > 0 {
                root += Vector3::from(token.translation);
            }
            let foot = |f: usize| {
                root + Vector3::from(token.effectors[f].expect("feet are posed").position)
            };
            PlacedStance {
                feet_down: [token.contacts[0], token.contacts[1]],
                duration: token.duration,
                feet: [foot(0), foot(1)],
            }
        })
        .collect()
}

/// Summary of one sample (count, mean, standard deviation, 10th/50th/90th percentiles), so a
/// measure is compared by more than one number.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Distribution {
    /// Sample size.
    pub n: usize,
    /// Mean.
    pub mean: f64,
    /// Standard deviation (population).
    pub sd: f64,
    /// 10th percentile.
    pub p10: f64,
    /// Median: the value the comparison table shows.
    pub p50: f64,
    /// 90th percentile.
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
        // Linear interpolation between the closest ranks: the median of an even sample is the
        // mean of its two middle values, so the median cadence is 60 / the median step time
        // within the interpolation's curvature.
        let q = |p: f64| {
            if n == 0 {
                return f64::NAN;
            }
            let rank = (n - 1) as f64 * p;
            let (low, high) = (rank.floor() as usize, rank.ceil() as usize);
            sorted[low] + (rank - low as f64) * (sorted[high] - sorted[low])
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

/// One gait measure in SI units and normalised by leg length (dimensionless), so walkers of
/// different size compare.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Measure {
    /// In SI units (m, s, steps/min).
    pub si: Distribution,
    /// Dimensionless: lengths / L, times × √(g/L), cadence (steps/s) × √(L/g).
    pub normalised: Distribution,
}

impl Measure {
    fn of(pairs: impl Iterator<Item = (f64, f64)>) -> Self {
        let (si, normalised): (Vec<f64>, Vec<f64>) = pairs.unzip();
        Self {
            si: Distribution::of(&si),
            normalised: Distribution::of(&normalised),
        }
    }
}

/// The gait measures of a walk over its complete steps (definitions in the module docs and
/// `docs/learning.md`); normalised: lengths / L, times × √(g/L), cadence × √(L/g).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct WalkStatistics {
    /// Leg length L (m) the normalisation divides by (the median over the steps).
    pub leg_length: f64,
    /// Heel-to-heel distance along the walking direction (m).
    pub step_length: Measure,
    /// Heel-to-heel distance across the walking direction (m).
    pub step_width: Measure,
    /// Strike to the other foot's strike (s); its count is the number of complete steps.
    pub step_time: Measure,
    /// Steps per minute, 60 / step time.
    pub cadence: Measure,
    /// The other foot's foot-off to its strike (s).
    pub single_support: Measure,
    /// Strike to the other foot's foot-off (s).
    pub double_support: Measure,
}

impl WalkStatistics {
    /// The statistics of `steps` (also the per-walker medians of `gait_law`).
    pub(crate) fn of(steps: &[Step]) -> Self {
        let leg: Vec<f64> = steps.iter().map(|s| s.leg_length).collect();
        let time = |t: f64, s: &Step| (t, t * (G / s.leg_length).sqrt());
        let along = || {
            steps
                .iter()
                .filter_map(|s| s.along.map(|a| (a, s.leg_length)))
        };
        Self {
            leg_length: Distribution::of(&leg).p50,
            step_length: Measure::of(along().map(|((l, _), leg)| (l, l / leg))),
            step_width: Measure::of(along().map(|((_, w), leg)| (w, w / leg))),
            step_time: Measure::of(steps.iter().map(|s| time(s.time, s))),
            cadence: Measure::of(
                steps
                    .iter()
                    .map(|s| (60.0 / s.time, (s.leg_length / G).sqrt() / s.time)),
            ),
            single_support: Measure::of(steps.iter().map(|s| time(s.single_support, s))),
            double_support: Measure::of(steps.iter().map(|s| time(s.double_support, s))),
        }
    }
}

/// Statistics of human walkers (pooled over the trials), each step normalised by its walker's
/// leg length: the pelvis's median height above the feet.
pub fn of_demonstrations(demos: &[Demonstration]) -> WalkStatistics {
    let steps: Vec<Step> = demos
        .iter()
        .flat_map(|d| steps(&demonstration_events(d), pelvis_height_above_feet(d)))
        .collect();
    WalkStatistics::of(&steps)
}

/// Statistics of generated sequences (human scale, pooled over the sequences), normalised by the
/// model's human pelvis height.
pub fn of_generated(model: &NgramModel, sequences: &[Generated]) -> WalkStatistics {
    let steps: Vec<Step> = sequences
        .iter()
        .flat_map(|g| steps(&stance_events(&placed(model, g)), model.human_pelvis_height))
        .collect();
    WalkStatistics::of(&steps)
}

/// Held-out walkers against the model's generated walks: what `walkctl learn --holdout` and
/// `walkctl realism` print (its `Display` is the table).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// Name and statistics of the held-out walkers.
    pub held_out: (String, WalkStatistics),
    /// Name and statistics of each set of generated sequences.
    pub generated: Vec<(String, WalkStatistics)>,
}

/// Compares `held_out` (named `name`) with the most probable 10 m sequence (beam 8) and ten
/// sampled ones (seeds 0–9) of `model`.
pub fn compare(
    model: &NgramModel,
    name: &str,
    held_out: &[Demonstration],
) -> Result<Comparison, LearnError> {
    let query = |search| Query {
        distance: GENERATED_DISTANCE_M,
        hands: [Vec::new(), Vec::new()],
        search,
    };
    let beam = generate_tokens(model, &query(Search::Beam(BEAM_WIDTH)))?;
    let samples = (0..SAMPLES)
        .map(|seed| generate_tokens(model, &query(Search::Sample(seed))))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Comparison {
        held_out: (name.to_owned(), of_demonstrations(held_out)),
        generated: vec![
            (
                format!("beam {BEAM_WIDTH}, {GENERATED_DISTANCE_M} m"),
                of_generated(model, &[beam]),
            ),
            (
                format!("{SAMPLES} samples × {GENERATED_DISTANCE_M} m"),
                of_generated(model, &samples),
            ),
        ],
    })
}

impl std::fmt::Display for Comparison {
    /// Medians over the complete steps; relative error (generated − held-out) / held-out.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        type Get = fn(&WalkStatistics) -> &Measure;
        let rows: [(&str, &str, &str, Get); 6] = [
            ("step length", "m", "/ L", |s| &s.step_length),
            ("step width", "m", "/ L", |s| &s.step_width),
            ("step time", "s", "× √(g/L)", |s| &s.step_time),
            ("cadence", "steps/min", "(steps/s) × √(L/g)", |s| {
                &s.cadence
            }),
            ("single support", "s", "× √(g/L)", |s| &s.single_support),
            ("double support", "s", "× √(g/L)", |s| &s.double_support),
        ];
        let all = std::iter::once(&self.held_out).chain(&self.generated);
        for (name, s) in all {
            writeln!(
                f,
                "{name}: {} complete steps ({} with a walking direction), leg length L {:.3} m",
                s.step_time.si.n, s.step_length.si.n, s.leg_length
            )?;
        }
        write!(f, "| measure (median) | {} |", self.held_out.0)?;
        for (name, _) in &self.generated {
            write!(f, " {name} | error |")?;
        }
        write!(f, "\n| --- | --- |")?;
        for _ in &self.generated {
            write!(f, " --- | --- |")?;
        }
        writeln!(f)?;
        for (measure, unit, normalisation, get) in rows {
            for normalised in [false, true] {
                let label = if normalised {
                    format!("{measure} {normalisation}")
                } else {
                    format!("{measure} [{unit}]")
                };
                let value = |s: &WalkStatistics| {
                    let m = get(s);
                    if normalised {
                        m.normalised.p50
                    } else {
                        m.si.p50
                    }
                };
                let reference = value(&self.held_out.1);
                write!(f, "| {label} | {reference:.3} |")?;
                for (_, s) in &self.generated {
                    let v = value(s);
                    let error = 100.0 * (v - reference) / reference;
                    write!(f, " {v:.3} | {error:+.1} % |")?;
                }
                writeln!(f)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RATE: f64 = 1000.0;
    const STEP_TIME: f64 = 0.55;
    const DOUBLE: f64 = 0.12;
    const STEP_LENGTH: f64 = 0.6;
    const WIDTH: f64 = 0.10;
    const PELVIS: f64 = 0.9;

    /// A straight walk along +x from `from` to `to` seconds of a longer one that started at time
    /// 0: the left foot strikes at 2k·T at x = 2k·ℓ, y = +w/2, the right at (2k+1)·T at
    /// (2k+1)·ℓ, −w/2; each foot stays down until the other's strike + `DOUBLE`, then swings
    /// (0.1 m high, straight) to its next strike. The pelvis yaws ±`turn` rad once per stride.
    fn synthetic_walk(from: f64, to: f64, turn: f64) -> Demonstration {
        let foot = |foot: usize, t: f64| -> [Vector3<f64>; 2] {
            // Strikes of this foot: at (2k + foot)·T.
            let period = 2.0 * STEP_TIME;
            let phase = t - foot as f64 * STEP_TIME;
            let k = (phase / period).floor();
            let since = phase - k * period;
            let y = if foot == 0 { WIDTH / 2.0 } else { -WIDTH / 2.0 };
            let x0 = (2.0 * k + foot as f64) * STEP_LENGTH;
            let lift = STEP_TIME + DOUBLE;
            let (x, z) = if since < lift {
                (x0, 0.0)
            } else {
                let s = (since - lift) / (period - lift);
                (
                    x0 + 2.0 * STEP_LENGTH * s,
                    0.1 * (std::f64::consts::PI * s).sin(),
                )
            };
            let heel = Vector3::new(x, y, z);
            [heel, heel + Vector3::new(0.2, 0.0, 0.0)]
        };
        let frames = ((to - from) * RATE).round() as usize;
        let times: Vec<f64> = (0..frames).map(|k| from + k as f64 / RATE).collect();
        let speed = STEP_LENGTH / STEP_TIME;
        Demonstration {
            name: "synthetic".into(),
            rate: RATE,
            pelvis: times
                .iter()
                .map(|&t| Vector3::new(speed * t, 0.0, PELVIS))
                .collect(),
            heading: times
                .iter()
                .map(|&t| turn * (std::f64::consts::PI * t / STEP_TIME).cos())
                .collect(),
            feet: [
                times.iter().map(|&t| foot(0, t)).collect(),
                times.iter().map(|&t| foot(1, t)).collect(),
            ],
            hands: None,
            events: Vec::new(),
        }
    }

    fn close(a: f64, b: f64, tolerance: f64) -> bool {
        (a - b).abs() <= tolerance
    }

    /// The width along the walking direction is the true one although the pelvis turns ±10°
    /// (the old heading-frame width at a 10° turn: 0.10 cos 10° + 0.6 sin 10° ≈ 0.20 m).
    #[test]
    fn width_and_length_are_along_the_walking_direction_not_the_pelvis_heading() {
        let demo = synthetic_walk(0.05, 6.0, 10f64.to_radians());
        let s = of_demonstrations(&[demo]);
        assert!(s.step_length.si.n >= 6, "{s:#?}");
        for d in [s.step_width.si.p10, s.step_width.si.p90] {
            assert!(close(d, WIDTH, 2e-3), "width {d}");
        }
        for d in [s.step_length.si.p10, s.step_length.si.p90] {
            assert!(close(d, STEP_LENGTH, 5e-3), "length {d}");
        }
        assert!(close(s.leg_length, PELVIS, 1e-9));
        assert!(close(s.step_width.normalised.p50, WIDTH / PELVIS, 3e-3));
    }

    /// A trial starting and ending mid-step: the cut stances make no step, so the mean step time
    /// is the true one, and double and single support are separated.
    #[test]
    fn steps_cut_by_the_recording_do_not_count_and_supports_are_separated() {
        let demo = synthetic_walk(0.3, 3.0, 0.0);
        let s = of_demonstrations(&[demo]);
        // Strikes inside (0.3, 3.0): 0.55, 1.1, 1.65, 2.2, 2.75 → 4 complete steps.
        assert_eq!(s.step_time.si.n, 4, "{s:#?}");
        assert!(close(s.step_time.si.mean, STEP_TIME, 2e-3), "{s:#?}");
        assert!(close(s.double_support.si.mean, DOUBLE, 3e-3), "{s:#?}");
        assert!(
            close(s.single_support.si.mean, STEP_TIME - DOUBLE, 3e-3),
            "{s:#?}"
        );
        assert!(close(s.cadence.si.mean, 60.0 / STEP_TIME, 0.5), "{s:#?}");
        let froude = STEP_TIME * (G / PELVIS).sqrt();
        assert!(close(s.step_time.normalised.mean, froude, 1e-2), "{s:#?}");
    }

    #[test]
    fn a_step_without_the_foot_off_between_its_strikes_is_not_counted() {
        let event = |foot, strike, time: f64| FootEvent {
            foot,
            strike,
            time,
            heel: Vector3::new(time, 0.0, 0.0),
        };
        // Left strike, right strike with no right foot-off between (missed detection), then a
        // complete step: right off, left strike.
        let events = [
            event(0, true, 0.0),
            event(1, true, 0.5),
            event(0, false, 0.6),
            event(0, true, 1.0),
        ];
        let steps = steps(&events, 1.0);
        assert_eq!(steps.len(), 1);
        assert!(close(steps[0].time, 0.5, 1e-12));
        assert!(close(steps[0].double_support, 0.1, 1e-12));
        assert!(close(steps[0].single_support, 0.4, 1e-12));
    }

    /// Generated stances 2F, 1F(l), 2F, 1F(r), …: strikes at the double supports, times from the
    /// stances' durations, lengths and widths from the feet of the striking stances.
    #[test]
    fn generated_stances_give_steps_from_their_durations_and_feet() {
        let mut stances = Vec::new();
        let mut feet = [Vector3::new(0.0, 0.05, 0.0), Vector3::new(0.0, -0.05, 0.0)];
        for k in 0..8 {
            stances.push(PlacedStance {
                feet_down: [true, true],
                duration: 0.1,
                feet,
            });
            let swing = (k + 1) % 2; // right swings first
            let down = [swing == 1, swing == 0];
            stances.push(PlacedStance {
                feet_down: down,
                duration: 0.4,
                feet,
            });
            feet[swing].x = feet[1 - swing].x + 0.6;
        }
        let s = WalkStatistics::of(&steps(&stance_events(&stances), 0.9));
        assert_eq!(s.step_time.si.n, 6, "{s:#?}");
        assert!(close(s.step_time.si.mean, 0.5, 1e-12));
        assert!(close(s.double_support.si.mean, 0.1, 1e-12));
        assert!(close(s.single_support.si.mean, 0.4, 1e-12));
        assert!(close(s.step_width.si.mean, 0.1, 1e-12));
        assert!(close(s.step_length.si.mean, 0.6, 1e-12));
    }
}
