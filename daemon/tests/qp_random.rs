//! Dense active-set vs clarabel on seeded random controller-sized QPs, plus a KKT certificate
//! of every dense solution that does not depend on clarabel, including degenerate constraint
//! sets (duplicate rows, equal lower and upper bounds, fixed joints).

mod qp_common;

use daemon::qp::{ClarabelSolver, DenseActiveSetSolver, QpInfo, QpProblem, QpSolver};
use nalgebra::DVector;
use qp_common::{
    Activity, Conditioning, Shape, assert_certified, controller_like, kkt, rel_dist, rel_gap,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Solves `problem` with both solvers (a failure panics naming `case`), asserts the dense
/// objective is clarabel's to 1e-6 (relative), and returns the dense report, the dense solution
/// and clarabel's.
fn solve_both(
    dense: &mut DenseActiveSetSolver,
    clarabel: &mut ClarabelSolver,
    problem: &QpProblem,
    case: &str,
) -> (QpInfo, DVector<f64>, DVector<f64>) {
    let (mut x, mut x_ref) = (vec![0.0; problem.n()], vec![0.0; problem.n()]);
    let info = dense
        .solve(problem, &mut x)
        .unwrap_or_else(|e| panic!("dense, {case}: {e}"));
    let info_ref = clarabel
        .solve(problem, &mut x_ref)
        .unwrap_or_else(|e| panic!("clarabel, {case}: {e}"));
    let obj_rel = rel_gap(info.objective, info_ref.objective);
    assert!(
        obj_rel <= 1e-6,
        "{case}: objective {} vs clarabel {} (rel {obj_rel:e})",
        info.objective,
        info_ref.objective
    );
    (info, DVector::from_vec(x), DVector::from_vec(x_ref))
}

fn cross_check(seed: u64, shape: Shape, activity: Activity) -> (usize, usize) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut dense = DenseActiveSetSolver::new(shape.n, shape.m_eq, shape.m_ineq);
    let mut clarabel = ClarabelSolver::high_precision();
    let mut total_active = 0;
    let count = 15;
    for k in 0..count {
        let problem = controller_like(&mut rng, shape, Conditioning::Well, activity);
        let (info, x_dense, x_ref) =
            solve_both(&mut dense, &mut clarabel, &problem, &format!("problem {k}"));
        let dist = rel_dist(&x_dense, &x_ref);
        assert!(
            dist <= 1e-5,
            "problem {k}: x differs from clarabel by {dist:e}"
        );
        assert_certified(&problem, &x_dense, &info, &format!("problem {k}"));
        if activity == Activity::None {
            assert_eq!(
                info.active_constraints, 0,
                "problem {k}: loose constraints must not be active"
            );
        }
        total_active += info.active_constraints;
    }
    (total_active, count)
}

#[test]
fn n36_without_active_constraints_matches_clarabel() {
    cross_check(1, Shape::new(36, 12, 8), Activity::None);
}

/// [`cross_check`] with active constraints: the generator must activate several per problem.
fn cross_check_with_active_constraints(seed: u64, shape: Shape) {
    let (active, count) = cross_check(seed, shape, Activity::Some);
    assert!(
        active >= 3 * count,
        "the generator should activate several constraints per problem, got {active} over {count}"
    );
}

#[test]
fn n36_with_active_constraints_matches_clarabel() {
    cross_check_with_active_constraints(2, Shape::new(36, 12, 12));
}

#[test]
fn n40_with_active_constraints_matches_clarabel() {
    cross_check_with_active_constraints(3, Shape::new(40, 12, 16));
}

#[test]
fn degenerate_constraints_match_clarabel() {
    let shape = Shape::new(36, 12, 12);
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let mut dense = DenseActiveSetSolver::new(shape.n, shape.m_eq, shape.m_ineq);
    let mut clarabel = ClarabelSolver::high_precision();
    for k in 0..10 {
        let mut problem = controller_like(&mut rng, shape, Conditioning::Well, Activity::Some);
        let mut x_eq = vec![0.0; shape.n];
        dense.solve(&problem, &mut x_eq).unwrap();
        {
            let mut parts = problem.parts_mut();
            // Row 1 duplicates row 0 (same bounds); row 2 becomes an equality written as l = u
            // at its current value; joint 20 is fixed where the solution had it; an equality row
            // is repeated.
            let row0 = parts.c.row(0).into_owned();
            parts.c.row_mut(1).copy_from(&row0);
            parts.l[1] = parts.l[0];
            parts.u[1] = parts.u[0];
            let value: f64 = (0..shape.n).map(|j| parts.c[(2, j)] * x_eq[j]).sum();
            parts.l[2] = value;
            parts.u[2] = value;
            parts.x_min[20] = x_eq[20];
            parts.x_max[20] = x_eq[20];
            let a0 = parts.a_eq.row(0).into_owned();
            parts.a_eq.row_mut(11).copy_from(&a0);
            parts.b_eq[11] = parts.b_eq[0];
        }
        let (_, x, _) = solve_both(&mut dense, &mut clarabel, &problem, &format!("problem {k}"));
        let cert = kkt(&problem, &x, 1e-9);
        assert!(
            cert.primal.max(cert.stationarity) <= 1e-9,
            "problem {k}: dense KKT residuals {cert:?}"
        );
    }
}

#[test]
fn varied_shapes_match_clarabel() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut clarabel = ClarabelSolver::high_precision();
    for k in 0..120 {
        let n = rng.random_range(3..=40);
        let shape = Shape {
            n,
            m_eq: rng.random_range(0..=n / 3),
            m_ineq: rng.random_range(0..=20),
        };
        let activity = if rng.random_bool(0.3) {
            Activity::None
        } else {
            Activity::Some
        };
        let problem = controller_like(&mut rng, shape, Conditioning::Well, activity);
        let mut dense = DenseActiveSetSolver::new(shape.n, shape.m_eq, shape.m_ineq);
        let case = format!("problem {k} {shape:?}");
        let (_, x, x_ref) = solve_both(&mut dense, &mut clarabel, &problem, &case);
        assert!(
            rel_dist(&x, &x_ref) <= 1e-5,
            "problem {k} {shape:?}: x differs"
        );
        let cert = kkt(&problem, &x, 1e-9);
        assert!(
            cert.worst() <= 1e-9,
            "problem {k} {shape:?}: dense KKT residuals {cert:?}"
        );
    }
}
