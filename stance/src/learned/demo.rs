//! Demonstrations in one canonical form: per-frame pelvis, heading, foot (heel, toe) and hand
//! points in metres, x forward, y left, z up. A demonstration folder holds a `demo.toml` manifest
//! listing its trials with their format and capture axes:
//!
//! ```toml
//! [[trial]]
//! file = "treadmill_events.c3d"
//! format = "c3d"          # c3d | gaitkit-json | npy-mocap53
//! forward = "-y"          # capture axis the subject walks along (checked)
//! up = "+z"
//! belt_speed = 1.105      # optional, treadmill trials: unrolled so stance feet stand still
//! rate = 120.0            # required for npy (the file carries none)
//! ```

use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use serde::Deserialize;

use super::c3d::C3dFile;
use super::error::LearnError;
use super::npy;
use super::validate::validate;

/// Annotated gait event kinds (C3D EVENT group).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EventKind {
    /// First contact of a foot.
    FootStrike,
    /// Last contact of a foot.
    FootOff,
}

/// An annotated event: which foot (0 left, 1 right), what, when (seconds from the first frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaitEvent {
    pub foot: usize,
    pub kind: EventKind,
    pub time: f64,
}

/// One trial in canonical form (x forward, y left, z up, metres).
#[derive(Clone, Debug)]
pub struct Demonstration {
    /// Name for reports (file stem).
    pub name: String,
    /// Frame rate (Hz).
    pub rate: f64,
    /// Pelvis centre per frame.
    pub pelvis: Vec<Vector3<f64>>,
    /// Pelvis heading (yaw of the forward direction) per frame.
    pub heading: Vec<f64>,
    /// `feet[foot][frame] = [heel, toe]`, foot 0 left, 1 right.
    pub feet: [Vec<[Vector3<f64>; 2]>; 2],
    /// `hands[hand][frame]` when the recording has hands.
    pub hands: Option<[Vec<Vector3<f64>>; 2]>,
    /// Annotated gait events, if the file has them.
    pub events: Vec<GaitEvent>,
}

impl Demonstration {
    /// Number of frames.
    pub fn len(&self) -> usize {
        self.pelvis.len()
    }

    /// True when the trial has no frames (refused by the loaders).
    pub fn is_empty(&self) -> bool {
        self.pelvis.is_empty()
    }
}

/// One `[[trial]]` of a `demo.toml` manifest.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrialEntry {
    /// File name relative to the manifest's folder.
    pub file: PathBuf,
    /// `c3d`, `gaitkit-json` or `npy-mocap53`.
    pub format: String,
    /// Capture axis of walking: `+x`, `-x`, `+y`, `-y`, `+z`, `-z`. Everything learned is
    /// relative to the pelvis heading, so this only orients the trial; it is checked against the
    /// direction the subject actually walks, and a treadmill belt is unrolled along it.
    pub forward: String,
    /// Capture axis pointing up.
    pub up: String,
    /// Treadmill belt speed (m/s) to unroll, if a treadmill trial.
    #[serde(default)]
    pub belt_speed: Option<f64>,
    /// Frame rate (Hz) for formats without one.
    #[serde(default)]
    pub rate: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    trial: Vec<TrialEntry>,
}

/// Loads every trial listed in `dir/demo.toml`.
pub fn load_folder(dir: &Path) -> Result<Vec<Demonstration>, LearnError> {
    let path = dir.join("demo.toml");
    let text = std::fs::read_to_string(&path).map_err(|error| LearnError::Io {
        path: path.clone(),
        error,
    })?;
    let manifest: Manifest = toml::from_str(&text).map_err(|e| LearnError::Manifest {
        path: path.clone(),
        message: e.to_string(),
    })?;
    manifest
        .trial
        .iter()
        .map(|entry| load_trial(&dir.join(&entry.file), entry))
        .collect()
}

/// Loads one trial file as described by its manifest entry and refuses it
/// ([`LearnError::BadTrial`]) unless it looks like a human walking along the declared `forward`
/// (checks in `learned/validate.rs`, listed in `docs/learning.md`).
pub fn load_trial(path: &Path, entry: &TrialEntry) -> Result<Demonstration, LearnError> {
    let axes = Axes::new(&entry.forward, &entry.up).map_err(|message| LearnError::Manifest {
        path: path.to_path_buf(),
        message,
    })?;
    let mut demo = match entry.format.as_str() {
        "c3d" => from_c3d(path, &axes)?,
        "gaitkit-json" => from_gaitkit(path, &axes)?,
        "npy-mocap53" => {
            let rate = entry.rate.ok_or_else(|| LearnError::Manifest {
                path: path.to_path_buf(),
                message: "format npy-mocap53 needs `rate` (Hz) in demo.toml".into(),
            })?;
            from_mocap53(path, &axes, rate)?
        }
        other => {
            return Err(LearnError::Manifest {
                path: path.to_path_buf(),
                message: format!("unknown format `{other}` (c3d, gaitkit-json, npy-mocap53)"),
            });
        }
    };
    if let Some(speed) = entry.belt_speed {
        unroll_belt(&mut demo, speed);
    }
    validate(&demo, &axes).map_err(|reason| LearnError::BadTrial {
        path: path.to_path_buf(),
        trial: demo.name.clone(),
        reason,
    })?;
    Ok(demo)
}

/// Capture axes → canonical (forward, left, up).
pub(super) struct Axes {
    forward: Vector3<f64>,
    up: Vector3<f64>,
}

impl Axes {
    fn new(forward: &str, up: &str) -> Result<Self, String> {
        let axis = |s: &str| -> Result<Vector3<f64>, String> {
            let sign = match s.chars().next() {
                Some('+') => 1.0,
                Some('-') => -1.0,
                _ => return Err(format!("axis `{s}`: use +x, -x, +y, -y, +z or -z")),
            };
            let unit = match &s[1..] {
                "x" => Vector3::x(),
                "y" => Vector3::y(),
                "z" => Vector3::z(),
                _ => return Err(format!("axis `{s}`: use +x, -x, +y, -y, +z or -z")),
            };
            Ok(unit * sign)
        };
        let (forward, up) = (axis(forward)?, axis(up)?);
        if forward.dot(&up) != 0.0 {
            return Err(format!("forward `{forward:?}` and up are not orthogonal"));
        }
        Ok(Self { forward, up })
    }

    fn canonical(&self, p: [f64; 3], scale: f64) -> Vector3<f64> {
        let p = Vector3::from(p) * scale;
        let left = self.up.cross(&self.forward);
        Vector3::new(p.dot(&self.forward), p.dot(&left), p.dot(&self.up))
    }

    /// The declared forward axis as written in `demo.toml` (`+x`, `-y`, …), for messages.
    pub(super) fn forward_name(&self) -> String {
        axis_name(&self.forward)
    }

    /// The declared up axis as written in `demo.toml`, for messages.
    pub(super) fn up_name(&self) -> String {
        axis_name(&self.up)
    }

    /// The capture axis nearest to the canonical direction `direction`, for messages.
    pub(super) fn capture_axis_name(&self, direction: &Vector3<f64>) -> String {
        let left = self.up.cross(&self.forward);
        axis_name(&(self.forward * direction.x + left * direction.y + self.up * direction.z))
    }
}

/// The name (`+x`, `-y`, …) of the coordinate axis nearest to `v`.
fn axis_name(v: &Vector3<f64>) -> String {
    let k = v.iamax();
    let sign = if v[k] < 0.0 { '-' } else { '+' };
    format!("{sign}{}", ['x', 'y', 'z'][k])
}

/// Adds the belt travel so that a foot standing on the belt stands still.
fn unroll_belt(demo: &mut Demonstration, speed: f64) {
    let rate = demo.rate;
    let shift = |frame: usize| Vector3::new(speed * frame as f64 / rate, 0.0, 0.0);
    for (k, p) in demo.pelvis.iter_mut().enumerate() {
        *p += shift(k);
    }
    for foot in &mut demo.feet {
        for (k, points) in foot.iter_mut().enumerate() {
            points[0] += shift(k);
            points[1] += shift(k);
        }
    }
    if let Some(hands) = &mut demo.hands {
        for hand in hands {
            for (k, p) in hand.iter_mut().enumerate() {
                *p += shift(k);
            }
        }
    }
}

/// Heading of the walking direction from a left-minus-right vector.
fn heading_of(left_minus_right: &Vector3<f64>) -> f64 {
    let forward = left_minus_right.cross(&Vector3::z());
    forward.y.atan2(forward.x)
}

/// Known C3D marker sets: (name, left heel, left toe, right heel, right toe, pelvis markers
/// left-front, right-front, left-back, right-back).
const MARKER_SETS: [(&str, [&str; 8]); 2] = [
    (
        "gaitalytics LowerLimb (LHEE/LMT2, LASIS…)",
        [
            "LHEE", "LMT2", "RHEE", "RMT2", "LASIS", "RASIS", "LPSIS", "RPSIS",
        ],
    ),
    (
        "Plug-in Gait (LHEE/LTOE, LASI…)",
        [
            "LHEE", "LTOE", "RHEE", "RTOE", "LASI", "RASI", "LPSI", "RPSI",
        ],
    ),
];

fn from_c3d(path: &Path, axes: &Axes) -> Result<Demonstration, LearnError> {
    let file = C3dFile::read(path)?;
    let (_, labels) = MARKER_SETS
        .iter()
        .find(|(_, labels)| labels.iter().all(|l| file.label_index(l).is_some()))
        .ok_or_else(|| {
            let tried: Vec<String> = MARKER_SETS
                .iter()
                .map(|(name, labels)| {
                    let missing: Vec<&str> = labels
                        .iter()
                        .copied()
                        .filter(|l| file.label_index(l).is_none())
                        .collect();
                    format!("{name} lacks {}", missing.join(", "))
                })
                .collect();
            LearnError::UnknownMarkerSet {
                path: path.to_path_buf(),
                message: format!(
                    "{}; the file has {} labels starting {}",
                    tried.join("; "),
                    file.labels.len(),
                    file.labels
                        .iter()
                        .take(12)
                        .cloned()
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            }
        })?;
    let scale = match file.text("POINT", "UNITS").and_then(|u| u.first()) {
        Some(u) if u == "m" => 1.0,
        Some(u) if u == "mm" => 1e-3,
        None => 1e-3,
        Some(other) => {
            return Err(LearnError::corrupt(
                path,
                format!("POINT:UNITS `{other}` unsupported (mm or m)"),
            ));
        }
    };
    let index: Vec<usize> = labels
        .iter()
        .map(|l| file.label_index(l).expect("checked above"))
        .collect();
    let point = |frame: usize, k: usize| -> Result<Vector3<f64>, LearnError> {
        let p = file.points[frame][index[k]];
        if p.iter().all(|v| v.is_finite()) {
            Ok(axes.canonical(p, scale))
        } else {
            Err(LearnError::MissingMarker {
                path: path.to_path_buf(),
                marker: labels[k].to_owned(),
                frame,
            })
        }
    };
    let frames = file.points.len();
    if frames < 2 {
        return Err(LearnError::corrupt(path, format!("{frames} frames")));
    }
    let mut demo = empty(path, file.rate, frames);
    for f in 0..frames {
        let p: Vec<Vector3<f64>> = (0..8).map(|k| point(f, k)).collect::<Result<_, _>>()?;
        demo.feet[0].push([p[0], p[1]]);
        demo.feet[1].push([p[2], p[3]]);
        demo.pelvis.push((p[4] + p[5] + p[6] + p[7]) / 4.0);
        demo.heading.push(heading_of(&(p[4] + p[6] - p[5] - p[7])));
    }
    demo.events = c3d_events(&file, path)?;
    Ok(demo)
}

/// Foot Strike / Foot Off events of the C3D EVENT group, in seconds from the first frame: the
/// stored times count from capture start, i.e. carry (TRIAL:ACTUAL_START_FIELD − 1) / rate.
fn c3d_events(file: &C3dFile, path: &Path) -> Result<Vec<GaitEvent>, LearnError> {
    let (Some(labels), Some(contexts), Some(times)) = (
        file.text("EVENT", "LABELS"),
        file.text("EVENT", "CONTEXTS"),
        file.floats("EVENT", "TIMES"),
    ) else {
        return Ok(Vec::new());
    };
    if times.len() < 2 * labels.len() || contexts.len() < labels.len() {
        return Err(LearnError::corrupt(
            path,
            format!(
                "EVENT:TIMES has {} values and EVENT:CONTEXTS {} for {} labels",
                times.len(),
                contexts.len(),
                labels.len()
            ),
        ));
    }
    let start_field = match file.integers("TRIAL", "ACTUAL_START_FIELD") {
        Some([low, high, ..]) => (*low as u16 as usize) + 65536 * (*high as u16 as usize),
        Some([low]) => *low as u16 as usize,
        _ => file.first_frame,
    };
    let offset = start_field.saturating_sub(1) as f64 / file.rate;
    let mut events = Vec::new();
    for (k, label) in labels.iter().enumerate() {
        let kind = match label.as_str() {
            "Foot Strike" => EventKind::FootStrike,
            "Foot Off" => EventKind::FootOff,
            _ => continue,
        };
        let foot = match contexts[k].as_str() {
            "Left" => 0,
            "Right" => 1,
            _ => continue,
        };
        let time = 60.0 * f64::from(times[2 * k]) + f64::from(times[2 * k + 1]) - offset;
        events.push(GaitEvent { foot, kind, time });
    }
    Ok(events)
}

fn empty(path: &Path, rate: f64, frames: usize) -> Demonstration {
    Demonstration {
        name: path
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned()),
        rate,
        pelvis: Vec::with_capacity(frames),
        heading: Vec::with_capacity(frames),
        feet: [Vec::with_capacity(frames), Vec::with_capacity(frames)],
        hands: None,
        events: Vec::new(),
    }
}

#[derive(Deserialize)]
struct GaitkitFile {
    fps: f64,
    angle_frames: Vec<GaitkitFrame>,
}

#[derive(Deserialize)]
struct GaitkitFrame {
    landmark_positions: std::collections::HashMap<String, [f64; 3]>,
}

/// Landmarks a gaitkit file must have, in the order used below.
const GAITKIT_LANDMARKS: [&str; 6] = [
    "left_heel",
    "left_toe",
    "right_heel",
    "right_toe",
    "left_hip",
    "right_hip",
];

fn from_gaitkit(path: &Path, axes: &Axes) -> Result<Demonstration, LearnError> {
    let text = std::fs::read_to_string(path).map_err(|error| LearnError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    let file: GaitkitFile = serde_json::from_str(&text)
        .map_err(|e| LearnError::corrupt(path, format!("gaitkit JSON: {e}")))?;
    if !(file.fps.is_finite() && file.fps > 0.0) || file.angle_frames.len() < 2 {
        return Err(LearnError::corrupt(
            path,
            format!(
                "fps {} and {} frames: need fps > 0 and ≥ 2 frames",
                file.fps,
                file.angle_frames.len()
            ),
        ));
    }
    let mut demo = empty(path, file.fps, file.angle_frames.len());
    for (f, frame) in file.angle_frames.iter().enumerate() {
        let p: Vec<Vector3<f64>> = GAITKIT_LANDMARKS
            .iter()
            .map(|name| {
                let point = frame.landmark_positions.get(*name).ok_or_else(|| {
                    if f == 0 {
                        LearnError::UnknownMarkerSet {
                            path: path.to_path_buf(),
                            message: format!(
                                "gaitkit landmark `{name}` missing (need {})",
                                GAITKIT_LANDMARKS.join(", ")
                            ),
                        }
                    } else {
                        LearnError::MissingMarker {
                            path: path.to_path_buf(),
                            marker: (*name).to_owned(),
                            frame: f,
                        }
                    }
                })?;
                Ok(axes.canonical(*point, 1e-3))
            })
            .collect::<Result<_, LearnError>>()?;
        demo.feet[0].push([p[0], p[1]]);
        demo.feet[1].push([p[2], p[3]]);
        demo.pelvis.push((p[4] + p[5]) / 2.0);
        demo.heading.push(heading_of(&(p[4] - p[5])));
    }
    Ok(demo)
}

/// Joint indices in the 53-joint mocap skeleton of holosoma-retargeting (`MOCAP_DEMO_JOINTS`).
mod mocap53 {
    pub const JOINTS: usize = 53;
    pub const HIPS: usize = 0;
    pub const LEFT_HAND: usize = 8;
    pub const RIGHT_HAND: usize = 27;
    pub const LEFT_UP_LEG: usize = 43;
    pub const LEFT_FOOT: usize = 45;
    pub const LEFT_TOE: usize = 46;
    pub const RIGHT_UP_LEG: usize = 47;
    pub const RIGHT_FOOT: usize = 49;
    pub const RIGHT_TOE: usize = 50;
}

fn from_mocap53(path: &Path, axes: &Axes, rate: f64) -> Result<Demonstration, LearnError> {
    use mocap53::*;
    let array = npy::read(path)?;
    if array.shape.len() != 3 || array.shape[2] != 3 || array.shape[1] != JOINTS {
        return Err(LearnError::UnknownMarkerSet {
            path: path.to_path_buf(),
            message: format!(
                "array shape {:?}: npy-mocap53 needs (frames, {JOINTS}, 3)",
                array.shape
            ),
        });
    }
    let frames = array.shape[0];
    if frames < 2 || !(rate.is_finite() && rate > 0.0) {
        return Err(LearnError::corrupt(
            path,
            format!("{frames} frames at {rate} Hz"),
        ));
    }
    let mut demo = empty(path, rate, frames);
    let mut hands = [Vec::with_capacity(frames), Vec::with_capacity(frames)];
    for f in 0..frames {
        let joint = |j: usize| -> Result<Vector3<f64>, LearnError> {
            let at = (f * JOINTS + j) * 3;
            let p = [array.data[at], array.data[at + 1], array.data[at + 2]];
            if p.iter().all(|v| v.is_finite()) {
                Ok(axes.canonical(p, 1.0))
            } else {
                Err(LearnError::MissingMarker {
                    path: path.to_path_buf(),
                    marker: format!("joint {j}"),
                    frame: f,
                })
            }
        };
        demo.feet[0].push([joint(LEFT_FOOT)?, joint(LEFT_TOE)?]);
        demo.feet[1].push([joint(RIGHT_FOOT)?, joint(RIGHT_TOE)?]);
        demo.pelvis.push(joint(HIPS)?);
        demo.heading
            .push(heading_of(&(joint(LEFT_UP_LEG)? - joint(RIGHT_UP_LEG)?)));
        hands[0].push(joint(LEFT_HAND)?);
        hands[1].push(joint(RIGHT_HAND)?);
    }
    demo.hands = Some(hands);
    Ok(demo)
}
