//! Forward kinematics, CoM and Jacobians against Pinocchio at 120 random configurations per robot.
//!
//! The fixtures are produced by `tools/pinocchio/make_fixtures.py` (see its docstring for the
//! conventions) and committed, so this test needs no Python.

mod common;

use kinematics::{
    Configuration, DMatrix, Isometry3, Kinematics, Model, Translation3, UnitQuaternion, Vector3,
};
use serde::Deserialize;

const TOLERANCE: f64 = 1e-9;

#[derive(Deserialize)]
struct FrameSpec {
    name: String,
    link: String,
    translation: [f64; 3],
    rpy: [f64; 3],
}

#[derive(Deserialize)]
struct Sample {
    base: [f64; 7],
    joints: Vec<f64>,
    link_poses: Vec<[f64; 7]>,
    frame_poses: Vec<[f64; 7]>,
    com: [f64; 3],
    frame_jacobians: Vec<Vec<Vec<f64>>>,
    com_jacobian: Vec<Vec<f64>>,
}

#[derive(Deserialize)]
struct Fixture {
    urdf: String,
    total_mass: f64,
    joint_names: Vec<String>,
    frames: Vec<FrameSpec>,
    links: Vec<String>,
    samples: Vec<Sample>,
}

fn isometry(p: &[f64; 7]) -> Isometry3<f64> {
    let rotation =
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(p[6], p[3], p[4], p[5]));
    Isometry3::from_parts(Translation3::new(p[0], p[1], p[2]), rotation)
}

/// Asserts agreement within [`TOLERANCE`]; returns the largest deviation.
fn assert_pose_eq(ours: &Isometry3<f64>, reference: &[f64; 7], what: &str) -> f64 {
    let reference = isometry(reference);
    let dp = (ours.translation.vector - reference.translation.vector).amax();
    let dr = (ours.rotation.to_rotation_matrix().matrix()
        - reference.rotation.to_rotation_matrix().matrix())
    .amax();
    assert!(
        dp < TOLERANCE && dr < TOLERANCE,
        "{what}: translation error {dp:e}, rotation error {dr:e}"
    );
    dp.max(dr)
}

/// Compares our Jacobian with the reference, whose joint columns are in Pinocchio's order;
/// returns the largest deviation.
fn assert_jacobian_eq(
    ours: &DMatrix<f64>,
    reference: &[Vec<f64>],
    columns: &[usize],
    what: &str,
) -> f64 {
    let mut largest: f64 = 0.0;
    assert_eq!(reference.len(), ours.nrows(), "{what}: row count");
    for (r, row) in reference.iter().enumerate() {
        assert_eq!(row.len(), ours.ncols(), "{what}: column count");
        for (c, &expected) in row.iter().enumerate() {
            let ours_column = if c < 6 { c } else { columns[c - 6] };
            let error = (ours[(r, ours_column)] - expected).abs();
            assert!(
                error < TOLERANCE,
                "{what}: entry ({r}, {c}) ours {} reference {expected} error {error:e}",
                ours[(r, ours_column)]
            );
            largest = largest.max(error);
        }
    }
    largest
}

fn check(fixture_name: &str) {
    let path = common::workspace_path(&format!("kinematics/tests/fixtures/{fixture_name}.json"));
    let fixture: Fixture = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let mut model = Model::from_urdf_path(&common::workspace_path(&fixture.urdf)).unwrap();
    assert!((model.total_mass() - fixture.total_mass).abs() < TOLERANCE);
    let frames: Vec<_> = fixture
        .frames
        .iter()
        .map(|f| {
            let link = model.link_index(&f.link).unwrap();
            model
                .add_frame(
                    &f.name,
                    link,
                    kinematics::model::pose_from_xyz_rpy(f.translation, f.rpy),
                )
                .unwrap()
        })
        .collect();
    // Same joint set; `columns[k]` = our ν column of Pinocchio's k-th joint.
    assert_eq!(fixture.joint_names.len(), model.dof());
    let columns: Vec<usize> = fixture
        .joint_names
        .iter()
        .map(|name| 6 + model.joint_index(name).expect(name))
        .collect();
    let links: Vec<_> = fixture
        .links
        .iter()
        .map(|name| model.link_index(name).expect(name))
        .collect();
    assert_eq!(links.len(), model.link_count());
    assert!(fixture.samples.len() >= 100);

    let mut kin = Kinematics::new(&model);
    let mut jacobian = DMatrix::zeros(6, model.nv());
    let mut com_jacobian = DMatrix::zeros(3, model.nv());
    let (mut pose_error, mut jacobian_error, mut com_error_max): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for (s, sample) in fixture.samples.iter().enumerate() {
        let mut q = Configuration::neutral(&model);
        q.base = isometry(&sample.base);
        for (k, &value) in sample.joints.iter().enumerate() {
            q.joints[columns[k] - 6] = value;
        }
        kin.update(&model, &q);
        for (l, &link) in links.iter().enumerate() {
            let what = format!("sample {s} link {}", fixture.links[l]);
            pose_error = pose_error.max(assert_pose_eq(
                kin.link_pose(link),
                &sample.link_poses[l],
                &what,
            ));
        }
        let com_error = (kin.com() - Vector3::from(sample.com)).amax();
        assert!(com_error < TOLERANCE, "sample {s}: CoM error {com_error:e}");
        com_error_max = com_error_max.max(com_error);
        for (f, &frame) in frames.iter().enumerate() {
            let name = &fixture.frames[f].name;
            let what = format!("sample {s} frame {name}");
            pose_error = pose_error.max(assert_pose_eq(
                &kin.frame_pose(&model, frame),
                &sample.frame_poses[f],
                &what,
            ));
            kin.frame_jacobian(&model, frame, &mut jacobian);
            let what = format!("sample {s} Jacobian of {name}");
            jacobian_error = jacobian_error.max(assert_jacobian_eq(
                &jacobian,
                &sample.frame_jacobians[f],
                &columns,
                &what,
            ));
        }
        kin.com_jacobian(&model, &mut com_jacobian);
        let what = format!("sample {s} CoM Jacobian");
        jacobian_error = jacobian_error.max(assert_jacobian_eq(
            &com_jacobian,
            &sample.com_jacobian,
            &columns,
            &what,
        ));
    }
    println!(
        "{fixture_name}: {} samples, largest deviation from Pinocchio: poses {pose_error:.1e}, CoM {com_error_max:.1e}, Jacobians {jacobian_error:.1e}",
        fixture.samples.len()
    );
}

#[test]
fn armar4_matches_pinocchio() {
    check("armar4");
}

#[test]
fn jvrc1_matches_pinocchio() {
    check("jvrc1");
}
