//! The controller tick allocates nothing after construction (dense solver), in every phase.

mod walk_support;

use kinematic_sim::Simulator;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use daemon::controller::ControllerState;
use daemon::controller::Measurement;

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

#[test]
fn controller_tick_does_not_allocate() {
    for robot in ["jvrc1", "armar4"] {
        let mut h = walk_support::Harness::new(robot, 200.0);
        let sequence = walk_support::synthetic_walk(&h.robot, 2, 0.08, true);
        h.start(&sequence);
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
        assert_eq!(
            h.closed.controller.status().state,
            ControllerState::Done,
            "{robot}"
        );
        assert_eq!(
            allocations, 0,
            "{robot}: {allocations} allocations in {ticks} ticks"
        );
    }
}
