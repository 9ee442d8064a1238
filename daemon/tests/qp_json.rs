//! JSON export/import of QPs: round trip (including infinite bounds and fewer active rows than
//! capacity) and errors that name the bad field.

mod qp_common;

use daemon::qp::{
    DenseActiveSetSolver, QpSolver, export_json, problem_from_json, problems_from_json,
};
use qp_common::{Activity, Conditioning, Shape, controller_like};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde_json::json;

#[test]
fn export_then_load_gives_the_same_problem_and_solution() {
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let shape = Shape::new(36, 12, 12);
    let mut problem = controller_like(&mut rng, shape, Conditioning::Well, Activity::Some);
    problem.set_active_rows(6, 9).unwrap();
    assert!(problem.x_min()[0].is_infinite() && problem.u().iter().any(|v| v.is_infinite()));
    let text = export_json(&problem).to_string();
    let loaded = problems_from_json(&serde_json::from_str(&text).unwrap()).unwrap();
    assert_eq!(loaded.len(), 1);
    let loaded = &loaded[0];
    assert_eq!((loaded.m_eq(), loaded.m_ineq()), (6, 9));
    assert_eq!(loaded.p(), problem.p());
    assert_eq!(loaded.q(), problem.q());
    assert_eq!(loaded.a_eq(), problem.a_eq());
    assert_eq!(loaded.b_eq(), problem.b_eq());
    assert_eq!(loaded.c(), problem.c());
    assert_eq!(loaded.l(), problem.l());
    assert_eq!(loaded.u(), problem.u());
    assert_eq!(loaded.x_min(), problem.x_min());
    assert_eq!(loaded.x_max(), problem.x_max());

    let mut solver = DenseActiveSetSolver::new(shape.n, shape.m_eq, shape.m_ineq);
    let (mut x, mut y) = (vec![0.0; shape.n], vec![0.0; shape.n]);
    solver.solve(&problem, &mut x).unwrap();
    solver.reset_warm_start();
    solver.solve(loaded, &mut y).unwrap();
    assert_eq!(x, y);
}

#[test]
fn recordings_may_be_arrays_or_wrapped() {
    let mut rng = ChaCha8Rng::seed_from_u64(22);
    let shape = Shape::new(10, 2, 3);
    let a = export_json(&controller_like(
        &mut rng,
        shape,
        Conditioning::Well,
        Activity::None,
    ));
    let b = export_json(&controller_like(
        &mut rng,
        shape,
        Conditioning::Well,
        Activity::Some,
    ));
    assert_eq!(problems_from_json(&json!([a, b])).unwrap().len(), 2);
    assert_eq!(
        problems_from_json(&json!({ "problems": [a, b, a] }))
            .unwrap()
            .len(),
        3
    );
}

#[test]
fn bad_recordings_name_the_field() {
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    let good = export_json(&controller_like(
        &mut rng,
        Shape::new(8, 2, 2),
        Conditioning::Well,
        Activity::None,
    ));
    let mut missing = good.clone();
    missing.as_object_mut().unwrap().remove("q");
    let err = problem_from_json(&missing).unwrap_err().to_string();
    assert!(err.contains("missing field \"q\""), "{err}");

    let mut short = good.clone();
    short["C"][1].as_array_mut().unwrap().pop();
    let err = problem_from_json(&short).unwrap_err().to_string();
    assert!(err.contains("\"C\"[1] has 7 entries"), "{err}");

    let mut text = good.clone();
    text["b_eq"][1] = json!("x");
    let err = problems_from_json(&json!([good, text]))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("problem 1") && err.contains("\"b_eq\"[1] is not a number"),
        "{err}"
    );

    let mut null_cost = good;
    null_cost["q"][0] = json!(null);
    let err = problem_from_json(&null_cost).unwrap_err().to_string();
    assert!(err.contains("\"q\"[0] is not a number"), "{err}");
}
