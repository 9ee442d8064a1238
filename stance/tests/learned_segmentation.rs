//! Segmentation of the vendored demonstrations against the annotated gait events, and the
//! readers' refusal of corrupt files and unknown marker sets.

use std::path::{Path, PathBuf};

use stance::learned::{
    EventKind, GaitEvent, LearnError, SegmentOptions, Segmentation, foot_events, load_folder,
    segment, taxonomy_label,
};

fn corpus(folder: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../data/demonstrations")
        .join(folder)
}

/// The first demonstration of the corpus folder `folder`, segmented with the default options.
fn segment_first(folder: &str) -> Segmentation {
    let demos = load_folder(&corpus(folder)).unwrap();
    segment(&demos[0], &SegmentOptions::default())
}

/// How many stances of `segmentation` have contacts (left foot, right foot, left hand, right
/// hand) for which `holds` is true.
fn stances_where(segmentation: &Segmentation, holds: impl Fn([bool; 4]) -> bool) -> usize {
    segmentation
        .keyframes
        .iter()
        .filter(|k| holds(k.contacts))
        .count()
}

/// Mean absolute error between each annotated event (inside the detectable range) and the
/// nearest detected event of the same foot and kind; also the number of annotated events.
fn mean_absolute_error(
    annotated: &[GaitEvent],
    detected: &[GaitEvent],
    kind: EventKind,
    end: f64,
) -> (f64, usize) {
    let errors: Vec<f64> = annotated
        .iter()
        .filter(|e| e.kind == kind && e.time > 0.05 && e.time < end - 0.05)
        .map(|a| {
            detected
                .iter()
                .filter(|d| d.kind == kind && d.foot == a.foot)
                .map(|d| (d.time - a.time).abs())
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    (
        errors.iter().sum::<f64>() / errors.len() as f64,
        errors.len(),
    )
}

#[test]
fn gaitalytics_events_are_reproduced_within_50_ms() {
    let demos = load_folder(&corpus("gaitalytics")).unwrap();
    let demo = &demos[0];
    assert!((demo.rate - 100.0).abs() < 1e-9);
    let segmentation = segment(demo, &SegmentOptions::default());
    let detected = foot_events(&segmentation.contacts, demo.rate);
    let end = demo.len() as f64 / demo.rate;
    for kind in [EventKind::FootStrike, EventKind::FootOff] {
        let (mae, count) = mean_absolute_error(&demo.events, &detected, kind, end);
        println!(
            "{kind:?}: mean absolute error {:.4} s over {count} annotated events",
            mae
        );
        assert!(count >= 18, "{kind:?}: only {count} annotated events");
        assert!(mae <= 0.05, "{kind:?}: mean absolute error {mae} s");
    }
    // Walking: alternating single and double support, never flight.
    let labels: Vec<String> = segmentation
        .keyframes
        .iter()
        .map(|k| taxonomy_label(k.contacts))
        .collect();
    assert!(
        labels
            .iter()
            .all(|l| ["2F", "1F(l)", "1F(r)"].contains(&l.as_str())),
        "{labels:?}"
    );
    assert!(
        segmentation.keyframes.len() >= 35,
        "{} stances",
        segmentation.keyframes.len()
    );
}

#[test]
fn gaitkit_overground_walk_segments_into_steps() {
    let segmentation = segment_first("gaitkit");
    let singles = stances_where(&segmentation, |c| c[0] != c[1]);
    assert!(singles >= 3, "{singles} single-support stances");
    let forward: f64 = segmentation
        .keyframes
        .iter()
        .map(|k| k.translation[0])
        .sum();
    assert!(forward > 1.5, "the walk covers {forward} m");
}

#[test]
fn climbing_has_hand_supported_stances() {
    let segmentation = segment_first("holosoma-climb");
    let with_hands = stances_where(&segmentation, |c| c[2] || c[3]);
    assert!(
        with_hands >= 2,
        "{with_hands} hand-supported stances of {}",
        segmentation.keyframes.len()
    );
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("learned-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes the manifest of `dir` naming one trial, the C3D file `file` (walking along −y, +z up).
fn write_c3d_manifest(dir: &Path, file: &str) {
    std::fs::write(
        dir.join("demo.toml"),
        format!("[[trial]]\nfile = \"{file}\"\nformat = \"c3d\"\nforward = \"-y\"\nup = \"+z\"\n"),
    )
    .unwrap();
}

#[test]
fn corrupt_c3d_is_refused_with_the_file_named() {
    let dir = scratch("corrupt");
    let bytes = std::fs::read(corpus("gaitalytics").join("treadmill_events.c3d")).unwrap();
    std::fs::write(dir.join("cut.c3d"), &bytes[..bytes.len() / 2]).unwrap();
    std::fs::write(dir.join("junk.c3d"), b"this is not a c3d file at all").unwrap();
    write_c3d_manifest(&dir, "cut.c3d");
    let error = load_folder(&dir).unwrap_err();
    assert!(matches!(error, LearnError::Truncated { .. }), "{error}");
    assert!(
        error.to_string().contains("cut.c3d") && error.to_string().contains("point data"),
        "{error}"
    );
    write_c3d_manifest(&dir, "junk.c3d");
    let error = load_folder(&dir).unwrap_err().to_string();
    assert!(
        error.contains("junk.c3d") && error.contains("not a C3D file"),
        "{error}"
    );
}

#[test]
fn unknown_marker_set_is_refused_with_the_missing_labels() {
    let dir = scratch("markers");
    let mut bytes = std::fs::read(corpus("gaitalytics").join("treadmill_events.c3d")).unwrap();
    // Rename every LHEE label to XHEE: the file no longer matches any known marker set.
    let needle = b"LHEE";
    let mut renamed = 0;
    for k in 0..bytes.len() - needle.len() {
        if &bytes[k..k + needle.len()] == needle {
            bytes[k] = b'X';
            renamed += 1;
        }
    }
    assert!(renamed >= 1);
    std::fs::write(dir.join("renamed.c3d"), &bytes).unwrap();
    write_c3d_manifest(&dir, "renamed.c3d");
    let error = load_folder(&dir).unwrap_err();
    let text = error.to_string();
    assert!(
        matches!(error, LearnError::UnknownMarkerSet { .. }),
        "{text}"
    );
    assert!(
        text.contains("lacks LHEE") && text.contains("renamed.c3d"),
        "{text}"
    );
    // A manifest typo is named too.
    std::fs::write(
        dir.join("demo.toml"),
        "[[trial]]\nfile = \"renamed.c3d\"\nformat = \"c3d\"\nforwrd = \"-y\"\nup = \"+z\"\n",
    )
    .unwrap();
    let text = load_folder(&dir).unwrap_err().to_string();
    assert!(
        text.contains("demo.toml") && text.contains("forwrd"),
        "{text}"
    );
}
