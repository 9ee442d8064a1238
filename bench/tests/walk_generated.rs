//! Closed-loop walks of generated, post-processed sequences: ARMAR-4 and JVRC-1, the three
//! affordance sets, 1, 2 and 5 m, both QP back-ends. Every tick must keep the stability margin
//! ≥ 0, contact slip < 1 mm, no joint limit violated and the command finite; every walk must
//! reach `done`. Runs at 200 Hz to keep CI time down (`walkd bench` checks the 500 Hz default).

mod walk_support;

use daemon::controller::SolverKind;
use stance::learned::StanceSource;
use stance::{AffordanceSet, PostProcessParams, WalkRequest};
use walk_bench::sequence::generated;

fn generated_walk(robot_name: &str, affordances: AffordanceSet, distance: f64, solver: SolverKind) {
    let robot = walk_support::robot(robot_name);
    let params =
        PostProcessParams::from_config_path(&walk_support::config_path(robot_name)).unwrap();
    let request = WalkRequest {
        distance,
        affordances,
        seed: 0,
        speed: None,
    };
    let sequence = generated(&robot, &params, &StanceSource::Synthetic, &request)
        .expect("generation and post-processing run");
    let label = format!("{robot_name} {affordances} {distance} m {solver:?}");
    walk_support::assert_walks_to_done(robot_name, &sequence, solver, 200.0, distance, &label);
}

/// One test per robot × affordance set × distance × solver.
macro_rules! walks {
    ($($name:ident: $robot:literal, $set:ident, $distance:literal, $solver:ident;)*) => {
        $(
            #[test]
            fn $name() {
                generated_walk($robot, AffordanceSet::$set, $distance, SolverKind::$solver);
            }
        )*
    };
}

walks! {
    armar4_feet_1m_dense: "armar4", Feet, 1.0, Dense;
    armar4_feet_2m_dense: "armar4", Feet, 2.0, Dense;
    armar4_feet_5m_dense: "armar4", Feet, 5.0, Dense;
    armar4_left_hand_1m_dense: "armar4", FeetLeftHand, 1.0, Dense;
    armar4_left_hand_2m_dense: "armar4", FeetLeftHand, 2.0, Dense;
    armar4_left_hand_5m_dense: "armar4", FeetLeftHand, 5.0, Dense;
    armar4_right_hand_1m_dense: "armar4", FeetRightHand, 1.0, Dense;
    armar4_right_hand_2m_dense: "armar4", FeetRightHand, 2.0, Dense;
    armar4_right_hand_5m_dense: "armar4", FeetRightHand, 5.0, Dense;
    jvrc1_feet_1m_dense: "jvrc1", Feet, 1.0, Dense;
    jvrc1_feet_2m_dense: "jvrc1", Feet, 2.0, Dense;
    jvrc1_feet_5m_dense: "jvrc1", Feet, 5.0, Dense;
    jvrc1_left_hand_1m_dense: "jvrc1", FeetLeftHand, 1.0, Dense;
    jvrc1_left_hand_2m_dense: "jvrc1", FeetLeftHand, 2.0, Dense;
    jvrc1_left_hand_5m_dense: "jvrc1", FeetLeftHand, 5.0, Dense;
    jvrc1_right_hand_1m_dense: "jvrc1", FeetRightHand, 1.0, Dense;
    jvrc1_right_hand_2m_dense: "jvrc1", FeetRightHand, 2.0, Dense;
    jvrc1_right_hand_5m_dense: "jvrc1", FeetRightHand, 5.0, Dense;
    armar4_feet_1m_clarabel: "armar4", Feet, 1.0, Clarabel;
    armar4_feet_2m_clarabel: "armar4", Feet, 2.0, Clarabel;
    armar4_feet_5m_clarabel: "armar4", Feet, 5.0, Clarabel;
    armar4_left_hand_1m_clarabel: "armar4", FeetLeftHand, 1.0, Clarabel;
    armar4_left_hand_2m_clarabel: "armar4", FeetLeftHand, 2.0, Clarabel;
    armar4_left_hand_5m_clarabel: "armar4", FeetLeftHand, 5.0, Clarabel;
    armar4_right_hand_1m_clarabel: "armar4", FeetRightHand, 1.0, Clarabel;
    armar4_right_hand_2m_clarabel: "armar4", FeetRightHand, 2.0, Clarabel;
    armar4_right_hand_5m_clarabel: "armar4", FeetRightHand, 5.0, Clarabel;
    jvrc1_feet_1m_clarabel: "jvrc1", Feet, 1.0, Clarabel;
    jvrc1_feet_2m_clarabel: "jvrc1", Feet, 2.0, Clarabel;
    jvrc1_feet_5m_clarabel: "jvrc1", Feet, 5.0, Clarabel;
    jvrc1_left_hand_1m_clarabel: "jvrc1", FeetLeftHand, 1.0, Clarabel;
    jvrc1_left_hand_2m_clarabel: "jvrc1", FeetLeftHand, 2.0, Clarabel;
    jvrc1_left_hand_5m_clarabel: "jvrc1", FeetLeftHand, 5.0, Clarabel;
    jvrc1_right_hand_1m_clarabel: "jvrc1", FeetRightHand, 1.0, Clarabel;
    jvrc1_right_hand_2m_clarabel: "jvrc1", FeetRightHand, 2.0, Clarabel;
    jvrc1_right_hand_5m_clarabel: "jvrc1", FeetRightHand, 5.0, Clarabel;
}
