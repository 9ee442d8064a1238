//! The dynamic gait against the kinematic simulator judging by the ZMP: the walking pattern keeps
//! the ZMP of the commanded motion inside the support (JVRC-1; ARMAR-4 its reference ZMP, the
//! commanded one most of the time), a generated JVRC-1 walk reaches `done` at 1 kHz through its
//! touchdowns, phases and balance readings are reported, a missing touchdown faults, a robot
//! without `[gait.dynamic]` refuses the walk, a version-1 stance file still walks, and a paced
//! learned walk is planned from its stance durations.

mod walk_support;

use daemon::controller::{
    Controller, ControllerState, FaultCode, Gait, GaitConfig, MeasurementFault, Phase, PhaseTiming,
    Refusal,
};
use kinematic_sim::Simulator;
use kinematics::ground::{SupportPolygon, sole_corners};
use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use stance::learned::StanceSource;
use stance::{PostProcessParams, WalkRequest};
use walk_bench::sequence::generated;
use walk_bench::{Outcome, WalkOptions, walk};
use walk_support::{
    Harness, config_path, controller_config, kinematic_gait_config, synthetic_walk,
};

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

/// ARMAR-4 walks the sequence its dynamic gait is tuned for (generated 1 m, post-processed with
/// `[postprocess.dynamic]`). Its reference ZMP sits 5 cm inside the sole centres
/// (`zmp_inward_offset_m`) and stays inside the support at every tick; the ZMP of the commanded
/// motion leaves it only briefly. The simulator splits the weight between the feet by the lever
/// rule between the sole centres, so with the ZMP on the inner part of the stance sole the other
/// foot still reads about a quarter of the weight at its lift-off: no wait for its release.
#[test]
fn armar4_keeps_the_dynamic_reference_zmp_inside_the_support() {
    let robot = "armar4";
    let mut h = Harness::dynamic(robot, 500.0);
    let config = kinematics::ConfigFile::load(&config_path(robot)).expect("config loads");
    let params = PostProcessParams::from_config_for(&config, Gait::Dynamic).expect("params");
    let request = WalkRequest::feet(1.0, 0);
    let sequence = stance::synthetic_walk(&h.robot, &params, &request).expect("walk generated");
    let mut gaits = kinematic_gait_config(robot);
    gaits
        .dynamic
        .as_mut()
        .expect("a dynamic gait")
        .late_lift_off_max_s = 0.0;
    h.start_dynamic(&sequence, &gaits);
    let (mut ticks, mut inside) = (0, 0);
    run(&mut h, 20_000, |h| {
        let status = h.closed.controller.status();
        if status.state != ControllerState::Executing {
            return;
        }
        let zmp = status.balance.zmp_reference;
        let mut corners = Vec::new();
        for (foot, pose) in [(0, &status.left_foot), (1, &status.right_foot)] {
            if status.contacts[foot] {
                let pose = Isometry3::from_parts(
                    Translation3::new(pose[0], pose[1], pose[2]),
                    UnitQuaternion::from_quaternion(Quaternion::new(
                        pose[6], pose[3], pose[4], pose[5],
                    )),
                );
                corners.extend(
                    sole_corners(&pose, &h.robot.sole)
                        .iter()
                        .map(|c| [c.x, c.y]),
                );
            }
        }
        let margin = SupportPolygon::from_points(&corners).signed_distance(zmp);
        assert!(
            margin >= -1e-6,
            "reference ZMP {zmp:?} {margin} m outside the support"
        );
        ticks += 1;
        if h.closed.sim.measurement().safety.stability_margin >= 0.0 {
            inside += 1;
        }
    });
    let status = h.closed.controller.status();
    assert_eq!(status.state, ControllerState::Done, "{:?}", status.fault);
    let share = f64::from(inside) / f64::from(ticks);
    eprintln!(
        "{robot}: commanded ZMP inside the support {:.1} % of {ticks} ticks",
        100.0 * share
    );
    assert!(
        share > 0.85,
        "{robot}: commanded ZMP inside the support {share:.3} of the time"
    );
}

/// A generated 1 m JVRC-1 walk, post-processed for the dynamic gait, walked as `walk-bench
/// --gait dynamic --rate-hz 1000` walks it. Regression: at the first touchdown the base, re-placed
/// between the stance foot and the still-moving swing foot, made the CoM jump; its finite
/// difference threw the ZMP 6 cm out of the support and the walk fell at 2.3 s.
#[test]
fn a_generated_jvrc1_dynamic_walk_reaches_done_at_1_khz() {
    let robot_name = "jvrc1";
    let robot = walk_support::robot(robot_name);
    let config = kinematics::ConfigFile::load(&config_path(robot_name)).expect("config loads");
    let params = PostProcessParams::from_config_for(&config, Gait::Dynamic).expect("params");
    let sequence = generated(
        &robot,
        &params,
        &StanceSource::Synthetic,
        &WalkRequest::feet(1.0, 0),
    )
    .expect("generation and post-processing run");
    let options = WalkOptions {
        rate_hz: 1000.0,
        gait: Gait::Dynamic,
        gaits: kinematic_gait_config(robot_name),
        ..WalkOptions::default()
    };
    let report = walk(
        robot,
        controller_config(robot_name),
        &sequence,
        &options,
        |_| {},
    )
    .expect("the walk runs");
    assert_eq!(report.outcome, Outcome::Done, "{report:?}");
    assert!(
        report.safety.min_stability_margin > 0.01,
        "ZMP margin {}",
        report.safety.min_stability_margin
    );
    // The generated "1 m" covers what whole steps of the dynamic post-processing reach: 0.82 m
    // with JVRC-1's `scf` 0.46.
    assert!(report.distance_m > 0.75, "walked {} m", report.distance_m);
}

/// The right foot's force-torque never confirms its touchdown. The walk must not hold on one
/// foot: it ends with a controlled stop that lands the foot by position (the ground holds it at
/// its foothold), brings the robot to rest on both feet and then holds, in fault. (The kinematic
/// simulator puts the weight on the landed foot, so the feet read unloaded before the missed
/// touchdown is due; under MuJoCo, `walkctl evaluate --inject withheld-touchdown`.)
#[test]
fn a_touchdown_force_torque_never_confirms_ends_in_a_controlled_stop_on_both_feet() {
    let mut h = Harness::dynamic("jvrc1", 500.0);
    let sequence = synthetic_walk(&h.robot, 2, 0.1, false);
    h.start_dynamic(&sequence, &kinematic_gait_config("jvrc1"));
    // The right foot swings first; once it is in the air its FT reads nothing, ever.
    let mut lifted = false;
    let mut states = Vec::new();
    for _ in 0..10_000 {
        h.tick_with(|wrenches| {
            if lifted {
                wrenches[EndEffector::RightFoot as usize] = [0.0; 6];
            }
        });
        assert!(h.closed.command.is_finite());
        let status = h.closed.controller.status();
        lifted |= !status.contacts[EndEffector::RightFoot as usize];
        if states.last() != Some(&status.state) {
            states.push(status.state);
        }
        if !matches!(
            status.state,
            ControllerState::Executing | ControllerState::ControlledStop
        ) {
            break;
        }
    }
    assert_eq!(
        states,
        [
            ControllerState::Executing,
            ControllerState::ControlledStop,
            ControllerState::Fault
        ]
    );
    let status = h.closed.controller.status();
    assert!(
        matches!(
            status.fault,
            FaultCode::MissedTouchdown
                | FaultCode::InvalidMeasurement(MeasurementFault::Unloaded(_))
        ),
        "{:?}",
        status.fault
    );
    assert!(
        status.contacts[EndEffector::LeftFoot as usize]
            && status.contacts[EndEffector::RightFoot as usize],
        "the stop ends on both feet: {:?}",
        status.contacts
    );
}

/// A swing foot that cannot reach its foothold ends the controlled stop with
/// `stop_could_not_land`, the one way a stop holds on one foot, and says so. Force-torque never
/// confirms the right foot's touchdown, and its sole reads above the foothold's height: the
/// measured knee of the swinging leg reads 0.3 rad more bent than it is.
#[test]
fn a_stop_that_cannot_land_its_swing_foot_says_so() {
    let mut h = Harness::dynamic("jvrc1", 500.0);
    let knee = h
        .robot
        .model
        .joint_names()
        .iter()
        .position(|name| name == "R_KNEE")
        .expect("JVRC-1 has R_KNEE");
    let sequence = synthetic_walk(&h.robot, 2, 0.1, false);
    h.start_dynamic(&sequence, &kinematic_gait_config("jvrc1"));
    let mut lifted = false;
    for _ in 0..10_000 {
        h.closed
            .tick_with(|readings| {
                if lifted {
                    readings.wrenches[EndEffector::RightFoot as usize] = [0.0; 6];
                    readings.q[knee] += 0.3;
                }
            })
            .expect("a command every tick");
        assert!(h.closed.command.is_finite());
        let status = h.closed.controller.status();
        lifted |= !status.contacts[EndEffector::RightFoot as usize];
        if !matches!(
            status.state,
            ControllerState::Executing | ControllerState::ControlledStop
        ) {
            break;
        }
    }
    let status = h.closed.controller.status();
    assert_eq!(status.state, ControllerState::Fault);
    assert_eq!(status.fault, FaultCode::StopCouldNotLand);
    assert_eq!(status.fault.code(), "stop_could_not_land");
    assert!(
        !status.contacts[EndEffector::RightFoot as usize],
        "the foot that could not land is not in contact"
    );
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

/// A step-down ZMP set beyond the sole's front edge is refused before anything moves, naming the
/// key and the sole.
#[test]
fn a_step_down_zmp_beyond_the_sole_is_refused() {
    let h = Harness::new("jvrc1", 500.0);
    let sequence = synthetic_walk(&h.robot, 2, 0.1, false);
    let mut gaits = kinematic_gait_config("jvrc1");
    gaits
        .dynamic
        .as_mut()
        .expect("jvrc1 has a dynamic gait")
        .step_down_zmp_forward_m = 0.15;
    let Err(Refusal(reason)) = Controller::prepare_gait(
        &h.robot,
        &controller_config("jvrc1"),
        &gaits,
        &sequence,
        Gait::Dynamic,
    ) else {
        panic!("a step-down ZMP 0.15 m ahead on a 0.2 m sole was accepted");
    };
    assert!(
        reason.contains("step_down_zmp_forward_m") && reason.contains("0.2 m long sole"),
        "{reason}"
    );
}

/// A stance file of format version 1 (written before stances had durations; the flat JVRC-1
/// walk of `stance/tests/data`) still loads, and the dynamic gait walks it on the config's
/// timing.
#[test]
fn a_version_1_stance_file_still_walks() {
    let mut h = Harness::dynamic("jvrc1", 500.0);
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../stance/tests/data/flat-jvrc1-dynamic-1.5m-seed5.json"
    );
    let text = std::fs::read_to_string(path).expect("the stored file reads");
    assert!(text.contains("\"format_version\": 1"));
    let sequence = stance::PostProcessedSequence::from_json_str(&text, &h.robot).expect("loads");
    h.start_dynamic(&sequence, &kinematic_gait_config("jvrc1"));
    let mut timings = Vec::new();
    run(&mut h, 30_000, |h| {
        let planned = h.closed.controller.status().balance.planned_phase;
        timings.extend(planned.map(|p| p.timing));
    });
    assert_eq!(h.closed.controller.status().state, ControllerState::Done);
    assert!(timings.iter().all(|t| *t == PhaseTiming::Configured));
}

/// A learned walk paced for 0.18 m/s carries its stances' durations to the dynamic gait: its
/// supports are planned from them (within the config's limits), and it reaches `done`.
#[test]
fn a_paced_learned_walk_is_planned_from_its_stance_durations() {
    let robot_name = "jvrc1";
    let mut h = Harness::dynamic(robot_name, 500.0);
    let config = kinematics::ConfigFile::load(&config_path(robot_name)).expect("config loads");
    let params = PostProcessParams::from_config_for(&config, Gait::Dynamic).expect("params");
    let gaits = kinematic_gait_config(robot_name);
    let dynamic = gaits.dynamic().expect("a dynamic gait");
    let limits = [
        dynamic.timed_single_support(),
        dynamic.timed_double_support(),
    ];
    let model = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../data/models/default-ngram.json"
    );
    let source = StanceSource::learned(std::path::Path::new(model), None).expect("model loads");
    let request = WalkRequest {
        speed: Some(stance::WalkingSpeed {
            m_s: 0.18,
            support_limits_s: limits,
        }),
        ..WalkRequest::feet(1.5, 0)
    };
    let sequence = generated(&h.robot, &params, &source, &request).expect("a paced walk");
    assert!(sequence.stances().iter().all(|s| s.duration_s.is_some()));
    h.start_dynamic(&sequence, &gaits);
    let mut phases: Vec<(Phase, f64, PhaseTiming)> = Vec::new();
    run(&mut h, 30_000, |h| {
        let status = h.closed.controller.status();
        if let Some(planned) = status.balance.planned_phase {
            let phase = (status.phase, planned.duration_s, planned.timing);
            if phases.last() != Some(&phase) {
                phases.push(phase);
            }
        }
    });
    assert_eq!(h.closed.controller.status().state, ControllerState::Done);
    let timed = phases
        .iter()
        .filter(|p| p.2 == PhaseTiming::Sequence)
        .count();
    assert!(timed * 4 > phases.len() * 3, "{phases:?}");
    for (phase, duration, timing) in &phases {
        if *phase == Phase::SingleSupport && *timing != PhaseTiming::Configured {
            assert!(
                (limits[0][0]..=limits[0][1]).contains(duration),
                "{phases:?}"
            );
        }
    }
}

/// The kinematic simulator stands the feet on the surfaces a sequence was post-processed on
/// (`sim_adapter::SceneGround`): JVRC-1's dynamic gait climbs the ten 0.10 m stairs of
/// `stairs-up-10cm.toml` to its top landing, one foot per stair (1.0 s of single support a
/// stair, below), its CoM ending 1 m higher
/// than it started. On the flat plane of before, the walk fell at the first stair (its feet
/// planned onto treads the simulator did not have).
#[test]
fn a_dynamic_walk_climbs_stairs_in_the_kinematic_simulator() {
    let robot = walk_support::robot("jvrc1");
    let file = kinematics::ConfigFile::load(&config_path("jvrc1")).unwrap();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../configs/scenes/stairs-up-10cm.toml");
    let scene = stance::Scene::from_path(&path).expect("scene loads");
    let params = PostProcessParams::from_config_for(&file, Gait::Dynamic).unwrap();
    let request = WalkRequest {
        distance: scene.path_length(),
        affordances: stance::AffordanceSet::Feet,
        seed: 0,
        speed: None,
    };
    let sequence = stance::walk_in(
        &robot,
        &params,
        &request,
        &scene.walk_environment(),
        |options| stance::generate(&robot, options),
    )
    .expect("walks on the scene");
    // The kinematic simulator judges the commanded motion's ZMP (its stabilizer's force-based
    // parts are off). Since a climbing swing sets down over its last fifth, its horizontal
    // motion is shorter and faster, and at the default 0.85 s of single support the swing leg's
    // acceleration takes that ZMP 0.17 m outside the soles (a fall there; MuJoCo walks it
    // 10/10, docs/scenes.md); at 1.0 s it stays inside.
    let mut gaits = kinematic_gait_config("jvrc1");
    gaits.dynamic.as_mut().unwrap().climb_past_single_support_s = Some(1.0);
    let options = WalkOptions {
        gait: Gait::Dynamic,
        gaits,
        ..WalkOptions::default()
    };
    let mut com_heights = (f64::NAN, f64::NAN);
    let report = walk(
        robot.clone(),
        controller_config("jvrc1"),
        &sequence,
        &options,
        |o| {
            if o.tick == 0 {
                com_heights.0 = o.sim.com.z;
            }
            com_heights.1 = o.sim.com.z;
        },
    )
    .expect("runs");
    assert_eq!(report.outcome, Outcome::Done, "{:?}", report.safety);
    let climbed = com_heights.1 - com_heights.0;
    assert!(
        (climbed - 1.0).abs() < 0.02,
        "the CoM climbed {climbed:.3} m"
    );
    assert!(report.safety.max_penetration < 0.005, "{:?}", report.safety);
}
