//! Walks put onto the committed scenes: a JVRC-1 walk from the synthetic source, asked for the
//! way every walking command asks for one (`stance::walk_in`), post-processed with a gait's
//! limits. Every foothold fits its surface, one foot per stair where the step limit takes two
//! treads and both feet on each otherwise, the walk ends at the goal, on its surface, and every
//! swing clears what it passes. And a flat walk comes out of post-processing exactly as it did
//! before the terrain pass existed, but for its held hands, now on top of their railing.

mod common;

use std::path::Path;

use kinematics::ConfigFile;
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Point3, Vector3};
use stance::derived::{steps, swing_reference};
use stance::passes::{HEEL_MARGIN_M, KINK_MARGIN_M, SHORT_SURFACE_SOLES, TOE_MARGIN_M, path_of};
use stance::poses::FEET;
use stance::{
    AffordanceSet, Environment, Gait, GenerateOptions, PoseSequence, PostProcessParams,
    PostProcessedSequence, PostProcessor, Scene, SupportSurface, WalkRequest, generate,
};

/// Slack of the geometric checks (the passes are exact up to rounding).
const EPS: f64 = 1e-9;

/// JVRC-1 with the limits of `gait` (`[postprocess]`, with `[postprocess.dynamic]` for the
/// dynamic gait).
fn jvrc1(gait: Gait) -> (&'static Robot, PostProcessParams) {
    let (robot, _) = common::jvrc1();
    let file = ConfigFile::load(&common::config_path("jvrc1")).unwrap();
    (
        robot,
        PostProcessParams::from_config_for(&file, gait).unwrap(),
    )
}

fn scene(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../configs/scenes")
        .join(format!("{name}.toml"));
    Scene::from_path(&path).unwrap()
}

/// A walk on `scene` as every walking command asks for it (`stance::walk_in`: generated flat,
/// longer than the path, the walk environment attached, post-processed with the limits of
/// `gait`, `s_max` replaced if given, and ended at the goal).
fn walk_in(
    scene: &Scene,
    gait: Gait,
    s_max: Option<f64>,
    seed: u64,
) -> (PostProcessedSequence, Environment) {
    let (robot, mut params) = jvrc1(gait);
    if let Some(s_max) = s_max {
        // A step limit of the test's own, on the step in space (JVRC-1's dynamic config
        // weights a rise 3.5 times, which is not what these tests are about).
        params.s_max = s_max;
        params.rise_weight = 1.0;
    }
    let environment = scene.walk_environment();
    let request = WalkRequest {
        distance: scene.path_length(),
        affordances: AffordanceSet::Feet,
        seed,
        speed: None,
    };
    let out = stance::walk_in(robot, &params, &request, &environment, |options| {
        generate(robot, options)
    })
    .unwrap();
    (out, environment)
}

/// A contact run: its foot, first stance and pose.
struct Foothold {
    foot: EndEffector,
    stance: usize,
    pose: Isometry3<f64>,
}

/// Every contact run of the feet, in order of touchdown (left first on a tie).
fn footholds(poses: &PoseSequence) -> Vec<Foothold> {
    (0..poses.len())
        .flat_map(|i| FEET.map(|foot| (i, foot)))
        .filter(|&(i, foot)| poses.contact_starts(i, foot))
        .map(|(i, foot)| Foothold {
            foot,
            stance: i,
            pose: *poses.pose(i, foot),
        })
        .collect()
}

/// The surface a sole centre stands on.
fn surface_of<'e>(environment: &'e Environment, pose: &Isometry3<f64>) -> &'e SupportSurface {
    environment
        .support_at(&pose.translation.vector)
        .unwrap_or_else(|| {
            panic!(
                "a foothold at {:?} is over no surface",
                pose.translation.vector
            )
        })
        .0
}

/// Rank of each surface along the walk (+x in the walk frame), by the x of its centre.
fn rank(environment: &Environment, surface: &SupportSurface) -> usize {
    let x = |s: &SupportSurface| s.pose.translation.x;
    environment
        .surfaces
        .iter()
        .filter(|s| x(s) < x(surface))
        .count()
}

/// The surface's extent along +x (the walk frame's path direction) through `y`.
fn depth(surface: &SupportSurface, y: f64) -> f64 {
    let [from, to] = surface
        .extent_along(&Vector3::new(0.0, y, 0.0), &Vector3::x())
        .unwrap();
    to - from
}

/// The room a sole on `surface` keeps from its surface's edges, `(heel, toe)`: where the
/// neighbouring surface meets it edge to edge at its height (a kink: a ramp's foot or top)
/// `KINK_MARGIN_M`; before a drop (the next surface begins 0.02 m or more lower, a stair going
/// down) none at the toe; else `HEEL_MARGIN_M` and `TOE_MARGIN_M`.
fn margins(
    environment: &Environment,
    surface: &SupportSurface,
    pose: &Isometry3<f64>,
) -> (f64, f64) {
    let y = pose.translation.y;
    let along = |s: &SupportSurface| s.extent_along(&Vector3::new(0.0, y, 0.0), &Vector3::x());
    let [from, to] = along(surface).unwrap();
    let edge = |s: &SupportSurface, x: f64| s.elevation_at(x, y).unwrap();
    let (start, end) = (edge(surface, from + 1e-6), edge(surface, to - 1e-6));
    let mut margins = (HEEL_MARGIN_M, TOE_MARGIN_M);
    for other in &environment.surfaces {
        let Some([other_from, other_to]) = along(other) else {
            continue;
        };
        if (other_to - from).abs() < 1e-3 && (edge(other, other_to - 1e-6) - start).abs() < 0.02 {
            margins.0 = KINK_MARGIN_M;
        }
        if (other_from - to).abs() < 1e-3 {
            let drop = end - edge(other, other_from + 1e-6);
            if drop >= 0.02 {
                margins.1 = 0.0;
            } else if drop.abs() < 0.02 {
                margins.1 = KINK_MARGIN_M;
            }
        }
    }
    margins
}

/// Every contact sole: on its surface's plane, parallel to it, with the sole's heel and toe on
/// the same surface with the margins (corners of the sole, lengthened by the margins: the
/// kink's where a neighbour meets the surface at its height, no toe margin before a drop).
fn check_soles_fit(poses: &PoseSequence, environment: &Environment, sole: [f64; 2]) {
    let [length, width] = sole;
    for i in 0..poses.len() {
        for foot in FEET.into_iter().filter(|&f| poses.in_contact(i, f)) {
            let pose = poses.pose(i, foot);
            let surface = surface_of(environment, pose);
            let p = pose.translation.vector;
            let z = surface.elevation_at(p.x, p.y).unwrap();
            assert!(
                (p.z - z).abs() < EPS,
                "stance {i} {foot:?}: {} off {}",
                p.z,
                surface.name
            );
            let normal = surface.pose.rotation * Vector3::z();
            let tilt = (pose.rotation * Vector3::z()).angle(&normal);
            assert!(
                tilt < EPS,
                "stance {i} {foot:?} tilted {tilt} on {}",
                surface.name
            );
            let (heel_margin, toe_margin) = margins(environment, surface, pose);
            let heel = -length / 2.0 - heel_margin + EPS;
            let toe = length / 2.0 + toe_margin - EPS;
            for (x, y) in [
                (heel, width / 2.0),
                (heel, -width / 2.0),
                (toe, width / 2.0),
                (toe, -width / 2.0),
            ] {
                let corner = pose * Point3::new(x, y, 0.0);
                assert!(
                    surface.elevation_at(corner.x, corner.y).is_some(),
                    "stance {i} {foot:?}: sole corner {x:+.3} off {} at ({:.3}, {:.3})",
                    surface.name,
                    corner.x,
                    corner.y
                );
            }
        }
    }
}

/// Footholds in touchdown order: each on the previous one's surface or the next along the path
/// (never back, never skipping one), at most `per_stair` in a row on a short surface, and every
/// surface the walk crosses is stood on. Returns the surface names in order.
fn check_feet_per_stair(
    poses: &PoseSequence,
    environment: &Environment,
    sole_length: f64,
    per_stair: usize,
) -> Vec<String> {
    let holds = footholds(poses);
    let surfaces: Vec<&SupportSurface> = holds
        .iter()
        .map(|h| surface_of(environment, &h.pose))
        .collect();
    let mut in_a_row = 1;
    for (k, pair) in surfaces.windows(2).enumerate() {
        let (from, to) = (rank(environment, pair[0]), rank(environment, pair[1]));
        assert!(
            to == from || to == from + 1,
            "foothold {} ({:?}, stance {}) goes from {} to {}",
            k + 1,
            holds[k + 1].foot,
            holds[k + 1].stance,
            pair[0].name,
            pair[1].name
        );
        let short =
            depth(pair[0], holds[k + 1].pose.translation.y) < SHORT_SURFACE_SOLES * sole_length;
        let together = holds[k].stance == holds[k + 1].stance;
        in_a_row = if to == from && short && !together {
            in_a_row + 1
        } else {
            1
        };
        assert!(
            in_a_row <= per_stair,
            "foothold {} is the {in_a_row}th in a row on the short {}",
            k + 1,
            pair[0].name
        );
    }
    let last = rank(environment, surfaces[surfaces.len() - 1]);
    let first = rank(environment, surfaces[0]);
    for r in first..=last {
        assert!(
            surfaces.iter().any(|s| rank(environment, s) == r),
            "surface {r} along the walk skipped: {:?}",
            surfaces.iter().map(|s| &s.name).collect::<Vec<_>>()
        );
    }
    surfaces.iter().map(|s| s.name.clone()).collect()
}

/// The last stance's feet stand on the surface under the goal, their mean at the goal or past
/// it by less than a step (`s_max`): the walk ends at its first double support there.
fn check_ends_on_goal_surface(
    poses: &PoseSequence,
    environment: &Environment,
    scene: &Scene,
    s_max: f64,
) {
    let goal = scene
        .start
        .inverse_transform_point(&scene.goal.into())
        .coords;
    let end = poses.len() - 1;
    let middle = FEET
        .map(|foot| poses.pose(end, foot).translation.x)
        .iter()
        .sum::<f64>()
        / 2.0;
    assert!(
        middle >= goal.x - EPS && middle < goal.x + s_max,
        "the walk ends at {middle:.3}, the goal is at {:.3}",
        goal.x
    );
    let goal_surface = &environment.support_at(&goal).unwrap().0.name;
    let last = poses.len() - 1;
    for foot in FEET {
        assert!(poses.in_contact(last, foot));
        let surface = surface_of(environment, poses.pose(last, foot));
        assert_eq!(
            &surface.name, goal_surface,
            "{foot:?} ends off the goal's surface"
        );
    }
}

/// Every swing stance at least `h_min` above the higher of its lift-off and landing surfaces
/// and above every surface under the line between the two sole centres (sampled every 5 mm).
fn check_swing_clearance(poses: &PoseSequence, environment: &Environment, h_min: f64) {
    for foot in FEET {
        let mut lift = None;
        for i in 0..poses.len() {
            if poses.in_contact(i, foot) {
                lift = Some(i);
                continue;
            }
            let (Some(lift), Some(land)) =
                (lift, (i..poses.len()).find(|&j| poses.in_contact(j, foot)))
            else {
                continue;
            };
            let z = poses.pose(i, foot).translation.z;
            let reference = swing_reference(poses, environment, i, foot).unwrap();
            let (a, b) = (
                poses.pose(lift, foot).translation.vector,
                poses.pose(land, foot).translation.vector,
            );
            let under = |p: Vector3<f64>| environment.support_at(&p).map(|(_, z)| z);
            assert!(
                reference >= under(a).unwrap() - EPS && reference >= under(b).unwrap() - EPS,
                "stance {i} {foot:?}: reference {reference} below an end"
            );
            assert!(
                z - reference >= h_min - EPS,
                "stance {i} {foot:?}: {} above {reference}",
                z
            );
            let samples = ((b - a).xy().norm() / 0.005).ceil() as usize;
            for k in 0..=samples {
                let p = a + (b - a) * (k as f64 / samples.max(1) as f64);
                let highest = environment
                    .surfaces
                    .iter()
                    .filter_map(|s| s.elevation_at(p.x, p.y))
                    .fold(f64::NEG_INFINITY, f64::max);
                assert!(
                    z - highest >= h_min - EPS,
                    "stance {i} {foot:?} at {z:.3} passes over {highest:.3} at x = {:.3}",
                    p.x
                );
            }
        }
    }
}

/// The checks every scene walk passes, with at most `per_stair` footholds in a row on a tread;
/// returns the footholds' surfaces in order.
fn check_walk(
    scene: &Scene,
    gait: Gait,
    s_max: Option<f64>,
    per_stair: usize,
    seed: u64,
) -> (PoseSequence, Vec<String>) {
    let (robot, params) = jvrc1(gait);
    let (out, environment) = walk_in(scene, gait, s_max, seed);
    let poses = out.to_poses();
    check_soles_fit(&poses, &environment, [robot.sole.length, robot.sole.width]);
    let surfaces = check_feet_per_stair(&poses, &environment, robot.sole.length, per_stair);
    check_ends_on_goal_surface(&poses, &environment, scene, s_max.unwrap_or(params.s_max));
    check_swing_clearance(&poses, &environment, params.h_min);
    (poses, surfaces)
}

/// Longest same-foot step along the path, and footholds on the treads.
fn stair_summary(poses: &PoseSequence, surfaces: &[String]) -> (f64, usize) {
    let path = path_of(poses).unwrap();
    let longest = steps(poses, &path)
        .iter()
        .map(|s| s.length)
        .fold(0.0, f64::max);
    let on_treads = surfaces.iter().filter(|s| s.starts_with("tread")).count();
    (longest, on_treads)
}

/// The stairs scene `name` walked with `gait` (its `s_max` replaced if given): `per_stair` feet
/// on each of the 9 treads, ending `rise` above the start.
fn check_stairs(name: &str, gait: Gait, s_max: Option<f64>, per_stair: usize, rise: f64) {
    let scene = scene(name);
    for seed in [1, 2, 3] {
        let (poses, surfaces) = check_walk(&scene, gait, s_max, per_stair, seed);
        let (longest, on_treads) = stair_summary(&poses, &surfaces);
        eprintln!(
            "{name}, {} gait, seed {seed}: longest step {longest:.3} m, {on_treads} footholds on \
             the 9 treads, {} in all: {surfaces:?}",
            gait.name(),
            surfaces.len()
        );
        assert_eq!(
            on_treads,
            9 * per_stair,
            "{per_stair} per tread: {surfaces:?}"
        );
        for foot in FEET {
            let end = poses.pose(poses.len() - 1, foot).translation.z;
            assert!((end - rise).abs() < EPS, "{foot:?} ends at {end}");
        }
    }
}

/// JVRC-1's dynamic stair limit (`stair_s_max` 0.68 m) takes two 0.10 m treads (0.632 m in
/// space) and two 0.15 m ones (0.671 m): one foot per stair, up and down.
#[test]
fn stairs_up_one_foot_per_tread() {
    check_stairs("stairs-up-10cm", Gait::Dynamic, None, 1, 1.0);
    check_stairs("stairs-up-15cm", Gait::Dynamic, None, 1, 1.5);
}

#[test]
fn stairs_down_one_foot_per_tread() {
    check_stairs("stairs-down-10cm", Gait::Dynamic, None, 1, -1.0);
    check_stairs("stairs-down-15cm", Gait::Dynamic, None, 1, -1.5);
}

/// Two 0.185 m treads (0.705 m in space) are beyond JVRC-1's dynamic stair limit, and its static
/// gait has none (its `s_max`, 0.24 m, is under one tread): both feet on every tread.
#[test]
fn a_step_limit_under_two_treads_puts_both_feet_on_every_tread() {
    check_stairs("stairs-up-18cm", Gait::Dynamic, None, 2, 1.85);
    check_stairs("stairs-down-18cm", Gait::Dynamic, None, 2, -1.85);
    check_stairs("stairs-up-10cm", Gait::Static, None, 2, 1.0);
    check_stairs("stairs-down-10cm", Gait::Static, None, 2, -1.0);
}

#[test]
fn ramp_soles_are_pitched_with_the_ramp() {
    check_ramp("ramp-10deg", 10.0);
    check_ramp("ramp-5deg", 5.0);
}

#[test]
fn a_walk_up_and_down_the_steep_ramp_reaches_the_goal() {
    // JVRC-1's steps on the 15° ramp are a third of its flat ones (its dynamic gait weights a
    // step's rise 3.5 times): a flat walk twice the path's length ended on the way down.
    check_ramp("ramp-15deg", 15.0);
}

/// The checks of [`check_walk`] on the ramp scene `name`, a few walks, and every sole on a ramp
/// pitched `slope` degrees with it.
fn check_ramp(name: &str, slope: f64) {
    let scene = scene(name);
    for (gait, seed) in [(Gait::Dynamic, 1), (Gait::Dynamic, 2), (Gait::Static, 1)] {
        let (poses, surfaces) = check_walk(&scene, gait, None, 1, seed);
        for name in ["ramp-up", "landing", "ramp-down"] {
            assert!(
                surfaces.iter().any(|s| s == name),
                "no foothold on {name}: {surfaces:?}"
            );
        }
        // Soles on the ramps are pitched with them (up: toes up), elsewhere level.
        for (hold, name) in footholds(&poses).iter().zip(&surfaces) {
            let forward = hold.pose.rotation * Vector3::x();
            let pitch = forward.z.atan2(forward.xy().norm()).to_degrees();
            let expected = match name.as_str() {
                "ramp-up" => slope,
                "ramp-down" => -slope,
                _ => 0.0,
            };
            assert!(
                (pitch - expected).abs() < 0.5,
                "{name}: sole slope {pitch:.2}°"
            );
        }
    }
}

/// The flat walks of `tests/data/flat-*.json` are recorded post-processed walks in format
/// version 1 (an untimed sequence is written the same in version 2 but for the version): first
/// by this crate before the terrain pass existed (commit c6b778b), recorded again when the
/// walking path began to follow the root's travel, the first step to lead by at most half of
/// `s_max`, and held hands to grasp abeam of their feet (docs/stance.md). Post-processing the same
/// walks now gives them to the bit: on the flat ground the terrain pass and pass 9 change
/// nothing, and a version 1 file still loads.
#[test]
fn flat_walks_are_post_processed_as_recorded() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let cases = [
        (
            "flat-jvrc1-dynamic-1.5m-seed5.json",
            jvrc1(Gait::Dynamic).0,
            jvrc1(Gait::Dynamic).1,
            1.5,
            AffordanceSet::Feet,
            5,
        ),
        (
            "flat-armar4-static-right-hand-1m-seed3.json",
            &common::armar4().0,
            common::armar4().1.clone(),
            1.0,
            AffordanceSet::FeetRightHand,
            3,
        ),
    ];
    for (file, robot, params, distance, affordances, seed) in cases {
        let text = std::fs::read_to_string(data.join(file)).unwrap();
        let recorded = PostProcessedSequence::from_json_str(&text, robot).unwrap();
        let options = GenerateOptions {
            distance: distance / params.scf,
            affordances,
            seed,
        };
        let raw = generate(robot, &options).unwrap();
        let now = PostProcessor::new(robot, params).process(&raw).unwrap();
        assert!(now == recorded, "{file}: post-processing changed");
        assert_eq!(
            now.to_json_string(),
            text.replacen("\"format_version\": 1", "\"format_version\": 2", 1),
            "{file}: not the same to the bit"
        );
    }
}
