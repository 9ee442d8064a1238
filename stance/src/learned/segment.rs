//! Segmentation of a demonstration into stances: per-frame contacts of feet and hands from point
//! speed and height with hysteresis (a contact starts below the "on" thresholds and ends above the
//! "off" ones) and debouncing, then one keyframe per run of constant contacts: contact flags,
//! end-effector poses relative to the root, the root translation from the previous stance, and
//! the stance's class in the whole-body pose taxonomy (which feet and hands support it).

use nalgebra::{Rotation3, Vector3};

use super::demo::{Demonstration, EventKind, GaitEvent};

/// Thresholds of contact detection (SI units). The defaults reproduce the annotated events of
/// the gaitalytics trial within a few milliseconds (see `stance/tests/learned_segmentation.rs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentOptions {
    /// A foot touches down when its slowest point is slower than this (m/s) …
    pub foot_speed_on: f64,
    /// … and lifts off when both points are faster than this (m/s).
    pub foot_speed_off: f64,
    /// A foot touches down only this close to the lowest height it has within ±`floor_window`.
    pub foot_height_on: f64,
    /// A foot lifts off when higher than this above that floor.
    pub foot_height_off: f64,
    /// Half-width of the window of the local floor (s) (stepping onto boxes raises it).
    pub floor_window: f64,
    /// A hand grasps when slower than this (m/s) …
    pub hand_speed_on: f64,
    /// … and lets go when faster than this (m/s).
    pub hand_speed_off: f64,
    /// A hand supports only when at least this far below the pelvis (m) (leaning on something) …
    pub hand_depth_on: f64,
    /// … and lets go when less than this far below it.
    pub hand_depth_off: f64,
    /// Contact or swing runs shorter than this (s) are merged into their neighbours.
    pub min_run: f64,
}

impl Default for SegmentOptions {
    fn default() -> Self {
        Self {
            foot_speed_on: 0.5,
            foot_speed_off: 0.8,
            foot_height_on: 0.05,
            foot_height_off: 0.075,
            floor_window: 1.0,
            hand_speed_on: 0.25,
            hand_speed_off: 0.5,
            hand_depth_on: 0.15,
            hand_depth_off: 0.1,
            min_run: 0.04,
        }
    }
}

/// An end-effector pose relative to the root: position in the root's heading frame (x forward,
/// y left, z up from the pelvis), yaw relative to the heading and pitch.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RelativePose {
    pub position: [f64; 3],
    pub yaw: f64,
    pub pitch: f64,
}

impl RelativePose {
    /// The mean of `poses` (`None` if empty).
    pub fn mean(poses: &[RelativePose]) -> Option<RelativePose> {
        if poses.is_empty() {
            return None;
        }
        let n = poses.len() as f64;
        let avg = |f: &dyn Fn(&RelativePose) -> f64| poses.iter().map(f).sum::<f64>() / n;
        Some(RelativePose {
            position: [
                avg(&|p| p.position[0]),
                avg(&|p| p.position[1]),
                avg(&|p| p.position[2]),
            ],
            yaw: avg(&|p| p.yaw),
            pitch: avg(&|p| p.pitch),
        })
    }
}

/// One stance of a demonstration.
#[derive(Clone, Debug, PartialEq)]
pub struct Keyframe {
    /// Contact flags `[left foot, right foot, left hand, right hand]`.
    pub contacts: [bool; 4],
    /// Start time (s) and duration (s) of the stance.
    pub start: f64,
    pub duration: f64,
    /// Pelvis height above the mean height of the contact feet (m).
    pub root_height: f64,
    /// Root displacement from the previous stance in the previous root's heading frame (zero
    /// for the first).
    pub translation: [f64; 3],
    /// Heading change from the previous stance (rad).
    pub turn: f64,
    /// Poses of the four end-effectors relative to the root; `None` for hands not recorded.
    pub effectors: [Option<RelativePose>; 4],
}

impl Keyframe {
    /// The keyframe of the mirror-image motion (left ↔ right).
    pub fn mirrored(&self) -> Keyframe {
        let flip = |pose: Option<RelativePose>| {
            pose.map(|p| RelativePose {
                position: [p.position[0], -p.position[1], p.position[2]],
                yaw: -p.yaw,
                pitch: p.pitch,
            })
        };
        let [lf, rf, lh, rh] = self.effectors;
        let [clf, crf, clh, crh] = self.contacts;
        Keyframe {
            contacts: [crf, clf, crh, clh],
            translation: [
                self.translation[0],
                -self.translation[1],
                self.translation[2],
            ],
            turn: -self.turn,
            effectors: [flip(rf), flip(lf), flip(rh), flip(lh)],
            ..self.clone()
        }
    }
}

/// The segmentation of one demonstration.
#[derive(Clone, Debug)]
pub struct Segmentation {
    /// Contact flags per frame.
    pub contacts: Vec<[bool; 4]>,
    /// One keyframe per run of constant contacts with at least one foot down.
    pub keyframes: Vec<Keyframe>,
}

/// Name of a contact set in the whole-body pose taxonomy (Borràs & Asfour): `2F`, `1F(l)`,
/// `2F+1H(r)`, `1F(l)+2H`, … and `0F` for flight (never a stance).
pub fn taxonomy_label(contacts: [bool; 4]) -> String {
    let part = |count: usize, a: bool, letter: char| match count {
        0 => None,
        1 => Some(format!("1{letter}({})", if a { 'l' } else { 'r' })),
        n => Some(format!("{n}{letter}")),
    };
    let feet = usize::from(contacts[0]) + usize::from(contacts[1]);
    let hands = usize::from(contacts[2]) + usize::from(contacts[3]);
    let mut label = part(feet, contacts[0], 'F').unwrap_or_else(|| "0F".into());
    if let Some(h) = part(hands, contacts[2], 'H') {
        label.push('+');
        label.push_str(&h);
    }
    label
}

/// Segments a demonstration.
pub fn segment(demo: &Demonstration, options: &SegmentOptions) -> Segmentation {
    let n = demo.len();
    let mut contacts = vec![[false; 4]; n];
    for foot in 0..2 {
        let flags = foot_contacts(demo, foot, options);
        for (c, f) in contacts.iter_mut().zip(flags) {
            c[foot] = f;
        }
    }
    if let Some(hands) = &demo.hands {
        for (hand, points) in hands.iter().enumerate() {
            let flags = hand_contacts(demo, points, options);
            for (c, f) in contacts.iter_mut().zip(flags) {
                c[2 + hand] = f;
            }
        }
    }
    let keyframes = keyframes(demo, &contacts);
    Segmentation {
        contacts,
        keyframes,
    }
}

/// Touch-down (foot strike) and lift-off (foot off) times of the feet, from per-frame contacts.
pub fn foot_events(contacts: &[[bool; 4]], rate: f64) -> Vec<GaitEvent> {
    let mut events = Vec::new();
    for foot in 0..2 {
        for k in 1..contacts.len() {
            let (before, now) = (contacts[k - 1][foot], contacts[k][foot]);
            if before != now {
                events.push(GaitEvent {
                    foot,
                    kind: if now {
                        EventKind::FootStrike
                    } else {
                        EventKind::FootOff
                    },
                    time: k as f64 / rate,
                });
            }
        }
    }
    events
}

/// Speed of a point track (central differences).
fn speeds(track: &[Vector3<f64>], rate: f64) -> Vec<f64> {
    let n = track.len();
    (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
            (track[b] - track[a]).norm() * rate / (b - a).max(1) as f64
        })
        .collect()
}

/// Two-threshold switching: on when `on(k)`, off when `off(k)`, then runs shorter than
/// `min_frames` flipped to their surroundings.
fn hysteresis(
    n: usize,
    on: impl Fn(usize) -> bool,
    off: impl Fn(usize) -> bool,
    min_frames: usize,
) -> Vec<bool> {
    let mut state = false;
    let mut flags: Vec<bool> = (0..n)
        .map(|k| {
            state = if state { !off(k) } else { on(k) };
            state
        })
        .collect();
    debounce(&mut flags, min_frames);
    flags
}

/// Flips interior runs shorter than `min_frames`.
fn debounce(flags: &mut [bool], min_frames: usize) {
    let (mut start, mut previous_start) = (0, 0);
    while start < flags.len() {
        let mut end = start;
        while end < flags.len() && flags[end] == flags[start] {
            end += 1;
        }
        if start > 0 && end < flags.len() && end - start < min_frames {
            let value = !flags[start];
            flags[start..end].iter_mut().for_each(|f| *f = value);
            // The flipped run joined its predecessor: rescan the merged run.
            start = previous_start;
        } else {
            previous_start = start;
            start = end;
        }
    }
}

fn foot_contacts(demo: &Demonstration, foot: usize, options: &SegmentOptions) -> Vec<bool> {
    let track = &demo.feet[foot];
    let heel: Vec<Vector3<f64>> = track.iter().map(|p| p[0]).collect();
    let toe: Vec<Vector3<f64>> = track.iter().map(|p| p[1]).collect();
    let (heel_speed, toe_speed) = (speeds(&heel, demo.rate), speeds(&toe, demo.rate));
    let low: Vec<f64> = track.iter().map(|p| p[0].z.min(p[1].z)).collect();
    let window = (options.floor_window * demo.rate).round() as usize;
    let height: Vec<f64> = (0..low.len())
        .map(|k| {
            let range = k.saturating_sub(window)..(k + window + 1).min(low.len());
            low[k] - low[range].iter().copied().fold(f64::INFINITY, f64::min)
        })
        .collect();
    let slowest = |k: usize| heel_speed[k].min(toe_speed[k]);
    hysteresis(
        low.len(),
        |k| slowest(k) < options.foot_speed_on && height[k] < options.foot_height_on,
        |k| slowest(k) > options.foot_speed_off || height[k] > options.foot_height_off,
        (options.min_run * demo.rate).round() as usize,
    )
}

fn hand_contacts(
    demo: &Demonstration,
    hand: &[Vector3<f64>],
    options: &SegmentOptions,
) -> Vec<bool> {
    let speed = speeds(hand, demo.rate);
    let depth = |k: usize| demo.pelvis[k].z - hand[k].z;
    hysteresis(
        hand.len(),
        |k| speed[k] < options.hand_speed_on && depth(k) > options.hand_depth_on,
        |k| speed[k] > options.hand_speed_off || depth(k) < options.hand_depth_off,
        (options.min_run * demo.rate).round() as usize,
    )
}

/// One keyframe per run of constant contacts with a foot down, posed at the run's middle frame.
fn keyframes(demo: &Demonstration, contacts: &[[bool; 4]]) -> Vec<Keyframe> {
    let mut keyframes: Vec<Keyframe> = Vec::new();
    let mut previous: Option<(Vector3<f64>, f64)> = None;
    let mut start = 0;
    while start < contacts.len() {
        let mut end = start;
        while end < contacts.len() && contacts[end] == contacts[start] {
            end += 1;
        }
        let flags = contacts[start];
        if flags[0] || flags[1] {
            let mid = (start + end) / 2;
            let (pelvis, heading) = (demo.pelvis[mid], demo.heading[mid]);
            let frame = Rotation3::from_axis_angle(&Vector3::z_axis(), -heading);
            let foot_pose = |foot: usize| {
                let [heel, toe] = demo.feet[foot][mid];
                let axis = toe - heel;
                let sole = Vector3::new(
                    0.5 * (heel.x + toe.x),
                    0.5 * (heel.y + toe.y),
                    heel.z.min(toe.z),
                );
                RelativePose {
                    position: (frame * (sole - pelvis)).into(),
                    yaw: wrap(axis.y.atan2(axis.x) - heading),
                    pitch: -axis.z.atan2(axis.xy().norm()),
                }
            };
            let hand_pose = |hand: usize| {
                demo.hands.as_ref().map(|h| RelativePose {
                    position: (frame * (h[hand][mid] - pelvis)).into(),
                    yaw: 0.0,
                    pitch: 0.0,
                })
            };
            let effectors = [
                Some(foot_pose(0)),
                Some(foot_pose(1)),
                hand_pose(0),
                hand_pose(1),
            ];
            let contact_feet: Vec<f64> = (0..2)
                .filter(|&f| flags[f])
                .map(|f| effectors[f].expect("feet always posed").position[2])
                .collect();
            let root_height = -contact_feet.iter().sum::<f64>() / contact_feet.len() as f64;
            let (translation, turn) = match previous {
                Some((p, h)) => {
                    let back = Rotation3::from_axis_angle(&Vector3::z_axis(), -h);
                    ((back * (pelvis - p)).into(), wrap(heading - h))
                }
                None => ([0.0; 3], 0.0),
            };
            keyframes.push(Keyframe {
                contacts: flags,
                start: start as f64 / demo.rate,
                duration: (end - start) as f64 / demo.rate,
                root_height,
                translation,
                turn,
                effectors,
            });
            previous = Some((pelvis, heading));
        }
        start = end;
    }
    keyframes
}

/// An angle wrapped into (−π, π].
pub(crate) fn wrap(angle: f64) -> f64 {
    let wrapped = angle.rem_euclid(std::f64::consts::TAU);
    if wrapped > std::f64::consts::PI {
        wrapped - std::f64::consts::TAU
    } else {
        wrapped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn taxonomy_labels_name_feet_and_hands() {
        assert_eq!(taxonomy_label([true, true, false, false]), "2F");
        assert_eq!(taxonomy_label([false, true, false, false]), "1F(r)");
        assert_eq!(taxonomy_label([true, false, false, true]), "1F(l)+1H(r)");
        assert_eq!(taxonomy_label([true, true, true, true]), "2F+2H");
    }

    #[test]
    fn hysteresis_holds_between_thresholds_and_debounces() {
        let signal = [1.0, 0.4, 0.6, 0.7, 0.9, 0.4, 0.9, 0.9, 0.9];
        let flags = hysteresis(signal.len(), |k| signal[k] < 0.5, |k| signal[k] > 0.8, 1);
        assert_eq!(
            flags,
            [false, true, true, true, false, true, false, false, false]
        );
        let flags = hysteresis(signal.len(), |k| signal[k] < 0.5, |k| signal[k] > 0.8, 2);
        assert_eq!(
            flags,
            [false, true, true, true, true, true, false, false, false]
        );
    }
}
