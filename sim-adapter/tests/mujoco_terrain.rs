//! The MuJoCo world built from a scene (`sim_adapter::mujoco::Terrain`): every committed scene
//! compiles into a box per surface and a capsule per railing; the robot stands at a scene's start
//! as it does on the flat floor, with no leg touching the terrain; a shin driven into a stair's
//! nosing is counted and named, and the count travels in the simulator's truth.
//! Needs the `mujoco` feature (and the library: `eval "$(scripts/setup-mujoco.sh)"`).
#![cfg(feature = "mujoco")]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use kinematic_sim::Simulator;
use kinematics::configuration::Configuration;
use kinematics::kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};
use mujoco_rs::prelude::MjtObjBase;
use nalgebra::{Translation3, Vector3};
use shm_types::SimTruth;
use sim_adapter::mujoco::{MujocoOptions, MujocoSim, Terrain};
use sim_adapter::{GroundTruth, SimulatedRobot};
use stance::Scene;

/// Control period (500 Hz, as walkd runs).
const DT: f64 = 0.002;

fn configs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs")
}

fn robot(name: &str) -> Arc<Robot> {
    let config = configs().join(format!("{name}.toml"));
    Arc::new(Robot::load(&config, None).unwrap_or_else(|e| panic!("{name}: {e}")))
}

fn terrain(scene: &str) -> Terrain {
    let scene = Scene::from_path(&configs().join("scenes").join(scene)).unwrap();
    Terrain::from_scene(&scene).unwrap()
}

/// `robot` in `terrain`, standing in `initial` (world).
fn sim_on(robot: &Arc<Robot>, terrain: Terrain, initial: &Configuration) -> MujocoSim {
    let urdf = robot.urdf.clone();
    MujocoSim::on_terrain(
        robot.clone(),
        &urdf,
        initial,
        MujocoOptions::default(),
        terrain,
    )
    .unwrap()
}

/// Names of the model's geoms starting with `prefix`.
fn geoms_named(sim: &MujocoSim, prefix: &str) -> Vec<String> {
    let model = sim.model();
    (0..model.ngeom() as usize)
        .filter_map(|g| model.id_to_name(MjtObjBase::mjOBJ_GEOM, g))
        .filter(|name| name.starts_with(prefix))
        .map(str::to_owned)
        .collect()
}

#[test]
fn every_committed_scene_builds_a_box_per_surface_and_a_capsule_per_railing() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(configs().join("scenes"))
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 11, "{files:?}");
    for name in ["jvrc1", "armar4"] {
        let robot = robot(name);
        for file in &files {
            let scene = Scene::from_path(file).unwrap();
            let terrain = Terrain::from_scene(&scene).unwrap();
            let sim = sim_on(&robot, terrain.clone(), &terrain.place(&robot.standing));
            let surfaces: Vec<String> = scene
                .environment
                .surfaces
                .iter()
                .map(|s| format!("surface/{}", s.name))
                .collect();
            assert_eq!(geoms_named(&sim, "surface/"), surfaces, "{name} {file:?}");
            let railings = geoms_named(&sim, "railing/");
            let expected = scene.environment.hand_affordances.len();
            assert_eq!(railings.len(), expected, "{name} {file:?}");
            assert_eq!(geoms_named(&sim, "leg/").len(), 4, "{name} {file:?}");
            assert_eq!(sim.terrain_collisions().count, 0, "{name} {file:?}");
        }
    }
}

/// Largest difference (m) between the base heights of `robot` standing still for 2 s at the
/// start of `scene` and on the flat floor, and the terrain collisions counted.
fn stand_at_start(name: &str, scene: &str) -> (f64, u64) {
    let robot = robot(name);
    let terrain = terrain(scene);
    let initial = terrain.place(&robot.standing);
    let mut on_terrain = sim_on(&robot, terrain, &initial);
    let urdf = robot.urdf.clone();
    let mut flat = MujocoSim::new(
        robot.clone(),
        &urdf,
        &robot.standing,
        MujocoOptions::default(),
    )
    .unwrap();
    let q: Vec<f64> = robot.standing.joints.iter().copied().collect();
    let qd = vec![0.0; q.len()];
    let mut worst = (on_terrain.base_height() - flat.base_height()).abs();
    for _ in 0..1000 {
        on_terrain.step(&q, &qd, DT).unwrap();
        flat.step(&q, &qd, DT).unwrap();
        worst = worst.max((on_terrain.base_height() - flat.base_height()).abs());
    }
    assert!(!on_terrain.summary().fell, "{name} on {scene}: fell");
    assert_eq!(
        on_terrain.measurement().contacts,
        [true, true, false, false],
        "{name} on {scene}: both feet and only the feet touch"
    );
    (worst, on_terrain.terrain_collisions().count)
}

#[test]
fn the_robot_stands_at_a_scenes_start_as_on_the_flat_floor() {
    // The start on the floor (z = 0) before stairs and a ramp, and on the top landing (z = 1.85)
    // of the stairs down: the base height is measured from the surface under the base.
    for (name, scene) in [
        ("jvrc1", "stairs-up-10cm.toml"),
        ("jvrc1", "stairs-down-18cm.toml"),
        ("jvrc1", "ramp-15deg.toml"),
        ("armar4", "stairs-up-10cm.toml"),
    ] {
        let (height_error, collisions) = stand_at_start(name, scene);
        assert!(
            height_error < 0.01,
            "{name} on {scene}: base height {height_error} m off the flat floor's"
        );
        assert_eq!(
            collisions, 0,
            "{name} on {scene}: the legs touched the terrain"
        );
    }
}

/// JVRC-1 on the 18.5 cm stairs, its soles' midpoint `to_riser` metres before the first riser,
/// squats in 1.5 s to hip, knee and ankle pitch angles of -1, 2, -1 rad and holds 0.5 s. Returns
/// the simulator.
fn squat_before_the_stairs(to_riser: f64) -> MujocoSim {
    let robot = robot("jvrc1");
    let terrain = terrain("stairs-up-18cm.toml");
    let mut initial = terrain.place(&robot.standing);
    let riser = 1.5;
    let shift = riser - to_riser - terrain.scene().start.translation.x;
    initial.base = Translation3::new(shift, 0.0, 0.0) * initial.base;
    let mut sim = sim_on(&robot, terrain, &initial);
    let standing: Vec<f64> = robot.standing.joints.iter().copied().collect();
    let mut squat = standing.clone();
    for (joint, angle) in [("HIP_P", -1.0), ("KNEE", 2.0), ("ANKLE_P", -1.0)] {
        for side in ["L", "R"] {
            let index = robot.model.joint_index(&format!("{side}_{joint}")).unwrap();
            squat[index] = angle;
        }
    }
    let qd = vec![0.0; standing.len()];
    let steps = (1.5 / DT) as usize;
    for k in 0..steps + (0.5 / DT) as usize {
        // Half-cosine from standing to the squat, then held.
        let s = (0.5
            - 0.5 * (std::f64::consts::PI * (k + 1).min(steps) as f64 / steps as f64).cos())
        .min(1.0);
        let q: Vec<f64> = standing
            .iter()
            .zip(&squat)
            .map(|(a, b)| a + (b - a) * s)
            .collect();
        sim.step(&q, &qd, DT).unwrap();
    }
    sim
}

#[test]
fn a_shin_driven_into_a_nosing_is_counted_and_named() {
    // The toes 5 mm before the riser (the sole is 0.20 m long): the shin axis (knee to ankle)
    // leans 0.89 rad forward, so each shin capsule (radius 0.04 m, from the ankle 0.135 m behind
    // the riser and 0.108 m up) reaches about 1.5 cm into the first tread's nosing (0.185 m up).
    let hit = squat_before_the_stairs(0.105);
    let collisions = hit.terrain_collisions();
    assert!(collisions.count >= 2, "{collisions:?}");
    let mut shins: Vec<&str> = collisions.first.iter().map(|c| &*c.link).collect();
    shins.sort();
    shins.dedup();
    assert_eq!(shins, ["L_KNEE_S", "R_KNEE_S"], "{collisions:?}");
    assert!(
        collisions.first.iter().all(|c| &*c.surface == "tread-1"),
        "{collisions:?}"
    );
    // The simulator's truth (protocol v5) carries the count.
    let count = collisions.count;
    assert_eq!(truth_of(hit).terrain_collisions, count);
    // The same squat 1 m before the riser touches nothing.
    let clear = squat_before_the_stairs(1.0);
    assert_eq!(
        clear.terrain_collisions().count,
        0,
        "{:?}",
        clear.terrain_collisions()
    );
    // ... and stays upright (the squat itself is stable: the pelvis only goes down).
    assert!(clear.torso_tilt() < 0.02, "tilt {} rad", clear.torso_tilt());
    assert_eq!(truth_of(clear).terrain_collisions, 0);
}

/// What walk-sim publishes on `sim-truth` for `sim`'s current state, written over a state that
/// claims collisions (so a count left unwritten shows).
fn truth_of(sim: MujocoSim) -> SimTruth {
    let mut truth = SimTruth {
        terrain_collisions: 99,
        ..SimTruth::ZERO
    };
    SimulatedRobot::new(sim).ground_truth(&mut truth);
    truth
}

#[test]
fn a_palm_on_a_railing_is_read_at_its_wrist_and_in_the_truth() {
    // JVRC-1 stands with a railing along x whose top is 1 mm into its right palm (a sphere of
    // `palm_radius` around the hand frame): the rail pushes the palm up, and nothing else.
    let robot = robot("jvrc1");
    let flat = terrain("railing.toml");
    let initial = flat.place(&robot.standing);
    let palm = sim_on(&robot, flat, &initial)
        .end_effector_pose(EndEffector::RightHand)
        .translation
        .vector;
    let (radius, overlap) = (0.02, 0.001);
    let top = palm.z - robot.palm_radius + overlap;
    let scene = format!(
        "format_version = 1\nname = \"rail-under-the-palm\"\n[path]\nstart = [0.0, 0.0]\n\
         goal = [1.0, 0.0]\n[[surface]]\nname = \"ground\"\ncenter = [0.0, 0.0, 0.0]\n\
         size = [4.0, 3.0]\n[[railing]]\nname = \"rail\"\nstart = [{}, {}, {}]\n\
         end = [{}, {}, {}]\nradius = {radius}\n",
        palm.x - 0.5,
        palm.y,
        top - radius,
        palm.x + 0.5,
        palm.y,
        top - radius
    );
    let file =
        std::env::temp_dir().join(format!("rail-under-the-palm-{}.toml", std::process::id()));
    std::fs::write(&file, scene).unwrap();
    let scene = Scene::from_path(&file).unwrap();
    std::fs::remove_file(&file).unwrap();
    let terrain = Terrain::from_scene(&scene).unwrap();
    let mut sim = sim_on(&robot, terrain.clone(), &terrain.place(&robot.standing));
    let q: Vec<f64> = robot.standing.joints.iter().copied().collect();
    let qd = vec![0.0; q.len()];
    for _ in 0..250 {
        sim.step(&q, &qd, DT).unwrap();
    }
    let measured = sim.measurement().clone();
    assert_eq!(
        measured.contacts[2..],
        [false, true],
        "only the right palm touches"
    );
    let [left, right] = [measured.wrenches[2], measured.wrenches[3]];
    assert_eq!(left, [0.0; 6]);
    assert!(right[2] > 5.0, "the rail pushes the palm up: {right:?}");
    eprintln!("right palm {right:?}, feet {:?}", &measured.wrenches[..2]);
    assert!(
        right[0].hypot(right[1]) < right[2],
        "within the friction cone: {right:?}"
    );
    // About the wrist FT frame: the force acts at the palm's bottom, below the palm centre
    // (within the overlap).
    let mut posture = robot.standing.clone();
    posture.base = measured.base;
    posture.joints.copy_from(&measured.q);
    let mut kinematics = Kinematics::new(&robot.model);
    kinematics.update(&robot.model, &posture);
    let at = |frame| {
        kinematics
            .frame_pose(&robot.model, frame)
            .translation
            .vector
    };
    let wrist = at(robot.wrist_ft_sensors[1]);
    let contact = at(robot.frame(EndEffector::RightHand)) - Vector3::z() * robot.palm_radius;
    let force = Vector3::new(right[0], right[1], right[2]);
    let moment = (contact - wrist).cross(&force);
    for k in 0..3 {
        assert!(
            (right[3 + k] - moment[k]).abs() < overlap * force.norm() + 1e-3,
            "moment about the wrist {right:?} vs {moment:?}"
        );
    }
    // The simulator's truth (protocol v6) carries the palm forces.
    let truth = truth_of(sim);
    assert_eq!(
        truth.hand_forces,
        [[0.0; 3], [right[0], right[1], right[2]]]
    );
}
