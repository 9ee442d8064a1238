//! Every frame Jacobian and the CoM Jacobian against central finite differences of the forward
//! kinematics, at random configurations, on both vendored models.

mod common;

use kinematics::{Configuration, DMatrix, Kinematics, LinkId, Model, Vector3};

const STEP: f64 = 1e-6;
const TOLERANCE: f64 = 1e-6;

/// Configuration moved by `step` along the k-th coordinate of ν.
fn perturbed(q: &Configuration, k: usize, step: f64) -> Configuration {
    let mut nu = vec![0.0; 6 + q.joints.len()];
    nu[k] = 1.0;
    let mut moved = q.clone();
    moved.integrate(&nu, step);
    moved
}

fn check_model(mut model: Model, seed: u64) {
    let mut rng = common::rng(seed);
    // One frame per link at a random offset, so every supporting chain is exercised.
    let links: Vec<LinkId> = model.link_ids().collect();
    let frames: Vec<_> = links
        .into_iter()
        .map(|link| {
            let name = format!("probe_{}", link.index());
            let offset = common::random_pose(&mut rng);
            model.add_frame(&name, link, offset).unwrap()
        })
        .collect();
    let nv = model.nv();
    let mut kin = Kinematics::new(&model);
    let mut plus = Kinematics::new(&model);
    let mut minus = Kinematics::new(&model);
    let mut jacobian = DMatrix::zeros(6, nv);
    let mut com_jacobian = DMatrix::zeros(3, nv);
    for _ in 0..5 {
        let q = common::random_configuration(&model, &mut rng);
        kin.update(&model, &q);
        kin.com_jacobian(&model, &mut com_jacobian);
        for k in 0..nv {
            plus.update(&model, &perturbed(&q, k, STEP));
            minus.update(&model, &perturbed(&q, k, -STEP));
            let dcom = (plus.com() - minus.com()) / (2.0 * STEP);
            let analytic = com_jacobian.fixed_view::<3, 1>(0, k).into_owned();
            assert!(
                (dcom - analytic).norm() < TOLERANCE,
                "CoM Jacobian column {k}: fd {dcom:?} vs {analytic:?}"
            );
            for &frame in &frames {
                kin.frame_jacobian(&model, frame, &mut jacobian);
                let p = plus.frame_pose(&model, frame);
                let m = minus.frame_pose(&model, frame);
                let linear = (p.translation.vector - m.translation.vector) / (2.0 * STEP);
                let angular: Vector3<f64> =
                    (p.rotation * m.rotation.inverse()).scaled_axis() / (2.0 * STEP);
                let column = jacobian.column(k);
                let error = (linear - column.fixed_rows::<3>(0)).norm()
                    + (angular - column.fixed_rows::<3>(3)).norm();
                assert!(
                    error < TOLERANCE,
                    "frame '{}' Jacobian column {k}: error {error:e}",
                    model.frame_name(frame)
                );
            }
        }
    }
}

#[test]
fn armar4_jacobians_match_finite_differences() {
    check_model(Model::from_urdf_path(&common::armar4_urdf()).unwrap(), 1);
}

#[test]
fn jvrc1_jacobians_match_finite_differences() {
    check_model(Model::from_urdf_path(&common::jvrc1_urdf()).unwrap(), 2);
}
