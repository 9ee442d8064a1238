//! Closed-loop walks of a synthetic step-to sequence with a hand contact (independent of the
//! stance generator), with both QP back-ends.

mod walk_support;

use daemon::controller::SolverKind;
use walk_bench::{Outcome, WalkOptions, walk};

fn synthetic(robot_name: &str, solver: SolverKind) {
    let robot = walk_support::robot(robot_name);
    let config = walk_support::controller_config(robot_name);
    let sequence = walk_support::synthetic_walk(&robot, 4, 0.1, true);
    let options = WalkOptions {
        solver,
        rate_hz: 200.0,
        time_limit_s: 120.0,
        ..WalkOptions::default()
    };
    let report = walk(robot, config, &sequence, &options, |o| {
        walk_support::check_tick(o)
    })
    .expect("walk runs");
    assert_eq!(report.outcome, Outcome::Done, "{report:?}");
}

#[test]
fn jvrc1_synthetic_walk_dense() {
    synthetic("jvrc1", SolverKind::Dense);
}

#[test]
fn armar4_synthetic_walk_dense() {
    synthetic("armar4", SolverKind::Dense);
}

#[test]
fn jvrc1_synthetic_walk_clarabel() {
    synthetic("jvrc1", SolverKind::Clarabel);
}

#[test]
fn armar4_synthetic_walk_clarabel() {
    synthetic("armar4", SolverKind::Clarabel);
}
