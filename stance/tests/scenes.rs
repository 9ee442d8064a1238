//! Scene files: every committed scene loads and has the geometry its name promises; every kind of
//! hostile scene is refused with a message naming the file and the key or surfaces at fault.

use std::path::{Path, PathBuf};

use nalgebra::Vector3;
use stance::{Scene, SceneError};

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/scenes")
}

fn committed(name: &str) -> Scene {
    Scene::from_path(&scenes_dir().join(format!("{name}.toml"))).unwrap()
}

/// Elevations along the scene's straight path, sampled every centimetre between the samples the
/// validator takes (so never on a shared edge of two treads).
fn elevations(scene: &Scene) -> Vec<f64> {
    let (start, goal) = (scene.start.translation.vector, scene.goal);
    let length = (goal - start).xy().norm();
    let samples = (length / 0.01).floor() as usize;
    (0..samples)
        .map(|i| {
            let p = start + (goal - start) * ((i as f64 + 0.5) * 0.01 / length);
            let (_, z) = scene
                .environment
                .support_at(&Vector3::new(p.x, p.y, 0.0))
                .unwrap_or_else(|| panic!("{}: no surface under {p:?}", scene.name));
            z
        })
        .collect()
}

/// The vertical steps along the path: differences between consecutive samples above 1 cm (a
/// 15° ramp rises 2.7 mm per centimetre).
fn steps(scene: &Scene) -> Vec<f64> {
    elevations(scene)
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| d.abs() > 0.01)
        .collect()
}

#[test]
fn every_committed_scene_loads() {
    let mut names: Vec<String> = std::fs::read_dir(scenes_dir())
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "toml"))
        .map(|path| {
            let scene = Scene::from_path(&path).unwrap_or_else(|e| panic!("{e}"));
            let stem = path.file_stem().unwrap().to_str().unwrap().to_owned();
            assert_eq!(scene.name, stem, "a scene's name is its file's");
            stem
        })
        .collect();
    names.sort();
    let expected = [
        "railing",
        "railing-left",
        "ramp-10deg",
        "ramp-15deg",
        "ramp-5deg",
        "stairs-down-10cm",
        "stairs-down-15cm",
        "stairs-down-18cm",
        "stairs-up-10cm",
        "stairs-up-15cm",
        "stairs-up-18cm",
    ];
    assert_eq!(names, expected);
}

#[test]
fn stairs_have_ten_risers_of_their_height() {
    for (cm, riser) in [("10", 0.10), ("15", 0.15), ("18", 0.185)] {
        for (direction, sign) in [("up", 1.0), ("down", -1.0)] {
            let scene = committed(&format!("stairs-{direction}-{cm}cm"));
            let steps = steps(&scene);
            assert_eq!(steps.len(), 10, "{}: {steps:?}", scene.name);
            for step in &steps {
                assert!(
                    (step - sign * riser).abs() < 1e-9,
                    "{}: {steps:?}",
                    scene.name
                );
            }
            let (low, high) = (0.0, 10.0 * riser);
            let (start_z, goal_z) = if sign > 0.0 { (low, high) } else { (high, low) };
            assert!((scene.start.translation.z - start_z).abs() < 1e-9);
            assert!((scene.goal.z - goal_z).abs() < 1e-9);
            // Treads 0.30 m deep: the risers are 0.30 m apart along the path.
            let elevations = elevations(&scene);
            let edges: Vec<usize> = (1..elevations.len())
                .filter(|&i| (elevations[i] - elevations[i - 1]).abs() > 0.01)
                .collect();
            assert!(
                edges.windows(2).all(|w| w[1] - w[0] == 30),
                "{}: risers at samples {edges:?}",
                scene.name
            );
            // At least 1 m of floor or landing before the first riser and after the last.
            assert!(edges[0] >= 100 && elevations.len() - edges[9] >= 100);
        }
    }
}

#[test]
fn ramps_rise_by_two_metres_times_the_tangent_without_a_step() {
    for degrees in [10.0f64, 15.0] {
        let scene = committed(&format!("ramp-{degrees}deg"));
        let height = 2.0 * degrees.to_radians().tan();
        let elevations = elevations(&scene);
        let top = elevations.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!((top - height).abs() < 1e-6, "{}: top {top}", scene.name);
        assert!(
            steps(&scene).is_empty(),
            "{}: a ramp has no step",
            scene.name
        );
        assert!(scene.start.translation.z.abs() < 1e-12 && scene.goal.z.abs() < 1e-12);
        // The slope along the ramps: tan θ up, then tan θ down.
        let slope = |x: f64| {
            let z = |x| scene.environment.support_at(&Vector3::new(x, 0.0, 0.0));
            z(x + 0.05).unwrap().1 - z(x - 0.05).unwrap().1
        };
        assert!((slope(2.5) / 0.1 - degrees.to_radians().tan()).abs() < 1e-6);
        assert!((slope(5.5) / 0.1 + degrees.to_radians().tan()).abs() < 1e-6);
    }
}

#[test]
fn railing_runs_along_the_path_on_the_right() {
    let scene = committed("railing");
    let [railing] = scene.environment.hand_affordances.as_slice() else {
        panic!("one railing expected");
    };
    assert_eq!(railing.radius, 0.02);
    assert_eq!(railing.available, [0.0, 5.0]);
    assert_eq!(railing.start, Vector3::new(-0.5, -0.45, 0.8));
    assert_eq!(railing.end, Vector3::new(5.5, -0.45, 0.8));
    assert_eq!((scene.goal - scene.start.translation.vector).norm(), 5.0);
}

/// A scene with `body` (its surfaces, railings) walked from `start` to `goal`, as a file under
/// configs/scenes would be.
fn text(start: &str, goal: &str, body: &str) -> String {
    format!(
        "format_version = 1\nname = \"hostile\"\n\n[path]\nstart = {start}\ngoal = {goal}\n\n{body}"
    )
}

/// A floor from x = 0 to 1 and `second` (a whole `[[surface]]` table).
fn with_floor(second: &str) -> String {
    let floor = "[[surface]]\nname = \"floor\"\ncenter = [0.5, 0.0, 0.0]\nsize = [1.0, 1.0]\n\n";
    text("[0.5, 0.0]", "[1.5, 0.0]", &format!("{floor}{second}"))
}

fn refused(text: &str) -> (SceneError, String) {
    let error = Scene::from_toml_str(text, Path::new("configs/scenes/hostile.toml")).unwrap_err();
    let message = error.to_string();
    (error, message)
}

#[test]
fn overlapping_surfaces_are_refused() {
    let (error, message) = refused(&with_floor(
        "[[surface]]\nname = \"tread-1\"\ncenter = [1.4, 0.0, 0.1]\nsize = [1.0, 1.0]\n",
    ));
    assert!(matches!(error, SceneError::Overlap { .. }), "{message}");
    assert_eq!(
        message,
        "configs/scenes/hostile.toml: surface[0] \"floor\" and surface[1] \"tread-1\" overlap: \
         their footprints (xy) overlap by 0.100 m, more than 0.001 m (surfaces may only touch \
         edge to edge)"
    );
}

#[test]
fn a_path_off_the_surfaces_is_refused() {
    // An L of two surfaces; the straight path from one arm to the other cuts the corner.
    let body = "[[surface]]\nname = \"along\"\ncenter = [1.5, 0.5, 0.0]\nsize = [3.0, 1.0]\n\n\
                [[surface]]\nname = \"across\"\ncenter = [2.5, 2.0, 0.0]\nsize = [1.0, 2.0]\n";
    let (error, message) = refused(&text("[0.5, 0.5]", "[2.5, 2.5]", body));
    assert!(
        matches!(error, SceneError::PathLeavesSurfaces { .. }),
        "{message}"
    );
    assert_eq!(
        message,
        "configs/scenes/hostile.toml: path: the straight line from start to goal leaves the \
         surfaces at (1.016, 1.016), 0.73 m from the start"
    );
    // A goal beside the floor is refused as the goal.
    let (error, message) = refused(&text(
        "[0.5, 0.5]",
        "[0.5, 1.2]",
        "[[surface]]\nname = \"floor\"\ncenter = [0.5, 0.5, 0.0]\nsize = [1.0, 1.0]\n",
    ));
    assert!(matches!(
        error,
        SceneError::EndOffSurfaces { key: "goal", .. }
    ));
    assert_eq!(
        message,
        "configs/scenes/hostile.toml: path: goal = [0.5, 1.2] is not over any surface"
    );
}

#[test]
fn a_one_metre_riser_is_refused() {
    let (error, message) = refused(&with_floor(
        "[[surface]]\nname = \"block\"\ncenter = [1.5, 0.0, 1.0]\nsize = [1.0, 1.0]\n",
    ));
    assert!(matches!(error, SceneError::RiseTooHigh { .. }), "{message}");
    assert_eq!(
        message,
        "configs/scenes/hostile.toml: path: the step from surface[0] \"floor\" to surface[1] \
         \"block\" is +1.000 m at 0.51 m from the start, higher than 0.3 m"
    );
}

#[test]
fn nan_in_a_size_is_refused() {
    let (error, message) = refused(&with_floor(
        "[[surface]]\nname = \"tread-1\"\ncenter = [1.5, 0.0, 0.1]\nsize = [nan, 1.0]\n",
    ));
    assert!(matches!(error, SceneError::BadNumber { .. }), "{message}");
    assert_eq!(
        message,
        "configs/scenes/hostile.toml: surface[1] \"tread-1\": size[0] = NaN: must be finite and > 0"
    );
}

#[test]
fn an_unknown_key_is_refused() {
    let (error, message) = refused(&with_floor(
        "[[surface]]\nname = \"tread-1\"\ncenter = [1.5, 0.0, 0.1]\nsize = [1.0, 1.0]\n\
         colour = \"red\"\n",
    ));
    assert!(matches!(error, SceneError::Toml { .. }), "{message}");
    assert_eq!(
        message,
        "configs/scenes/hostile.toml: surface[1].colour (line 17, column 1): unknown field \
         `colour`, expected one of `name`, `center`, `size`, `pitch_deg`, `yaw_deg`"
    );
}

#[test]
fn another_format_version_is_refused() {
    let text = with_floor("").replace("format_version = 1", "format_version = 2");
    let (error, message) = refused(&text);
    assert!(matches!(
        error,
        SceneError::UnsupportedVersion { found: 2, .. }
    ));
    assert_eq!(
        message,
        "configs/scenes/hostile.toml: format_version = 2 is not supported (this build reads 1)"
    );
    // Refused as a version even when the rest is of another shape.
    let (error, _) = refused("format_version = 3\n[scene]\nfloor = true\n");
    assert!(matches!(
        error,
        SceneError::UnsupportedVersion { found: 3, .. }
    ));
}

#[test]
fn other_bad_values_are_refused_by_key() {
    let surface = |extra: &str| {
        with_floor(&format!(
            "[[surface]]\nname = \"ramp\"\ncenter = [1.5, 0.0, 0.0]\nsize = [1.0, 1.0]\n{extra}"
        ))
    };
    // toml alone would drop a third number (a thickness, say) without a word.
    let (_, message) = refused(&with_floor(
        "[[surface]]\nname = \"ramp\"\ncenter = [1.5, 0.0, 0.0]\nsize = [1.0, 1.0, 0.2]\n",
    ));
    assert!(
        message.ends_with(
            "surface[1].size (line 16, column 8): invalid length 3, expected an array of 2 numbers"
        ),
        "{message}"
    );
    let (_, message) = refused(&surface("pitch_deg = 45.0\n"));
    assert!(
        message.ends_with(
            "surface[1] \"ramp\": pitch_deg = 45: must be finite and within (-45, 45) degrees"
        ),
        "{message}"
    );
    let (_, message) = refused(&surface("yaw_deg = inf\n"));
    assert!(message.ends_with("surface[1] \"ramp\": yaw_deg = inf: must be finite"));
    let (_, message) = refused(&with_floor(
        "[[surface]]\nname = \"floor\"\ncenter = [1.5, 0.0, 0.0]\nsize = [1.0, 1.0]\n",
    ));
    assert!(
        message.ends_with("surface[1] \"floor\": the name is already used by surface[0] \"floor\""),
        "{message}"
    );
    let railing = |values: &str| surface(&format!("\n[[railing]]\nname = \"railing\"\n{values}"));
    let (_, message) = refused(&railing(
        "start = [0, 1, 0.8]\nend = [1, 1, 0.8]\nradius = 0.0\n",
    ));
    assert!(
        message.ends_with("railing[0] \"railing\": radius = 0: must be finite and > 0"),
        "{message}"
    );
    let (error, message) = refused(&railing(
        "start = [0, 1, 0.8]\nend = [0, 1, 0.8]\nradius = 0.02\n",
    ));
    assert!(matches!(error, SceneError::DegenerateRailing { .. }));
    assert!(
        message.ends_with(
            "railing[0] \"railing\": start and end are the same point [0.0, 1.0, 0.8]: a railing \
             is a segment"
        ),
        "{message}"
    );
    let (_, message) = refused(&railing(
        "start = [0, 1, 0.8]\nend = [1, 1, 0.8]\nradius = 0.02\navailable = [2.0, 1.0]\n",
    ));
    assert!(
        message.ends_with(
            "railing[0] \"railing\": available[1] = 1: must not be less than available[0]"
        ),
        "{message}"
    );
}

#[test]
fn an_unreachable_surface_is_refused() {
    let (error, message) = refused(&with_floor(
        "[[surface]]\nname = \"next\"\ncenter = [1.5, 0.0, 0.1]\nsize = [1.0, 1.0]\n\n\
         [[surface]]\nname = \"island\"\ncenter = [0.5, 2.0, 0.0]\nsize = [1.0, 1.0]\n",
    ));
    assert!(matches!(error, SceneError::Unreachable { .. }), "{message}");
    assert_eq!(
        message,
        "configs/scenes/hostile.toml: surface[2] \"island\" is unreachable: its footprint is \
         1.000 m from the nearest surface connected to the start's surface[0] \"floor\" \
         (surfaces within 0.01 m of each other connect)"
    );
}

#[test]
fn a_missing_key_and_a_wrong_type_name_their_table() {
    let (_, message) = refused(&text(
        "[0.5, 0.0]",
        "[0.6, 0.0]",
        "[[surface]]\nname = \"floor\"\nsize = [1.0, 1.0]\n",
    ));
    assert!(
        message.contains("surface[0]") && message.contains("missing field `center`"),
        "{message}"
    );
    let (_, message) = refused(&with_floor("").replace("goal = [1.5, 0.0]", "goal = \"far\""));
    assert!(
        message
            .starts_with("configs/scenes/hostile.toml: path.goal (line 6, column 8): invalid type"),
        "{message}"
    );
}

#[test]
fn a_turned_surface_covers_its_turned_rectangle() {
    // 4 m long along its x, turned to run along world y; the start faces the goal by default.
    let body = "[[surface]]\nname = \"corridor\"\ncenter = [0.0, 1.5, 0.2]\nsize = [4.0, 1.0]\n\
                yaw_deg = 90.0\n";
    let scene = Scene::from_toml_str(
        &text("[0.0, 0.0]", "[0.0, 3.0]", body),
        Path::new("turned.toml"),
    )
    .unwrap();
    let yaw = scene.start.rotation.euler_angles().2;
    assert!((yaw - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert!((scene.goal - Vector3::new(0.0, 3.0, 0.2)).norm() < 1e-12);
    let (_, message) = refused(&text("[0.0, 0.0]", "[1.0, 0.0]", body));
    assert!(
        message.ends_with("path: goal = [1, 0] is not over any surface"),
        "{message}"
    );
}
