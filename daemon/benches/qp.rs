//! Dense active-set vs clarabel on the same seeded controller-sized QPs (criterion).
//!
//! Cases: n = 36 with no active inequality and with several active, n = 40 with several active,
//! and ill-conditioned (cond(P) ≈ 3e8) variants. `dense_cold` forgets the active set before each
//! solve; `dense_warm` solves a drifting sequence as the controller does tick by tick. The
//! `recorded_*` groups replay QPs the controller exported (`tests/qp_data/`).
//! Run: `cargo bench -p daemon --bench qp`.

#[path = "../tests/qp_common/mod.rs"]
mod qp_common;

use std::hint::black_box;
use std::time::Duration;

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, Criterion, criterion_group, criterion_main};
use daemon::qp::{ClarabelSolver, DenseActiveSetSolver, QpProblem, QpSolver, problems_from_json};
use nalgebra::DVector;
use qp_common::{Activity, Conditioning, Shape, controller_like};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const PROBLEMS: usize = 20;

struct Case {
    name: &'static str,
    shape: Shape,
    conditioning: Conditioning,
    activity: Activity,
}

const CASES: [Case; 5] = [
    Case {
        name: "n36_none_active",
        shape: Shape::new(36, 12, 8),
        conditioning: Conditioning::Well,
        activity: Activity::None,
    },
    Case {
        name: "n36_some_active",
        shape: Shape::new(36, 12, 12),
        conditioning: Conditioning::Well,
        activity: Activity::Some,
    },
    Case {
        name: "n40_some_active",
        shape: Shape::new(40, 12, 16),
        conditioning: Conditioning::Well,
        activity: Activity::Some,
    },
    Case {
        name: "ill_n36_none_active",
        shape: Shape::new(36, 12, 8),
        conditioning: Conditioning::Ill,
        activity: Activity::None,
    },
    Case {
        name: "ill_n40_some_active",
        shape: Shape::new(40, 12, 16),
        conditioning: Conditioning::Ill,
        activity: Activity::Some,
    },
];

/// Independent random problems of one case.
fn problems(case: &Case, seed: u64) -> Vec<QpProblem> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..PROBLEMS)
        .map(|_| controller_like(&mut rng, case.shape, case.conditioning, case.activity))
        .collect()
}

/// A slowly drifting sequence (linear cost and joint bounds move a little each tick).
fn drifting(case: &Case, seed: u64) -> Vec<QpProblem> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let base = controller_like(&mut rng, case.shape, case.conditioning, case.activity);
    let dq = DVector::from_fn(case.shape.n, |_, _| rng.random_range(-1.0..1.0));
    (0..PROBLEMS)
        .map(|tick| {
            let mut problem = base.clone();
            let mut parts = problem.parts_mut();
            parts.q.copy_from(&(base.q() + tick as f64 * 2e-3 * &dq));
            for j in 6..case.shape.n {
                parts.x_min[j] -= tick as f64 * 1e-4;
                parts.x_max[j] -= tick as f64 * 1e-4;
            }
            problem
        })
        .collect()
}

fn mean_active(case: &Case, problems: &[QpProblem]) -> f64 {
    let mut solver = DenseActiveSetSolver::new(case.shape.n, case.shape.m_eq, case.shape.m_ineq);
    let mut x = vec![0.0; case.shape.n];
    let total: usize = problems
        .iter()
        .map(|p| {
            solver
                .solve(p, &mut x)
                .expect("generated problems are feasible")
                .active_constraints
        })
        .sum();
    total as f64 / problems.len() as f64
}

/// The recorded controller QPs of `tests/qp_data/{name}_sample.json`.
fn recorded(name: &str) -> Vec<QpProblem> {
    let path = format!(
        "{}/tests/qp_data/{name}_sample.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    problems_from_json(&serde_json::from_str(&text).expect("recorded QPs are JSON"))
        .unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Benchmarks `solve` as `name` of `group`, on `problems` in turn, one problem per iteration.
fn bench_cycling<R>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    problems: &[QpProblem],
    mut solve: impl FnMut(&QpProblem) -> R,
) {
    let mut i = 0;
    group.bench_function(name, |b| {
        b.iter(|| {
            i += 1;
            black_box(solve(&problems[i % problems.len()]))
        })
    });
}

/// Dense (cold) and clarabel on recorded controller QPs.
fn bench_recorded(c: &mut Criterion) {
    for name in ["jvrc1", "armar4"] {
        let problems = recorded(name);
        let (n, max_eq, max_ineq) = problems.iter().fold((0, 0, 0), |(n, e, i), p| {
            (n.max(p.n()), e.max(p.m_eq()), i.max(p.m_ineq()))
        });
        let mut group = c.benchmark_group(format!("recorded_{name}"));
        let mut x = vec![0.0; n];
        let mut dense = DenseActiveSetSolver::new(n, max_eq, max_ineq);
        bench_cycling(&mut group, "dense_cold", &problems, |p| {
            dense.reset_warm_start();
            dense.solve(p, &mut x).unwrap()
        });
        let mut clarabel = ClarabelSolver::new();
        bench_cycling(&mut group, "clarabel", &problems, |p| {
            clarabel.solve(p, &mut x).unwrap()
        });
        group.finish();
    }
}

fn bench(c: &mut Criterion) {
    for (k, case) in CASES.iter().enumerate() {
        let independent = problems(case, 100 + k as u64);
        let sequence = drifting(case, 200 + k as u64);
        eprintln!(
            "{}: mean active inequalities {:.1}",
            case.name,
            mean_active(case, &independent)
        );
        let mut group = c.benchmark_group(case.name);
        let (n, m_eq, m_ineq) = (case.shape.n, case.shape.m_eq, case.shape.m_ineq);
        let mut x = vec![0.0; n];
        let mut dense = DenseActiveSetSolver::new(n, m_eq, m_ineq);
        bench_cycling(&mut group, "dense_cold", &independent, |p| {
            dense.reset_warm_start();
            dense.solve(p, &mut x).unwrap()
        });
        bench_cycling(&mut group, "dense_warm", &sequence, |p| {
            dense.solve(p, &mut x).unwrap()
        });
        let mut clarabel = ClarabelSolver::new();
        bench_cycling(&mut group, "clarabel", &independent, |p| {
            clarabel.solve(p, &mut x).unwrap()
        });
        group.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(Duration::from_secs(1)).measurement_time(Duration::from_secs(3)).sample_size(50);
    targets = bench, bench_recorded
}
criterion_main!(benches);
