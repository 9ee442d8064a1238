//! Guesses of the `[robot]` frames from link names and the model's geometry in the standing
//! posture (base at the identity, the body axes of [`super::legs`]):
//!
//! - **base link**: the heaviest link welded to the link where the two legs meet (the pelvis);
//! - **sole frames**: level (z up, x forward) in the standing posture, on the foot link (the
//!   last link of each leg chain), or on a link named `…sole…` welded to it. Its height is, in
//!   this order: that sole link's origin (iCub's `l_sole`/`r_sole`, the models' own contact
//!   frames); else the lowest point of the foot's primitive collision (else visual) shapes; else
//!   the lowest point of the foot's *inertia-equivalent box* — the uniform box with the foot's
//!   mass and inertia (its rigid group's), centred at its centre of mass along its principal
//!   axes — for models drawn only by meshes (JVRC-1, ARMAR-4). Its centre and the sole
//!   rectangle are those shapes' footprint, else the box's (but sideways under the ankle: a
//!   foot is built about the leg's axis, its mass centre need not be). Both soles are put at
//!   the same height (the mean) and the rectangle is the larger of the two feet's;
//! - **hands**: the link of the last `wrist` joint on each side, else of the last arm joint
//!   (by the arm words of [`super::groups`], fingers excluded), else a link named
//!   `hand`/`palm`; the palm at the centre of mass of that link and everything below it
//!   (fingers), in the link's orientation;
//! - **FT sensors**: a link welded to the foot whose name has the token `ft` or contains
//!   `fsensor` or `force` (not an `imu`/`gyro`/`acc` link; the shortest name wins), in its own
//!   orientation; else the foot link at the ankle, oriented like the sole.

use kinematics::{Configuration, Isometry3, LinkId, Translation3, UnitQuaternion, Vector3};
use nalgebra::{Matrix3, SymmetricEigen};

use super::legs::{BodyAxes, Legs, Side};
use super::model::{Posed, UrdfModel};

/// A frame of the `[robot]` section: a link and a pose in it.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameSpec {
    /// The link the frame is attached to.
    pub link: String,
    /// Its position in the link frame (m).
    pub translation: [f64; 3],
    /// Its orientation in the link frame (URDF roll, pitch, yaw; rad).
    pub rpy: [f64; 3],
}

/// One guess and how it was made, for the table the user confirms.
#[derive(Debug, Clone, PartialEq)]
pub struct Guess<T> {
    /// The guessed value.
    pub value: T,
    /// Where it comes from.
    pub basis: String,
}

/// What the user may set instead of a guess.
#[derive(Debug, Clone, Default)]
pub struct FrameOverrides {
    /// `--base-link`.
    pub base_link: Option<String>,
    /// `--sole LxW` (m).
    pub sole: Option<(f64, f64)>,
    /// `--sole-below` (m below the foot link's origin).
    pub sole_below: Option<f64>,
    /// `--left-hand`, `--right-hand`.
    pub hands: [Option<String>; 2],
}

/// Every guessed frame of the `[robot]` section.
#[derive(Debug, Clone)]
pub struct Frames {
    /// The pelvis.
    pub base_link: Guess<String>,
    /// Sole length and width (m).
    pub sole: Guess<(f64, f64)>,
    /// Sole frames, left and right.
    pub feet: Guess<[FrameSpec; 2]>,
    /// Palm frames, left and right.
    pub hands: Guess<[FrameSpec; 2]>,
    /// FT sensor frames, left and right.
    pub ft_sensors: Guess<[FrameSpec; 2]>,
}

/// A foot's footprint in body axes: centre along forward and left, length, width, and the
/// height of its lowest point (world coordinates).
#[derive(Debug, Clone, Copy)]
struct Footprint {
    forward: f64,
    left: f64,
    length: f64,
    width: f64,
    bottom: f64,
}

/// Guesses every frame of the `[robot]` section in the standing posture `q`.
pub fn guess_frames(
    model: &UrdfModel,
    legs: &Legs,
    q: &Configuration,
    overrides: &FrameOverrides,
) -> anyhow::Result<Frames> {
    let posed = Posed::new(model, q);
    let base_link = match &overrides.base_link {
        Some(name) => Guess {
            value: model.name(model.link(name, "--base-link")?).to_owned(),
            basis: "given with --base-link".to_owned(),
        },
        None => base_link(model, legs),
    };
    let (sole, feet) = soles(model, legs, &posed, overrides)?;
    let hands = hands(model, legs, &posed, &overrides.hands)?;
    let ft_sensors = ft_sensors(model, legs, &posed);
    Ok(Frames {
        base_link,
        sole,
        feet,
        hands,
        ft_sensors,
    })
}

/// The heaviest link welded to the pelvis (fixed joints up or down).
fn base_link(model: &UrdfModel, legs: &Legs) -> Guess<String> {
    let mut top = legs.pelvis;
    while model.facts(top).actuated.is_none() {
        match model.model.link_parent(top) {
            Some(parent) => top = parent,
            None => break,
        }
    }
    let heaviest = model
        .rigid_group(top)
        .into_iter()
        .max_by(|&a, &b| {
            model
                .model
                .link_mass(a)
                .total_cmp(&model.model.link_mass(b))
        })
        .unwrap_or(legs.pelvis);
    let basis = if heaviest == legs.pelvis {
        "where the two legs meet".to_owned()
    } else {
        format!(
            "the heaviest link welded to {}, where the two legs meet",
            model.name(legs.pelvis)
        )
    };
    Guess {
        value: model.name(heaviest).to_owned(),
        basis,
    }
}

/// Whether a link name has `token` as one of its `_`/`-`/case-separated words.
pub fn has_token(name: &str, token: &str) -> bool {
    name.to_lowercase()
        .split(|c: char| !c.is_ascii_alphanumeric())
        .any(|word| word == token)
}

/// The sole rectangle (length, width) and both sole frames.
type Soles = (Guess<(f64, f64)>, Guess<[FrameSpec; 2]>);

/// The sole rectangle and both sole frames.
fn soles(
    model: &UrdfModel,
    legs: &Legs,
    posed: &Posed,
    overrides: &FrameOverrides,
) -> anyhow::Result<Soles> {
    let axes = &legs.axes;
    let mut prints = Vec::new();
    let mut sole_links = Vec::new();
    let mut basis = String::new();
    for leg in legs.both() {
        let group = model.rigid_group(leg.foot);
        let sole_link = group
            .iter()
            .copied()
            .find(|&l| has_token(model.name(l), "sole") && !has_token(model.name(l), "skin"));
        let (print, how) = footprint(model, posed, axes, &group)?;
        prints.push(print);
        sole_links.push(sole_link);
        basis = how;
    }
    let ankle_height = |leg: usize| {
        posed
            .link(legs.both()[leg].foot)
            .translation
            .vector
            .dot(&axes.up)
    };
    let heights: Vec<f64> = (0..2)
        .map(|i| match (overrides.sole_below, sole_links[i]) {
            (Some(below), _) => ankle_height(i) - below,
            (None, Some(link)) => posed.link(link).translation.vector.dot(&axes.up),
            (None, None) => prints[i].bottom,
        })
        .collect();
    let height = (heights[0] + heights[1]) / 2.0;
    let height_basis = match (overrides.sole_below, sole_links[0]) {
        (Some(below), _) => format!("{below} m below the foot link (--sole-below)"),
        (None, Some(link)) => format!("at the model's sole link {}", model.name(link)),
        (None, None) => format!("at the lowest point of {basis}"),
    };
    let size = match overrides.sole {
        Some(size) => Guess {
            value: size,
            basis: "given with --sole".to_owned(),
        },
        None => Guess {
            value: (
                round(prints[0].length.max(prints[1].length), 1e-3),
                round(prints[0].width.max(prints[1].width), 1e-3),
            ),
            basis: format!("footprint of {basis}"),
        },
    };
    let level = level(axes);
    let specs: Vec<FrameSpec> = (0..2)
        .map(|i| {
            let leg = legs.both()[i];
            let link = sole_links[i].unwrap_or(leg.foot);
            let centre =
                axes.forward * prints[i].forward + axes.left * prints[i].left + axes.up * height;
            frame_in(
                model,
                posed,
                link,
                &Isometry3::from_parts(Translation3::from(centre), level),
            )
        })
        .collect();
    let ankle_drop = ankle_height(0) - height;
    let feet = Guess {
        value: [specs[0].clone(), specs[1].clone()],
        basis: format!(
            "level in the standing posture, {height_basis} ({ankle_drop:.4} m below {}), centred \
             on the footprint",
            model.name(legs.left.foot)
        ),
    };
    Ok((size, feet))
}

/// The footprint of a foot's rigid group: its primitive shapes', else its inertia box's.
fn footprint(
    model: &UrdfModel,
    posed: &Posed,
    axes: &BodyAxes,
    group: &[LinkId],
) -> anyhow::Result<(Footprint, String)> {
    let shaped: Vec<LinkId> = group
        .iter()
        .copied()
        .filter(|&l| !model.facts(l).shapes.is_empty())
        .collect();
    if !shaped.is_empty() {
        let mut bounds = [(f64::INFINITY, f64::NEG_INFINITY); 3];
        for &link in &shaped {
            let pose = posed.link(link);
            for shape in &model.facts(link).shapes {
                for (bound, direction) in bounds.iter_mut().zip([axes.forward, axes.left, axes.up])
                {
                    let (low, high) = shape.extent(&pose, &direction);
                    bound.0 = bound.0.min(low);
                    bound.1 = bound.1.max(high);
                }
            }
        }
        let source = if model.facts(shaped[0]).shapes_from_collision {
            "collision"
        } else {
            "visual"
        };
        let names: Vec<&str> = shaped.iter().map(|&l| model.name(l)).collect();
        return Ok((
            Footprint {
                forward: (bounds[0].0 + bounds[0].1) / 2.0,
                left: (bounds[1].0 + bounds[1].1) / 2.0,
                length: bounds[0].1 - bounds[0].0,
                width: bounds[1].1 - bounds[1].0,
                bottom: bounds[2].0,
            },
            format!("the {source} shapes of {}", names.join(", ")),
        ));
    }
    let (mass, com, inertia) = posed.mass_properties(group);
    if mass <= 0.0 {
        anyhow::bail!(
            "{}: the foot {} has neither primitive geometry nor mass to size its sole from; pass \
             --sole LxW and --sole-below M",
            model.path.display(),
            model.name(group[0])
        );
    }
    let (axes_of_box, half) = inertia_box(mass, &inertia);
    let reach = |direction: &Vector3<f64>| -> f64 {
        (0..3)
            .map(|k| axes_of_box.column(k).dot(direction).abs() * half[k])
            .sum()
    };
    Ok((
        Footprint {
            forward: com.dot(&axes.forward),
            // Sideways under the ankle: a foot is built about the leg's axis, its mass centre
            // need not be (ARMAR-4's sits 1 cm outwards, with the ankle drive).
            left: posed.link(group[0]).translation.vector.dot(&axes.left),
            length: 2.0 * reach(&axes.forward),
            width: 2.0 * reach(&axes.left),
            bottom: com.dot(&axes.up) - reach(&axes.up),
        },
        format!(
            "the inertia-equivalent box of {} ({:.2} kg; the model has no primitive geometry \
             there)",
            group
                .iter()
                .filter(|&&l| model.model.link_mass(l) > 0.0)
                .map(|&l| model.name(l))
                .collect::<Vec<_>>()
                .join(" + "),
            mass
        ),
    ))
}

/// The uniform box with `mass` and `inertia` (about its centre): its axes (columns) and half
/// extents. For a box of sides a, b, c: I_a = m (b² + c²) / 12, so a² = 6 (I_b + I_c − I_a) / m.
pub fn inertia_box(mass: f64, inertia: &Matrix3<f64>) -> (Matrix3<f64>, Vector3<f64>) {
    let eigen = SymmetricEigen::new(*inertia);
    let i = eigen.eigenvalues;
    let side = |a: usize, b: usize, c: usize| (6.0 * (i[b] + i[c] - i[a]) / mass).max(0.0).sqrt();
    let half = Vector3::new(side(0, 1, 2), side(1, 0, 2), side(2, 0, 1)) / 2.0;
    (eigen.eigenvectors, half)
}

/// The frame `world` (a pose in the standing posture) expressed on `link`.
fn frame_in(model: &UrdfModel, posed: &Posed, link: LinkId, world: &Isometry3<f64>) -> FrameSpec {
    let local = posed.link(link).inverse() * world;
    let t = local.translation.vector;
    let (roll, pitch, yaw) = local.rotation.euler_angles();
    FrameSpec {
        link: model.name(link).to_owned(),
        translation: [round(t.x, 1e-7), round(t.y, 1e-7), round(t.z, 1e-7)],
        rpy: [tidy_angle(roll), tidy_angle(pitch), tidy_angle(yaw)],
    }
}

/// Rounds `x` to a multiple of `step` (a power of ten), as the decimal number it prints as
/// (0.1 + 0.2 rounded to 0.01 is 0.3, not 0.30000000000000004; −0 is 0).
pub fn round(x: f64, step: f64) -> f64 {
    let decimals = (-step.log10()).round().max(0.0) as usize;
    let rounded = (x / step).round() * step;
    format!("{rounded:.decimals$}")
        .parse::<f64>()
        .unwrap_or(rounded)
        + 0.0
}

/// An angle with numerical noise removed: exactly 0, ±π/2 or ±π when within 1e-12 of it.
fn tidy_angle(angle: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    for exact in [0.0, FRAC_PI_2, -FRAC_PI_2, PI, -PI] {
        if (angle - exact).abs() < 1e-12 {
            return exact;
        }
    }
    angle
}

/// The palm frames.
fn hands(
    model: &UrdfModel,
    legs: &Legs,
    posed: &Posed,
    given: &[Option<String>; 2],
) -> anyhow::Result<Guess<[FrameSpec; 2]>> {
    let leg_joints: Vec<usize> = legs.both().iter().flat_map(|l| l.joints.clone()).collect();
    let pelvis = posed.link(legs.pelvis).translation.vector;
    let side_of = |link: LinkId| {
        if (posed.link(link).translation.vector - pelvis).dot(&legs.axes.left) >= 0.0 {
            Side::Left
        } else {
            Side::Right
        }
    };
    let depth = |link: LinkId| model.ancestry(link).len();
    let mut specs = Vec::new();
    let mut bases = Vec::new();
    for (i, side) in [Side::Left, Side::Right].into_iter().enumerate() {
        let (link, basis) = if let Some(name) = &given[i] {
            let option = format!("--{}-hand", side.name());
            (model.link(name, &option)?, format!("given with {option}"))
        } else {
            let deepest = |word: fn(&str) -> bool| {
                (0..model.model.dof())
                    .filter(|j| !leg_joints.contains(j))
                    .filter(|&j| word(&model.joint_name(j).to_lowercase()))
                    .map(|j| model.joint_link(j))
                    .filter(|&l| side_of(l) == side)
                    .max_by_key(|&l| depth(l))
            };
            let wrist = deepest(|name| name.contains("wrist"));
            let arm = || {
                deepest(|name| {
                    super::groups::ARMS.iter().any(|w| name.contains(w))
                        && !super::groups::FINGERS.iter().any(|w| name.contains(w))
                })
            };
            let named = || {
                model
                    .model
                    .link_ids()
                    .filter(|&l| {
                        let name = model.name(l).to_lowercase();
                        (name.contains("hand") || name.contains("palm"))
                            && model.model.link_mass(l) > 0.0
                    })
                    .filter(|&l| side_of(l) == side)
                    .min_by_key(|&l| depth(l))
            };
            if let Some(link) = wrist {
                (link, "the link of the last wrist joint".to_owned())
            } else if let Some(link) = arm() {
                (
                    link,
                    "the link of the last arm joint (none is named wrist)".to_owned(),
                )
            } else if let Some(link) = named() {
                (link, "a link named hand/palm".to_owned())
            } else {
                anyhow::bail!(
                    "{}: no {} hand: no arm joint (named wrist, shoulder, elbow, arm, hand) and \
                     no link named hand or palm on that side; pass --{}-hand LINK",
                    model.path.display(),
                    side.name(),
                    side.name()
                )
            }
        };
        let (mass, com, _) = posed.mass_properties(&model.subtree(link));
        let pose = posed.link(link);
        let centre = if mass > 0.0 {
            com
        } else {
            pose.translation.vector
        };
        let mut spec = frame_in(
            model,
            posed,
            link,
            &Isometry3::from_parts(Translation3::from(centre), pose.rotation),
        );
        spec.translation = spec.translation.map(|x| round(x, 1e-3));
        spec.rpy = [0.0; 3];
        specs.push(spec);
        bases.push(basis);
    }
    bases.dedup();
    Ok(Guess {
        value: [specs[0].clone(), specs[1].clone()],
        basis: format!(
            "{}; palm at the centre of mass of the hand and what hangs below it",
            bases.join(" / ")
        ),
    })
}

/// The FT sensor frames.
fn ft_sensors(model: &UrdfModel, legs: &Legs, posed: &Posed) -> Guess<[FrameSpec; 2]> {
    let mut bases = Vec::new();
    let specs: Vec<FrameSpec> = legs
        .both()
        .iter()
        .map(|leg| {
            let named = model
                .rigid_group(leg.foot)
                .into_iter()
                .filter(|&l| {
                    let name = model.name(l).to_lowercase();
                    (has_token(&name, "ft") || name.contains("fsensor") || name.contains("force"))
                        && !["imu", "gyro", "acc"].iter().any(|t| has_token(&name, t))
                })
                .min_by_key(|&l| (model.name(l).len(), model.name(l).to_owned()));
            match named {
                Some(link) => {
                    bases.push("a force-sensor link welded to the foot".to_owned());
                    FrameSpec {
                        link: model.name(link).to_owned(),
                        translation: [0.0; 3],
                        rpy: [0.0; 3],
                    }
                }
                None => {
                    bases.push(
                        "no force-sensor link on the foot: at the ankle, oriented like the sole"
                            .to_owned(),
                    );
                    let ankle = posed.link(leg.foot).translation;
                    let mut spec = frame_in(
                        model,
                        posed,
                        leg.foot,
                        &Isometry3::from_parts(ankle, level(&legs.axes)),
                    );
                    spec.translation = [0.0; 3];
                    spec
                }
            }
        })
        .collect();
    bases.dedup();
    Guess {
        value: [specs[0].clone(), specs[1].clone()],
        basis: bases.join(" / "),
    }
}

/// The level orientation of the body axes: x forward, y left, z up.
fn level(axes: &BodyAxes) -> UnitQuaternion<f64> {
    UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_basis_unchecked(&[
        axes.forward,
        axes.left,
        axes.up,
    ]))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use kinematics::{EndEffector, Robot};

    use super::*;
    use crate::init_robot::groups::{JointGroups, joint_groups};
    use crate::init_robot::legs::find_legs;
    use crate::init_robot::standing::standing;

    struct Guessed {
        model: UrdfModel,
        legs: Legs,
        frames: Frames,
        groups: JointGroups,
        standing: Vec<(String, f64)>,
    }

    fn guess(urdf: &str) -> Guessed {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../configs/robots")
            .join(urdf);
        let model = UrdfModel::load(&path).expect("URDF");
        let legs = find_legs(&model, [None, None]).expect("legs");
        let posture = standing(&model, &legs).expect("standing");
        let frames =
            guess_frames(&model, &legs, &posture.q, &FrameOverrides::default()).expect("frames");
        let groups = joint_groups(&model, &legs);
        let standing = posture
            .angles
            .iter()
            .map(|&(j, a)| (model.joint_name(j).to_owned(), a))
            .collect();
        Guessed {
            model,
            legs,
            frames,
            groups,
            standing,
        }
    }

    fn names(robot: &Robot, joints: &[usize]) -> Vec<String> {
        joints
            .iter()
            .map(|&j| robot.model.joint_names()[j].clone())
            .collect()
    }

    /// The configured joint groups equal the guessed ones (same joints, same order).
    fn same_groups(robot: &Robot, groups: &JointGroups) {
        let g = &robot.joint_groups;
        assert_eq!(names(robot, &g.legs), groups.legs);
        assert_eq!(names(robot, &g.arms), groups.arms);
        assert_eq!(names(robot, &g.torso), groups.torso);
        assert_eq!(names(robot, &g.head), groups.head);
        assert!(groups.unassigned.is_empty(), "{:?}", groups.unassigned);
    }

    fn frame_of(robot: &Robot, effector: EndEffector) -> (String, Isometry3<f64>) {
        let frame = robot.frame(effector);
        (
            robot
                .model
                .link_name(robot.model.frame_link(frame))
                .to_owned(),
            *robot.model.frame_offset(frame),
        )
    }

    fn pose(spec: &FrameSpec) -> Isometry3<f64> {
        kinematics::model::pose_from_xyz_rpy(spec.translation, spec.rpy)
    }

    #[test]
    fn jvrc1_guesses_match_its_config_but_the_sole_depth() {
        let g = guess("jvrc1/jvrc1.urdf");
        let robot = Robot::vendored("jvrc1");
        assert_eq!(g.model.name(g.legs.pelvis), "PELVIS_S");
        assert!((g.legs.axes.forward - Vector3::x()).norm() < 1e-9);
        assert_eq!(g.frames.base_link.value, "PELVIS_S");
        for (i, effector) in [EndEffector::LeftFoot, EndEffector::RightFoot]
            .into_iter()
            .enumerate()
        {
            let (link, configured) = frame_of(&robot, effector);
            let guessed = &g.frames.feet.value[i];
            assert_eq!(guessed.link, link);
            assert_eq!(guessed.rpy, [0.0; 3]);
            // The inertia box: 0.030 m forward as configured, 0.0986 m below the ankle where
            // the config (from the meshes) has 0.1077 m.
            let offset = pose(guessed).translation.vector - configured.translation.vector;
            assert!(offset.x.abs() < 1e-6 && offset.y.abs() < 1e-6, "{offset:?}");
            assert!((offset.z - 0.0091).abs() < 5e-4, "{offset:?}");
        }
        let (length, width) = g.frames.sole.value;
        assert!(
            (length - 0.20).abs() < 0.005 && (width - 0.08).abs() < 0.011,
            "{length} {width}"
        );
        let ft: Vec<&str> = g
            .frames
            .ft_sensors
            .value
            .iter()
            .map(|f| f.link.as_str())
            .collect();
        assert_eq!(ft, ["lfsensor", "rfsensor"]);
        let hands: Vec<&str> = g
            .frames
            .hands
            .value
            .iter()
            .map(|f| f.link.as_str())
            .collect();
        assert_eq!(hands, ["L_WRIST_Y_S", "R_WRIST_Y_S"]);
        same_groups(&robot, &g.groups);
        // The legs stand as configured (the config also bends the arms).
        for (joint, angle) in &g.standing {
            let configured = robot.standing.joint(&robot.model, joint).unwrap();
            assert!(
                (angle - configured).abs() < 1e-12,
                "{joint}: {angle} vs {configured}"
            );
        }
        assert_eq!(g.standing.len(), 6);
    }

    #[test]
    fn armar4_guesses_match_its_config_but_the_sole() {
        let g = guess("armar4/armar4_fixed_hands.urdf");
        let robot = Robot::vendored("armar4");
        assert_eq!(g.frames.base_link.value, "root");
        let feet: Vec<&str> = g
            .frames
            .feet
            .value
            .iter()
            .map(|f| f.link.as_str())
            .collect();
        assert_eq!(feet, ["leg_ank2_r0", "leg_ank2_r1"]);
        // Level soles on the skewed ankle links: the configured orientation.
        for (i, effector) in [EndEffector::LeftFoot, EndEffector::RightFoot]
            .into_iter()
            .enumerate()
        {
            let (_, configured) = frame_of(&robot, effector);
            let turn = pose(&g.frames.feet.value[i])
                .rotation
                .angle_to(&configured.rotation);
            assert!(
                turn < 2e-3,
                "{effector:?} sole turned {turn} rad from the config"
            );
            let ft = pose(&g.frames.ft_sensors.value[i]).rotation;
            assert!(ft.angle_to(&configured.rotation) < 2e-3);
        }
        same_groups(&robot, &g.groups);
        // The IK levelled the feet: the knees bent about as configured (0.735 rad).
        let knee = g
            .standing
            .iter()
            .find(|(j, _)| j == "leg_knee_joint_r0")
            .unwrap()
            .1;
        assert!((knee - 0.735).abs() < 0.03, "{knee}");
        assert!(g.legs.left.ankle_roll.is_some());
        assert_eq!(
            g.model.joint_name(g.legs.left.ankle_roll.unwrap()),
            "leg_ank2_joint_r0"
        );
    }

    #[test]
    fn icub_soles_ft_sensors_and_hands() {
        let g = guess("icub/iCubGazeboV2_7.urdf");
        assert_eq!(g.frames.base_link.value, "root_link");
        assert!(
            (g.legs.axes.forward + Vector3::x()).norm() < 1e-9,
            "iCub faces −x"
        );
        let links =
            |specs: &[FrameSpec; 2]| specs.iter().map(|f| f.link.clone()).collect::<Vec<_>>();
        assert_eq!(links(&g.frames.feet.value), ["l_sole", "r_sole"]);
        assert_eq!(
            links(&g.frames.ft_sensors.value),
            ["l_foot_ft", "r_foot_ft"]
        );
        assert_eq!(links(&g.frames.hands.value), ["l_hand", "r_hand"]);
        // The sole frames are iCub's own (x forward, z up), moved to the collision box's centre.
        for spec in &g.frames.feet.value {
            assert_eq!(spec.rpy, [0.0; 3]);
            assert!((spec.translation[0] - 0.0265).abs() < 1e-6, "{spec:?}");
            assert!(spec.translation[2].abs() < 5e-5, "{spec:?}");
        }
        assert_eq!(g.frames.sole.value, (0.16, 0.072));
        assert_eq!(
            (
                g.groups.legs.len(),
                g.groups.arms.len(),
                g.groups.torso.len(),
                g.groups.head.len()
            ),
            (12, 14, 3, 3)
        );
        let get = |name: &str| g.standing.iter().find(|(j, _)| j == name).map(|x| x.1);
        assert_eq!(
            (
                get("l_hip_pitch"),
                get("l_knee"),
                get("l_ankle_pitch"),
                get("l_hip_roll")
            ),
            (Some(0.38), Some(-0.76), Some(-0.38), None)
        );
    }

    #[test]
    fn a_model_without_two_legs_is_refused() {
        let one_leg = r#"<robot name="stork">
  <link name="pelvis"><inertial><mass value="5"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="thigh"/><link name="shank"/><link name="foot"/>
  <joint name="hip" type="revolute"><parent link="pelvis"/><child link="thigh"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <joint name="knee" type="revolute"><parent link="thigh"/><child link="shank"/><origin xyz="0 0 -0.4"/><axis xyz="0 1 0"/><limit lower="0" upper="2" effort="10" velocity="1"/></joint>
  <joint name="ankle" type="revolute"><parent link="shank"/><child link="foot"/><origin xyz="0 0 -0.4"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>"#;
        let path =
            std::env::temp_dir().join(format!("init-robot-stork-{}.urdf", std::process::id()));
        std::fs::write(&path, one_leg).unwrap();
        let model = UrdfModel::load(&path).unwrap();
        let error = find_legs(&model, [None, None]).unwrap_err().to_string();
        std::fs::remove_file(&path).ok();
        assert!(
            error.contains("no two recognisable legs") && error.contains("foot"),
            "{error}"
        );
    }
}
