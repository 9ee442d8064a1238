//! `walkctl init-robot` end to end: the binary on the vendored URDFs, its output loaded by the
//! robot and stance loaders, the committed `configs/icub.toml` and `configs/hrp4.toml`
//! regenerated, bad input refused.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use clap::Parser;
use client::init_robot::{InitRobotArgs, generate};
use kinematics::{ConfigFile, Robot};
use stance::{Gait, PostProcessParams};

fn workspace(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("walkctl-init-robot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn walkctl(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_walkctl"))
        .arg("init-robot")
        .args(args)
        .output()
        .expect("run walkctl")
}

fn number(file: &ConfigFile, table: &str, key: &str) -> f64 {
    let mut parts = table.split('.');
    let mut value = file.section(parts.next().unwrap()).unwrap();
    for part in parts {
        value = value.get(part).unwrap();
    }
    value.get(key).and_then(|v| v.as_float()).expect(key)
}

#[test]
fn jvrc1_from_its_urdf_loads_and_derives_its_hand_tuned_values() {
    let out = scratch("jvrc1.toml");
    let urdf = workspace("configs/robots/jvrc1/jvrc1.urdf");
    let output = walkctl(&[
        "--urdf",
        urdf.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "walkctl failed: {stderr}");
    // The guesses were printed for the user, with the options that override them.
    for expected in [
        "base link",
        "PELVIS_S",
        "--left-foot",
        "--sole LxW",
        "lfsensor",
    ] {
        assert!(
            stderr.contains(expected),
            "{expected} missing from:\n{stderr}"
        );
    }
    let robot = Robot::load(&out, None).expect("the written config loads");
    assert_eq!(robot.name, "jvrc1");
    assert_eq!(robot.model.dof(), 34);
    let file = ConfigFile::load(&out).unwrap();
    for gait in [Gait::Static, Gait::Dynamic] {
        PostProcessParams::from_config_for(&file, gait).expect("[postprocess] parses");
    }
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.starts_with("# Robot configuration for jvrc1, written by\n#   walkctl init-robot")
    );
    assert!(text.contains("service_prefix = \"walk/jvrc1\""));
    // Its guessed soles sit 9 mm higher than the configured ones, so the legs measure 1 %
    // shorter: the hand-tuned values come back within a few percent.
    let hand = ConfigFile::load(&workspace("configs/jvrc1.toml")).unwrap();
    for (table, key) in [
        ("gait.dynamic", "single_support_s"),
        ("gait.dynamic", "double_support_s"),
        ("postprocess", "s_max"),
        ("postprocess", "scf"),
        ("postprocess", "o_min"),
        ("postprocess", "o_max"),
        ("postprocess.dynamic", "s_max"),
        ("postprocess.dynamic", "scf"),
        ("controller", "max_step_m"),
    ] {
        let (derived, tuned) = (number(&file, table, key), number(&hand, table, key));
        assert!(
            (derived / tuned - 1.0).abs() < 0.03,
            "[{table}] {key}: derived {derived}, hand-tuned {tuned}"
        );
    }
}

#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    args: InitRobotArgs,
}

/// The shipped configs that `walkctl init-robot` wrote (iCub from its URDF, HRP-4 from its
/// published dimensions) are exactly what it writes now: nothing in them was edited by hand.
#[test]
fn the_committed_derived_configs_are_what_init_robot_writes() {
    for file in ["configs/icub.toml", "configs/hrp4.toml"] {
        let committed = std::fs::read_to_string(workspace(file)).unwrap();
        // The header records the command that wrote it (run from the repository root).
        let command = committed
            .lines()
            .nth(1)
            .and_then(|line| line.strip_prefix("#   "))
            .expect("the command on the second line");
        let words: Vec<String> = command.split_whitespace().map(str::to_owned).collect();
        assert_eq!(&words[..2], ["walkctl", "init-robot"]);
        // Paths as the repository root sees them.
        let argv = words[2..].iter().map(|word| {
            if word.starts_with("configs/") {
                workspace(word).to_string_lossy().into_owned()
            } else {
                word.clone()
            }
        });
        let cli = Cli::try_parse_from(std::iter::once("walkctl".to_owned()).chain(argv)).unwrap();
        let generated = generate(&cli.args, command).expect("generates");
        assert!(
            generated.text == committed,
            "{file} differs from what `{command}` writes now; regenerate it"
        );
    }
}

#[test]
fn hrp4_from_its_dimensions_with_the_frames_of_its_config() {
    let out = scratch("hrp4.toml");
    let output = walkctl(&[
        "--dimensions",
        workspace("configs/robots/hrp4/dimensions.toml")
            .to_str()
            .unwrap(),
        "--frames-from",
        workspace("configs/hrp4.toml").to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let file = ConfigFile::load(&out).unwrap();
    for gait in [Gait::Static, Gait::Dynamic] {
        PostProcessParams::from_config_for(&file, gait).expect("[postprocess] parses");
    }
    // [robot] is hrp4.toml's: no URDF, so loading the robot asks for one.
    let error = Robot::from_config(&file, None).unwrap_err().to_string();
    assert!(error.contains("--urdf PATH"), "{error}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("left_foot = { link = \"L_ANKLE_R_LINK\""),
        "{text}"
    );
}

fn refused(args: &[&str], expected: &[&str]) {
    let output = walkctl(args);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{args:?} was accepted");
    for word in expected {
        assert!(stderr.contains(word), "{args:?}: `{word}` not in: {stderr}");
    }
}

#[test]
fn bad_input_is_refused_naming_what_and_where() {
    let dimensions =
        std::fs::read_to_string(workspace("configs/robots/hrp4/dimensions.toml")).unwrap();
    let write = |name: &str, text: &str| {
        let path = scratch(name);
        std::fs::write(&path, text).unwrap();
        path.to_string_lossy().into_owned()
    };
    let replace = |key: &str, to: &str| -> String {
        dimensions
            .lines()
            .map(|line| {
                if line.starts_with(&format!("{key} =")) {
                    to.to_owned()
                } else {
                    line.to_owned()
                }
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    let nan = write("nan.toml", &replace("leg_length_m", "leg_length_m = nan"));
    refused(
        &["--dimensions", &nan],
        &["nan.toml", "leg_length_m", "finite"],
    );
    let negative = write("negative.toml", &replace("mass_kg", "mass_kg = -39.0"));
    refused(&["--dimensions", &negative], &["negative.toml", "mass_kg"]);
    let unknown = write("unknown.toml", &replace("mass_kg", "weight_kg = 39.0"));
    refused(&["--dimensions", &unknown], &["unknown.toml", "weight_kg"]);
    let stork = write(
        "stork.urdf",
        r#"<robot name="stork">
  <link name="pelvis"><inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="thigh"/><link name="shank"/>
  <joint name="hip" type="revolute"><parent link="pelvis"/><child link="thigh"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <joint name="knee" type="revolute"><parent link="thigh"/><child link="shank"/><origin xyz="0 0 -0.4"/><axis xyz="0 1 0"/><limit lower="0" upper="2" effort="10" velocity="1"/></joint>
</robot>"#,
    );
    refused(
        &["--urdf", &stork],
        &["stork.urdf", "no two recognisable legs"],
    );
    let urdf = workspace("configs/robots/jvrc1/jvrc1.urdf");
    let urdf = urdf.to_str().unwrap();
    refused(
        &["--urdf", urdf, "--sole", "0.2"],
        &["--sole", "LENGTHxWIDTH"],
    );
    refused(&["--urdf", urdf, "--sole", "0.2x5"], &["--sole"]);
    refused(
        &["--urdf", urdf, "--left-foot", "NO_SUCH_LINK"],
        &["--left-foot", "NO_SUCH_LINK"],
    );
    refused(&["--urdf", urdf, "--name", "jvrc 1"], &["name"]);
    assert!(Path::new(&nan).exists());
}
