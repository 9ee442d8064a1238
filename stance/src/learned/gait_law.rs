//! The gait law: how humans lengthen and quicken their steps with walking speed, in the
//! dimensionless (Froude) form gait studies use, fitted on the training walkers and stored in the
//! model, so that a walk can be requested at a speed and get the step length and timing humans
//! use at that speed.
//!
//! Each walker is scaled by its own leg length L (the pelvis height above the feet, as in
//! [`realism`](super::realism)): v̂ = v / √(gL), λ = s / L, τ = T·√(g/L), δ = DS / T. The law is
//! λ = a·v̂^b (least squares in log–log), τ = λ / v̂ (since s = v·T) and δ linear in v̂ (its mean
//! with fewer than three walkers). See `docs/learning.md` ("Gait law").

use std::fmt;

use kinematics::ground::GRAVITY as G;
use serde::{Deserialize, Serialize};

use super::demo::Demonstration;
use super::realism::{WalkStatistics, demonstration_events, steps};
use super::validate::pelvis_height_above_feet;

/// Fewest complete steps with a walking direction a trial needs to count as a walker: its
/// medians then rest on more than one or two steps.
const MIN_STEPS: usize = 3;

/// Level ground: every foot strike's heel within this height (m) of the trial's first strike
/// heel. Heel markers at strike vary by 1–3 cm on a level floor; a kerb or stair is ≥ 0.1 m and
/// the climbing boxes 0.5 m, where steps are not level walking.
const LEVEL_TOLERANCE_M: f64 = 0.05;

/// The fastest walker's v̂ must be at least this multiple of the slowest one's for a slope: the
/// walkers' medians carry a few percent of uncertainty, which closer speeds would turn into an
/// arbitrary exponent.
const MIN_SPEED_RATIO: f64 = 1.1;

/// Fewest walkers for a linear δ(v̂); with fewer, δ is their mean (a line through two points
/// would fit their noise exactly).
const MIN_WALKERS_FOR_SUPPORT_SLOPE: usize = 3;

/// The dimensionless (Froude) speed v / √(gL) of a walker with leg length `leg_length` (m)
/// walking at `speed` (m/s): the speed at which walkers of different size walk alike.
pub fn froude_speed(speed: f64, leg_length: f64) -> f64 {
    speed / (G * leg_length).sqrt()
}

/// One training walker's gait (medians over its complete steps, SI units): a point the law is
/// fitted through, kept in the model so the fit can be checked and reported.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WalkerGait {
    /// Trial name.
    pub name: String,
    /// Leg length L (m): the pelvis's median height above the feet.
    pub leg_length: f64,
    /// Walking speed v = s / T (m/s).
    pub speed: f64,
    /// Step length s (m), heel to heel along the walking direction.
    pub step_length: f64,
    /// Step time T (s), strike to the other foot's strike.
    pub step_time: f64,
    /// Single support (s), the other foot's foot-off to its strike.
    pub single_support: f64,
    /// Double support DS (s), strike to the other foot's foot-off.
    pub double_support: f64,
}

/// A walker's gait in Froude units, the quantities the law relates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DimensionlessGait {
    /// v̂ = v / √(gL).
    pub froude_speed: f64,
    /// λ = s / L.
    pub step_length: f64,
    /// τ = T·√(g/L).
    pub step_time: f64,
    /// δ = DS / T, the share of the step in double support.
    pub double_support_share: f64,
}

impl WalkerGait {
    /// Measures a demonstration with the realism step extraction, or says why it is no walker
    /// for the law: fewer than `MIN_STEPS` (3) complete steps, or not on level ground.
    pub fn measure(demo: &Demonstration) -> Result<Self, String> {
        let events = demonstration_events(demo);
        let heights: Vec<f64> = events
            .iter()
            .filter(|e| e.strike)
            .map(|e| e.heel.z)
            .collect();
        let first = heights.first().copied().unwrap_or_default();
        let rise = heights
            .iter()
            .map(|h| (h - first).abs())
            .fold(0.0, f64::max);
        if rise > LEVEL_TOLERANCE_M {
            return Err(format!(
                "not level walking: a strike heel is {rise:.2} m above or below the first one \
                 (at most {LEVEL_TOLERANCE_M} m)"
            ));
        }
        let s = WalkStatistics::of(&steps(&events, pelvis_height_above_feet(demo)));
        if s.step_length.si.n < MIN_STEPS {
            return Err(format!(
                "{} complete steps with a walking direction (need {MIN_STEPS})",
                s.step_length.si.n
            ));
        }
        let (step_length, step_time) = (s.step_length.si.p50, s.step_time.si.p50);
        Ok(Self {
            name: demo.name.clone(),
            leg_length: s.leg_length,
            speed: step_length / step_time,
            step_length,
            step_time,
            single_support: s.single_support.si.p50,
            double_support: s.double_support.si.p50,
        })
    }

    /// The walker in Froude units, by its own leg length.
    pub fn dimensionless(&self) -> DimensionlessGait {
        let l = self.leg_length;
        DimensionlessGait {
            froude_speed: froude_speed(self.speed, l),
            step_length: self.step_length / l,
            step_time: self.step_time * (G / l).sqrt(),
            double_support_share: self.double_support / self.step_time,
        }
    }
}

/// λ = coefficient · v̂^exponent: dimensionless step length over dimensionless speed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PowerLaw {
    /// a.
    pub coefficient: f64,
    /// b: > 0 when steps lengthen with speed.
    pub exponent: f64,
}

/// δ = intercept + slope · v̂: double-support share over dimensionless speed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinearLaw {
    /// δ at v̂ = 0.
    pub intercept: f64,
    /// dδ/dv̂ (0 when fitted on fewer than three walkers).
    pub slope: f64,
}

/// The law at one dimensionless speed: step length and timing, all in Froude units (lengths / L,
/// times × √(g/L)), for the caller to scale to its walker.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepGait {
    /// λ = s / L.
    pub step_length: f64,
    /// τ = T·√(g/L).
    pub step_time: f64,
    /// Single support × √(g/L).
    pub single_support: f64,
    /// Double support × √(g/L).
    pub double_support: f64,
}

/// Dimensionless step length and timing as functions of dimensionless speed, fitted on the
/// training walkers (stored in the model file; `None` there when it could not be fitted).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaitLaw {
    /// λ(v̂).
    pub step_length: PowerLaw,
    /// δ(v̂), clamped to 0–1 when evaluated.
    pub double_support_share: LinearLaw,
    walkers: Vec<WalkerGait>,
}

impl GaitLaw {
    /// Fits the law on `walkers`, or says why not: a slope needs at least two walkers whose v̂
    /// differ by the factor `MIN_SPEED_RATIO` (1.1) or more.
    pub fn fit(walkers: &[WalkerGait]) -> Result<Self, String> {
        let points: Vec<DimensionlessGait> =
            walkers.iter().map(WalkerGait::dimensionless).collect();
        let [slowest, fastest] = range(points.iter().map(|p| p.froude_speed));
        if walkers.len() < 2 || fastest < MIN_SPEED_RATIO * slowest {
            let speeds: Vec<String> = walkers
                .iter()
                .zip(&points)
                .map(|(w, p)| format!("{} {:.3}", w.name, p.froude_speed))
                .collect();
            return Err(format!(
                "{} walker(s) on level ground (v̂: {}): a speed law needs at least two whose v̂ \
                 differ by {:.0} % or more",
                walkers.len(),
                if speeds.is_empty() {
                    "none".into()
                } else {
                    speeds.join(", ")
                },
                100.0 * (MIN_SPEED_RATIO - 1.0)
            ));
        }
        let [ln_a, b] = least_squares(
            points
                .iter()
                .map(|p| (p.froude_speed.ln(), p.step_length.ln())),
        );
        let shares = points
            .iter()
            .map(|p| (p.froude_speed, p.double_support_share));
        let [intercept, slope] = if points.len() >= MIN_WALKERS_FOR_SUPPORT_SLOPE {
            least_squares(shares)
        } else {
            [
                shares.map(|(_, d)| d).sum::<f64>() / points.len() as f64,
                0.0,
            ]
        };
        Ok(Self {
            step_length: PowerLaw {
                coefficient: ln_a.exp(),
                exponent: b,
            },
            double_support_share: LinearLaw { intercept, slope },
            walkers: walkers.to_vec(),
        })
    }

    /// The step length and timing at dimensionless speed `froude_speed` (> 0). Outside
    /// [`speed_range`](Self::speed_range) this extrapolates; the caller reports that.
    pub fn at(&self, froude_speed: f64) -> StepGait {
        let PowerLaw {
            coefficient,
            exponent,
        } = self.step_length;
        let step_length = coefficient * froude_speed.powf(exponent);
        let step_time = step_length / froude_speed;
        let LinearLaw { intercept, slope } = self.double_support_share;
        let share = (intercept + slope * froude_speed).clamp(0.0, 1.0);
        StepGait {
            step_length,
            step_time,
            single_support: (1.0 - share) * step_time,
            double_support: share * step_time,
        }
    }

    /// Slowest and fastest v̂ of the walkers fitted on: where the law interpolates.
    pub fn speed_range(&self) -> [f64; 2] {
        range(self.walkers.iter().map(|w| w.dimensionless().froude_speed))
    }

    /// The walkers the law was fitted on.
    pub fn walkers(&self) -> &[WalkerGait] {
        &self.walkers
    }

    /// Checks a law read from a model file: finite coefficients, a > 0, walkers that could have
    /// been fitted on.
    pub(crate) fn check(&self) -> Result<(), String> {
        let PowerLaw {
            coefficient,
            exponent,
        } = self.step_length;
        let LinearLaw { intercept, slope } = self.double_support_share;
        let finite = [coefficient, exponent, intercept, slope]
            .iter()
            .all(|v| v.is_finite());
        let positive = |w: &WalkerGait| {
            [w.leg_length, w.speed, w.step_length, w.step_time]
                .iter()
                .all(|v| v.is_finite() && *v > 0.0)
        };
        if !(finite && coefficient > 0.0) || self.walkers.len() < 2 {
            return Err(format!(
                "gait law: coefficients {coefficient}, {exponent}, {intercept}, {slope} (need \
                 finite, a > 0) over {} walkers (need 2)",
                self.walkers.len()
            ));
        }
        match self.walkers.iter().find(|w| !positive(w)) {
            Some(w) => Err(format!(
                "gait law: walker `{}` has a non-positive or non-finite L, v, s or T",
                w.name
            )),
            None => Ok(()),
        }
    }
}

impl fmt::Display for GaitLaw {
    /// The fitted law in one line: λ(v̂), τ(v̂), δ(v̂) and the v̂ range of its walkers.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [slowest, fastest] = self.speed_range();
        let (a, b) = (self.step_length.coefficient, self.step_length.exponent);
        let LinearLaw { intercept, slope } = self.double_support_share;
        write!(
            f,
            "gait law over {} walkers, v̂ {slowest:.3}–{fastest:.3}: λ = {a:.3}·v̂^{b:.3}, \
             τ = λ/v̂ = {a:.3}·v̂^{:.3}, δ = {intercept:.3} {} {:.3}·v̂",
            self.walkers.len(),
            b - 1.0,
            if slope < 0.0 { '−' } else { '+' },
            slope.abs()
        )
    }
}

/// The trials of `demos` that are walkers for the law ([`WalkerGait::measure`]), and each other
/// trial's name with the reason it is left out: what training fits and `walkctl learn` reports.
pub fn walkers_of<'a>(
    demos: impl Iterator<Item = &'a Demonstration>,
) -> (Vec<WalkerGait>, Vec<(String, String)>) {
    let mut walkers = Vec::new();
    let mut left_out = Vec::new();
    for demo in demos {
        match WalkerGait::measure(demo) {
            Ok(walker) => walkers.push(walker),
            Err(reason) => left_out.push((demo.name.clone(), reason)),
        }
    }
    (walkers, left_out)
}

/// The walkers as a Markdown table (name, L, v, v̂, λ, τ, δ), as `walkctl learn` prints them.
pub fn walker_table(walkers: &[WalkerGait]) -> String {
    let mut table = String::from(
        "| walker | L [m] | v [m/s] | v̂ | λ = s/L | τ = T·√(g/L) | δ = DS/T |\n\
         | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for w in walkers {
        let d = w.dimensionless();
        table += &format!(
            "| {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} |\n",
            w.name,
            w.leg_length,
            w.speed,
            d.froude_speed,
            d.step_length,
            d.step_time,
            d.double_support_share
        );
    }
    table
}

/// Smallest and largest of `values` (∞, −∞ when empty).
fn range(values: impl Iterator<Item = f64>) -> [f64; 2] {
    values.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], v| {
        [lo.min(v), hi.max(v)]
    })
}

/// Ordinary least squares y = intercept + slope·x over `points` (x not all equal).
fn least_squares(points: impl Iterator<Item = (f64, f64)> + Clone) -> [f64; 2] {
    let n = points.clone().count() as f64;
    let (mean_x, mean_y) = points
        .clone()
        .fold((0.0, 0.0), |(x, y), (px, py)| (x + px / n, y + py / n));
    let (sxy, sxx) = points.fold((0.0, 0.0), |(sxy, sxx), (x, y)| {
        let dx = x - mean_x;
        (sxy + dx * (y - mean_y), sxx + dx * dx)
    });
    let slope = sxy / sxx;
    [mean_y - slope * mean_x, slope]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A walker of leg length `leg` at Froude speed `froude` whose step length follows
    /// λ = 0.9·v̂^0.4 (times `noise`) and whose double-support share is 0.3 − 0.2·v̂.
    fn walker(name: &str, leg: f64, froude: f64, noise: f64) -> WalkerGait {
        let speed = froude * (G * leg).sqrt();
        let step_length = 0.9 * froude.powf(0.4) * noise * leg;
        let step_time = step_length / speed;
        let double_support = (0.3 - 0.2 * froude) * step_time;
        WalkerGait {
            name: name.into(),
            leg_length: leg,
            speed,
            step_length,
            step_time,
            single_support: step_time - double_support,
            double_support,
        }
    }

    #[test]
    fn a_known_power_law_is_recovered() {
        let walkers = [
            walker("a", 0.8, 0.15, 1.0),
            walker("b", 0.95, 0.3, 1.0),
            walker("c", 0.9, 0.45, 1.0),
        ];
        let law = GaitLaw::fit(&walkers).unwrap();
        assert!((law.step_length.coefficient - 0.9).abs() < 1e-9, "{law}");
        assert!((law.step_length.exponent - 0.4).abs() < 1e-9, "{law}");
        let LinearLaw { intercept, slope } = law.double_support_share;
        assert!((intercept - 0.3).abs() < 1e-9 && (slope + 0.2).abs() < 1e-9);
        let [lo, hi] = law.speed_range();
        assert!((lo - 0.15).abs() < 1e-9 && (hi - 0.45).abs() < 1e-9);
        // At a walker's speed the law gives that walker back, τ = λ / v̂ included.
        let at = law.at(0.3);
        let expected = walkers[1].dimensionless();
        assert!((at.step_length - expected.step_length).abs() < 1e-9);
        assert!((at.step_time - expected.step_time).abs() < 1e-9);
        assert!((at.double_support / at.step_time - (0.3 - 0.2 * 0.3)).abs() < 1e-9);
        assert!((at.single_support + at.double_support - at.step_time).abs() < 1e-12);
    }

    #[test]
    fn noisy_walkers_give_the_exponent_approximately() {
        let walkers = [
            walker("a", 0.8, 0.15, 1.03),
            walker("b", 0.95, 0.25, 0.97),
            walker("c", 0.9, 0.35, 1.02),
            walker("d", 0.85, 0.45, 0.99),
        ];
        let law = GaitLaw::fit(&walkers).unwrap();
        assert!((law.step_length.exponent - 0.4).abs() < 0.1, "{law}");
    }

    #[test]
    fn two_walkers_give_the_mean_double_support_share() {
        let law = GaitLaw::fit(&[walker("a", 0.8, 0.2, 1.0), walker("b", 0.9, 0.4, 1.0)]).unwrap();
        let LinearLaw { intercept, slope } = law.double_support_share;
        assert_eq!(slope, 0.0);
        assert!((intercept - (0.3 - 0.2 * 0.3)).abs() < 1e-9);
        assert!((law.step_length.exponent - 0.4).abs() < 1e-9);
    }

    #[test]
    fn one_speed_gives_no_law() {
        let reason = GaitLaw::fit(&[walker("a", 0.8, 0.3, 1.0)]).unwrap_err();
        assert!(reason.contains("1 walker(s)"), "{reason}");
        let same = [walker("a", 0.8, 0.3, 1.0), walker("b", 0.95, 0.31, 1.1)];
        let reason = GaitLaw::fit(&same).unwrap_err();
        assert!(reason.contains("a 0.300, b 0.310"), "{reason}");
        assert!(GaitLaw::fit(&[]).is_err());
    }

    #[test]
    fn double_support_share_is_clamped_when_extrapolating() {
        let law = GaitLaw::fit(&[
            walker("a", 0.8, 0.15, 1.0),
            walker("b", 0.95, 0.3, 1.0),
            walker("c", 0.9, 0.45, 1.0),
        ])
        .unwrap();
        let fast = law.at(3.0);
        assert_eq!(fast.double_support, 0.0);
        assert_eq!(fast.single_support, fast.step_time);
    }
}
