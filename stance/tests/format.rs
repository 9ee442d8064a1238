//! The stance file: round trips, and one refused file per error class, each with a message that
//! names the stance index and field (or line and column).

mod common;

use serde_json::{Value, json};
use stance::{
    AffordanceSet, FormatError, Gait, GenerateOptions, Location, PostProcessParams,
    PostProcessedSequence, PostProcessor, RawSequence, generate,
};

fn raw() -> RawSequence {
    let (robot, _) = common::jvrc1();
    generate(
        robot,
        &GenerateOptions {
            distance: 1.0,
            affordances: AffordanceSet::FeetRightHand,
            seed: 4,
        },
    )
    .unwrap()
}

fn processed() -> PostProcessedSequence {
    let (robot, params) = common::jvrc1();
    PostProcessor::new(robot, params.clone())
        .process(&raw())
        .unwrap()
}

/// The raw file as JSON, edited by `edit`, read back for JVRC-1.
fn read_edited(edit: impl FnOnce(&mut Value)) -> Result<RawSequence, FormatError> {
    let mut value: Value = serde_json::from_str(&raw().to_json_string()).unwrap();
    edit(&mut value);
    RawSequence::from_json_str(&value.to_string(), &common::jvrc1().0)
}

/// `file` (JSON) with the number at `pointer` spelled `literal`: NaN, -Infinity, 1e999 and the
/// like, which are not finite JSON numbers and so cannot be written through `serde_json`.
fn with_number_spelled(file: &str, pointer: &str, literal: &str) -> String {
    let mut value: Value = serde_json::from_str(file).unwrap();
    *value.pointer_mut(pointer).expect("the field exists") = json!(12345.678);
    value.to_string().replace("12345.678", literal)
}

#[test]
fn raw_and_post_processed_files_round_trip() {
    let (robot, _) = common::jvrc1();
    let raw = raw();
    assert_eq!(
        RawSequence::from_json_str(&raw.to_json_string(), robot).unwrap(),
        raw
    );
    let pp = processed();
    let back = PostProcessedSequence::from_json_str(&pp.to_json_string(), robot).unwrap();
    assert_eq!(back.len(), pp.len());
    for i in 0..pp.len() {
        assert_eq!(back.posture(i), pp.posture(i));
        assert_eq!(back.contacts(i), pp.contacts(i));
        for (a, b) in back.targets(i).iter().zip(pp.targets(i)) {
            assert!((a.translation.vector - b.translation.vector).norm() < 1e-12);
            assert!(a.rotation.angle_to(&b.rotation) < 1e-9);
        }
    }
}

#[test]
fn truncated_json_is_refused_with_its_position() {
    let text = raw().to_json_string();
    let cut = &text[..text.len() * 2 / 3];
    let err = RawSequence::from_json_str(cut, &common::jvrc1().0).unwrap_err();
    let FormatError::Truncated { line, location, .. } = &err else {
        panic!("{err}")
    };
    assert!(*line > 1 && location.stance.is_some(), "{err}");
    assert!(err.to_string().contains("truncated JSON"), "{err}");
}

#[test]
fn nan_is_refused_naming_stance_and_field() {
    let text = raw().to_json_string();
    let read = |literal: &str| {
        let edited = with_number_spelled(&text, "/stances/3/q/5", literal);
        RawSequence::from_json_str(&edited, &common::jvrc1().0).unwrap_err()
    };
    let non_finite = FormatError::NonFinite {
        location: Location::stance(3, "q[5]"),
    };
    let err = read("NaN");
    assert_eq!(err, non_finite, "{err}");
    assert_eq!(
        err.to_string(),
        "stance 3, field `q[5]`: non-finite number (NaN or infinity) is not allowed"
    );
    // An overflowing number is an infinity: refused the same way.
    let err = read("1e999");
    assert_eq!(err, non_finite, "{err}");
}

#[test]
fn wrong_joint_count_in_a_stance_is_refused() {
    let err = read_edited(|v| {
        v["stances"][2]["q"].as_array_mut().unwrap().pop();
    })
    .unwrap_err();
    assert!(
        matches!(
            err,
            FormatError::JointCount {
                stance: 2,
                expected: 34,
                found: 33
            }
        ),
        "{err}"
    );
    assert!(err.to_string().starts_with("stance 2, field `q`"), "{err}");
}

#[test]
fn wrong_joint_names_are_refused() {
    let err = read_edited(|v| v["joint_names"][4] = json!("R_KNEE_TYPO")).unwrap_err();
    assert!(
        matches!(&err, FormatError::JointName { index: 4, found, .. } if found == "R_KNEE_TYPO"),
        "{err}"
    );
    let err = read_edited(|v| {
        v["joint_names"].as_array_mut().unwrap().pop();
        for stance in v["stances"].as_array_mut().unwrap() {
            stance["q"].as_array_mut().unwrap().pop();
        }
    })
    .unwrap_err();
    assert!(
        matches!(
            err,
            FormatError::JointNameCount {
                expected: 34,
                found: 33,
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn empty_sequence_is_refused() {
    let err = read_edited(|v| v["stances"] = json!([])).unwrap_err();
    assert_eq!(err, FormatError::EmptySequence);
    assert!(err.to_string().contains("`stances`"));
}

#[test]
fn unknown_robot_is_refused() {
    let err = read_edited(|v| v["robot"] = json!("hrp5")).unwrap_err();
    assert_eq!(
        err.to_string(),
        "the sequence is for robot `hrp5`, not for `jvrc1` (field `robot`)"
    );
}

#[test]
fn stance_without_foot_support_is_refused() {
    let err = read_edited(|v| v["stances"][6]["contacts"] = json!(["right_hand"])).unwrap_err();
    assert_eq!(err, FormatError::NoFootSupport { stance: 6 });
    assert!(
        err.to_string().starts_with("stance 6, field `contacts`"),
        "{err}"
    );
}

#[test]
fn structural_errors_name_their_field() {
    let err = read_edited(|v| v["stances"][1]["translaton"] = json!([0, 0, 0])).unwrap_err();
    assert!(
        matches!(&err, FormatError::Structure { location, .. } if location.stance == Some(1)),
        "{err}"
    );
    assert!(err.to_string().contains("translaton"), "{err}");
    let err = read_edited(|v| v["format_version"] = json!(3)).unwrap_err();
    assert!(
        matches!(err, FormatError::UnsupportedVersion { found: 3, .. }),
        "{err}"
    );
    let err = read_edited(|v| v["stances"][0]["contacts"] = json!(["left_foot", "left_foot"]))
        .unwrap_err();
    assert!(
        matches!(err, FormatError::BadContact { stance: 0, .. }),
        "{err}"
    );
    let err =
        read_edited(|v| v["stances"][2]["root_orientation"] = json!([0, 0, 0, 2])).unwrap_err();
    assert!(
        matches!(err, FormatError::NonUnitQuaternion { .. }),
        "{err}"
    );
    assert!(
        err.to_string()
            .starts_with("stance 2, field `root_orientation`"),
        "{err}"
    );
}

#[test]
fn files_of_the_other_kind_are_refused() {
    let (robot, _) = common::jvrc1();
    // The kind a refusal of the wrong kind of file expected.
    let expected = |err: FormatError| match err {
        FormatError::WrongKind { expected, .. } => expected,
        other => panic!("{other}"),
    };
    let err = RawSequence::from_json_str(&processed().to_json_string(), robot).unwrap_err();
    assert_eq!(expected(err), "raw");
    let err = PostProcessedSequence::from_json_str(&raw().to_json_string(), robot).unwrap_err();
    assert_eq!(expected(err), "post_processed");
}

#[test]
fn post_processed_target_nan_is_refused() {
    let text = with_number_spelled(
        &processed().to_json_string(),
        "/stances/2/targets/left_hand/translation/1",
        "-Infinity",
    );
    let err = PostProcessedSequence::from_json_str(&text, &common::jvrc1().0).unwrap_err();
    assert_eq!(
        err,
        FormatError::NonFinite {
            location: Location::stance(2, "targets.left_hand.translation[1]")
        }
    );
}

#[test]
fn a_post_processed_file_carries_the_gait_it_was_post_processed_for() {
    let (robot, params) = common::jvrc1();
    let statically = processed();
    assert_eq!(statically.gait(), Some(Gait::Static));
    let dynamic_params = PostProcessParams {
        gait: Gait::Dynamic,
        ..params.clone()
    };
    let dynamically = PostProcessor::new(robot, dynamic_params)
        .process(&raw())
        .unwrap();
    let text = dynamically.to_json_string();
    let value: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(value["gait"], json!("dynamic"));
    let back = PostProcessedSequence::from_json_str(&text, robot).unwrap();
    assert_eq!(back.gait(), Some(Gait::Dynamic));
    // A file that does not say leaves the choice to the robot's config.
    let mut value = value;
    value.as_object_mut().unwrap().remove("gait");
    let unsaid = PostProcessedSequence::from_json_str(&value.to_string(), robot).unwrap();
    assert_eq!(unsaid.gait(), None);
    assert!(!unsaid.to_json_string().contains("\"gait\""));
    // An unknown gait is named; a raw file has none.
    value["gait"] = json!("running");
    let err = PostProcessedSequence::from_json_str(&value.to_string(), robot).unwrap_err();
    assert!(err.to_string().contains("running"), "{err}");
    let err = read_edited(|raw| raw["gait"] = json!("dynamic")).unwrap_err();
    assert!(
        err.to_string().contains("`gait`") && err.to_string().contains("post-processed"),
        "{err}"
    );
}

#[test]
fn a_gait_that_is_not_a_name_is_refused_naming_the_field_and_the_choices() {
    let (robot, _) = common::jvrc1();
    let mut value: Value = serde_json::from_str(&processed().to_json_string()).unwrap();
    for gait in [
        json!(1),
        json!(true),
        json!(["dynamic"]),
        json!({"dynamic": 1}),
    ] {
        value["gait"] = gait.clone();
        let err = PostProcessedSequence::from_json_str(&value.to_string(), robot).unwrap_err();
        let text = err.to_string();
        assert!(
            matches!(&err, FormatError::Structure { location, .. } if *location == Location::file("gait"))
                && text.contains("\"static\" or \"dynamic\""),
            "gait {gait}: {text}"
        );
    }
}

#[test]
fn a_file_that_is_not_an_object_is_refused_as_such() {
    let (robot, _) = common::jvrc1();
    for (text, found) in [
        ("[1, 2, 3]", "an array"),
        ("[]", "an array"),
        ("  \"stances\"", "a string"),
        ("42", "a number"),
        ("true", "a boolean"),
        ("null", "null"),
    ] {
        for err in [
            PostProcessedSequence::from_json_str(text, robot).unwrap_err(),
            RawSequence::from_json_str(text, robot).unwrap_err(),
            stance::format::count_stances(text).unwrap_err(),
        ] {
            let message = err.to_string();
            assert!(
                message.contains("a stance file is a JSON object") && message.contains(found),
                "{text}: {message}"
            );
        }
    }
}

#[test]
fn a_railing_radius_is_optional_and_zero_when_absent() {
    let text = raw().to_json_string();
    let railing = "/environment/hand_affordances/0";
    // The source's own railing has no radius, and a radius of 0 is not written: files from
    // before the field existed read the same.
    let value: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(value.pointer(&format!("{railing}/radius")), None);
    assert_eq!(raw().environment().hand_affordances[0].radius, 0.0);
    // A scene's railing keeps its radius through the file.
    let thick = read_edited(|v| {
        v.pointer_mut(railing).unwrap()["radius"] = json!(0.02);
    })
    .unwrap();
    assert_eq!(thick.environment().hand_affordances[0].radius, 0.02);
    let again = RawSequence::from_json_str(&thick.to_json_string(), &common::jvrc1().0).unwrap();
    assert_eq!(again, thick);
    // A negative radius is refused, naming the field.
    let err = read_edited(|v| {
        v.pointer_mut(railing).unwrap()["radius"] = json!(-0.02);
    })
    .unwrap_err();
    assert!(
        err.to_string()
            .contains("environment.hand_affordances[0].radius"),
        "{err}"
    );
}

#[test]
fn a_stance_duration_is_optional_written_in_version_2_and_checked() {
    let text = raw().to_json_string();
    let value: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(value["format_version"], json!(2));
    // Untimed stances write no duration, so a file of the previous version reads the same.
    assert_eq!(value.pointer("/stances/0/duration_s"), None);
    let old = read_edited(|v| v["format_version"] = json!(1)).unwrap();
    assert_eq!(old, raw());
    // A timed stance keeps its duration through the file.
    let timed = read_edited(|v| v["stances"][1]["duration_s"] = json!(0.45)).unwrap();
    assert_eq!(timed.stances()[1].duration_s, Some(0.45));
    assert_eq!(timed.stances()[0].duration_s, None);
    let again = RawSequence::from_json_str(&timed.to_json_string(), &common::jvrc1().0).unwrap();
    assert_eq!(again, timed);
    // Refused, naming the stance and the field: a zero, a negative, a too long and a
    // non-finite duration, and a duration in a version-1 file.
    for bad in [json!(0.0), json!(-0.2), json!(61.0)] {
        let err = read_edited(|v| v["stances"][3]["duration_s"] = bad.clone()).unwrap_err();
        assert!(
            err.to_string().starts_with("stance 3, field `duration_s`"),
            "{bad}: {err}"
        );
    }
    let nan = with_number_spelled(&timed.to_json_string(), "/stances/1/duration_s", "NaN");
    let err = RawSequence::from_json_str(&nan, &common::jvrc1().0).unwrap_err();
    assert!(matches!(err, FormatError::NonFinite { .. }), "{err}");
    let err = read_edited(|v| {
        v["format_version"] = json!(1);
        v["stances"][2]["duration_s"] = json!(0.5);
    })
    .unwrap_err();
    assert!(
        err.to_string().contains("stance 2, field `duration_s`")
            && err.to_string().contains("format_version 2"),
        "{err}"
    );
}
