//! QPs recorded from the controller (`walkd bench --export-qp`, JVRC-1 and ARMAR-4, double and
//! single support, up to 8 active constraints): dense and clarabel agree, the dense solution is
//! KKT-exact, and a replay with warm starts gives the same solutions.

mod qp_common;

use daemon::qp::{ClarabelSolver, DenseActiveSetSolver, QpProblem, QpSolver, problems_from_json};
use nalgebra::DVector;
use qp_common::{kkt, rel_dist};

fn load(name: &str) -> Vec<QpProblem> {
    let path = format!(
        "{}/tests/qp_data/{name}_sample.json",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{path}: {e}"));
    let problems = problems_from_json(&value).unwrap_or_else(|e| panic!("{path}: {e}"));
    assert!(
        problems.len() >= 4,
        "{path}: expected a sample of several problems"
    );
    problems
}

fn check(name: &str) {
    let problems = load(name);
    let (n, max_eq, max_ineq) = problems.iter().fold((0, 0, 0), |(n, e, i), p| {
        (n.max(p.n()), e.max(p.m_eq()), i.max(p.m_ineq()))
    });
    let mut warm = DenseActiveSetSolver::new(n, max_eq, max_ineq);
    let mut clarabel = ClarabelSolver::high_precision();
    let mut max_active = 0;
    for (k, problem) in problems.iter().enumerate() {
        let mut cold = DenseActiveSetSolver::new(n, max_eq, max_ineq);
        let (mut x, mut x_warm, mut x_ref) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let info = cold
            .solve(problem, &mut x)
            .unwrap_or_else(|e| panic!("{name} {k}: dense: {e}"));
        warm.solve(problem, &mut x_warm)
            .unwrap_or_else(|e| panic!("{name} {k}: warm dense: {e}"));
        let info_ref = clarabel
            .solve(problem, &mut x_ref)
            .unwrap_or_else(|e| panic!("{name} {k}: clarabel: {e}"));
        let x = DVector::from_vec(x);
        let cert = kkt(problem, &x, 1e-9);
        assert!(cert.worst() <= 1e-12, "{name} {k}: KKT residuals {cert:?}");
        assert_eq!(
            info.active_constraints, cert.active,
            "{name} {k}: active count"
        );
        let obj_rel =
            (info.objective - info_ref.objective).abs() / (1.0 + info_ref.objective.abs());
        assert!(
            obj_rel <= 1e-8,
            "{name} {k}: objective vs clarabel {obj_rel:e}"
        );
        let dist = rel_dist(&x, &DVector::from_vec(x_ref));
        assert!(dist <= 1e-6, "{name} {k}: x vs clarabel {dist:e}");
        let warm_dist = rel_dist(&DVector::from_vec(x_warm), &x);
        assert!(warm_dist <= 1e-10, "{name} {k}: warm vs cold {warm_dist:e}");
        max_active = max_active.max(info.active_constraints);
    }
    assert!(
        max_active >= 2,
        "{name}: the sample should contain active constraints"
    );
}

#[test]
fn recorded_jvrc1_problems() {
    check("jvrc1");
}

#[test]
fn recorded_armar4_problems() {
    check("armar4");
}
