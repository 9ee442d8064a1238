//! The controller tick allocates nothing after construction (dense solver), in every phase.

mod walk_support;

use kinematic_sim::Simulator;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use daemon::controller::{ControllerState, Measurement, Phase};
use kinematics::Kinematics;
use kinematics::robot::EndEffector;
use nalgebra::Vector3;

struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// One test for both gaits: the counter is global, so walks running in parallel would count
/// each other's allocations.
#[test]
fn controller_tick_does_not_allocate() {
    for robot in ["jvrc1", "armar4"] {
        let mut h = walk_support::Harness::new(robot, 200.0);
        // A railing 5 cm right of the free right hand: it keeps clear of it on every tick.
        let mut kinematics = Kinematics::new(&h.robot.model);
        kinematics.update(&h.robot.model, &h.robot.standing);
        let right_hand = kinematics
            .frame_pose(&h.robot.model, h.robot.frame(EndEffector::RightHand))
            .translation
            .vector;
        let mut environment = stance::Environment::default();
        environment.hand_affordances.push(stance::HandAffordance {
            name: "railing".to_owned(),
            start: right_hand + Vector3::new(-1.0, -0.05, 0.0),
            end: right_hand + Vector3::new(2.0, -0.05, 0.0),
            radius: 0.02,
            available: [0.0, 1.0],
        });
        // The left hand is held where the static gait holds railings (JVRC-1's; ARMAR-4's
        // refuses a held hand in a scene with railings: docs/scenes.md, "Hands on railings").
        let held = walk_support::controller_config(robot).hold_railings;
        let sequence = walk_support::synthetic_walk_in(&h.robot, 2, 0.08, held, environment);
        h.start(&sequence);
        let end = walk_counting_allocations(robot, h, |_, _| {});
        assert_eq!(end, ControllerState::Done, "{robot}");
    }
    // The dynamic gait's tick (walking pattern, stabilizer, compliance, swing) allocates nothing
    // either: its plan is built when the sequence is prepared. Nor does a controlled stop, with
    // a tick on the last valid state: a NaN 0.1 s into the first single support, and a hold at
    // the same moment.
    let dynamic = || {
        let mut h = walk_support::Harness::dynamic("jvrc1", 500.0);
        let sequence = walk_support::synthetic_walk(&h.robot, 4, 0.1, true);
        let mut gaits = walk_support::kinematic_gait_config("jvrc1");
        // Foot damping runs its code path here too (it has no effect worth having on a
        // kinematic robot, but it walks).
        gaits.dynamic.as_mut().unwrap().stabilizer.foot_damping = true;
        h.start_dynamic(&sequence, &gaits);
        h
    };
    let mut holding = dynamic();
    let mut fault_tick = 50;
    while holding.closed.controller.status().phase != Phase::SingleSupport {
        holding.tick();
        fault_tick += 1;
    }
    for _ in 0..50 {
        holding.tick();
    }
    let end = walk_counting_allocations("jvrc1", dynamic(), |_, _| {});
    assert_eq!(end, ControllerState::Done);
    let end = walk_counting_allocations("jvrc1", dynamic(), |tick, q| {
        if tick == fault_tick {
            q[0] = f64::NAN;
        }
    });
    assert_eq!(end, ControllerState::Fault);
    assert_eq!(
        holding.closed.controller.status().phase,
        Phase::SingleSupport
    );
    count_allocations("jvrc1", "hold", || holding.closed.controller.hold());
    let end = walk_counting_allocations("jvrc1", holding, |_, _| {});
    assert_eq!(end, ControllerState::Holding);
    // Up stairs: steps up, their heels rising about the toes before each (toe-off).
    let end = walk_counting_allocations("jvrc1", up_the_stairs(), |_, _| {});
    assert_eq!(end, ControllerState::Done);
}

/// JVRC-1 starting a dynamic walk up the first 1.6 m of `stairs-up-10cm.toml` (two stairs, both
/// feet on each) on the kinematic simulator, standing on the scene's treads, its heels rising before each step up.
fn up_the_stairs() -> walk_support::Harness {
    let file = kinematics::ConfigFile::load(&walk_support::config_path("jvrc1")).unwrap();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../configs/scenes/stairs-up-10cm.toml");
    let scene = stance::Scene::from_path(&path).expect("scene loads");
    // Both feet on each stair, as the kinematic simulator walks a heel raised by toe-off (one
    // foot per stair, each swing two treads long, it faults there).
    let params = stance::PostProcessParams {
        stair_s_max: None,
        ..stance::PostProcessParams::from_config_for(&file, stance::Gait::Dynamic).unwrap()
    };
    let request = stance::WalkRequest {
        distance: 1.6,
        affordances: stance::AffordanceSet::Feet,
        seed: 0,
        speed: None,
    };
    let environment = scene.walk_environment();
    let mut h = walk_support::Harness::dynamic_on("jvrc1", 500.0, &environment);
    let sequence = stance::walk_in(&h.robot, &params, &request, &environment, |options| {
        stance::generate(&h.robot, options)
    })
    .expect("walks on the scene");
    // The kinematic simulator's settings switch toe-off off (its soles are flat contacts); the
    // controller's toe-off runs here all the same, its foot let go by the simulator, which then
    // takes the step's slower timing to reach the top (at the climb's it tips). The heel rises
    // 0.05 rad: since a climbing swing sets down over its last fifth, a rise of 0.15 rad or more
    // (0.5 before) rocks the kinematic robot off the upper foot at the next toe-off (`tipping`).
    let mut gaits = walk_support::kinematic_gait_config("jvrc1");
    let dynamic = gaits.dynamic.as_mut().unwrap();
    dynamic.toe_off_rad = 0.05;
    dynamic.climb_single_support_s = Some(dynamic.step_single_support());
    dynamic.climb_double_support_s = Some(dynamic.step_double_support());

    h.start_dynamic(&sequence, &gaits);
    h
}

/// Runs `call` counting its allocations; asserts there were none.
fn count_allocations(robot: &str, what: &str, call: impl FnOnce()) {
    ALLOCATIONS.store(0, Ordering::Relaxed);
    COUNTING.store(true, Ordering::Relaxed);
    call();
    COUNTING.store(false, Ordering::Relaxed);
    let allocations = ALLOCATIONS.load(Ordering::Relaxed);
    assert_eq!(
        allocations, 0,
        "{robot}: {allocations} allocations in {what}"
    );
}

/// Ticks the started sequence of `h` until it ends (neither executing nor coming to a
/// controlled stop), its measured joint angles passed through `tamper` (with the tick's number)
/// first; asserts that no tick allocates and returns the state it ended in.
fn walk_counting_allocations(
    robot: &str,
    mut h: walk_support::Harness,
    mut tamper: impl FnMut(usize, &mut [f64]),
) -> ControllerState {
    let mut q = vec![0.0; h.robot.model.dof()];
    for tick in 0..20_000 {
        let m = h.closed.sim.measurement();
        q.copy_from_slice(m.q.as_slice());
        tamper(tick, &mut q);
        let measurement = Measurement {
            q: &q,
            qd: m.qd.as_slice(),
            wrenches: &m.wrenches,
            imu_orientation: Some(m.base_orientation),
        };
        let mut commanded = false;
        count_allocations(robot, "a tick", || {
            commanded = h
                .closed
                .controller
                .tick(&measurement, h.dt, &mut h.closed.command);
        });
        assert!(commanded, "{robot}: the controller commands on every tick");
        h.closed
            .sim
            .step(
                h.closed.command.q_des.as_slice(),
                h.closed.command.qd_des.as_slice(),
                h.dt,
            )
            .unwrap();
        let status = h.closed.controller.status();
        if !matches!(
            status.state,
            ControllerState::Executing | ControllerState::ControlledStop
        ) {
            return status.state;
        }
    }
    panic!("{robot}: the walk did not end in 20 000 ticks");
}
