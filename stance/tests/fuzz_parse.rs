//! The stance-file reader on hostile input: random bytes, and valid post-processed files with
//! random bytes written over them, cut short, or with numbers replaced. Reading never panics:
//! every input is either a valid sequence or an error that names where it went wrong, and the
//! stance counter (which walkd runs before parsing) agrees with the parser on what it reads.
//! Prints the number of inputs and the time (`--nocapture`).

mod common;

use std::time::Instant;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use stance::format::count_stances;
use stance::{AffordanceSet, GenerateOptions, PostProcessedSequence, PostProcessor, RawSequence};

const CASES: u32 = 20_000;

/// A valid post-processed 0.5 m walk of JVRC-1 as a stance file.
fn valid_file() -> String {
    let (robot, params) = common::jvrc1();
    let raw = stance::generate(
        robot,
        &GenerateOptions {
            distance: 0.5 / params.scf,
            affordances: AffordanceSet::FeetLeftHand,
            seed: 3,
        },
    )
    .unwrap();
    PostProcessor::new(robot, params.clone())
        .process(&raw)
        .unwrap()
        .to_json_string()
}

/// Ways to damage a valid file.
#[derive(Debug, Clone)]
enum Damage {
    Bytes(Vec<(usize, u8)>),
    Cut(usize),
    Number { at: usize, text: &'static str },
}

fn damage() -> impl Strategy<Value = Damage> {
    prop_oneof![
        proptest::collection::vec((any::<usize>(), any::<u8>()), 1..6).prop_map(Damage::Bytes),
        any::<usize>().prop_map(Damage::Cut),
        (
            any::<usize>(),
            prop_oneof![
                Just("NaN"),
                Just("1e999"),
                Just("-1e308"),
                Just("\"x\""),
                Just("null"),
                Just("[]"),
                Just("{}"),
                Just("1e300"),
            ]
        )
            .prop_map(|(at, text)| Damage::Number { at, text }),
    ]
}

fn apply(file: &str, damage: &Damage) -> Vec<u8> {
    let mut bytes = file.as_bytes().to_vec();
    match damage {
        Damage::Bytes(edits) => {
            for (at, byte) in edits {
                let i = at % bytes.len();
                bytes[i] = *byte;
            }
        }
        Damage::Cut(at) => bytes.truncate(at % bytes.len()),
        Damage::Number { at, text } => {
            // Replace the number that starts at or after `at`.
            let start = (at % bytes.len()..bytes.len())
                .find(|&i| bytes[i].is_ascii_digit() || bytes[i] == b'-')
                .unwrap_or(0);
            let end = (start..bytes.len())
                .find(|&i| !(bytes[i].is_ascii_digit() || b"-+.eE".contains(&bytes[i])))
                .unwrap_or(bytes.len());
            bytes.splice(start..end, text.bytes());
        }
    }
    bytes
}

/// Reads `bytes` every way walkd and walkctl do; panics only on a reader bug.
fn read(bytes: &[u8]) -> bool {
    let (robot, _) = common::jvrc1();
    let Ok(text) = std::str::from_utf8(bytes) else {
        return false;
    };
    let counted = count_stances(text);
    let parsed = PostProcessedSequence::from_json_str(text, robot);
    let _ = RawSequence::parse_json_str(text);
    if let (Ok(sequence), Ok(count)) = (&parsed, &counted) {
        assert_eq!(
            sequence.len(),
            *count,
            "the counter and the parser disagree"
        );
    }
    if let Err(error) = &parsed {
        assert!(!error.to_string().is_empty());
    }
    parsed.is_ok()
}

fn run(name: &str, strategy: impl Strategy<Value = Vec<u8>>) {
    let mut runner = TestRunner::new(Config {
        cases: CASES,
        failure_persistence: None,
        ..Config::default()
    });
    let start = Instant::now();
    let valid = std::cell::Cell::new(0);
    runner
        .run(&strategy, |bytes| {
            if read(&bytes) {
                valid.set(valid.get() + 1);
            }
            Ok(())
        })
        .unwrap();
    eprintln!(
        "fuzz stance files ({name}): {CASES} inputs read in {:.2} s, {} still valid, the rest \
         refused with a message, no panic",
        start.elapsed().as_secs_f64(),
        valid.get()
    );
}

#[test]
fn random_bytes_are_refused() {
    run(
        "random bytes",
        proptest::collection::vec(any::<u8>(), 0..4096),
    );
}

#[test]
fn damaged_files_are_refused_or_read() {
    let file = valid_file();
    assert!(read(file.as_bytes()));
    run(
        "damaged files",
        damage().prop_map(move |d| apply(&file, &d)),
    );
}
