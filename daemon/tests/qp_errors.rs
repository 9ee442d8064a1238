//! Failure modes: infeasible problems, NaN inputs, non-convex Hessians and size mismatches
//! give the matching error from both back-ends and leave the output untouched.

mod qp_common;

use daemon::qp::{ClarabelSolver, DenseActiveSetSolver, QpError, QpPartsMut, QpProblem, QpSolver};
use qp_common::{Activity, Conditioning, Shape, controller_like};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

const SHAPE: Shape = Shape::new(36, 12, 10);
const SENTINEL: f64 = 12345.0;

fn base_problem(seed: u64) -> QpProblem {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    controller_like(&mut rng, SHAPE, Conditioning::Well, Activity::Some)
}

/// Runs both solvers; asserts both fail and `x` keeps the sentinel; returns the two errors.
fn both_fail(problem: &QpProblem) -> (QpError, QpError) {
    let mut dense = DenseActiveSetSolver::new(SHAPE.n, SHAPE.m_eq, SHAPE.m_ineq);
    let mut clarabel = ClarabelSolver::new();
    let mut x = vec![SENTINEL; SHAPE.n];
    let dense_err = dense.solve(problem, &mut x).expect_err("dense must fail");
    assert!(x.iter().all(|&v| v == SENTINEL), "dense wrote x on failure");
    let clarabel_err = clarabel
        .solve(problem, &mut x)
        .expect_err("clarabel must fail");
    assert!(
        x.iter().all(|&v| v == SENTINEL),
        "clarabel wrote x on failure"
    );
    (dense_err, clarabel_err)
}

/// `base_problem(seed)` with `edit` applied: both solvers must refuse it as infeasible.
fn assert_infeasible_after(seed: u64, case: &str, edit: impl FnOnce(&mut QpPartsMut<'_>)) {
    let mut problem = base_problem(seed);
    edit(&mut problem.parts_mut());
    let (dense, clarabel) = both_fail(&problem);
    assert_eq!(dense, QpError::Infeasible, "{case}: dense");
    assert_eq!(clarabel, QpError::Infeasible, "{case}: clarabel");
}

#[test]
fn the_base_problem_is_feasible() {
    let problem = base_problem(1);
    let mut x = vec![0.0; SHAPE.n];
    DenseActiveSetSolver::new(SHAPE.n, SHAPE.m_eq, SHAPE.m_ineq)
        .solve(&problem, &mut x)
        .expect("dense");
    ClarabelSolver::new()
        .solve(&problem, &mut x)
        .expect("clarabel");
}

#[test]
fn general_row_conflicting_with_a_bound_is_infeasible() {
    assert_infeasible_after(2, "row vs bound", |parts| {
        parts.c.row_mut(3).fill(0.0);
        parts.c[(3, 20)] = 2.0;
        parts.x_max[20] = 0.1;
        parts.l[3] = 0.5; // 2 x_20 ≥ 0.5 but x_20 ≤ 0.1
        parts.u[3] = f64::INFINITY;
    });
}

#[test]
fn inconsistent_equalities_are_infeasible() {
    let case = "duplicate equality rows with different right-hand sides";
    assert_infeasible_after(3, case, |parts| {
        let row = parts.a_eq.row(0).into_owned();
        parts.a_eq.row_mut(5).copy_from(&row);
        parts.b_eq[5] = parts.b_eq[0] + 1.0;
    });
}

#[test]
fn equality_outside_the_box_is_infeasible() {
    assert_infeasible_after(4, "equality beyond the box", |parts| {
        parts.a_eq.row_mut(2).fill(0.0);
        parts.a_eq[(2, 10)] = 1.0;
        parts.x_min[10] = -0.3;
        parts.x_max[10] = 0.3;
        parts.b_eq[2] = 0.5;
    });
}

#[test]
fn opposite_general_rows_are_infeasible() {
    assert_infeasible_after(5, "c x ≥ 1 and c x ≤ 0", |parts| {
        let row = parts.c.row(0).into_owned();
        parts.c.row_mut(1).copy_from(&(-row));
        parts.l[0] = 1.0; // c x ≥ 1
        parts.u[0] = f64::INFINITY;
        parts.l[1] = 0.0; // −c x ≥ 0, i.e. c x ≤ 0
        parts.u[1] = f64::INFINITY;
    });
}

#[test]
fn crossed_bounds_are_infeasible() {
    assert_infeasible_after(6, "x_min > x_max", |parts| {
        parts.x_min[7] = 0.2;
        parts.x_max[7] = 0.1;
    });
}

#[test]
fn nan_inputs_are_named() {
    type Poison = fn(&mut QpProblem);
    let cases: [(&str, usize, usize, Poison); 9] = [
        ("P", 3, 5, |p| p.parts_mut().p[(3, 5)] = f64::NAN),
        ("q", 7, 0, |p| p.parts_mut().q[7] = f64::NAN),
        ("A_eq", 2, 9, |p| p.parts_mut().a_eq[(2, 9)] = f64::NAN),
        ("b_eq", 11, 0, |p| p.parts_mut().b_eq[11] = f64::NAN),
        ("C", 4, 1, |p| p.parts_mut().c[(4, 1)] = f64::NAN),
        ("l", 6, 0, |p| p.parts_mut().l[6] = f64::NAN),
        ("u", 8, 0, |p| p.parts_mut().u[8] = f64::NAN),
        ("x_min", 30, 0, |p| p.parts_mut().x_min[30] = f64::NAN),
        ("x_max", 0, 0, |p| p.parts_mut().x_max[0] = f64::NAN),
    ];
    for (field, row, col, poison) in cases {
        let mut problem = base_problem(7);
        poison(&mut problem);
        let expected = QpError::InvalidInput {
            field,
            row,
            col,
            what: "is NaN",
        };
        let (dense, clarabel) = both_fail(&problem);
        assert_eq!(dense, expected, "dense, NaN in {field}");
        assert_eq!(clarabel, expected, "clarabel, NaN in {field}");
        assert!(
            dense.to_string().contains(field),
            "message names the field: {dense}"
        );
    }
}

#[test]
fn infinite_cost_and_wrong_side_infinities_are_rejected() {
    let mut problem = base_problem(8);
    problem.parts_mut().q[1] = f64::INFINITY;
    let (dense, _) = both_fail(&problem);
    assert_eq!(
        dense,
        QpError::InvalidInput {
            field: "q",
            row: 1,
            col: 0,
            what: "is infinite"
        }
    );

    let mut problem = base_problem(8);
    problem.parts_mut().x_min[9] = f64::INFINITY;
    let (dense, _) = both_fail(&problem);
    assert!(
        matches!(
            dense,
            QpError::InvalidInput {
                field: "x_min",
                row: 9,
                ..
            }
        ),
        "{dense}"
    );
}

#[test]
fn asymmetric_hessian_is_rejected() {
    let mut problem = base_problem(9);
    problem.parts_mut().p[(4, 2)] += 1.0;
    let (dense, clarabel) = both_fail(&problem);
    let expected = QpError::InvalidInput {
        field: "P",
        row: 4,
        col: 2,
        what: "breaks symmetry",
    };
    assert_eq!(dense, expected);
    assert_eq!(clarabel, expected);
}

#[test]
fn indefinite_hessian_is_not_positive_definite_for_the_dense_solver() {
    let mut problem = base_problem(10);
    problem.parts_mut().p[(17, 17)] = -1.0;
    let mut x = vec![SENTINEL; SHAPE.n];
    let err = DenseActiveSetSolver::new(SHAPE.n, SHAPE.m_eq, SHAPE.m_ineq)
        .solve(&problem, &mut x)
        .unwrap_err();
    assert!(matches!(err, QpError::NotPositiveDefinite { .. }), "{err}");
    assert!(x.iter().all(|&v| v == SENTINEL));

    let mut singular = base_problem(10);
    singular.parts_mut().p.fill(0.0);
    let err = DenseActiveSetSolver::new(SHAPE.n, SHAPE.m_eq, SHAPE.m_ineq)
        .solve(&singular, &mut x)
        .unwrap_err();
    assert!(
        matches!(err, QpError::NotPositiveDefinite { pivot: 0 }),
        "{err}"
    );
}

#[test]
fn sizes_beyond_capacity_are_rejected() {
    let problem = base_problem(11);
    let mut x = vec![0.0; SHAPE.n];
    let err = DenseActiveSetSolver::new(SHAPE.n, SHAPE.m_eq - 1, SHAPE.m_ineq)
        .solve(&problem, &mut x)
        .unwrap_err();
    assert_eq!(
        err,
        QpError::Dimension {
            what: "m_eq",
            expected: SHAPE.m_eq - 1,
            found: SHAPE.m_eq
        }
    );
    let err = DenseActiveSetSolver::new(SHAPE.n + 1, SHAPE.m_eq, SHAPE.m_ineq)
        .solve(&problem, &mut x)
        .unwrap_err();
    assert_eq!(
        err,
        QpError::Dimension {
            what: "n",
            expected: SHAPE.n + 1,
            found: SHAPE.n
        }
    );
    let mut short = vec![0.0; SHAPE.n - 1];
    let err = DenseActiveSetSolver::new(SHAPE.n, SHAPE.m_eq, SHAPE.m_ineq)
        .solve(&problem, &mut short)
        .unwrap_err();
    assert_eq!(
        err,
        QpError::Dimension {
            what: "x",
            expected: SHAPE.n,
            found: SHAPE.n - 1
        }
    );
    let mut resized = problem.clone();
    assert_eq!(
        resized.set_active_rows(SHAPE.m_eq + 1, 0),
        Err(QpError::Dimension {
            what: "m_eq",
            expected: SHAPE.m_eq,
            found: SHAPE.m_eq + 1
        })
    );
}

#[test]
fn solvers_and_problems_can_move_to_the_control_thread() {
    fn assert_send<T: Send + 'static>() {}
    assert_send::<DenseActiveSetSolver>();
    assert_send::<ClarabelSolver>();
    assert_send::<QpProblem>();
    assert_send::<QpError>();
}
