//! Strict demonstrations: the vendored trials pass the load-time checks of
//! `stance::learned::demo::load_trial`, and trials with wrong axes, a wrong `forward`, no data,
//! no steps or no progress are refused with the file, the trial and the reason named.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use stance::learned::{LearnError, load_folder};

fn corpus(folder: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data/demonstrations")
        .join(folder)
}

/// A fresh folder for one test's demonstration files.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("learned-demos-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `dir/demo.toml` naming one trial; `extra` holds further `key = value` lines.
fn write_manifest(dir: &Path, file: &str, format: &str, forward: &str, up: &str, extra: &str) {
    std::fs::write(
        dir.join("demo.toml"),
        format!(
            "[[trial]]\nfile = \"{file}\"\nformat = \"{format}\"\nforward = \"{forward}\"\n\
             up = \"{up}\"\n{extra}"
        ),
    )
    .unwrap();
}

/// The refusal of the single trial in `dir`, checked to be a `BadTrial` naming `file`; its text.
fn refusal(dir: &Path, file: &str) -> String {
    let Err(error) = load_folder(dir) else {
        panic!("{} was not refused", dir.join(file).display());
    };
    let text = error.to_string();
    println!("{text}");
    match &error {
        LearnError::BadTrial { path, trial, .. } => {
            assert_eq!(path, &dir.join(file), "{text}");
            assert_eq!(Some(trial.as_str()), file.split('.').next(), "{text}");
        }
        _ => panic!("not a BadTrial refusal: {text}"),
    }
    assert!(
        text.contains(file) && text.contains("refused trial"),
        "{text}"
    );
    text
}

/// The vendored gaitkit trial (mm, x forward, y up, z right) as JSON.
fn gaitkit_json() -> Value {
    let text = std::fs::read_to_string(corpus("gaitkit").join("example_healthy.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Writes `value` as the gaitkit trial `dir/file` with the manifest entry for `forward` and `up`.
fn write_gaitkit(dir: &Path, file: &str, value: &Value, forward: &str, up: &str) {
    std::fs::write(dir.join(file), value.to_string()).unwrap();
    write_manifest(dir, file, "gaitkit-json", forward, up, "");
}

/// The vendored gaitkit trial copied to `dir` with the manifest entry for `forward` and `up`.
fn gaitkit_declared(dir: &Path, forward: &str, up: &str) {
    write_gaitkit(dir, "example_healthy.json", &gaitkit_json(), forward, up);
}

/// A synthetic gaitkit trial at 100 Hz (mm, x forward, y up, z right): a subject stands for 1 s,
/// takes `steps` steps (0.5 s swing, 0.3 s double support), each putting the swing foot
/// `advance` m ahead of the other foot (0: stepping in place), and stands for 1 s; the pelvis,
/// 0.9 m high, follows the mean of the feet and sways 1 cm sideways at 0.3 Hz.
fn synthetic(steps: usize, advance: f64) -> Value {
    const RATE: f64 = 100.0;
    const SWING: f64 = 0.5;
    const DOUBLE: f64 = 0.3;
    let mut feet = [0.0f64; 2];
    // Per frame: foot positions along x and the swing foot's lift.
    let mut track: Vec<([f64; 2], [f64; 2])> = vec![(feet, [0.0; 2]); RATE as usize];
    for step in 0..steps {
        let (swing, other) = (step % 2, 1 - step % 2);
        let (from, to) = (feet[swing], feet[other] + advance);
        for k in 0..(SWING * RATE) as usize {
            let phase = k as f64 / (SWING * RATE);
            feet[swing] = from + (to - from) * (1.0 - (PI * phase).cos()) / 2.0;
            let mut lift = [0.0; 2];
            lift[swing] = 0.1 * (PI * phase).sin();
            track.push((feet, lift));
        }
        feet[swing] = to;
        track.extend(vec![(feet, [0.0; 2]); (DOUBLE * RATE) as usize]);
    }
    track.extend(vec![(feet, [0.0; 2]); RATE as usize]);
    let mm = |x: f64, y: f64, z: f64| json!([x * 1e3, y * 1e3, z * 1e3]);
    let frames: Vec<Value> = track
        .iter()
        .enumerate()
        .map(|(k, (x, lift))| {
            let sway = 0.01 * (2.0 * PI * 0.3 * k as f64 / RATE).sin();
            let pelvis = (x[0] + x[1]) / 2.0;
            json!({ "landmark_positions": {
                "left_heel": mm(x[0], 0.05 + lift[0], -0.1),
                "left_toe": mm(x[0] + 0.2, 0.03 + lift[0], -0.1),
                "right_heel": mm(x[1], 0.05 + lift[1], 0.1),
                "right_toe": mm(x[1] + 0.2, 0.03 + lift[1], 0.1),
                "left_hip": mm(pelvis, 0.9, sway - 0.1),
                "right_hip": mm(pelvis, 0.9, sway + 0.1),
            }})
        })
        .collect();
    json!({ "fps": RATE, "angle_frames": frames })
}

#[test]
fn corpus_trials_pass_the_checks() {
    for (folder, trials) in [
        ("gaitalytics", &["treadmill_events"][..]),
        ("gaitkit", &["example_healthy"]),
        (
            "holosoma-climb",
            &["mocap_climb_seq_1_joint_positions_f0-2422"],
        ),
        ("gaitkit-walkers", &["example_parkinson", "example_stroke"]),
    ] {
        let demos = load_folder(&corpus(folder)).unwrap_or_else(|e| panic!("{e}"));
        let names: Vec<&str> = demos.iter().map(|d| d.name.as_str()).collect();
        assert_eq!(names, trials);
    }
}

#[test]
fn synthetic_walk_passes_the_checks() {
    // The synthetic trials below are refused for their one defect, not for being synthetic.
    let dir = scratch("walk");
    write_gaitkit(&dir, "walk.json", &synthetic(4, 0.3), "+x", "+y");
    let demos = load_folder(&dir).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(demos[0].len(), 100 + 4 * 80 + 100);
}

#[test]
fn wrong_up_axis_is_refused_with_the_pelvis_height() {
    let dir = scratch("up");
    // z is the gaitkit file's lateral axis: the "height" is the hips' sideways offset.
    gaitkit_declared(&dir, "+x", "+z");
    let text = refusal(&dir, "example_healthy.json");
    assert!(
        text.contains("above the feet")
            && text.contains("outside the human range 0.5–1.3 m")
            && text.contains("`up = \"+z\"`")
            && text.contains("units may be wrong"),
        "{text}"
    );
    // Upside down: the pelvis is below the feet.
    gaitkit_declared(&dir, "+x", "-y");
    let text = refusal(&dir, "example_healthy.json");
    assert!(
        text.contains("the pelvis is -0.") && text.contains("`up = \"-y\"`"),
        "{text}"
    );
}

#[test]
fn feet_above_the_pelvis_are_refused() {
    let dir = scratch("swapped");
    // Every fourth frame the left toe and left hip labels are swapped (an auto-labelling error):
    // the median pelvis height stays human, but a quarter of the frames have a foot on top.
    let mut value = gaitkit_json();
    for frame in value["angle_frames"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .step_by(4)
    {
        let landmarks = frame["landmark_positions"].as_object_mut().unwrap();
        let toe = landmarks["left_toe"].clone();
        landmarks["left_toe"] = landmarks["left_hip"].clone();
        landmarks["left_hip"] = toe;
    }
    write_gaitkit(&dir, "swapped.json", &value, "+x", "+y");
    let text = refusal(&dir, "swapped.json");
    assert!(
        text.contains("a foot is at or above the pelvis in 94 of 374 frames")
            && text.contains("`up = \"+y\"` is wrong or inverted"),
        "{text}"
    );
}

#[test]
fn wrong_forward_is_refused_naming_the_axis_walked() {
    let dir = scratch("forward");
    for (declared, angle) in [("-x", "179°"), ("+z", "89°"), ("-z", "-91°")] {
        gaitkit_declared(&dir, declared, "+y");
        let text = refusal(&dir, "example_healthy.json");
        assert!(
            text.contains(&format!(
                "walks along capture axis +x, not the declared forward {declared}"
            )) && text.contains(&format!("3.13 m from its start at {angle}")),
            "{text}"
        );
    }
}

#[test]
fn treadmill_trial_with_wrong_forward_or_no_belt_speed_is_refused() {
    let dir = scratch("treadmill");
    std::fs::copy(
        corpus("gaitalytics").join("treadmill_events.c3d"),
        dir.join("treadmill_events.c3d"),
    )
    .unwrap();
    let belt = "belt_speed = 1.105\n";
    // The belt is unrolled along the declared forward, so the trial progresses along it right
    // or wrong. Unrolled backwards (+y), the subject walks backwards relative to its pelvis.
    write_manifest(&dir, "treadmill_events.c3d", "c3d", "+y", "+z", belt);
    let text = refusal(&dir, "treadmill_events.c3d");
    assert!(
        text.contains("does not walk the way its pelvis faces")
            && text.contains("share -1.00")
            && text.contains("declared forward +y, so check `forward` and `belt_speed`"),
        "{text}"
    );
    // Unrolled sideways (+x), the stance feet slide and no step is found.
    write_manifest(&dir, "treadmill_events.c3d", "c3d", "+x", "+z", belt);
    let text = refusal(&dir, "treadmill_events.c3d");
    assert!(
        text.contains("0 foot strike(s) detected (although the file annotates 22")
            && text.contains("declared forward +x, so check `forward` and `belt_speed`"),
        "{text}"
    );
    // Not unrolled, the subject walks in place.
    write_manifest(&dir, "treadmill_events.c3d", "c3d", "-y", "+z", "");
    let text = refusal(&dir, "treadmill_events.c3d");
    assert!(
        text.contains("the pelvis never gets farther than 0.07 m from its start")
            && text.contains("a treadmill trial needs `belt_speed`"),
        "{text}"
    );
    // A belt speed that is not a number makes every point NaN.
    write_manifest(
        &dir,
        "treadmill_events.c3d",
        "c3d",
        "-y",
        "+z",
        "belt_speed = nan\n",
    );
    let text = refusal(&dir, "treadmill_events.c3d");
    assert!(
        text.contains("the pelvis is not finite in frame 0"),
        "{text}"
    );
    // The corpus entry loads.
    write_manifest(&dir, "treadmill_events.c3d", "c3d", "-y", "+z", belt);
    load_folder(&dir).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn zero_trial_is_refused() {
    let dir = scratch("zero");
    let mut value = synthetic(4, 0.3);
    for frame in value["angle_frames"].as_array_mut().unwrap() {
        for point in frame["landmark_positions"]
            .as_object_mut()
            .unwrap()
            .values_mut()
        {
            *point = json!([0.0, 0.0, 0.0]);
        }
    }
    write_gaitkit(&dir, "zero.json", &value, "+x", "+y");
    let text = refusal(&dir, "zero.json");
    assert!(
        text.contains("every landmark is zero in all 520 frames"),
        "{text}"
    );
}

#[test]
fn frozen_trial_is_refused() {
    let dir = scratch("frozen");
    // The first frame of the real walk, repeated for 3 s.
    let mut value = gaitkit_json();
    let first = value["angle_frames"][0].clone();
    value["angle_frames"] = Value::Array(vec![first; 450]);
    write_gaitkit(&dir, "frozen.json", &value, "+x", "+y");
    let text = refusal(&dir, "frozen.json");
    assert!(
        text.contains("the pelvis does not move") && text.contains("0.0 mm"),
        "{text}"
    );
}

#[test]
fn standing_trial_is_refused() {
    let dir = scratch("standing");
    // 2 s of a subject standing still, swaying 1 cm: a calibration trial.
    write_gaitkit(&dir, "standing.json", &synthetic(0, 0.3), "+x", "+y");
    let text = refusal(&dir, "standing.json");
    assert!(
        text.contains("fewer than 2 steps: 0 foot strike(s) detected")
            && text.contains("standing or calibration trial"),
        "{text}"
    );
}

#[test]
fn single_step_is_refused() {
    let dir = scratch("one-step");
    write_gaitkit(&dir, "one_step.json", &synthetic(1, 0.3), "+x", "+y");
    let text = refusal(&dir, "one_step.json");
    assert!(
        text.contains("fewer than 2 steps: 1 foot strike(s) detected"),
        "{text}"
    );
    // Two steps are enough.
    write_gaitkit(&dir, "two_steps.json", &synthetic(2, 0.3), "+x", "+y");
    load_folder(&dir).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn stepping_in_place_is_refused() {
    let dir = scratch("in-place");
    write_gaitkit(&dir, "in_place.json", &synthetic(6, 0.0), "+x", "+y");
    let text = refusal(&dir, "in_place.json");
    assert!(
        text.contains("the pelvis never gets farther than 0.01 m from its start"),
        "{text}"
    );
}
