//! The controller tick allocates nothing after construction (dense solver), in every phase.

mod walk_support;

use kinematic_sim::Simulator;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use daemon::controller::{ControllerState, Measurement};

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
        let sequence = walk_support::synthetic_walk(&h.robot, 2, 0.08, true);
        h.start(&sequence);
        walk_counting_allocations(robot, h);
    }
    // The dynamic gait's tick (walking pattern, stabilizer, compliance, swing) allocates nothing
    // either: its plan is built when the sequence is prepared. (ARMAR-4 has no dynamic gait.)
    let mut h = walk_support::Harness::dynamic("jvrc1", 500.0);
    let sequence = walk_support::synthetic_walk(&h.robot, 4, 0.1, true);
    let mut gaits = walk_support::kinematic_gait_config("jvrc1");
    // Foot damping runs its code path here too (it has no effect worth having on a kinematic
    // robot, but it walks).
    gaits.dynamic.as_mut().unwrap().stabilizer.foot_damping = true;
    h.start_dynamic(&sequence, &gaits);
    walk_counting_allocations("jvrc1", h);
}

/// Walks the started sequence of `h` to `done`, counting the allocations inside the ticks.
fn walk_counting_allocations(robot: &str, mut h: walk_support::Harness) {
    let mut ticks = 0;
    let mut allocations = 0;
    while h.closed.controller.status().state != ControllerState::Done && ticks < 20_000 {
        let m = h.closed.sim.measurement();
        let measurement = Measurement {
            q: m.q.as_slice(),
            qd: m.qd.as_slice(),
            wrenches: &m.wrenches,
            imu_orientation: Some(m.base_orientation),
        };
        ALLOCATIONS.store(0, Ordering::Relaxed);
        COUNTING.store(true, Ordering::Relaxed);
        let commanded = h
            .closed
            .controller
            .tick(&measurement, h.dt, &mut h.closed.command);
        COUNTING.store(false, Ordering::Relaxed);
        allocations += ALLOCATIONS.load(Ordering::Relaxed);
        assert!(commanded, "{robot}: the simulator's measurements are valid");
        h.closed
            .sim
            .step(
                h.closed.command.q_des.as_slice(),
                h.closed.command.qd_des.as_slice(),
                h.dt,
            )
            .unwrap();
        ticks += 1;
    }
    let status = h.closed.controller.status();
    assert_eq!(
        status.state,
        ControllerState::Done,
        "{robot}: {:?} in {:?} at stance {}",
        status.fault,
        status.phase,
        status.stance_index
    );
    assert_eq!(
        allocations, 0,
        "{robot}: {allocations} allocations in {ticks} ticks"
    );
}
