//! `Kinematics::update_frames` (ancestor chains only) against the full `Kinematics::update`.

mod common;

use std::collections::HashSet;

use kinematics::{EndEffector, FrameSet, Kinematics, Robot};

const TOLERANCE: f64 = 1e-12;

fn check_robot(name: &str, seed: u64) {
    let robot = Robot::load(
        &common::workspace_path(&format!("configs/{name}.toml")),
        None,
    )
    .unwrap();
    let model = &robot.model;
    let frames = EndEffector::ALL.map(|e| robot.frame(e));
    let set = FrameSet::new(model, &frames);

    // The set is the union of the chains, parent first, and smaller than the whole tree.
    let links: Vec<usize> = set.links().map(|l| l.index()).collect();
    assert_eq!(links[0], 0, "{name}: the base starts every chain");
    assert!(
        links.windows(2).all(|w| w[0] < w[1]),
        "{name}: not in link order"
    );
    assert!(
        links.len() < model.link_count(),
        "{name}: the set is the whole tree"
    );
    let members: HashSet<usize> = links.iter().copied().collect();
    for &frame in &frames {
        assert!(members.contains(&model.frame_link(frame).index()));
    }

    let mut rng = common::rng(seed);
    let mut full = Kinematics::new(model);
    let mut partial = Kinematics::new(model);
    for sample in 0..200 {
        // Leave the partial workspace at another configuration so stale poses would show.
        partial.update(model, &common::random_configuration(model, &mut rng));
        let q = common::random_configuration(model, &mut rng);
        full.update(model, &q);
        partial.update_frames(model, &q, &set);
        for (&frame, effector) in frames.iter().zip(EndEffector::ALL) {
            let expected = full.frame_pose(model, frame);
            let got = partial.frame_pose(model, frame);
            let dp = (got.translation.vector - expected.translation.vector).amax();
            let dr = (got.rotation.coords - expected.rotation.coords).amax();
            assert!(
                dp <= TOLERANCE && dr <= TOLERANCE,
                "{name} sample {sample} {effector:?}: translation error {dp:e}, rotation error {dr:e}"
            );
        }
    }
}

#[test]
fn armar4_frames_match_full_update() {
    check_robot("armar4", 11);
}

#[test]
fn jvrc1_frames_match_full_update() {
    check_robot("jvrc1", 12);
}

#[test]
#[should_panic(expected = "frame set of another model")]
fn frame_set_of_another_model_is_refused() {
    let armar4 = Robot::load(&common::workspace_path("configs/armar4.toml"), None).unwrap();
    let jvrc1 = Robot::load(&common::workspace_path("configs/jvrc1.toml"), None).unwrap();
    let set = FrameSet::new(&armar4.model, &[armar4.frame(EndEffector::ALL[0])]);
    let mut kinematics = Kinematics::new(&jvrc1.model);
    kinematics.update_frames(&jvrc1.model, &jvrc1.standing, &set);
}
