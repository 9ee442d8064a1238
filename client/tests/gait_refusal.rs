//! A robot without `[gait.dynamic]` asked to walk dynamically: `walkctl` refuses at once, with
//! the message that names the config file, the missing section and the fix, before it writes a
//! file or starts walkd. Run on JVRC-1's config without its `[gait]` section.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use stance::GaitUnavailable;

fn workspace(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

/// A directory of its own for one test, emptied first.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("walkctl-gait-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes JVRC-1's config as `dir/<name>.toml`, its URDF made absolute; `static_only` leaves
/// out the `[gait]` section and its tables.
fn jvrc1_config(dir: &Path, name: &str, static_only: bool) -> PathBuf {
    let text = std::fs::read_to_string(workspace("configs/jvrc1.toml")).unwrap();
    let urdf = "urdf = \"robots/jvrc1/jvrc1.urdf\"";
    assert!(text.contains(urdf), "configs/jvrc1.toml names its URDF");
    let absolute = format!(
        "urdf = \"{}\"",
        workspace("configs/robots/jvrc1/jvrc1.urdf").display()
    );
    let mut in_gait = false;
    let mut kept = String::new();
    for line in text.replace(urdf, &absolute).lines() {
        if line.starts_with('[') {
            in_gait = line.starts_with("[gait]") || line.starts_with("[gait.");
        }
        if !(static_only && in_gait) {
            kept.push_str(line);
            kept.push('\n');
        }
    }
    assert_eq!(
        kept.lines().any(|line| line.starts_with("[gait")),
        !static_only,
        "the [gait] tables are {}",
        if static_only { "gone" } else { "kept" }
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, kept).unwrap();
    path
}

fn walkctl(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_walkctl"))
        .args(args)
        .output()
        .expect("run walkctl")
}

fn text(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// `output` failed with exactly the refusal for `config` and nothing in front of it: the message
/// of the client's own check, not walkd's ("walkd refused the sequence: dynamic gait: sequence
/// refused: ...") nor a run's.
fn assert_refused(output: &Output, config: &Path) {
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "walkctl succeeded: {stderr}");
    for part in ["[gait.dynamic]", text(config), "walkctl init-robot"] {
        assert!(stderr.contains(part), "{part:?} not in {stderr:?}");
    }
    let refusal = GaitUnavailable {
        path: config.to_owned(),
    };
    assert_eq!(stderr.trim_end(), format!("walkctl: error: {refusal}"));
}

#[test]
fn generate_refuses_a_dynamic_walk_without_gait_dynamic_and_writes_nothing() {
    let dir = scratch("generate");
    let config = jvrc1_config(&dir, "static-only", true);
    let raw = dir.join("raw.json");
    let generate = |gait: &str| {
        walkctl(&[
            "generate",
            "--robot",
            text(&config),
            "--distance",
            "0.3",
            "--gait",
            gait,
            "-o",
            text(&raw),
        ])
    };
    let refused = generate("dynamic");
    assert_refused(&refused, &config);
    assert!(!raw.exists(), "{} was written", raw.display());
    // The same config walks statically: the refusal is the gait's, not a broken config's.
    let accepted = generate("static");
    assert!(
        accepted.status.success() && raw.is_file(),
        "{}",
        String::from_utf8_lossy(&accepted.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn postprocess_and_submit_refuse_before_reading_their_input() {
    let dir = scratch("postprocess");
    let config = jvrc1_config(&dir, "static-only", true);
    let (raw, processed) = (dir.join("absent.json"), dir.join("pp.json"));
    let postprocess = walkctl(&[
        "postprocess",
        "--robot",
        text(&config),
        "--gait",
        "dynamic",
        text(&raw),
        "-o",
        text(&processed),
    ]);
    assert_refused(&postprocess, &config);
    assert!(!processed.exists(), "{} was written", processed.display());
    for extra in [&[][..], &["--postprocess"]] {
        let submit = walkctl(
            &[
                &["submit", text(&raw), "--config", text(&config)][..],
                &["--gait", "dynamic"],
                extra,
            ]
            .concat(),
        );
        assert_refused(&submit, &config);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn demo_refuses_a_dynamic_walk_without_gait_dynamic_before_starting_walkd() {
    let dir = scratch("demo");
    let config = jvrc1_config(&dir, "static-only", true);
    let output = walkctl(&[
        "demo",
        "--robot",
        "jvrc1",
        "--config",
        text(&config),
        "--physics",
        "kinematic",
        "--clock",
        "lockstep",
        "--distance",
        "0.3",
        "--gait",
        "dynamic",
        "--record",
        text(&dir.join("recording")),
        "--plots",
        text(&dir.join("plots")),
    ]);
    assert_refused(&output, &config);
    assert!(!dir.join("recording").exists() && !dir.join("plots").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn evaluate_checks_every_robot_before_the_first_run() {
    let dir = scratch("evaluate");
    // The first robot can walk dynamically; the second cannot, and is refused before the first
    // robot's first run starts walkd.
    jvrc1_config(&dir, "jvrc1", false);
    let config = jvrc1_config(&dir, "static-only", true);
    let output = walkctl(&[
        "evaluate",
        "--robots",
        "jvrc1,static-only",
        "--config-dir",
        text(&dir),
        "--physics",
        "kinematic",
        "--affordances",
        "feet",
        "--distances",
        "0.3",
        "--runs",
        "1",
        "--gait",
        "dynamic",
        "--record",
        text(&dir.join("recordings")),
        "--plots",
        text(&dir.join("plots")),
    ]);
    assert_refused(&output, &config);
    assert!(!dir.join("recordings").exists() && !dir.join("plots").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
