//! Dense active-set vs clarabel on seeded random controller-sized QPs, plus a KKT certificate
//! of every dense solution that does not depend on clarabel, including degenerate constraint
//! sets (duplicate rows, equal lower and upper bounds, fixed joints).

mod qp_common;

use daemon::qp::{ClarabelSolver, DenseActiveSetSolver, QpSolver};
use nalgebra::DVector;
use qp_common::{Activity, Conditioning, Shape, controller_like, kkt, rel_dist};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn cross_check(seed: u64, shape: Shape, activity: Activity) -> (usize, usize) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut dense = DenseActiveSetSolver::new(shape.n, shape.m_eq, shape.m_ineq);
    let mut clarabel = ClarabelSolver::high_precision();
    let mut total_active = 0;
    let count = 15;
    for k in 0..count {
        let problem = controller_like(&mut rng, shape, Conditioning::Well, activity);
        let mut x_dense = vec![0.0; shape.n];
        let mut x_ref = vec![0.0; shape.n];
        let info = dense
            .solve(&problem, &mut x_dense)
            .unwrap_or_else(|e| panic!("dense, problem {k}: {e}"));
        let info_ref = clarabel
            .solve(&problem, &mut x_ref)
            .unwrap_or_else(|e| panic!("clarabel, problem {k}: {e}"));
        let (x_dense, x_ref) = (DVector::from_vec(x_dense), DVector::from_vec(x_ref));
        let obj_rel =
            (info.objective - info_ref.objective).abs() / (1.0 + info_ref.objective.abs());
        assert!(
            obj_rel <= 1e-6,
            "problem {k}: objective {} vs clarabel {} (rel {obj_rel:e})",
            info.objective,
            info_ref.objective
        );
        let dist = rel_dist(&x_dense, &x_ref);
        assert!(
            dist <= 1e-5,
            "problem {k}: x differs from clarabel by {dist:e}"
        );
        let cert = kkt(&problem, &x_dense, 1e-9);
        assert!(
            cert.worst() <= 1e-9,
            "problem {k}: dense KKT residuals {cert:?}"
        );
        assert_eq!(
            info.active_constraints, cert.active,
            "problem {k}: reported vs certified active count"
        );
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
    cross_check(
        1,
        Shape {
            n: 36,
            m_eq: 12,
            m_ineq: 8,
        },
        Activity::None,
    );
}

#[test]
fn n36_with_active_constraints_matches_clarabel() {
    let (active, count) = cross_check(
        2,
        Shape {
            n: 36,
            m_eq: 12,
            m_ineq: 12,
        },
        Activity::Some,
    );
    assert!(
        active >= 3 * count,
        "the generator should activate several constraints per problem, got {active} over {count}"
    );
}

#[test]
fn n40_with_active_constraints_matches_clarabel() {
    let (active, count) = cross_check(
        3,
        Shape {
            n: 40,
            m_eq: 12,
            m_ineq: 16,
        },
        Activity::Some,
    );
    assert!(
        active >= 3 * count,
        "the generator should activate several constraints per problem, got {active} over {count}"
    );
}

#[test]
fn degenerate_constraints_match_clarabel() {
    let shape = Shape {
        n: 36,
        m_eq: 12,
        m_ineq: 12,
    };
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
        let (mut x, mut x_ref) = (vec![0.0; shape.n], vec![0.0; shape.n]);
        let info = dense
            .solve(&problem, &mut x)
            .unwrap_or_else(|e| panic!("dense, problem {k}: {e}"));
        let info_ref = clarabel
            .solve(&problem, &mut x_ref)
            .unwrap_or_else(|e| panic!("clarabel, problem {k}: {e}"));
        let obj_rel =
            (info.objective - info_ref.objective).abs() / (1.0 + info_ref.objective.abs());
        assert!(
            obj_rel <= 1e-6,
            "problem {k}: objective {} vs clarabel {}",
            info.objective,
            info_ref.objective
        );
        let x = DVector::from_vec(x);
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
        let (mut x, mut x_ref) = (vec![0.0; n], vec![0.0; n]);
        let info = dense
            .solve(&problem, &mut x)
            .unwrap_or_else(|e| panic!("dense, problem {k} {shape:?}: {e}"));
        let info_ref = clarabel
            .solve(&problem, &mut x_ref)
            .unwrap_or_else(|e| panic!("clarabel, problem {k} {shape:?}: {e}"));
        let obj_rel =
            (info.objective - info_ref.objective).abs() / (1.0 + info_ref.objective.abs());
        assert!(
            obj_rel <= 1e-6,
            "problem {k} {shape:?}: objective {} vs {}",
            info.objective,
            info_ref.objective
        );
        let x = DVector::from_vec(x);
        assert!(
            rel_dist(&x, &DVector::from_vec(x_ref)) <= 1e-5,
            "problem {k} {shape:?}: x differs"
        );
        let cert = kkt(&problem, &x, 1e-9);
        assert!(
            cert.worst() <= 1e-9,
            "problem {k} {shape:?}: dense KKT residuals {cert:?}"
        );
    }
}
