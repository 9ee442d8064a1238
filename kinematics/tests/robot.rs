//! Loading the `[robot]` sections of the shipped configs, and the errors for bad ones.

mod common;

use std::path::{Path, PathBuf};

use kinematics::{EndEffector, Kinematics, Robot, RobotError};

fn config(name: &str) -> PathBuf {
    common::workspace_path(&format!("configs/{name}.toml"))
}

fn assert_soles_flat(robot: &Robot) {
    let mut kin = Kinematics::new(&robot.model);
    kin.update(&robot.model, &robot.standing);
    let mut midpoint = kinematics::Vector3::zeros();
    for foot in [EndEffector::LeftFoot, EndEffector::RightFoot] {
        let pose = kin.frame_pose(&robot.model, robot.frame(foot));
        let (roll, pitch, _) = pose.rotation.euler_angles();
        assert!(
            roll.abs() < 1e-6 && pitch.abs() < 1e-6,
            "{}: {} roll {roll} pitch {pitch}",
            robot.name,
            foot.name()
        );
        assert!(
            pose.translation.z.abs() < 1e-6,
            "{}: {} z = {}",
            robot.name,
            foot.name(),
            pose.translation.z
        );
        midpoint += pose.translation.vector / 2.0;
    }
    assert!(
        midpoint.xy().norm() < 1e-9,
        "{}: soles' midpoint {midpoint:?}",
        robot.name
    );
    // The feet are apart sideways (left foot on the left) and the pelvis is above them.
    let left = kin
        .frame_pose(&robot.model, robot.frame(EndEffector::LeftFoot))
        .translation
        .y;
    let right = kin
        .frame_pose(&robot.model, robot.frame(EndEffector::RightFoot))
        .translation
        .y;
    assert!(
        left - right > 0.1,
        "{}: left foot y {left}, right foot y {right}",
        robot.name
    );
    assert!(kin.link_pose(robot.base_link).translation.z > 0.5);
}

/// `configs/<name>.toml` loaded; it must have `dof` joints and weigh `mass` kg (to 0.1 g).
fn load_with(name: &str, dof: usize, mass: f64) -> Robot {
    let robot = Robot::load(&config(name), None).unwrap();
    assert_eq!(robot.model.dof(), dof);
    assert!(
        (robot.model.total_mass() - mass).abs() < 1e-4,
        "mass {}",
        robot.model.total_mass()
    );
    robot
}

#[test]
fn armar4_loads_and_stands_flat() {
    let robot = load_with("armar4", 30, 72.04);
    assert_eq!(robot.joint_groups.legs.len(), 12);
    assert_eq!(robot.joint_groups.arms.len(), 16);
    assert_eq!(robot.joint_groups.torso.len(), 2);
    assert_soles_flat(&robot);
}

#[test]
fn jvrc1_loads_and_stands_flat() {
    let robot = load_with("jvrc1", 34, 62.40);
    let knee = robot.model.joint_index("L_KNEE").unwrap();
    assert!(robot.standing.joints[knee] > 0.1, "knees are bent");
    assert_soles_flat(&robot);
}

#[test]
fn hrp4_without_urdf_says_how_to_give_it() {
    let error = Robot::load(&config("hrp4"), None).unwrap_err();
    assert!(matches!(error, RobotError::MissingUrdf { .. }));
    let message = error.to_string();
    assert!(
        message.contains("--urdf PATH") && message.contains("hrp4.toml"),
        "{message}"
    );
}

/// Writes a copy of the jvrc1 config with `edit` applied, pointing at the vendored URDF.
fn edited_jvrc1(edit: impl Fn(String) -> String, tag: &str) -> PathBuf {
    let text = std::fs::read_to_string(config("jvrc1")).unwrap();
    let urdf = common::jvrc1_urdf();
    let text = text.replace(
        "\"robots/jvrc1/jvrc1.urdf\"",
        &format!("{:?}", urdf.display().to_string()),
    );
    let dir = std::env::temp_dir().join(format!("kinematics-robot-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{tag}.toml"));
    std::fs::write(&path, edit(text)).unwrap();
    path
}

fn load_error(path: &Path) -> String {
    Robot::load(path, None).unwrap_err().to_string()
}

/// The jvrc1 config with `from` replaced by `to` (written under `tag`) is refused with a message
/// that contains each of `names`.
fn assert_edit_refused(tag: &str, from: &str, to: &str, names: &[&str]) {
    let message = load_error(&edited_jvrc1(|t| t.replace(from, to), tag));
    assert!(names.iter().all(|name| message.contains(name)), "{message}");
}

#[test]
fn unknown_link_names_key_and_link() {
    assert_edit_refused(
        "link",
        "link = \"L_WRIST_Y_S\"",
        "link = \"NO_SUCH_LINK\"",
        &["frames.left_hand.link", "NO_SUCH_LINK"],
    );
}

#[test]
fn unknown_joint_names_key_and_joint() {
    assert_edit_refused(
        "joint",
        "\"WAIST_Y\",",
        "\"WAIST_Q\",",
        &["joint_groups.torso", "WAIST_Q"],
    );
    assert_edit_refused(
        "standing",
        "R_KNEE = 0.76",
        "R_KNEES = 0.76",
        &["standing", "R_KNEES"],
    );
}

#[test]
fn unknown_key_is_refused() {
    assert_edit_refused(
        "key",
        "base_link = \"PELVIS_S\"",
        "base_link = \"PELVIS_S\"\nbase_lnk = 1",
        &["base_lnk"],
    );
}

#[test]
fn posture_with_tilted_sole_is_refused() {
    assert_edit_refused(
        "tilt",
        "R_ANKLE_P = -0.38",
        "R_ANKLE_P = -0.2",
        &["robot.standing", "parallel"],
    );
}

#[test]
fn urdf_override_wins() {
    let error =
        Robot::load(&config("jvrc1"), Some(Path::new("/nonexistent/model.urdf"))).unwrap_err();
    assert!(
        error.to_string().contains("/nonexistent/model.urdf"),
        "{error}"
    );
}

/// An HRP-4-shaped stand-in URDF with the official joint and link names (the real model is not
/// public): legs yaw-roll-pitch hip, pitch knee, pitch-roll ankle; arms, chest, neck as chains.
fn hrp4_like_urdf() -> String {
    let mut links = vec!["body".to_owned()];
    let mut joints = Vec::new();
    let mut chain = |parent: &str, names: &[(&str, &str, [f64; 3])], end: Option<&str>| {
        let mut parent = parent.to_owned();
        for (joint, axis, xyz) in names {
            let link = format!("{joint}_LINK");
            joints.push(format!(
                r#"<joint name="{joint}" type="revolute"><parent link="{parent}"/><child link="{link}"/>
                <origin xyz="{} {} {}"/><axis xyz="{axis}"/><limit lower="-2.5" upper="2.5" effort="1" velocity="1"/></joint>"#,
                xyz[0], xyz[1], xyz[2]
            ));
            links.push(link.clone());
            parent = link;
        }
        if let Some(end) = end {
            joints.push(format!(
                r#"<joint name="{end}_fixed" type="fixed"><parent link="{parent}"/><child link="{end}"/></joint>"#
            ));
            links.push(end.to_owned());
        }
    };
    for (side, y) in [("R", -0.08), ("L", 0.08)] {
        let j = |n: &str| format!("{side}_{n}");
        let leg = [
            j("HIP_Y"),
            j("HIP_R"),
            j("HIP_P"),
            j("KNEE_P"),
            j("ANKLE_P"),
            j("ANKLE_R"),
        ];
        chain(
            "body",
            &[
                (&leg[0], "0 0 1", [0.0, y, -0.08]),
                (&leg[1], "1 0 0", [0.0, 0.0, 0.0]),
                (&leg[2], "0 1 0", [0.0, 0.0, 0.0]),
                (&leg[3], "0 1 0", [0.0, 0.0, -0.3]),
                (&leg[4], "0 1 0", [0.0, 0.0, -0.3]),
                (&leg[5], "1 0 0", [0.0, 0.0, 0.0]),
            ],
            None,
        );
        let arm = [
            "SHOULDER_P",
            "SHOULDER_R",
            "SHOULDER_Y",
            "ELBOW_P",
            "WRIST_Y",
            "WRIST_P",
            "WRIST_R",
        ]
        .map(j);
        let hand = [j("HAND_J0"), j("HAND_J1")];
        let wrist = format!("{}_wrist", side.to_lowercase());
        let mut arm_chain: Vec<(&str, &str, [f64; 3])> = arm
            .iter()
            .map(|n| (n.as_str(), "0 1 0", [0.0, 0.0, -0.05]))
            .collect();
        arm_chain[0].2 = [0.0, 2.0 * y, 0.4];
        chain("body", &arm_chain, Some(&wrist));
        chain(
            &wrist,
            &[
                (&hand[0], "1 0 0", [0.0, 0.0, -0.05]),
                (&hand[1], "1 0 0", [0.0, 0.0, -0.05]),
            ],
            None,
        );
    }
    chain(
        "body",
        &[
            ("CHEST_P", "0 1 0", [0.0, 0.0, 0.1]),
            ("CHEST_Y", "0 0 1", [0.0, 0.0, 0.1]),
        ],
        None,
    );
    chain(
        "CHEST_Y_LINK",
        &[
            ("NECK_Y", "0 0 1", [0.0, 0.0, 0.2]),
            ("NECK_P", "0 1 0", [0.0, 0.0, 0.0]),
        ],
        None,
    );
    let inertial = r#"<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>"#;
    let links: String = links
        .iter()
        .map(|l| format!(r#"<link name="{l}">{inertial}</link>"#))
        .collect();
    format!(
        r#"<robot name="hrp4_stand_in">{links}{}</robot>"#,
        joints.concat()
    )
}

#[test]
fn hrp4_config_loads_with_a_user_supplied_urdf() {
    let dir = std::env::temp_dir().join(format!("kinematics-hrp4-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let urdf = dir.join("hrp4_stand_in.urdf");
    std::fs::write(&urdf, hrp4_like_urdf()).unwrap();
    let robot = Robot::load(&config("hrp4"), Some(&urdf)).unwrap();
    assert_eq!(robot.model.dof(), 34);
    let groups = &robot.joint_groups;
    assert_eq!(
        groups.legs.len() + groups.arms.len() + groups.torso.len() + groups.head.len(),
        34
    );
    assert_soles_flat(&robot);
}

/// The error and its sources joined as `anyhow`'s `{:#}` prints them (what the binaries log).
fn chain(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        text.push_str(": ");
        text.push_str(&cause.to_string());
        source = cause.source();
    }
    text
}

#[test]
fn a_missing_urdf_is_named_once() {
    let path = edited_jvrc1(|t| t.replace("jvrc1.urdf", "no-such.urdf"), "missing_urdf");
    let message = chain(&Robot::load(&path, None).unwrap_err());
    assert_eq!(message.matches("no-such.urdf").count(), 1, "{message}");
    assert_eq!(
        message.matches("No such file").count(),
        1,
        "the cause repeats: {message}"
    );
}

#[test]
fn an_unknown_section_is_refused() {
    assert_edit_refused(
        "section",
        "[runtime]",
        "[runtme]",
        &["unknown section [runtme]"],
    );
}

#[test]
fn the_palm_and_the_wrist_sensors_default_to_the_sole_and_the_wrist() {
    let jvrc1 = Robot::load(&config("jvrc1"), None).unwrap();
    assert_eq!(jvrc1.palm_radius, 0.5 * jvrc1.sole.width);
    // Configured: the URDF's wrist sensor links, at the wrist-yaw axis (0.07 m above the palm).
    let mut kin = Kinematics::new(&jvrc1.model);
    kin.update(&jvrc1.model, &jvrc1.standing);
    let at = |frame| kin.frame_pose(&jvrc1.model, frame).translation.vector;
    let arm = at(jvrc1.wrist_ft_sensors[1]) - at(jvrc1.frame(EndEffector::RightHand));
    assert!((arm.norm() - 0.07).abs() < 1e-9, "{arm}");
    // Without `left_hand`/`right_hand` the wrist sensor is the hand link's origin.
    let unset = Robot::load(
        &edited_jvrc1(
            |t| {
                t.replace("left_hand = { link = \"lhsensor\" }\n", "")
                    .replace("right_hand = { link = \"rhsensor\" }\n", "")
            },
            "no-wrist-sensors",
        ),
        None,
    )
    .unwrap();
    let mut kin = Kinematics::new(&unset.model);
    kin.update(&unset.model, &unset.standing);
    let wrist = kin.frame_pose(&unset.model, unset.wrist_ft_sensors[0]);
    let link = unset.model.link_index("L_WRIST_Y_S").unwrap();
    assert!((wrist.translation.vector - kin.link_pose(link).translation.vector).norm() < 1e-12);
}

#[test]
fn a_palm_radius_out_of_range_is_refused_by_name() {
    assert_edit_refused(
        "palm-radius",
        "sole = { length = 0.20, width = 0.08 }",
        "sole = { length = 0.20, width = 0.08 }\npalm_radius = 0.5",
        &["palm_radius", "0.5"],
    );
}

#[test]
fn soles_at_different_heights_are_refused_with_the_measured_gap() {
    // Parallel soles (hip + knee + ankle pitch still zero), the right one a few µm higher: the
    // message gives the gap in a precision that shows it, and the tolerance it exceeds.
    let message = load_error(&edited_jvrc1(
        |t| {
            t.replace("R_HIP_P = -0.38", "R_HIP_P = -0.38002")
                .replace("R_KNEE = 0.76", "R_KNEE = 0.76004")
                .replace("R_ANKLE_P = -0.38", "R_ANKLE_P = -0.38002")
        },
        "heights",
    ));
    assert!(
        message.contains("soles at different heights")
            && message.contains("more than 1e-6 m")
            && !message.contains("0.0000 m"),
        "{message}"
    );
}
