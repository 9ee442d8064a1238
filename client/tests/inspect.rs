//! `walkctl inspect` end to end: run the binary on the JVRC-1 config and check its JSON.

use std::path::PathBuf;
use std::process::Command;

fn workspace(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

fn inspect(extra: &[&str]) -> serde_json::Value {
    let output = Command::new(env!("CARGO_BIN_EXE_walkctl"))
        .arg("inspect")
        .arg("--robot")
        .arg(workspace("configs/jvrc1.toml"))
        .args(extra)
        .output()
        .expect("run walkctl");
    assert!(
        output.status.success(),
        "walkctl failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).expect("stdout is one JSON object")
}

#[test]
fn jvrc1_report_has_model_facts_and_soles_on_the_ground() {
    let report = inspect(&["--jacobians"]);
    assert_eq!(report["robot"], "jvrc1");
    assert_eq!(report["dof"], 34);
    assert!((report["mass"].as_f64().unwrap() - 62.4).abs() < 1e-9);
    assert_eq!(report["links"].as_object().unwrap().len(), 60);
    for frame in ["left_foot", "right_foot", "left_hand", "right_hand"] {
        let pose = &report["frames"][frame];
        assert_eq!(pose["translation"].as_array().unwrap().len(), 3, "{frame}");
        assert_eq!(pose["rotation"].as_array().unwrap().len(), 4, "{frame}");
        let jacobian = report["jacobians"][frame].as_array().unwrap();
        assert_eq!(jacobian.len(), 6);
        assert!(
            jacobian
                .iter()
                .all(|row| row.as_array().unwrap().len() == 40)
        );
    }
    // Standing posture: soles on z = 0, CoM above the ground.
    assert!(
        report["frames"]["left_foot"]["translation"][2]
            .as_f64()
            .unwrap()
            .abs()
            < 1e-9
    );
    assert!(report["com"][2].as_f64().unwrap() > 0.5);
    assert_eq!(report["com_jacobian"].as_array().unwrap().len(), 3);
}

#[test]
fn joint_override_and_base_move_the_right_links() {
    let standing = inspect(&[]);
    assert!(standing.get("jacobians").is_none());
    let q_file =
        std::env::temp_dir().join(format!("walkctl-inspect-q-{}.json", std::process::id()));
    std::fs::write(&q_file, r#"{"joints": {"L_SHOULDER_P": -1.0}}"#).unwrap();
    let moved = inspect(&["--q", q_file.to_str().unwrap()]);
    let hand = |r: &serde_json::Value| r["frames"]["left_hand"]["translation"].clone();
    assert_ne!(
        hand(&standing),
        hand(&moved),
        "the left hand follows the shoulder"
    );
    assert_eq!(
        standing["frames"]["right_hand"], moved["frames"]["right_hand"],
        "the right hand does not"
    );

    let based = inspect(&["--base", r#"{"translation":[1,2,3],"rotation":[0,0,0,1]}"#]);
    assert_eq!(
        based["links"]["base_link"]["translation"],
        serde_json::json!([1.0, 2.0, 3.0])
    );
}

#[test]
fn bad_joint_name_is_reported() {
    let q_file =
        std::env::temp_dir().join(format!("walkctl-inspect-bad-{}.json", std::process::id()));
    std::fs::write(&q_file, r#"{"joints": {"NO_SUCH_JOINT": 0.1}}"#).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_walkctl"))
        .args(["inspect", "--robot"])
        .arg(workspace("configs/jvrc1.toml"))
        .arg("--q")
        .arg(&q_file)
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("NO_SUCH_JOINT"), "{stderr}");
}
