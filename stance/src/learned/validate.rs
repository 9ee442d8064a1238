//! Plausibility checks on a trial in canonical form, run by [`super::demo::load_trial`] right
//! after loading (and unrolling a treadmill belt), so that a trial with wrong axes, wrong units,
//! a wrong `forward`, no data or no walking is refused with the reason instead of training a
//! model that fails much later at query time with an error that says nothing about the trial.
//! See `docs/learning.md` ("Strict demonstrations").

use nalgebra::Vector3;

use super::demo::{Axes, Demonstration, EventKind, GaitEvent};
use super::segment::{SegmentOptions, foot_events, segment};

/// A trial whose pelvis never leaves a ball of this radius (m) around its first position is a
/// frozen recording (one frame repeated, a placeholder export): even a subject standing still
/// sways by centimetres, and motion capture resolves well below a millimetre.
const MIN_PELVIS_MOTION_M: f64 = 1e-3;

/// Human range of the pelvis's median height above the lower foot (m). Adults stand with the
/// pelvis (hip joint centres, or the mean of the pelvis markers) about 0.8–1.0 m above the soles;
/// the range leaves room for children (down to 0.5 m) and tall adults (up to 1.3 m). A wrong `up`
/// gives heights near 0 (a horizontal axis) or negative ones (inverted), wrong units heights a
/// thousand times off.
const PELVIS_HEIGHT_M: [f64; 2] = [0.5, 1.3];

/// Largest fraction of frames in which a heel or toe point may be at or above the pelvis: a foot
/// lifted high onto a box gets there for a moment (1 % of the frames of one climbing sequence of
/// `scripts/fetch-demos.sh`, none in the vendored trials), a wrong `up` in most frames.
const MAX_FEET_ABOVE_PELVIS: f64 = 0.05;

/// Fewest foot strikes the segmentation must detect: two steps are the least that make a stance
/// *sequence* to learn from; a standing or calibration trial has none.
const MIN_FOOT_STRIKES: usize = 2;

/// Least horizontal distance (m) the pelvis must get from its start, half an adult step
/// (0.6–0.7 m): a subject that stays closer steps in place, and no walking direction can be told.
const MIN_PROGRESS_M: f64 = 0.3;

/// Largest angle (degrees) between the declared `forward` and the direction in which the pelvis
/// goes (from its start to the point farthest from it): the capture axis nearest to that
/// direction is within 45°, so the check asks for the nearest axis and refuses any other.
const MAX_PROGRESS_ANGLE_DEG: f64 = 45.0;

/// Least share of the pelvis's horizontal path that (net) goes the way the pelvis faces: walking
/// gives 0.98–1.0, the vendored climbing trial 0.40 (side steps, stepping back down), walking
/// backwards −1, sideways 0. It catches what the progress check cannot: a treadmill trial is
/// unrolled along the declared `forward`, so it always progresses along it, right or wrong.
const MIN_FACING_SHARE: f64 = 0.25;

/// Checks that `demo` (in canonical form, loaded with `axes`) is a plausible human walk; the error
/// is the reason, phrased for the user who wrote the trial's `demo.toml` entry.
pub(super) fn validate(demo: &Demonstration, axes: &Axes) -> Result<(), String> {
    finite(demo)?;
    moving(demo)?;
    pelvis_height(demo, axes)?;
    feet_below_pelvis(demo, axes)?;
    steps(demo, axes)?;
    progress(demo, axes)?;
    facing(demo, axes)
}

/// Every point of frame `k`: pelvis, left heel and toe, right heel and toe, hands.
fn points(demo: &Demonstration, k: usize) -> impl Iterator<Item = (&'static str, Vector3<f64>)> {
    const HANDS: [&str; 2] = ["left hand", "right hand"];
    let [left, right] = [demo.feet[0][k], demo.feet[1][k]];
    let hands = demo
        .hands
        .iter()
        .flat_map(move |h| HANDS.into_iter().zip([h[0][k], h[1][k]]));
    [
        ("pelvis", demo.pelvis[k]),
        ("left heel", left[0]),
        ("left toe", left[1]),
        ("right heel", right[0]),
        ("right toe", right[1]),
    ]
    .into_iter()
    .chain(hands)
}

fn finite(demo: &Demonstration) -> Result<(), String> {
    for k in 0..demo.len() {
        if let Some((name, p)) = points(demo, k).find(|(_, p)| !p.iter().all(|v| v.is_finite())) {
            return Err(format!(
                "the {name} is not finite in frame {k} ({:?}; a NaN or infinite `belt_speed`?)",
                [p.x, p.y, p.z]
            ));
        }
        if !demo.heading[k].is_finite() {
            return Err(format!("the pelvis heading is not finite in frame {k}"));
        }
    }
    Ok(())
}

fn moving(demo: &Demonstration) -> Result<(), String> {
    if (0..demo.len()).all(|k| points(demo, k).all(|(_, p)| p == Vector3::zeros())) {
        return Err(format!(
            "every landmark is zero in all {} frames (an empty or placeholder export)",
            demo.len()
        ));
    }
    let motion = demo
        .pelvis
        .iter()
        .map(|p| (p - demo.pelvis[0]).norm())
        .fold(0.0, f64::max);
    if motion < MIN_PELVIS_MOTION_M {
        return Err(format!(
            "the pelvis does not move: it stays within {:.1} mm of its first position over {} \
             frames (need {:.0} mm; a frozen recording or one frame repeated)",
            motion * 1e3,
            demo.len(),
            MIN_PELVIS_MOTION_M * 1e3
        ));
    }
    Ok(())
}

/// Heights of the heel and toe points of both feet in frame `k`.
fn foot_heights(demo: &Demonstration, k: usize) -> impl Iterator<Item = f64> {
    demo.feet.iter().flat_map(move |foot| foot[k].map(|p| p.z))
}

/// The median over the frames of the pelvis's height above the lowest heel or toe point (m): the
/// walker's size, checked here against the human range and used as the leg length that
/// normalises the realism measures ([`super::realism`]).
pub(crate) fn pelvis_height_above_feet(demo: &Demonstration) -> f64 {
    let mut heights: Vec<f64> = (0..demo.len())
        .map(|k| demo.pelvis[k].z - foot_heights(demo, k).fold(f64::INFINITY, f64::min))
        .collect();
    heights.sort_by(f64::total_cmp);
    heights[heights.len() / 2]
}

fn pelvis_height(demo: &Demonstration, axes: &Axes) -> Result<(), String> {
    let median = pelvis_height_above_feet(demo);
    let [low, high] = PELVIS_HEIGHT_M;
    if !(low..=high).contains(&median) {
        return Err(format!(
            "the pelvis is {median:.3} m above the feet (median over the frames), outside the \
             human range {low}–{high} m: the axes (`up = \"{}\"`) or the units may be wrong",
            axes.up_name()
        ));
    }
    Ok(())
}

fn feet_below_pelvis(demo: &Demonstration, axes: &Axes) -> Result<(), String> {
    let above = (0..demo.len())
        .filter(|&k| foot_heights(demo, k).any(|z| z >= demo.pelvis[k].z))
        .count();
    let share = above as f64 / demo.len() as f64;
    if share > MAX_FEET_ABOVE_PELVIS {
        return Err(format!(
            "a foot is at or above the pelvis in {above} of {} frames ({:.0} %, at most {:.0} % \
             allowed): `up = \"{}\"` is wrong or inverted, or markers are mislabelled",
            demo.len(),
            share * 100.0,
            MAX_FEET_ABOVE_PELVIS * 100.0,
            axes.up_name()
        ));
    }
    Ok(())
}

/// Counts the foot strikes the segmentation (default thresholds) detects, as training segments
/// the trial; foot strikes annotated in the file only explain the refusal.
fn steps(demo: &Demonstration, axes: &Axes) -> Result<(), String> {
    let strikes = |events: &[GaitEvent]| {
        events
            .iter()
            .filter(|e| e.kind == EventKind::FootStrike)
            .count()
    };
    let contacts = segment(demo, &SegmentOptions::default()).contacts;
    let detected = strikes(&foot_events(&contacts, demo.rate));
    if detected >= MIN_FOOT_STRIKES {
        return Ok(());
    }
    let annotated = strikes(&demo.events);
    let why = if annotated >= MIN_FOOT_STRIKES {
        format!(
            "although the file annotates {annotated}: the stance feet do not stand still; on a \
             treadmill the belt is unrolled along the declared forward {}, so check `forward` \
             and `belt_speed`",
            axes.forward_name()
        )
    } else {
        "a standing or calibration trial?".to_owned()
    };
    Err(format!(
        "fewer than {MIN_FOOT_STRIKES} steps: {detected} foot strike(s) detected ({why})"
    ))
}

/// The direction the subject goes is that of the pelvis's farthest horizontal point from its
/// start: the end of a walk, the turning point of a round trip (the climbing sequences of
/// `scripts/fetch-demos.sh` go up onto the boxes and come back down the same side).
fn progress(demo: &Demonstration, axes: &Axes) -> Result<(), String> {
    let start = demo.pelvis[0];
    let travel = demo
        .pelvis
        .iter()
        .map(|p| Vector3::new(p.x - start.x, p.y - start.y, 0.0))
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))
        .expect("a trial has frames");
    let distance = travel.norm();
    if distance < MIN_PROGRESS_M {
        return Err(format!(
            "the pelvis never gets farther than {distance:.2} m from its start (need \
             {MIN_PROGRESS_M} m): the subject steps in place (a treadmill trial needs \
             `belt_speed`)"
        ));
    }
    let angle = travel.y.atan2(travel.x).to_degrees();
    if angle.abs() > MAX_PROGRESS_ANGLE_DEG {
        return Err(format!(
            "the subject walks along capture axis {}, not the declared forward {} (the pelvis \
             gets {distance:.2} m from its start at {angle:.0}° from the declared forward, at \
             most {MAX_PROGRESS_ANGLE_DEG}° allowed)",
            axes.capture_axis_name(&travel),
            axes.forward_name()
        ));
    }
    Ok(())
}

/// The net share of the pelvis's horizontal path along its heading: Σ Δp·ĥ / Σ |Δp| over the
/// frames.
fn facing(demo: &Demonstration, axes: &Axes) -> Result<(), String> {
    let (mut along, mut path) = (0.0, 0.0);
    for (k, pair) in demo.pelvis.windows(2).enumerate() {
        let step = (pair[1] - pair[0]).xy();
        let heading = demo.heading[k];
        along += step.x * heading.cos() + step.y * heading.sin();
        path += step.norm();
    }
    let share = along / path;
    if share < MIN_FACING_SHARE {
        return Err(format!(
            "the subject does not walk the way its pelvis faces: net {along:.2} m of its \
             {path:.2} m horizontal path goes that way (share {share:.2}, need \
             {MIN_FACING_SHARE}): on a treadmill the belt is unrolled along the declared \
             forward {}, so check `forward` and `belt_speed`; otherwise left and right markers \
             may be swapped",
            axes.forward_name()
        ));
    }
    Ok(())
}
