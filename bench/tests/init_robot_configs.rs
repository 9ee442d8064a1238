//! The configs `walkctl init-robot` derives — from the URDFs of JVRC-1, ARMAR-4 and iCub, and
//! the committed configs/icub.toml and configs/hrp4.toml (HRP-4 from its published dimensions)
//! — are read by every loader walkd, walk-sim and walkctl use: the daemon's `[controller]` and
//! `[gait]` parsers (which the client cannot link), `[runtime]`, both gaits' `[postprocess]` and
//! the robot itself.

use std::path::{Path, PathBuf};

use clap::Parser;
use client::init_robot::{InitRobotArgs, generate};
use daemon::controller::{ControllerConfig, GaitConfig};
use kinematics::ConfigFile;
use kinematics::robot::Robot;
use shm_types::RuntimeConfig;
use stance::{Gait, PostProcessParams};

fn workspace(relative: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join(relative)
}

#[derive(Parser)]
struct Cli {
    #[command(flatten)]
    args: InitRobotArgs,
}

/// Generates `name`'s config with `args` into a scratch file and returns its path.
fn generated(name: &str, args: &[String]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("init-robot-configs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join(format!("{name}.toml"));
    let argv = ["walkctl".to_owned()]
        .into_iter()
        .chain(args.iter().cloned())
        .chain(["-o".to_owned(), out.to_string_lossy().into_owned()]);
    let cli = Cli::try_parse_from(argv).expect("arguments");
    let config = generate(&cli.args, "walkctl init-robot (test)").expect("generates");
    std::fs::write(&out, config.text).unwrap();
    out
}

/// Loads `path` through every section's loader; `robot`: the `[robot]` section has a URDF.
fn load_everything(path: &Path, robot: bool) -> (ControllerConfig, GaitConfig) {
    let file = ConfigFile::load(path).expect("config file");
    let controller = ControllerConfig::from_config(&file).expect("[controller]");
    let gaits = GaitConfig::from_config(&file).expect("[gait]");
    RuntimeConfig::from_section(file.section("runtime"), &file.origin()).expect("[runtime]");
    for gait in [Gait::Static, Gait::Dynamic] {
        PostProcessParams::from_config_for(&file, gait).expect("[postprocess]");
    }
    if robot {
        Robot::from_config(&file, None).expect("[robot]");
    }
    (controller, gaits)
}

fn urdf_args(urdf: &str, name: &str) -> Vec<String> {
    vec![
        "--urdf".to_owned(),
        workspace(urdf).to_string_lossy().into_owned(),
        "--name".to_owned(),
        name.to_owned(),
    ]
}

#[test]
fn configs_derived_from_urdfs_load_everywhere() {
    for (name, urdf) in [
        ("jvrc1", "configs/robots/jvrc1/jvrc1.urdf"),
        ("armar4", "configs/robots/armar4/armar4_fixed_hands.urdf"),
        ("icub", "configs/robots/icub/iCubGazeboV2_7.urdf"),
    ] {
        let path = generated(name, &urdf_args(urdf, name));
        let (controller, gaits) = load_everything(&path, true);
        assert_eq!(gaits.default, Gait::Static, "{name}");
        let dynamic = gaits.dynamic().expect("a dynamic gait");
        assert!(
            dynamic.single_support_s > dynamic.double_support_s,
            "{name}"
        );
        assert!(controller.max_step_m > 0.0, "{name}");
    }
}

#[test]
fn the_committed_icub_config_loads_everywhere() {
    let (_, gaits) = load_everything(&workspace("configs/icub.toml"), true);
    let dynamic = gaits.dynamic().expect("a dynamic gait");
    // iCub's legs are 0.57 of JVRC-1's: its steps take √0.57 of JVRC-1's 0.55 / 0.25 s.
    assert_eq!(
        (dynamic.single_support_s, dynamic.double_support_s),
        (0.42, 0.19)
    );
}

/// HRP-4 as shipped (derived from its published dimensions, its model not public): every
/// section loads, and the dynamic gait is one it can walk.
#[test]
fn the_committed_hrp4_config_loads_everywhere_but_the_model() {
    let path = workspace("configs/hrp4.toml");
    let (_, gaits) = load_everything(&path, false);
    assert!(gaits.dynamic.is_some());
    let file = ConfigFile::load(&path).unwrap();
    assert_eq!(
        Gait::for_walk(Some(Gait::Dynamic), &file).unwrap(),
        Gait::Dynamic
    );
}
