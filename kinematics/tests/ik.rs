//! Inverse kinematics: reaching poses produced by forward kinematics, within joint limits.

mod common;

use kinematics::{
    Configuration, EndEffector, IkError, IkOptions, IkSolver, IkTarget, Kinematics, Model, Robot,
};
use rand::Rng;

fn robot(name: &str) -> Robot {
    Robot::load(
        &common::workspace_path(&format!("configs/{name}.toml")),
        None,
    )
    .unwrap()
}

/// Targets for all four end-effectors at their poses in `q`.
fn targets_at(robot: &Robot, q: &Configuration) -> Vec<IkTarget> {
    let mut kin = Kinematics::new(&robot.model);
    kin.update(&robot.model, q);
    EndEffector::ALL
        .iter()
        .map(|&e| IkTarget {
            frame: robot.frame(e),
            pose: kin.frame_pose(&robot.model, robot.frame(e)),
            position_weight: 1.0,
            orientation_weight: 1.0,
        })
        .collect()
}

fn assert_within_limits(model: &Model, q: &Configuration) {
    for (j, (value, limits)) in q.joints.iter().zip(model.joint_limits()).enumerate() {
        assert!(
            limits.lower <= *value && *value <= limits.upper,
            "joint {} = {value} outside limits",
            model.joint_names()[j]
        );
    }
}

fn reaches_reachable_targets(name: &str, seed: u64) {
    let robot = robot(name);
    let model = &robot.model;
    let mut rng = common::rng(seed);
    let mut solver = IkSolver::new(model);
    let mut kin = Kinematics::new(model);
    for _ in 0..10 {
        // A goal near the standing posture, and a start 0.2 rad away from it in every joint.
        let mut goal = robot.standing.clone();
        for (value, limits) in goal.joints.iter_mut().zip(model.joint_limits()) {
            *value = (*value + rng.random_range(-0.3..0.3)).clamp(limits.lower, limits.upper);
        }
        goal.base.translation.vector.x += rng.random_range(-0.2..0.2);
        let targets = targets_at(&robot, &goal);
        let mut start = goal.clone();
        for value in start.joints.iter_mut() {
            *value += rng.random_range(-0.2..0.2);
        }
        let solution = solver
            .solve(
                model,
                &targets,
                &start,
                Some(&robot.standing.joints),
                &IkOptions::default(),
            )
            .unwrap();
        assert!(solution.position_error < 1e-6 && solution.orientation_error < 1e-6);
        assert_within_limits(model, &solution.configuration);
        kin.update(model, &solution.configuration);
        for target in &targets {
            let reached = kin.frame_pose(model, target.frame);
            assert!((reached.translation.vector - target.pose.translation.vector).norm() < 1e-6);
            assert!(reached.rotation.angle_to(&target.pose.rotation) < 1e-6);
        }
    }
}

#[test]
fn armar4_reaches_reachable_targets() {
    reaches_reachable_targets("armar4", 11);
}

#[test]
fn jvrc1_reaches_reachable_targets() {
    reaches_reachable_targets("jvrc1", 12);
}

#[test]
fn unreachable_target_is_reported_with_limits_respected() {
    let robot = robot("jvrc1");
    let model = &robot.model;
    let mut target_pose = robot.standing.base;
    target_pose.translation.vector.z += 5.0; // the hand 5 m above the pelvis, base fixed
    let targets = [IkTarget {
        frame: robot.frame(EndEffector::LeftHand),
        pose: target_pose,
        position_weight: 1.0,
        orientation_weight: 0.0,
    }];
    let options = IkOptions {
        fixed_base: true,
        max_iterations: 50,
        ..IkOptions::default()
    };
    let error = IkSolver::new(model)
        .solve(model, &targets, &robot.standing, None, &options)
        .unwrap_err();
    let IkError::NotConverged(best) = error else {
        panic!("expected NotConverged, got {error}")
    };
    assert!(best.position_error > 1.0);
    assert_eq!(
        best.configuration.base, robot.standing.base,
        "fixed base moved"
    );
    assert_within_limits(model, &best.configuration);
}

#[test]
fn wrong_joint_count_is_refused() {
    let robot = robot("jvrc1");
    let mut q = robot.standing.clone();
    q.joints = kinematics::DVector::zeros(3);
    let error = IkSolver::new(&robot.model)
        .solve(&robot.model, &[], &q, None, &IkOptions::default())
        .unwrap_err();
    assert!(
        matches!(
            error,
            IkError::WrongJointCount {
                expected: 34,
                got: 3,
                ..
            }
        ),
        "{error}"
    );
}
