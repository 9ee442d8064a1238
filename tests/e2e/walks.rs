//! A walk completes end to end: `walkctl demo` starts real `walkd` and `walk-sim` processes,
//! generates, post-processes, submits and watches a walk, and shuts them down. `walkctl
//! evaluate` does the same in lockstep and judges the walk from the simulator's ground truth
//! (`sim-truth`): under MuJoCo physics (walk-sim must be built with `--features
//! sim-adapter/mujoco`; otherwise the test fails with walk-sim's explanation) and kinematically. The
//! dynamic gait walks against the kinematic simulator in lockstep and in real time.

use std::process::{Command, Output};

use walk_tests::{bin_dir, config, unique_prefix, workspace_dir};

/// The JSON report a `walkctl … --json` run printed, and its stderr (for messages).
fn json_report(output: &Output) -> (serde_json::Value, String) {
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    let report = serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("no JSON report ({e}); stdout: {stdout}\nstderr: {stderr}"));
    (report, stderr)
}

/// Runs `walkctl demo --json` (the kinematic simulator, the config's gait unless `extra` names
/// one) and checks the reported outcome: `done`, without a fall, about the distance asked for.
fn demo_walk(test: &str, robot: &str, clock: &str, extra: &[&str]) {
    let distance = 0.2;
    let output = Command::new(bin_dir().join("walkctl"))
        .args([
            "demo",
            "--robot",
            robot,
            "--clock",
            clock,
            "--rate-hz",
            "500",
            "--json",
        ])
        .args(extra)
        .args(["--distance", &distance.to_string()])
        .args(["--config", &config(robot).display().to_string()])
        .args(["--service-prefix", &unique_prefix(test)])
        .output()
        .expect("walkctl runs (build the binaries first: cargo build --release --bins)");
    let (report, stderr) = json_report(&output);
    assert_eq!(report["outcome"], "done", "{report}\n{stderr}");
    assert!(output.status.success(), "{stderr}");
    let covered = report["distance_m"].as_f64().unwrap();
    assert!(
        (covered - distance).abs() < 0.5 * distance,
        "walked {covered} m of {distance} m: {report}"
    );
    assert!(report["stances"].as_u64().unwrap() >= 3, "{report}");
    let tick = &report["tick_us"];
    assert!(tick["p50"].as_f64().unwrap() > 0.0, "{report}");
    assert!(tick["p50"].as_f64() <= tick["p99"].as_f64(), "{report}");
    assert!(tick["p99"].as_f64() <= tick["max"].as_f64(), "{report}");
    if clock == "lockstep" {
        assert_eq!(
            report["deadline_misses"], 0,
            "lockstep has no deadlines: {report}"
        );
    }
}

#[test]
fn armar4_walks_in_lockstep() {
    demo_walk("armar4_lockstep", "armar4", "lockstep", &[]);
}

#[test]
fn jvrc1_walks_in_lockstep() {
    demo_walk("jvrc1_lockstep", "jvrc1", "lockstep", &[]);
}

#[test]
fn armar4_walks_in_real_time_at_500_hz() {
    demo_walk("armar4_realtime", "armar4", "realtime", &[]);
}

#[test]
fn jvrc1_walks_in_real_time_at_500_hz() {
    demo_walk("jvrc1_realtime", "jvrc1", "realtime", &[]);
}

/// The dynamic gait against the kinematic simulator over processes walks as `walk-bench` does
/// in process: walkd runs without the stabilizer parts that act through contact compliance, and
/// walk-sim judges the walk by its ZMP (docs/controller.md). Before, the stance foot's tilt
/// damping diverged and the QP was infeasible at stance 2, and judged by its CoM the walk fell.
fn dynamic_kinematic_walk(test: &str, clock: &str) {
    demo_walk(
        test,
        "jvrc1",
        clock,
        &["--gait", "dynamic", "--physics", "kinematic"],
    );
}

#[test]
fn jvrc1_walks_the_dynamic_gait_kinematically_in_lockstep() {
    dynamic_kinematic_walk("jvrc1_dynamic_lockstep", "lockstep");
}

/// In real time the adapter applies its last setpoint again when a command comes late; the
/// kinematic simulator took that for a dead stop and its ZMP left the feet.
#[test]
fn jvrc1_walks_the_dynamic_gait_kinematically_in_real_time() {
    dynamic_kinematic_walk("jvrc1_dynamic_realtime", "realtime");
}

/// Runs `walkctl evaluate` for one short feet-only walk of `robot` and returns its JSON run.
fn evaluate_walk(robot: &str, physics: &str, distance: f64) -> serde_json::Value {
    evaluate_walk_with(robot, "feet", physics, distance)
}

/// [`evaluate_walk`] with the affordance set `affordances`.
fn evaluate_walk_with(
    robot: &str,
    affordances: &str,
    physics: &str,
    distance: f64,
) -> serde_json::Value {
    let output = Command::new(bin_dir().join("walkctl"))
        .args(["evaluate", "--robots", robot, "--affordances", affordances])
        .args(["--distances", &distance.to_string(), "--runs", "1"])
        .args(["--physics", physics, "--json"])
        .args([
            "--config-dir",
            &workspace_dir().join("configs").display().to_string(),
        ])
        .output()
        .expect("walkctl runs (build the binaries first: cargo build --release --bins)");
    let (report, stderr) = json_report(&output);
    let run = report["runs"][0].clone();
    assert_eq!(run["outcome"], "done", "{run}\n{stderr}");
    assert_eq!(
        run["success"], true,
        "done but fell in the simulator: {run}"
    );
    assert!(output.status.success(), "{stderr}");
    run
}

/// The simulator's truth was paired with the daemon's statuses: the controller's CoM and sole
/// estimates stayed within `max_drift` of the simulated robot, which ended near its final
/// targets.
fn assert_tracked_truth(run: &serde_json::Value, max_drift: f64) {
    assert!(run["drift_samples"].as_u64().unwrap() >= 3, "{run}");
    let drift = run["drift_m"].as_f64().unwrap();
    assert!((0.0..max_drift).contains(&drift), "drift {drift} m: {run}");
    assert!(
        run["final_position_error_m"].as_f64().unwrap() < 0.03,
        "{run}"
    );
    assert!(run["sim_s"].as_f64().unwrap() > 0.0, "{run}");
}

#[test]
fn jvrc1_walks_under_mujoco_physics_without_falling() {
    let run = evaluate_walk("jvrc1", "mujoco", 0.4);
    assert_tracked_truth(&run, 0.02);
    // Still standing after being watched past the end (a fall then is no `done`).
    let watched = run["watched_after_end_s"].as_f64().unwrap();
    assert!(
        watched >= client::evaluate::WATCH_AFTER_END_S,
        "watched {watched} s: {run}"
    );
    // Upright all the way (the fall rule is 0.6 rad).
    assert!(run["max_tilt_rad"].as_f64().unwrap() < 0.1, "{run}");
}

/// A walk that holds the left hand on a railing, in a MuJoCo world without one (the flat
/// floor): the hand presses on nothing (it sinks `hand_press_depth_m` at most, docs/controller.md,
/// "Hands on a railing"); asked for its share of the weight (walkd's telemetry shows the force
/// asked: JVRC-1's `hand_support_share` is 0.165), it is measured to carry none, so the CoM never
/// leans towards it ("Hands carry weight in the static gait"), and the walk goes on without it
/// to the end, upright, the simulator reading no force on the palm.
#[test]
fn a_hand_that_finds_no_railing_leaves_the_walk_to_the_feet() {
    let run = evaluate_walk_with("jvrc1", "feet+left-hand", "mujoco", 0.4);
    assert!(run["max_tilt_rad"].as_f64().unwrap() < 0.1, "{run}");
    let share = run["hand_support_share"].as_f64().expect("a held hand");
    assert!(share.abs() < 1e-9, "the palm touched something: {run}");
    let asked = run["hand_support_asked"].as_f64().expect("a hand held");
    assert!(
        asked > 0.1,
        "walkd asked the hand for {asked} of the weight: {run}"
    );
}

#[test]
fn kinematic_evaluation_pairs_the_simulator_truth_with_the_status() {
    let run = evaluate_walk("armar4", "kinematic", 0.2);
    assert_tracked_truth(&run, 0.005);
}
