//! Ill-conditioned controller QPs (cond(P) ≈ 1e8–1e9 from a low posture weight): the dense
//! solution satisfies the KKT conditions to round-off and equals the exact solve of the KKT
//! system at its active set; clarabel with tight tolerances lands close but measurably away.

mod qp_common;

use daemon::qp::{ClarabelSolver, DenseActiveSetSolver, QpSolver};
use nalgebra::DVector;
use qp_common::{
    Activity, Conditioning, Shape, assert_certified, condition_number, controller_like,
    exact_at_active_set, rel_dist, rel_gap,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn check(seed: u64, shape: Shape, activity: Activity) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut dense = DenseActiveSetSolver::new(shape.n, shape.m_eq, shape.m_ineq);
    let mut clarabel = ClarabelSolver::high_precision();
    for k in 0..10 {
        let problem = controller_like(&mut rng, shape, Conditioning::Ill, activity);
        let cond = condition_number(&problem);
        assert!(
            (1e8..=2e9).contains(&cond),
            "problem {k}: generator gave cond(P) = {cond:e}"
        );
        let mut x = vec![0.0; shape.n];
        let info = dense
            .solve(&problem, &mut x)
            .unwrap_or_else(|e| panic!("dense, problem {k}: {e}"));
        let x = DVector::from_vec(x);
        assert_certified(&problem, &x, &info, &format!("problem {k} (cond {cond:e})"));
        let exact = exact_at_active_set(&problem, &x, 1e-9);
        let dist = rel_dist(&x, &exact);
        let obj_exact = problem.objective(exact.as_slice());
        let obj_rel = rel_gap(info.objective, obj_exact);
        assert!(
            obj_rel <= 1e-12,
            "problem {k} (cond {cond:e}): objective off the exact KKT solve by {obj_rel:e}"
        );
        // Forward error of any backward-stable solve is O(cond · eps); allow 1e-15 · cond.
        assert!(
            dist <= 1e-15 * cond,
            "problem {k} (cond {cond:e}): x off the exact KKT solve by {dist:e}"
        );
        let mut x_ref = vec![0.0; shape.n];
        let info_ref = clarabel
            .solve(&problem, &mut x_ref)
            .unwrap_or_else(|e| panic!("clarabel, problem {k}: {e}"));
        let ref_obj_rel = rel_gap(info.objective, info_ref.objective);
        eprintln!(
            "problem {k}: cond {cond:.1e}, active {}, |x - exact| {dist:.1e}, obj vs exact {obj_rel:.1e}, |x - clarabel| {:.1e}, obj vs clarabel {ref_obj_rel:.1e}",
            info.active_constraints,
            rel_dist(&x, &DVector::from_vec(x_ref))
        );
        assert!(
            ref_obj_rel <= 1e-6,
            "problem {k}: objective {} vs clarabel {}",
            info.objective,
            info_ref.objective
        );
    }
}

#[test]
fn ill_conditioned_without_active_constraints_is_exact() {
    check(11, Shape::new(36, 12, 8), Activity::None);
}

#[test]
fn ill_conditioned_n36_with_active_constraints_is_exact() {
    check(12, Shape::new(36, 12, 12), Activity::Some);
}

#[test]
fn ill_conditioned_n40_with_active_constraints_is_exact() {
    check(13, Shape::new(40, 12, 16), Activity::Some);
}
