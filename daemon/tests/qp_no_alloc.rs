//! The dense solver performs no heap allocation in `solve` after construction, counted by a
//! global allocator on the solving thread, across cold and warm solves, contact changes and
//! failing solves.

mod qp_common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use daemon::qp::{DenseActiveSetSolver, QpSolver};
use qp_common::{Activity, Conditioning, Shape, controller_like};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

struct CountingAllocator;

thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn record() {
    // `try_with` so allocation during thread teardown cannot panic.
    let _ = ARMED.try_with(|armed| {
        if armed.get() {
            let _ = ALLOCATIONS.try_with(|count| count.set(count.get() + 1));
        }
    });
}

unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        record();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        record();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        record();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

/// Allocations made by `f` on this thread.
fn allocations_during(f: impl FnOnce()) -> usize {
    ALLOCATIONS.with(|c| c.set(0));
    ARMED.with(|a| a.set(true));
    f();
    ARMED.with(|a| a.set(false));
    ALLOCATIONS.with(|c| c.get())
}

#[test]
fn the_counter_sees_allocations() {
    let count = allocations_during(|| drop(std::hint::black_box(vec![1u8; 64])));
    assert_eq!(count, 1);
}

#[test]
fn dense_solve_does_not_allocate() {
    let shape = Shape::new(40, 12, 16);
    let mut rng = ChaCha8Rng::seed_from_u64(41);
    let mut problems: Vec<_> = (0..12)
        .map(|k| {
            let conditioning = if k % 2 == 0 {
                Conditioning::Well
            } else {
                Conditioning::Ill
            };
            let activity = if k % 3 == 0 {
                Activity::None
            } else {
                Activity::Some
            };
            controller_like(&mut rng, shape, conditioning, activity)
        })
        .collect();
    problems[5].set_active_rows(6, 8).unwrap();
    let mut infeasible = problems[1].clone();
    infeasible.parts_mut().x_min[10] = infeasible.x_max()[10] + 1.0;
    problems.push(infeasible);
    let mut nan = problems[2].clone();
    nan.parts_mut().q[3] = f64::NAN;
    problems.push(nan);
    let mut solver = DenseActiveSetSolver::new(shape.n, shape.m_eq, shape.m_ineq);
    let mut x = vec![0.0; shape.n];
    let (mut ok, mut failed) = (0, 0);
    let count = allocations_during(|| {
        for _ in 0..5 {
            for problem in &problems {
                match solver.solve(problem, &mut x) {
                    Ok(_) => ok += 1,
                    Err(_) => failed += 1,
                }
            }
            solver.reset_warm_start();
        }
    });
    assert_eq!(
        (ok, failed),
        (60, 10),
        "every generated problem solves, the two poisoned ones fail"
    );
    assert_eq!(count, 0, "solve allocated {count} times");
}

#[test]
fn dense_solve_does_not_allocate_for_larger_robots() {
    for n in [16, 64, 100, 128] {
        let shape = Shape::new(n, 12, 8);
        let mut rng = ChaCha8Rng::seed_from_u64(42 + n as u64);
        let problems: Vec<_> = (0..4)
            .map(|_| controller_like(&mut rng, shape, Conditioning::Well, Activity::Some))
            .collect();
        let mut solver = DenseActiveSetSolver::new(n, shape.m_eq, shape.m_ineq);
        let mut x = vec![0.0; n];
        let mut ok = 0;
        let count = allocations_during(|| {
            for problem in &problems {
                ok += usize::from(solver.solve(problem, &mut x).is_ok());
            }
        });
        assert_eq!(ok, problems.len(), "n = {n}: every problem solves");
        assert_eq!(count, 0, "n = {n}: solve allocated {count} times");
    }
}
