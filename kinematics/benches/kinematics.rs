//! One iteration = forward kinematics of all links + CoM, the four end-effector frame Jacobians
//! and the CoM Jacobian, at a fixed random configuration, per robot; and, separately, forward
//! kinematics of only the four end-effector chains (`update_frames`). Compare with
//! `tools/pinocchio/bench.py` (same work in Pinocchio), see docs/kinematics.md.

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use kinematics::{
    Configuration, DMatrix, EndEffector, FrameSet, Kinematics, Robot, UnitQuaternion, Vector3,
};

fn config(robot: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("configs")
        .join(format!("{robot}.toml"))
}

/// A generic configuration: standing posture, every joint moved a little, base tilted.
fn generic_configuration(robot: &Robot) -> Configuration {
    let mut q = robot.standing.clone();
    for (i, (value, limits)) in q
        .joints
        .iter_mut()
        .zip(robot.model.joint_limits())
        .enumerate()
    {
        *value = (*value + 0.1 * ((i as f64) * 0.7).sin()).clamp(limits.lower, limits.upper);
    }
    q.base.rotation =
        UnitQuaternion::from_scaled_axis(Vector3::new(0.05, -0.03, 0.4)) * q.base.rotation;
    q
}

fn full_update(c: &mut Criterion) {
    for name in ["armar4", "jvrc1"] {
        let robot = Robot::load(&config(name), None).expect("robot config");
        let model = &robot.model;
        let q = generic_configuration(&robot);
        let mut kin = Kinematics::new(model);
        let mut jacobians: Vec<DMatrix<f64>> =
            (0..4).map(|_| DMatrix::zeros(6, model.nv())).collect();
        let mut com_jacobian = DMatrix::zeros(3, model.nv());
        c.bench_function(
            &format!("{name}: FK all links + CoM + 4 frame Jacobians + CoM Jacobian"),
            |b| {
                b.iter(|| {
                    kin.update(model, black_box(&q));
                    for (effector, jacobian) in EndEffector::ALL.iter().zip(jacobians.iter_mut()) {
                        kin.frame_jacobian(model, robot.frame(*effector), jacobian);
                    }
                    kin.com_jacobian(model, &mut com_jacobian);
                    black_box((&jacobians, &com_jacobian, kin.com()));
                })
            },
        );
    }
}

/// Only the four end-effector frame poses (`update_frames`), as stance post-processing needs.
fn effector_frames(c: &mut Criterion) {
    for name in ["armar4", "jvrc1"] {
        let robot = Robot::load(&config(name), None).expect("robot config");
        let model = &robot.model;
        let frames = EndEffector::ALL.map(|e| robot.frame(e));
        let set = FrameSet::new(model, &frames);
        let q = generic_configuration(&robot);
        let mut kin = Kinematics::new(model);
        c.bench_function(
            &format!(
                "{name}: FK of the 4 end-effector chains ({} of {} links)",
                set.links().len(),
                model.link_count()
            ),
            |b| {
                b.iter(|| {
                    kin.update_frames(model, black_box(&q), &set);
                    black_box(frames.map(|frame| kin.frame_pose(model, frame)));
                })
            },
        );
    }
}

criterion_group!(benches, full_update, effector_frames);
criterion_main!(benches);
