//! A walk completes end to end: `walkctl demo` starts real `walkd` and `walk-sim` processes,
//! generates, post-processes, submits and watches a walk, and shuts them down.

use std::process::Command;

use walk_tests::{bin_dir, config, unique_prefix};

/// Runs `walkctl demo --json` and checks the reported outcome.
fn demo_walk(test: &str, robot: &str, clock: &str) {
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
        .args(["--distance", &distance.to_string()])
        .args(["--config", &config(robot).display().to_string()])
        .args(["--service-prefix", &unique_prefix(test)])
        .output()
        .expect("walkctl runs (build the binaries first: cargo build --release --bins)");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let report: serde_json::Value = serde_json::from_str(stdout.trim())
        .unwrap_or_else(|e| panic!("no JSON report ({e}); stdout: {stdout}\nstderr: {stderr}"));
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
    demo_walk("armar4_lockstep", "armar4", "lockstep");
}

#[test]
fn jvrc1_walks_in_lockstep() {
    demo_walk("jvrc1_lockstep", "jvrc1", "lockstep");
}

#[test]
fn armar4_walks_in_real_time_at_500_hz() {
    demo_walk("armar4_realtime", "armar4", "realtime");
}

#[test]
fn jvrc1_walks_in_real_time_at_500_hz() {
    demo_walk("jvrc1_realtime", "jvrc1", "realtime");
}
