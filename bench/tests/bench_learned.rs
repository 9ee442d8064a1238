//! Closed-loop walks of sequences from the learned stance source (the committed default n-gram
//! model, retargeted, post-processed with the config's `[postprocess]`), built by the same
//! function `walkd bench --model` uses: ARMAR-4 and JVRC-1 × the three affordance sets, 1 and
//! 2 m sampled plus the most probable 2 m sequence. Every tick must keep the stability margin
//! ≥ 0, contact slip < 1 mm, no joint limit violated and the command finite (the checks of
//! `walk_generated`); every walk must reach `done`. Sequences for a hand set must actually use
//! that hand. Also `walkd bench --sequence`'s file input, and its errors.

mod walk_support;

use std::path::{Path, PathBuf};

use daemon::controller::SolverKind;
use kinematics::robot::EndEffector;
use stance::learned::StanceSource;
use stance::walk::WalkError;
use stance::{AffordanceSet, PostProcessParams, PostProcessedSequence, WalkRequest};
use walk_bench::sequence::{self, SequenceError};

/// Runs at 200 Hz to keep CI time down (`walkd bench` checks the 500 Hz default).
const RATE_HZ: f64 = 200.0;

fn default_model() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../data/models/default-ngram.json")
}

fn params(robot_name: &str) -> PostProcessParams {
    PostProcessParams::from_config_path(&walk_support::config_path(robot_name)).unwrap()
}

/// The post-processed learned sequence `walkd bench --model default --distance D` executes.
fn learned_sequence(
    robot_name: &str,
    affordances: AffordanceSet,
    distance: f64,
    beam: Option<usize>,
    seed: u64,
) -> PostProcessedSequence {
    let robot = walk_support::robot(robot_name);
    let source = StanceSource::learned(&default_model(), beam).expect("default model loads");
    let request = WalkRequest {
        distance,
        affordances,
        seed,
        speed: None,
    };
    sequence::generated(&robot, &params(robot_name), &source, &request)
        .expect("learned sequence is generated and post-processed")
}

/// Stances in which `hand` supports.
fn hand_stances(sequence: &PostProcessedSequence, hand: EndEffector) -> usize {
    sequence
        .stances()
        .iter()
        .filter(|s| s.in_contact(hand))
        .count()
}

fn learned_walk(
    robot_name: &str,
    affordances: AffordanceSet,
    distance: f64,
    beam: Option<usize>,
    seed: u64,
) {
    let sequence = learned_sequence(robot_name, affordances, distance, beam, seed);
    let hand = match affordances {
        AffordanceSet::Feet => None,
        AffordanceSet::FeetLeftHand => Some(EndEffector::LeftHand),
        AffordanceSet::FeetRightHand => Some(EndEffector::RightHand),
    };
    // A sampled walk with a hand available must use it, else the case tests nothing new.
    if let (Some(hand), None) = (hand, beam) {
        assert!(
            hand_stances(&sequence, hand) > 0,
            "{robot_name} {affordances} seed {seed}: no stance uses the {hand:?}"
        );
    }
    let label = format!("{robot_name} {affordances} {distance} m beam {beam:?} seed {seed}");
    walk_support::assert_walks_to_done(
        robot_name,
        &sequence,
        SolverKind::Dense,
        RATE_HZ,
        distance,
        &label,
    );
}

/// One test per robot × affordance set × distance × search (`None` = sampled with the seed).
macro_rules! walks {
    ($($name:ident: $robot:literal, $set:ident, $distance:literal, $beam:expr, $seed:literal;)*) => {
        $(
            #[test]
            fn $name() {
                learned_walk($robot, AffordanceSet::$set, $distance, $beam, $seed);
            }
        )*
    };
}

walks! {
    armar4_feet_1m: "armar4", Feet, 1.0, None, 0;
    armar4_left_hand_1m: "armar4", FeetLeftHand, 1.0, None, 0;
    armar4_right_hand_1m: "armar4", FeetRightHand, 1.0, None, 0;
    armar4_feet_2m: "armar4", Feet, 2.0, None, 2;
    armar4_left_hand_2m: "armar4", FeetLeftHand, 2.0, None, 2;
    armar4_right_hand_2m: "armar4", FeetRightHand, 2.0, None, 2;
    armar4_feet_2m_beam: "armar4", Feet, 2.0, Some(8), 0;
    jvrc1_feet_1m: "jvrc1", Feet, 1.0, None, 0;
    jvrc1_left_hand_1m: "jvrc1", FeetLeftHand, 1.0, None, 0;
    jvrc1_right_hand_1m: "jvrc1", FeetRightHand, 1.0, None, 0;
    jvrc1_feet_2m: "jvrc1", Feet, 2.0, None, 2;
    jvrc1_left_hand_2m: "jvrc1", FeetLeftHand, 2.0, None, 2;
    jvrc1_right_hand_2m: "jvrc1", FeetRightHand, 2.0, None, 2;
    jvrc1_feet_2m_beam: "jvrc1", Feet, 2.0, Some(8), 0;
}

/// A scratch file unique to this test process and `name`.
fn scratch(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("bench_learned_{}_{name}", std::process::id()))
}

fn read(robot_name: &str, path: &Path, postprocess: bool) -> Result<PostProcessedSequence, String> {
    let robot = walk_support::robot(robot_name);
    sequence::from_file(&robot, params(robot_name), path, postprocess).map_err(|e| e.to_string())
}

#[test]
fn sequence_files_read_back_as_generated() {
    let robot = walk_support::robot("jvrc1");
    let source = StanceSource::learned(&default_model(), None).unwrap();
    let request = WalkRequest {
        distance: 1.0,
        affordances: AffordanceSet::FeetLeftHand,
        seed: 1,
        speed: None,
    };
    let options = request.generate_options(&params("jvrc1"));
    let raw = source.generate(&robot, &options, None, None).unwrap().raw;
    let expected = learned_sequence("jvrc1", AffordanceSet::FeetLeftHand, 1.0, None, 1);

    let (raw_path, processed_path) = (scratch("raw.json"), scratch("pp.json"));
    std::fs::write(&raw_path, raw.to_json_string()).unwrap();
    std::fs::write(&processed_path, expected.to_json_string()).unwrap();
    let from_processed = read("jvrc1", &processed_path, false);
    let from_raw = read("jvrc1", &raw_path, true);
    let raw_as_processed = read("jvrc1", &raw_path, false);
    let processed_as_raw = read("jvrc1", &processed_path, true);
    let wrong_robot = read("armar4", &processed_path, false);
    std::fs::remove_file(&raw_path).unwrap();
    std::fs::remove_file(&processed_path).unwrap();

    let expected = expected.to_json_string();
    assert_eq!(from_processed.unwrap().to_json_string(), expected);
    assert_eq!(from_raw.unwrap().to_json_string(), expected);
    for (case, result) in [
        ("raw file without --postprocess", raw_as_processed),
        ("post-processed file with --postprocess", processed_as_raw),
        ("file of another robot", wrong_robot),
    ] {
        let error = result.expect_err(case);
        assert!(
            error.contains(&processed_path.display().to_string())
                || error.contains(&raw_path.display().to_string()),
            "{case}: the error names the file: {error}"
        );
    }
}

#[test]
fn bad_sequence_files_are_named() {
    let missing = scratch("missing.json");
    let error = read("jvrc1", &missing, false).unwrap_err();
    assert!(error.contains(&missing.display().to_string()), "{error}");

    let corrupt = scratch("corrupt.json");
    std::fs::write(&corrupt, "{\"format_version\": ").unwrap();
    let result = read("jvrc1", &corrupt, false);
    std::fs::remove_file(&corrupt).unwrap();
    let error = result.unwrap_err();
    assert!(error.contains(&corrupt.display().to_string()), "{error}");
}

#[test]
fn a_bad_model_file_is_named() {
    let path = scratch("model.json");
    std::fs::write(&path, "{\"version\": 1, \"order\": }").unwrap();
    let result = StanceSource::learned(&path, None);
    std::fs::remove_file(&path).unwrap();
    let error = SequenceError::Walk(WalkError::Source(result.unwrap_err())).to_string();
    assert!(error.contains(&path.display().to_string()), "{error}");
}
