//! What walkd's control thread allocates in `DaemonLoopPorts`: taking samples (pinning the
//! adapter, refusing another publisher's samples) allocates nothing; each send (a command, a
//! telemetry) allocates exactly one block inside iceoryx2 0.10 — its loan wraps the chunk's
//! state in an `Rc` — and frees it before returning (docs/architecture.md).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use shm_types::{AdapterPorts, DaemonLoopPorts, SensorSample, ServiceNames};

struct Counting;

thread_local! {
    /// Allocations of this thread while counting (`None`: not counting).
    static ALLOCATIONS: Cell<Option<usize>> = const { Cell::new(None) };
    /// Frees of this thread while counting.
    static FREES: Cell<Option<usize>> = const { Cell::new(None) };
}

fn count() {
    ALLOCATIONS.with(|count| count.set(count.get().map(|n| n + 1)));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        FREES.with(|count| count.set(count.get().map(|n| n + 1)));
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations `work` makes on this thread.
fn allocations(work: impl FnOnce()) -> usize {
    ALLOCATIONS.with(|count| count.set(Some(0)));
    work();
    ALLOCATIONS.with(|count| count.replace(None)).unwrap()
}

#[test]
fn taking_the_pinned_adapters_samples_and_refusing_others_allocates_nothing() {
    let prefix = format!("walk-test/shm-types/pinned-alloc/{}", std::process::id());
    let names = ServiceNames::new(&prefix).unwrap();
    let daemon = DaemonLoopPorts::open(&names, "daemon").unwrap();
    let adapter = AdapterPorts::open(&names, "adapter").unwrap();
    let intruder = AdapterPorts::open(&names, "intruder").unwrap();
    let publish = |ports: &AdapterPorts, seq: u64| {
        ports.publish_sample(|s| s.seq = seq).unwrap();
    };
    let mut sample = SensorSample::ZERO;
    // Connections to both publishers are set up on the first receive (that allocates, once).
    publish(&adapter, 1);
    assert!(daemon.take_latest_sample(&mut sample).unwrap());
    publish(&intruder, 1);
    assert!(!daemon.take_latest_sample(&mut sample).unwrap());
    let pinned = daemon.sensor_pin().pinned();

    // Publishing is not counted: each iceoryx2 loan allocates (the adapter's side).
    let (mut taken, mut counted) = (0, 0);
    for seq in 2..200 {
        publish(&adapter, seq);
        publish(&intruder, seq);
        counted += allocations(|| {
            if daemon.take_latest_sample(&mut sample).unwrap() {
                taken += 1;
            }
            assert_eq!(daemon.sensor_pin().pinned(), pinned);
        });
    }
    assert_eq!(counted, 0, "the control thread's take allocated");
    assert_eq!(taken, 198);
    assert_eq!(daemon.sensor_pin().refused(), 199);
}

#[test]
fn each_send_allocates_one_block_inside_iceoryx2_and_frees_it() {
    let prefix = format!("walk-test/shm-types/send-alloc/{}", std::process::id());
    let names = ServiceNames::new(&prefix).unwrap();
    let daemon = DaemonLoopPorts::open(&names, "daemon").unwrap();
    let adapter = AdapterPorts::open(&names, "adapter").unwrap();
    let mut command = shm_types::JointCommand::ZERO;
    // Connections are set up on the first sends and receives.
    for seq in 0..3 {
        daemon.send_command(|c| c.seq = seq).unwrap();
        daemon.publish_telemetry(|t| t.seq = seq).unwrap();
        adapter.take_latest_command(&mut command).unwrap();
    }
    for seq in 3..100 {
        FREES.with(|count| count.set(Some(0)));
        let allocated = allocations(|| {
            daemon.send_command(|c| c.seq = seq).unwrap();
            daemon.publish_telemetry(|t| t.seq = seq).unwrap();
        });
        let freed = FREES.with(|count| count.replace(None)).unwrap();
        assert_eq!(allocated, 2, "one block a send");
        assert_eq!(freed, 2, "freed before the send returned");
        adapter.take_latest_command(&mut command).unwrap();
    }
}
