//! `walkctl learn` refuses a demonstration with wrong axes at once, naming the file and the
//! reason, also when it is mixed into a corpus of good trials: before, a Z-up gaitkit file
//! declared `up = "+y"` trained (exit 0, "human pelvis height 0.020 m") and failed only at query
//! time with a message about stances not moving forward. The checks themselves are tested one
//! by one in `stance/tests/learned_demonstrations.rs`.

use std::path::{Path, PathBuf};
use std::process::Output;

fn workspace(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

/// A directory of its own for one test, emptied first.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("walkctl-learn-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A demonstration folder holding the held-out gaitkit walker (x forward, y up) declared with
/// `up = "+z"`: its pelvis then stands a few centimetres above its feet.
fn wrong_axes(dir: &Path) -> PathBuf {
    let folder = dir.join("wrong-axes");
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::copy(
        workspace("data/demonstrations/gaitkit/example_healthy.json"),
        folder.join("example_healthy.json"),
    )
    .unwrap();
    std::fs::write(
        folder.join("demo.toml"),
        "[[trial]]\nfile = \"example_healthy.json\"\nformat = \"gaitkit-json\"\n\
         forward = \"+x\"\nup = \"+z\"\n",
    )
    .unwrap();
    folder
}

fn learn(folders: &[PathBuf], model: &Path) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_walkctl"))
        .arg("learn")
        .arg("--demos")
        .args(folders)
        .arg("-o")
        .arg(model)
        .output()
        .unwrap()
}

#[test]
fn a_trial_with_wrong_axes_is_refused_naming_the_file_alone_and_in_a_corpus() {
    let dir = scratch("wrong-axes");
    let bad = wrong_axes(&dir);
    let good = workspace("data/demonstrations/gaitalytics");
    for folders in [vec![bad.clone()], vec![good, bad.clone()]] {
        let model = dir.join("model.json");
        let out = learn(&folders, &model);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success(),
            "{folders:?}: learn succeeded: {stderr}"
        );
        assert!(
            stderr.contains(&*bad.join("example_healthy.json").to_string_lossy())
                && stderr.contains("refused trial `example_healthy`")
                && stderr.contains("the pelvis is")
                && stderr.contains("up = \"+z\""),
            "{folders:?}: {stderr}"
        );
        assert!(!model.exists(), "{folders:?}: a model was written");
    }
}
