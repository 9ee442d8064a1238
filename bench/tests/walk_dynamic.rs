//! The dynamic gait against the kinematic simulator judging by the ZMP: the walking pattern keeps
//! the ZMP of the commanded motion inside the support, phases and balance readings are
//! reported, a missing touchdown faults, and a robot without `[gait.dynamic]` refuses the walk.

mod walk_support;

use daemon::controller::{
    Controller, ControllerState, FaultCode, Gait, GaitConfig, Phase, Refusal,
};
use kinematic_sim::Simulator;
use kinematics::robot::EndEffector;
use walk_support::{Harness, controller_config, kinematic_gait_config, synthetic_walk};

/// Ticks until the walk ends (at most `limit`), calling `each` after every tick.
fn run(h: &mut Harness, limit: usize, mut each: impl FnMut(&Harness)) {
    for _ in 0..limit {
        h.tick();
        each(h);
        if h.closed.controller.status().state != ControllerState::Executing {
            return;
        }
    }
}

#[test]
fn the_zmp_of_a_dynamic_walk_stays_inside_the_support() {
    let robot = "jvrc1";
    {
        let mut h = Harness::dynamic(robot, 500.0);
        let sequence = synthetic_walk(&h.robot, 6, 0.12, false);
        h.start_dynamic(&sequence, &kinematic_gait_config(robot));
        let mut phases = Vec::new();
        let mut lowest_margin = f64::INFINITY;
        run(&mut h, 10_000, |h| {
            let status = h.closed.controller.status();
            if phases.last() != Some(&status.phase) {
                phases.push(status.phase);
            }
            lowest_margin = lowest_margin.min(h.closed.sim.measurement().safety.stability_margin);
            if status.state == ControllerState::Executing {
                let zmp = status.balance.zmp_reference;
                assert!(
                    zmp.iter().all(|v| v.is_finite()),
                    "{robot}: reference ZMP {zmp:?}"
                );
            }
        });
        let status = h.closed.controller.status();
        assert_eq!(
            status.state,
            ControllerState::Done,
            "{robot}: {:?}",
            status.fault
        );
        assert!(lowest_margin > 0.0, "{robot}: ZMP margin {lowest_margin}");
        for phase in [Phase::DoubleSupport, Phase::SingleSupport, Phase::Settle] {
            assert!(phases.contains(&phase), "{robot}: {phases:?}");
        }
        // Six steps of 0.12 m, each foot three.
        let start = h.robot.standing.base.translation.x;
        let end = h.closed.sim.configuration().base.translation.x;
        assert!(end - start > 0.3, "{robot}: walked {} m", end - start);
    }
}

#[test]
fn a_touchdown_force_torque_never_confirms_is_a_fault() {
    let mut h = Harness::dynamic("jvrc1", 500.0);
    let sequence = synthetic_walk(&h.robot, 2, 0.1, false);
    h.start_dynamic(&sequence, &kinematic_gait_config("jvrc1"));
    // The right foot swings first; once it is in the air its FT reads nothing, ever.
    let mut lifted = false;
    for _ in 0..10_000 {
        h.tick_with(|wrenches| {
            if lifted {
                wrenches[EndEffector::RightFoot as usize] = [0.0; 6];
            }
        });
        let status = h.closed.controller.status();
        lifted |= !status.contacts[EndEffector::RightFoot as usize];
        if status.state != ControllerState::Executing {
            break;
        }
    }
    let status = h.closed.controller.status();
    assert_eq!(status.state, ControllerState::Fault);
    assert_eq!(status.fault, FaultCode::MissedTouchdown);
    assert_eq!(status.fault.code(), "missed_touchdown");
}

#[test]
fn a_robot_without_a_dynamic_gait_refuses_a_dynamic_walk() {
    let h = Harness::new("jvrc1", 500.0);
    let sequence = synthetic_walk(&h.robot, 2, 0.1, false);
    let config = controller_config("jvrc1");
    let Err(Refusal(reason)) = Controller::prepare_gait(
        &h.robot,
        &config,
        &GaitConfig::default(),
        &sequence,
        Gait::Dynamic,
    ) else {
        panic!("a dynamic walk without [gait.dynamic] was accepted");
    };
    assert!(reason.contains("[gait.dynamic]"), "{reason}");
    // The static gait needs no [gait] at all.
    let prepared = Controller::prepare_gait(
        &h.robot,
        &config,
        &GaitConfig::default(),
        &sequence,
        Gait::Static,
    )
    .expect("static walk accepted");
    assert_eq!(prepared.gait(), Gait::Static);
}
