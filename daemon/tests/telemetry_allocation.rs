//! `Controller::telemetry` allocates nothing (the control thread calls it after every tick's
//! command) and reports what the controller estimated: the same sole poses and CoM as its status,
//! the feet in contact in its contact set, a support polygon while a foot stands.

mod walk_support;

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

#[test]
fn telemetry_allocates_nothing_and_matches_the_status() {
    for robot in ["jvrc1", "armar4"] {
        let mut h = walk_support::Harness::new(robot, 200.0);
        let sequence = walk_support::synthetic_walk(&h.robot, 2, 0.08, true);
        h.start(&sequence);
        let (mut ticks, mut allocations, mut with_support) = (0, 0, 0);
        while h.controller.status().state != ControllerState::Done && ticks < 20_000 {
            let m = h.sim.measurement();
            let measurement = Measurement {
                q: m.q.as_slice(),
                qd: m.qd.as_slice(),
                wrenches: &m.wrenches,
                imu_orientation: Some(m.base_orientation),
            };
            assert!(h.controller.tick(&measurement, h.dt, &mut h.command));
            ALLOCATIONS.store(0, Ordering::Relaxed);
            COUNTING.store(true, Ordering::Relaxed);
            let telemetry = h.controller.telemetry();
            COUNTING.store(false, Ordering::Relaxed);
            allocations += ALLOCATIONS.load(Ordering::Relaxed);
            let status = h.controller.status();
            assert_eq!(telemetry.end_effectors[0], status.left_foot, "{robot}");
            assert_eq!(telemetry.end_effectors[1], status.right_foot, "{robot}");
            assert_eq!(telemetry.com, status.com, "{robot}");
            assert_eq!(telemetry.contacts, status.contacts, "{robot}");
            assert_eq!(telemetry.stance_index, status.stance_index, "{robot}");
            if telemetry.contacts[0] || telemetry.contacts[1] {
                assert!(telemetry.support.vertices().len() >= 3, "{robot}");
                with_support += 1;
            }
            assert!(
                telemetry.balance.is_none(),
                "{robot}: the static gait has no ZMP/DCM"
            );
            h.sim
                .step(
                    h.command.q_des.as_slice(),
                    h.command.qd_des.as_slice(),
                    h.dt,
                )
                .unwrap();
            ticks += 1;
        }
        assert_eq!(
            h.controller.status().state,
            ControllerState::Done,
            "{robot}"
        );
        assert!(with_support > ticks / 2, "{robot}");
        assert_eq!(
            allocations, 0,
            "{robot}: {allocations} allocations in {ticks} ticks"
        );
    }
}
