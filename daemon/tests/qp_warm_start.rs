//! Warm start: along slowly changing problem sequences (the controller's ticks, including a
//! contact change), warm-started solves equal cold solves and need fewer iterations.

mod qp_common;

use daemon::qp::{DenseActiveSetSolver, QpProblem, QpSolver};
use nalgebra::DVector;
use qp_common::{Activity, Conditioning, Shape, controller_like, kkt, rel_dist};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Solves `ticks` drifting variants of a problem with one warm solver and with cold solves;
/// returns (warm, cold) iteration totals after checking every pair of solutions agrees.
fn run(seed: u64, shape: Shape, conditioning: Conditioning, ticks: usize) -> (usize, usize) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let base = controller_like(&mut rng, shape, conditioning, Activity::Some);
    let dq = DVector::from_fn(shape.n, |_, _| rng.random_range(-1.0..1.0));
    let mut warm = DenseActiveSetSolver::new(shape.n, shape.m_eq, shape.m_ineq);
    let mut cold = DenseActiveSetSolver::new(shape.n, shape.m_eq, shape.m_ineq);
    let (mut warm_total, mut cold_total) = (0, 0);
    let mut problem: QpProblem = base.clone();
    for tick in 0..ticks {
        let drift = tick as f64;
        {
            let mut parts = problem.parts_mut();
            parts.q.copy_from(&(base.q() + drift * 2e-3 * &dq));
            for j in 6..shape.n {
                parts.x_min[j] = base.x_min()[j] - drift * 1e-4;
                parts.x_max[j] = base.x_max()[j] - drift * 1e-4;
            }
        }
        // Contact change half-way: fewer equality and support-polygon rows.
        if tick == ticks / 2 {
            problem
                .set_active_rows(shape.m_eq / 2, shape.m_ineq - 4)
                .unwrap();
        }
        let (mut x_warm, mut x_cold) = (vec![0.0; shape.n], vec![0.0; shape.n]);
        let info_warm = warm
            .solve(&problem, &mut x_warm)
            .unwrap_or_else(|e| panic!("warm, tick {tick}: {e}"));
        cold.reset_warm_start();
        let info_cold = cold
            .solve(&problem, &mut x_cold)
            .unwrap_or_else(|e| panic!("cold, tick {tick}: {e}"));
        let (x_warm, x_cold) = (DVector::from_vec(x_warm), DVector::from_vec(x_cold));
        let dist = rel_dist(&x_warm, &x_cold);
        let tol = if conditioning == Conditioning::Well {
            1e-10
        } else {
            1e-8
        };
        assert!(
            dist <= tol,
            "tick {tick}: warm and cold solutions differ by {dist:e}"
        );
        assert_eq!(
            info_warm.active_constraints, info_cold.active_constraints,
            "tick {tick}: active sets"
        );
        let cert = kkt(&problem, &x_warm, 1e-9);
        assert!(
            cert.worst() <= 1e-9,
            "tick {tick}: warm KKT residuals {cert:?}"
        );
        warm_total += info_warm.iterations;
        cold_total += info_cold.iterations;
    }
    (warm_total, cold_total)
}

/// [`run`] over 40 ticks (`what` names the sequences): warm starts must at least halve the
/// iterations of cold ones.
fn assert_warm_start_halves_iterations(
    what: &str,
    seed: u64,
    shape: Shape,
    conditioning: Conditioning,
) {
    let (warm, cold) = run(seed, shape, conditioning, 40);
    eprintln!("{what}: warm {warm} vs cold {cold} iterations over 40 ticks");
    assert!(
        2 * warm < cold,
        "warm start should at least halve the iterations: warm {warm}, cold {cold}"
    );
}

#[test]
fn warm_start_matches_cold_start_with_fewer_iterations() {
    let shape = Shape::new(36, 12, 12);
    assert_warm_start_halves_iterations("well-conditioned", 31, shape, Conditioning::Well);
}

#[test]
fn warm_start_matches_cold_start_on_ill_conditioned_sequences() {
    let shape = Shape::new(40, 12, 16);
    assert_warm_start_halves_iterations("ill-conditioned", 32, shape, Conditioning::Ill);
}
