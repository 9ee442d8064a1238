//! The two legs of a URDF and the body's axes, found from the geometry of the zero
//! configuration (the URDF's z axis up, as REP-103 has it, and the robot standing straight):
//!
//! - **feet**: the two lowest *end links* — links moved by an actuated joint with no actuated
//!   joint below them — at the same height (within [`FOOT_LEVEL_M`]) and apart sideways; or the
//!   links given with `--left-foot` / `--right-foot`;
//! - **pelvis**: the link where the two feet's chains to the root meet;
//! - **leg joints**: the actuated joints from the pelvis down to each foot (at least
//!   [`MIN_LEG_JOINTS`]); the **knee** is the one named `knee`, else the one farthest from both
//!   ends of the leg; the joints above it are the hip's, those below the ankle's;
//! - **forward**: the knee bends the way its larger limit points (`sign`), and bending the knee
//!   swings the foot backwards, so forward is opposite the foot's horizontal motion when the
//!   knee bends; left = up × forward; which foot is left follows from the side it is on;
//! - **pitch and roll joints**: each joint's axis projected on the lateral (pitch) and forward
//!   (roll) axes; the hip- and ankle-pitch joints are those most aligned with the lateral axis,
//!   the ankle roll the ankle joint most aligned with the forward axis; the hip's lateral
//!   position is the origin of its joint least aligned with the lateral axis.

use kinematics::{Configuration, LinkId, Vector3};

use super::model::{Posed, UrdfModel};

/// The two feet of a biped stand at the same height in the zero configuration (m).
pub const FOOT_LEVEL_M: f64 = 0.05;
/// Fewest actuated joints a leg has (hip, knee, ankle).
pub const MIN_LEG_JOINTS: usize = 3;
/// The pelvis stands at least this far above the feet (m).
pub const MIN_LEG_HEIGHT_M: f64 = 0.1;

/// Left or right.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The robot's left (+y of the body axes).
    Left,
    /// The robot's right.
    Right,
}

impl Side {
    /// `left` or `right`.
    pub fn name(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }
}

/// The body's axes in the model's root frame (unit vectors).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyAxes {
    /// Walking direction (horizontal).
    pub forward: Vector3<f64>,
    /// The robot's left (horizontal).
    pub left: Vector3<f64>,
    /// Up (the URDF's z).
    pub up: Vector3<f64>,
}

/// One leg: its foot, its actuated joints and their roles (model-order joint indices).
#[derive(Debug, Clone, PartialEq)]
pub struct Leg {
    /// Which side.
    pub side: Side,
    /// The last link of the chain: the foot.
    pub foot: LinkId,
    /// The actuated joints from the pelvis down to the foot.
    pub joints: Vec<usize>,
    /// The joints above the knee.
    pub hip: Vec<usize>,
    /// The knee.
    pub knee: usize,
    /// The joints below the knee.
    pub ankle: Vec<usize>,
    /// The hip joint most aligned with the lateral axis: its axis' height is the hip's.
    pub hip_pitch: usize,
    /// The hip joint least aligned with the lateral axis (a roll or yaw joint, else the first):
    /// its origin's lateral position is the hip's (a pitch axis' origin may sit anywhere along
    /// it: iCub's is 4 cm inside its hip).
    pub hip_centre: usize,
    /// The ankle joint most aligned with the lateral axis.
    pub ankle_pitch: Option<usize>,
    /// The ankle joint most aligned with the forward axis.
    pub ankle_roll: Option<usize>,
    /// +1 or −1: the sign of the knee angle that bends it (the side of its larger limit).
    pub knee_bend: f64,
}

/// Both legs, where they meet and the body axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Legs {
    /// Where the two legs' chains meet (the pelvis).
    pub pelvis: LinkId,
    /// The left leg.
    pub left: Leg,
    /// The right leg.
    pub right: Leg,
    /// Body axes.
    pub axes: BodyAxes,
    /// How the feet were found (for the table of guesses).
    pub basis: String,
}

impl Legs {
    /// Both legs, left first.
    pub fn both(&self) -> [&Leg; 2] {
        [&self.left, &self.right]
    }
}

/// Finds the legs; `feet` (left, right) overrides the guess of the foot links.
pub fn find_legs(model: &UrdfModel, feet: [Option<LinkId>; 2]) -> anyhow::Result<Legs> {
    let zero = Configuration::neutral(&model.model);
    let posed = Posed::new(model, &zero);
    let (pair, basis) = match feet {
        [Some(a), Some(b)] => ([a, b], "given with --left-foot / --right-foot".to_owned()),
        [Some(given), None] | [None, Some(given)] => {
            let other = lowest_end_links(model, &posed)
                .into_iter()
                .find(|&l| model.common_ancestor(l, given) != given && l != given)
                .ok_or_else(|| anyhow::anyhow!("no end link besides {}", model.name(given)))?;
            (
                [given, other],
                format!(
                    "one given, the other the lowest end link ({})",
                    model.name(other)
                ),
            )
        }
        [None, None] => (
            guess_feet(model, &posed)?,
            "the two lowest end links of the model, at the same height".to_owned(),
        ),
    };
    let pelvis = model.common_ancestor(pair[0], pair[1]);
    let up = Vector3::z();
    let drop = posed.link(pelvis).translation.vector.z
        - posed
            .link(pair[0])
            .translation
            .vector
            .z
            .max(posed.link(pair[1]).translation.vector.z);
    if drop < MIN_LEG_HEIGHT_M {
        anyhow::bail!(
            "{}: no two recognisable legs: the chains to {} and {} meet at {}, only {:.3} m above \
             them (a humanoid's pelvis stands above its feet with the URDF's z up and the legs \
             straight at zero; pass --left-foot and --right-foot)",
            model.path.display(),
            model.name(pair[0]),
            model.name(pair[1]),
            model.name(pelvis),
            drop
        );
    }
    let chains = pair.map(|foot| model.chain(pelvis, foot));
    for (foot, chain) in pair.iter().zip(&chains) {
        if chain.len() < MIN_LEG_JOINTS {
            anyhow::bail!(
                "{}: no two recognisable legs: the chain from {} to {} has {} actuated joint(s) \
                 ({}), a leg has at least {MIN_LEG_JOINTS} (hip, knee, ankle); pass --left-foot \
                 and --right-foot",
                model.path.display(),
                model.name(pelvis),
                model.name(*foot),
                chain.len(),
                chain
                    .iter()
                    .map(|&j| model.joint_name(j))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    let knees = [
        knee(model, &posed, &chains[0]),
        knee(model, &posed, &chains[1]),
    ];
    let bends = knees.map(|k| knee_bend(model, k));
    // Bending the knee swings the foot backwards.
    let mut backwards = Vector3::zeros();
    for ((&foot, &knee), bend) in pair.iter().zip(&knees).zip(bends) {
        let lever = posed.link(foot).translation.vector - posed.joint_origin(knee);
        backwards += posed.joint_axis(knee).cross(&lever) * bend;
    }
    let horizontal = backwards - up * backwards.dot(&up);
    if horizontal.norm() < 1e-6 {
        anyhow::bail!(
            "{}: cannot tell forward from backward: bending the knees {} and {} does not move the \
             feet horizontally (are they knees?)",
            model.path.display(),
            model.joint_name(knees[0]),
            model.joint_name(knees[1])
        );
    }
    let forward = -horizontal.normalize();
    let axes = BodyAxes {
        forward,
        left: up.cross(&forward),
        up,
    };
    let side_of = |foot: LinkId| {
        let lateral = (posed.link(foot).translation.vector - posed.link(pelvis).translation.vector)
            .dot(&axes.left);
        if lateral >= 0.0 {
            Side::Left
        } else {
            Side::Right
        }
    };
    let legs: Vec<Leg> = (0..2)
        .map(|i| {
            leg(
                &posed,
                &axes,
                side_of(pair[i]),
                pair[i],
                &chains[i],
                knees[i],
                bends[i],
            )
        })
        .collect();
    let [first, second]: [Leg; 2] = legs.try_into().expect("two legs");
    if first.side == second.side {
        anyhow::bail!(
            "{}: no two recognisable legs: {} and {} are both on the {} side",
            model.path.display(),
            model.name(first.foot),
            model.name(second.foot),
            first.side.name()
        );
    }
    let (left, right) = if first.side == Side::Left {
        (first, second)
    } else {
        (second, first)
    };
    for (given, leg, option, other) in [
        (feet[0], &left, "--left-foot", "right"),
        (feet[1], &right, "--right-foot", "left"),
    ] {
        if let Some(given) = given.filter(|&f| f != leg.foot) {
            anyhow::bail!(
                "{option} {}: that foot is on the robot's {other} (forward, from the way the \
                 knees bend, is {:.3?} in the URDF's root frame)",
                model.name(given),
                axes.forward.as_slice()
            );
        }
    }
    Ok(Legs {
        pelvis,
        left,
        right,
        axes,
        basis,
    })
}

/// End links (moved by an actuated joint, none below), lowest first.
fn lowest_end_links(model: &UrdfModel, posed: &Posed) -> Vec<LinkId> {
    let mut ends: Vec<LinkId> = model
        .model
        .link_ids()
        .filter(|&l| model.facts(l).actuated.is_some() && !model.has_actuated_descendant(l))
        .collect();
    ends.sort_by(|&a, &b| {
        posed
            .link(a)
            .translation
            .z
            .total_cmp(&posed.link(b).translation.z)
    });
    ends
}

/// The two lowest end links at the same height, apart: the feet (in either order).
fn guess_feet(model: &UrdfModel, posed: &Posed) -> anyhow::Result<[LinkId; 2]> {
    let ends = lowest_end_links(model, posed);
    let describe = |ends: &[LinkId]| {
        ends.iter()
            .take(4)
            .map(|&l| format!("{} (z {:.3} m)", model.name(l), posed.link(l).translation.z))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let Some(&lowest) = ends.first() else {
        anyhow::bail!(
            "{}: no two recognisable legs: the model has no actuated joints",
            model.path.display()
        );
    };
    let at = posed.link(lowest).translation.vector;
    let other = ends.iter().skip(1).copied().find(|&l| {
        let p = posed.link(l).translation.vector;
        (p.z - at.z).abs() <= FOOT_LEVEL_M && (p - at).xy().norm() > FOOT_LEVEL_M
    });
    match other {
        Some(other) => Ok([lowest, other]),
        None => anyhow::bail!(
            "{}: no two recognisable legs: the lowest end links are {}; a biped has two at the \
             same height (within {FOOT_LEVEL_M} m) and apart, with the URDF's z up (pass \
             --left-foot and --right-foot)",
            model.path.display(),
            describe(&ends)
        ),
    }
}

/// The knee of a leg chain: the joint named so, else the one farthest from both ends.
fn knee(model: &UrdfModel, posed: &Posed, chain: &[usize]) -> usize {
    if let Some(&named) = chain
        .iter()
        .find(|&&j| model.joint_name(j).to_lowercase().contains("knee"))
    {
        return named;
    }
    let first = posed.joint_origin(chain[0]);
    let last = posed.joint_origin(chain[chain.len() - 1]);
    chain[1..chain.len() - 1]
        .iter()
        .copied()
        .max_by(|&a, &b| {
            let reach = |j: usize| {
                let p = posed.joint_origin(j);
                (p - first).norm().min((p - last).norm())
            };
            reach(a).total_cmp(&reach(b))
        })
        .unwrap_or(chain[1])
}

/// +1 when the knee's upper limit reaches farther from zero than its lower one, else −1.
fn knee_bend(model: &UrdfModel, knee: usize) -> f64 {
    let limits = model.model.joint_limits()[knee];
    if limits.upper.abs() >= limits.lower.abs() {
        1.0
    } else {
        -1.0
    }
}

/// The joint of `joints` whose axis is most aligned with `direction` (first on ties).
fn most_aligned(posed: &Posed, joints: &[usize], direction: &Vector3<f64>) -> Option<usize> {
    let mut best: Option<(usize, f64)> = None;
    for &j in joints {
        let alignment = posed.joint_axis(j).dot(direction).abs();
        if best.is_none_or(|(_, b)| alignment > b + 1e-9) {
            best = Some((j, alignment));
        }
    }
    best.filter(|&(_, a)| a > 0.5).map(|(j, _)| j)
}

#[allow(clippy::too_many_arguments)]
fn leg(
    posed: &Posed,
    axes: &BodyAxes,
    side: Side,
    foot: LinkId,
    chain: &[usize],
    knee: usize,
    knee_bend: f64,
) -> Leg {
    let at = chain
        .iter()
        .position(|&j| j == knee)
        .expect("knee in chain");
    let hip = chain[..at].to_vec();
    let ankle = chain[at + 1..].to_vec();
    // A hip without a joint that turns about the lateral axis has no pitch: use its first joint.
    let hip_pitch = most_aligned(posed, &hip, &axes.left)
        .or_else(|| {
            // A spherical hip with skewed axes (ARMAR-4): any of them, its origin is the centre.
            hip.first().copied()
        })
        .unwrap_or(knee);
    let hip_centre = hip
        .iter()
        .copied()
        .min_by(|&a, &b| {
            let lateral = |j: usize| posed.joint_axis(j).dot(&axes.left).abs();
            lateral(a).total_cmp(&lateral(b))
        })
        .unwrap_or(hip_pitch);
    Leg {
        side,
        foot,
        hip_centre,
        joints: chain.to_vec(),
        ankle_pitch: most_aligned(posed, &ankle, &axes.left),
        ankle_roll: most_aligned(posed, &ankle, &axes.forward),
        hip,
        knee,
        ankle,
        hip_pitch,
        knee_bend,
    }
}
