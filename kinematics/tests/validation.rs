//! One broken URDF per validation rule, each refused with an error naming the element; plus the
//! documented treatment of mimic joints and missing elements.

use kinematics::model::InertiaDefect;
use kinematics::{Configuration, Kinematics, Model, ModelError};

const INERTIAL: &str = r#"<inertial><origin xyz="0 0 0.1" rpy="0 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>"#;

fn link(name: &str) -> String {
    format!(r#"<link name="{name}">{INERTIAL}</link>"#)
}

fn revolute(name: &str, parent: &str, child: &str) -> String {
    format!(
        r#"<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>
        <origin xyz="0 0 0.5" rpy="0 0 0"/><axis xyz="0 1 0"/>
        <limit lower="-1" upper="1" effort="10" velocity="2"/></joint>"#
    )
}

fn robot(parts: &[String]) -> String {
    format!(
        r#"<?xml version="1.0"?><robot name="test">{}</robot>"#,
        parts.concat()
    )
}

/// A valid three-link chain.
fn chain() -> Vec<String> {
    vec![
        link("a"),
        link("b"),
        link("c"),
        revolute("j1", "a", "b"),
        revolute("j2", "b", "c"),
    ]
}

fn error_of(parts: &[String]) -> ModelError {
    Model::from_urdf_str(&robot(parts)).expect_err("the URDF must be refused")
}

/// The error refusing [`chain`] with `from` replaced by `to` in its part `index` (0–2: the links
/// a, b, c; 3, 4: the joints j1, j2).
fn error_with_edit(index: usize, from: &str, to: &str) -> ModelError {
    let mut parts = chain();
    parts[index] = parts[index].replace(from, to);
    error_of(&parts)
}

#[test]
fn valid_chain_loads() {
    let model = Model::from_urdf_str(&robot(&chain())).unwrap();
    assert_eq!(model.dof(), 2);
    assert_eq!(model.nv(), 8);
    assert_eq!(model.total_mass(), 3.0);
    assert_eq!(model.joint_names(), ["j1", "j2"]);
}

#[test]
fn revolute_joint_without_limit() {
    let error = error_with_edit(
        4,
        r#"<limit lower="-1" upper="1" effort="10" velocity="2"/>"#,
        "",
    );
    assert!(
        matches!(&error, ModelError::MissingLimit(joint, "revolute") if joint == "j2"),
        "{error}"
    );
    assert!(error.to_string().contains("'j2'"));
}

#[test]
fn limit_in_a_comment_does_not_count() {
    let mut parts = chain();
    parts[4] = parts[4]
        .replace("<limit", "<!-- <limit")
        .replace(r#"velocity="2"/>"#, r#"velocity="2"/> -->"#);
    assert!(matches!(error_of(&parts), ModelError::MissingLimit(..)));
}

#[test]
fn inertia_not_positive_definite() {
    let error = error_with_edit(1, r#"ixx="0.01""#, r#"ixx="0""#);
    assert!(
        matches!(&error, ModelError::InvalidInertia { link, defect: InertiaDefect::NotPositiveDefinite { .. } } if link == "b"),
        "{error}"
    );
}

#[test]
fn inertia_breaks_triangle_inequality() {
    let error = error_with_edit(2, r#"izz="0.01""#, r#"izz="0.05""#);
    assert!(
        matches!(&error, ModelError::InvalidInertia { link, defect: InertiaDefect::TriangleInequality { .. } } if link == "c"),
        "{error}"
    );
}

#[test]
fn unknown_parent_link() {
    let mut parts = chain();
    parts[4] = revolute("j2", "nowhere", "c");
    let error = error_of(&parts);
    assert!(
        matches!(&error, ModelError::UnknownLink { joint, role: "parent", link } if joint == "j2" && link == "nowhere"),
        "{error}"
    );
}

#[test]
fn unknown_child_link() {
    let mut parts = chain();
    parts[4] = revolute("j2", "b", "nowhere");
    assert!(matches!(
        error_of(&parts),
        ModelError::UnknownLink { role: "child", .. }
    ));
}

#[test]
fn cycle() {
    // a → b → c → a: no root at all.
    let mut parts = chain();
    parts.push(revolute("j3", "c", "a"));
    assert!(matches!(error_of(&parts), ModelError::Cycle(_)));
    // A root plus a detached loop d → e → d.
    let mut parts = chain();
    parts.extend([
        link("d"),
        link("e"),
        revolute("j4", "d", "e"),
        revolute("j5", "e", "d"),
    ]);
    let error = error_of(&parts);
    assert!(
        matches!(&error, ModelError::Cycle(link) if link == "d" || link == "e"),
        "{error}"
    );
}

#[test]
fn link_with_two_parents() {
    let mut parts = chain();
    parts.push(revolute("j3", "a", "c"));
    let error = error_of(&parts);
    assert!(
        matches!(&error, ModelError::MultipleParents { link, .. } if link == "c"),
        "{error}"
    );
}

#[test]
fn two_roots() {
    let mut parts = chain();
    parts.push(link("loose"));
    assert!(matches!(error_of(&parts), ModelError::MultipleRoots(..)));
}

#[test]
fn duplicate_link_name() {
    let mut parts = chain();
    parts.push(link("b"));
    assert!(matches!(error_of(&parts), ModelError::DuplicateLink(name) if name == "b"));
}

#[test]
fn duplicate_joint_name() {
    let mut parts = chain();
    parts.push(link("d"));
    parts.push(revolute("j1", "c", "d"));
    assert!(matches!(error_of(&parts), ModelError::DuplicateJoint(name) if name == "j1"));
}

#[test]
fn nan_and_infinity_anywhere_numeric() {
    for (from, to, element, attribute) in [
        (r#"xyz="0 0 0.5""#, r#"xyz="0 NaN 0.5""#, "origin", "xyz"),
        (r#"upper="1""#, r#"upper="inf""#, "limit", "upper"),
        (
            r#"axis xyz="0 1 0""#,
            r#"axis xyz="0 1 nan""#,
            "axis",
            "xyz",
        ),
    ] {
        let error = error_with_edit(3, from, to);
        let ModelError::NonFinite {
            owner,
            element: e,
            attribute: a,
            ..
        } = &error
        else {
            panic!("{error}")
        };
        assert_eq!(
            (owner.as_str(), e.as_str(), a.as_str()),
            ("joint 'j1'", element, attribute)
        );
    }
    let error = error_with_edit(0, r#"<mass value="1"/>"#, r#"<mass value="NaN"/>"#);
    assert!(
        matches!(&error, ModelError::NonFinite { owner, .. } if owner == "link 'a'"),
        "{error}"
    );
}

#[test]
fn unsupported_joint_type() {
    let error = error_with_edit(4, r#"type="revolute""#, r#"type="floating""#);
    assert!(matches!(error, ModelError::UnsupportedJoint { joint, .. } if joint == "j2"));
}

#[test]
fn inverted_limits() {
    let error = error_with_edit(3, r#"lower="-1" upper="1""#, r#"lower="1" upper="-1""#);
    assert!(matches!(error, ModelError::InvalidLimits { joint, .. } if joint == "j1"));
}

#[test]
fn mimic_joint_is_fixed_at_its_offset() {
    let mut parts = chain();
    parts[4] = parts[4].replace(
        "</joint>",
        r#"<mimic joint="j1" multiplier="2" offset="0.3"/></joint>"#,
    );
    let model = Model::from_urdf_str(&robot(&parts)).unwrap();
    assert_eq!(model.dof(), 1, "the mimic joint is not in the joint vector");
    let mut q = Configuration::neutral(&model);
    q.joints[0] = 0.5; // j1 moves; j2 stays at its offset 0.3
    let mut kin = Kinematics::new(&model);
    kin.update(&model, &q);
    let b = kin.link_pose(model.link_index("b").unwrap());
    let c = kin.link_pose(model.link_index("c").unwrap());
    let relative = b.inverse() * c;
    assert!((relative.rotation.angle() - 0.3).abs() < 1e-12);
}

#[test]
fn continuous_joint_has_infinite_limits_and_link_without_inertial_is_massless() {
    let parts = [
        link("a"),
        r#"<link name="b"/>"#.to_owned(),
        r#"<joint name="wheel" type="continuous"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/></joint>"#
            .to_owned(),
    ];
    let model = Model::from_urdf_str(&robot(&parts)).unwrap();
    assert_eq!(model.total_mass(), 1.0);
    let limits = model.joint_limits()[0];
    assert!(limits.lower == f64::NEG_INFINITY && limits.upper == f64::INFINITY);
}

#[test]
fn frames_are_validated() {
    let mut model = Model::from_urdf_str(&robot(&chain())).unwrap();
    let c = model.link_index("c").unwrap();
    let frame = model
        .add_frame("tool", c, kinematics::Isometry3::identity())
        .unwrap();
    assert_eq!(model.frame_index("tool"), Some(frame));
    assert!(matches!(
        model.add_frame("tool", c, kinematics::Isometry3::identity()),
        Err(ModelError::DuplicateFrame(_))
    ));
    let mut bad = kinematics::Isometry3::identity();
    bad.translation.x = f64::NAN;
    assert!(matches!(
        model.add_frame("bad", c, bad),
        Err(ModelError::FrameNotFinite(_))
    ));
}

#[test]
fn an_actuated_joint_with_a_zero_velocity_limit_is_refused() {
    let error = error_with_edit(4, r#"velocity="2""#, r#"velocity="0""#);
    assert!(
        matches!(error, ModelError::ZeroVelocityLimit { ref joint, .. } if joint == "j2"),
        "{error}"
    );
    assert!(error.to_string().contains("'j2'"), "{error}");
}
