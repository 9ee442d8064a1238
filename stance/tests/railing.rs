//! Walks that hold a scene's railing: a JVRC-1 walk with the right hand, put in
//! `configs/scenes/railing.toml` as `walkctl generate --scene` puts it and post-processed, holds
//! the scene's railing with the palm on top of it; a walk that holds a hand is refused in a
//! scene without a railing, and a walk on the feet alone is not.

mod common;

use std::path::Path;

use kinematics::robot::EndEffector;
use nalgebra::Vector3;
use stance::walk::WalkError;
use stance::{
    AffordanceSet, GenerateOptions, NoRailing, PostProcessor, RawSequence, Scene, WalkRequest,
    generate, walk_in,
};

fn scene(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../configs/scenes")
        .join(format!("{name}.toml"));
    Scene::from_path(&path).unwrap()
}

/// JVRC-1's raw walk of `scene`'s path with `affordances` (generated for `path_length / scf`).
fn raw_walk(scene: &Scene, affordances: AffordanceSet, seed: u64) -> RawSequence {
    let (robot, params) = common::jvrc1();
    let options = GenerateOptions {
        distance: scene.path_length() / params.scf,
        affordances,
        seed,
    };
    generate(robot, &options).unwrap()
}

#[test]
fn a_held_right_hand_rests_on_top_of_the_scene_railing() {
    let (robot, params) = common::jvrc1();
    let scene = scene("railing");
    let environment = scene.walk_environment();
    // The scene starts at the origin heading +x: its walk frame is the world's, and the railing
    // is where the file puts it, 0.45 m to the right, its axis 0.8 m high.
    assert_eq!(
        environment.hand_affordances,
        scene.environment.hand_affordances
    );
    let top = 0.8 + 0.02 + robot.palm_radius;
    for seed in 0..3 {
        let raw = raw_walk(&scene, AffordanceSet::FeetRightHand, seed)
            .in_environment(environment.clone())
            .unwrap();
        let out = PostProcessor::new(robot, params.clone())
            .process(&raw)
            .unwrap();
        let held: Vec<Vector3<f64>> = (0..out.len())
            .filter(|&i| out.contacts(i)[EndEffector::RightHand as usize])
            .map(|i| out.target(i, EndEffector::RightHand).translation.vector)
            .collect();
        assert!(held.len() > 5, "seed {seed}: {} held stances", held.len());
        for hand in held {
            assert!(
                (hand.y + 0.45).abs() < 1e-9 && (hand.z - top).abs() < 1e-9,
                "seed {seed}: a held hand at {hand:?}, not on top of the railing"
            );
            assert!((-0.5..=5.5).contains(&hand.x), "seed {seed}: {hand:?}");
        }
    }
}

#[test]
fn a_held_hand_is_refused_in_a_scene_without_a_railing() {
    let (robot, params) = common::jvrc1();
    let stairs = scene("stairs-up-10cm");
    assert!(stairs.environment.hand_affordances.is_empty());
    let raw = raw_walk(&stairs, AffordanceSet::FeetRightHand, 1);
    let first_held = raw
        .stances()
        .iter()
        .position(|s| s.in_contact(EndEffector::RightHand))
        .unwrap();
    let refusal = raw.in_environment(stairs.walk_environment()).unwrap_err();
    assert_eq!(
        refusal,
        NoRailing {
            hand: EndEffector::RightHand,
            stance: first_held
        }
    );
    assert!(
        refusal
            .to_string()
            .contains("holds a hand on a railing (right_hand from stance")
            && refusal.to_string().contains("but the scene has none"),
        "{refusal}"
    );
    // The commands' walk refuses it too, before post-processing.
    let request = WalkRequest {
        distance: stairs.path_length(),
        affordances: AffordanceSet::FeetRightHand,
        seed: 1,
        speed: None,
    };
    let walked = walk_in(robot, params, &request, &stairs.walk_environment(), |o| {
        generate(robot, o)
    });
    assert!(matches!(walked, Err(WalkError::Scene(_))), "{walked:?}");
    // On the feet alone the scene is fine.
    let feet = raw_walk(&stairs, AffordanceSet::Feet, 1);
    assert!(feet.in_environment(stairs.walk_environment()).is_ok());
}
