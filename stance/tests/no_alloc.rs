//! `PostProcessor::process_into` allocates nothing once its buffers (and the output's) have grown:
//! the Table I timing measures FK and the passes, not the allocator.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use stance::{AffordanceSet, GenerateOptions, PostProcessedSequence, PostProcessor, generate};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator, only counting calls.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn process_into_does_not_allocate_after_warm_up() {
    let (robot, params) = common::armar4();
    let options = GenerateOptions {
        distance: 3.0 / params.scf,
        affordances: AffordanceSet::FeetLeftHand,
        seed: 9,
    };
    let raw = generate(robot, &options).unwrap();
    let mut processor = PostProcessor::new(robot, params.clone());
    let mut out = PostProcessedSequence::empty();
    processor.process_into(&raw, &mut out).unwrap();
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    for _ in 0..3 {
        processor.process_into(&raw, &mut out).unwrap();
    }
    assert_eq!(ALLOCATIONS.load(Ordering::Relaxed) - before, 0);
    assert_eq!(out.len(), raw.len());
}
