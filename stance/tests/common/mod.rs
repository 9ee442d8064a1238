//! Shared helpers of the integration tests: the vendored robots, loaded once per test binary.

#![allow(dead_code)] // each test binary uses a subset

use std::path::PathBuf;
use std::sync::OnceLock;

use kinematics::robot::Robot;
use stance::PostProcessParams;

/// Path of a robot config in the workspace's `configs/`.
pub fn config_path(robot: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../configs")
        .join(format!("{robot}.toml"))
}

fn load(robot: &str) -> (Robot, PostProcessParams) {
    let path = config_path(robot);
    let model = Robot::load(&path, None).unwrap_or_else(|e| panic!("{robot}: {e}"));
    let params =
        PostProcessParams::from_config_path(&path).unwrap_or_else(|e| panic!("{robot}: {e}"));
    (model, params)
}

/// ARMAR-4 and its `[postprocess]` parameters.
pub fn armar4() -> &'static (Robot, PostProcessParams) {
    static ROBOT: OnceLock<(Robot, PostProcessParams)> = OnceLock::new();
    ROBOT.get_or_init(|| load("armar4"))
}

/// JVRC-1 and its `[postprocess]` parameters.
pub fn jvrc1() -> &'static (Robot, PostProcessParams) {
    static ROBOT: OnceLock<(Robot, PostProcessParams)> = OnceLock::new();
    ROBOT.get_or_init(|| load("jvrc1"))
}
