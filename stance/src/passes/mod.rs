//! Algorithm 1: the nine post-processing passes (DESIGN.md §4), the terrain pass that puts
//! the walk on its surfaces (DESIGN.md §11) and the pass that puts held hands on the railings,
//! each a function on a [`PoseSequence`], and [`run_passes`], which composes them in the paper's
//! order with the terrain and hand passes after pass 8.

mod contacts;
mod elevation;
mod hands;
mod height;
mod orientation;
mod path;
mod terrain;

use std::sync::LazyLock;

pub use contacts::unify_contacts;
pub use elevation::{contact_feet_to_surface_elevation, move_stances_up};
pub use hands::hold_hand_affordances;
pub use height::limit_swing_foot_height;
pub use orientation::{contact_feet_parallel_to_surface, limit_swing_foot_rotation};
pub use path::{limit_orthogonal_feet_distance, limit_to_max_step_size, scale_translation};
pub use terrain::{
    HEEL_MARGIN_M, KINK_MARGIN_M, SHORT_SURFACE_SOLES, TOE_MARGIN_M, place_on_terrain,
};

use kinematics::robot::{Robot, SoleRectangle};

use crate::environment::Environment;
use crate::geometry::PathFrame;
use crate::params::PostProcessParams;
use crate::poses::{FEET, PoseSequence};

/// The passes in execution order: Algorithm 1's (lines 2–10) with the terrain pass and the hand
/// pass after line 9.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pass {
    /// Line 2, [`move_stances_up`].
    MoveStancesUp,
    /// Line 3, [`unify_contacts`].
    UnifyContacts,
    /// Line 4, [`contact_feet_parallel_to_surface`].
    ContactFeetParallelToSurface,
    /// Line 5, [`contact_feet_to_surface_elevation`].
    ContactFeetToSurfaceElevation,
    /// Line 6, [`limit_swing_foot_rotation`].
    LimitSwingFootRotation,
    /// Line 7, [`scale_translation`].
    ScaleTranslation,
    /// Line 8, [`limit_to_max_step_size`].
    LimitToMaxStepSize,
    /// Line 9, [`limit_orthogonal_feet_distance`].
    LimitOrthogonalFeetDistance,
    /// Not in Algorithm 1: [`place_on_terrain`].
    PlaceOnTerrain,
    /// Not in Algorithm 1: [`hold_hand_affordances`].
    HoldHandAffordances,
    /// Line 10, [`limit_swing_foot_height`].
    LimitSwingFootHeight,
}

impl Pass {
    /// All passes in order.
    pub const ALL: [Pass; 11] = [
        Pass::MoveStancesUp,
        Pass::UnifyContacts,
        Pass::ContactFeetParallelToSurface,
        Pass::ContactFeetToSurfaceElevation,
        Pass::LimitSwingFootRotation,
        Pass::ScaleTranslation,
        Pass::LimitToMaxStepSize,
        Pass::LimitOrthogonalFeetDistance,
        Pass::PlaceOnTerrain,
        Pass::HoldHandAffordances,
        Pass::LimitSwingFootHeight,
    ];

    /// The paper's name of the pass (ours for the terrain and hand passes).
    pub fn name(self) -> &'static str {
        match self {
            Pass::MoveStancesUp => "moveStancesUp",
            Pass::UnifyContacts => "unifyContacts",
            Pass::ContactFeetParallelToSurface => "contactFeetParallelToGroundSurface",
            Pass::ContactFeetToSurfaceElevation => "contactFeetToSurfaceElevation",
            Pass::LimitSwingFootRotation => "limitSwingFootRotation",
            Pass::ScaleTranslation => "scaleTranslation",
            Pass::LimitToMaxStepSize => "limitToMaxStepSize",
            Pass::LimitOrthogonalFeetDistance => "limitOrthogonalFeetDistance",
            Pass::PlaceOnTerrain => "placeOnTerrain",
            Pass::HoldHandAffordances => "holdHandAffordances",
            Pass::LimitSwingFootHeight => "limitSwingFootHeight",
        }
    }

    /// Line of Algorithm 1 that runs the pass; `None` for the terrain and hand passes, which
    /// the paper does not have.
    pub fn line(self) -> Option<usize> {
        match self {
            Pass::PlaceOnTerrain | Pass::HoldHandAffordances => None,
            Pass::LimitSwingFootHeight => Some(10),
            earlier => Some(earlier as usize + 2),
        }
    }

    /// The environment the pass works in, so its result lies on: the flat ground the raw walk
    /// was generated on (the plane z = 0 through its start) before the terrain pass, `walk`
    /// (the sequence's own, its railings included) from it on.
    pub fn environment(self, walk: &Environment) -> &Environment {
        match self {
            Pass::PlaceOnTerrain | Pass::HoldHandAffordances | Pass::LimitSwingFootHeight => walk,
            _ => flat_ground(),
        }
    }
}

/// The ground plane z = 0 through the start of a walk, where every stance source generates it:
/// passes 1–5 work on it whatever the walk's environment ([`Pass::environment`]), as the raw
/// walk is still at the human-to-robot scale that pass 6 changes.
fn flat_ground() -> &'static Environment {
    static FLAT: LazyLock<Environment> = LazyLock::new(Environment::default);
    &FLAT
}

/// The walking path of a pose sequence (see [`PathFrame`]): from the first root along the line
/// of the root's travel to the last stance, pointing the way the contact feet head, or along
/// the feet's mean heading when the root does not travel at all; `None` when empty.
///
/// The line, not the travel's sign: pass 7 shortens a short walk's steps along that line and
/// can bring its last root behind its first (a root ahead of the feet in the first stance), so
/// a path taken from the travel's sign would turn to the feet's heading on the second run, and
/// the passes would no longer be idempotent.
pub fn path_of(poses: &PoseSequence) -> Option<PathFrame> {
    let origin = poses.roots.first()?.translation.vector;
    let contact_feet = (0..poses.len()).flat_map(|i| {
        FEET.iter()
            .filter(move |&&foot| poses.in_contact(i, foot))
            .map(move |&foot| poses.pose(i, foot))
    });
    let heading = PathFrame::of_walk(&origin, contact_feet);
    let travel = poses.roots.last()?.translation.vector - origin;
    let forward = if travel.dot(heading.direction()) < 0.0 {
        -travel
    } else {
        travel
    };
    Some(PathFrame::new(&origin, &forward).unwrap_or(heading))
}

/// The sizes of the robot's contact geometry that the passes need: a foot's sole fits on its
/// surface (terrain pass) and clears the edges it swings over (pass 9); a held palm rests on
/// top of its railing (hand pass).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactGeometry {
    /// The sole rectangle of each foot.
    pub sole: SoleRectangle,
    /// Radius (m) of the sphere centred on each hand frame, the hand's collision geometry.
    pub palm_radius: f64,
}

impl ContactGeometry {
    /// The robot's sole and palm.
    pub fn of(robot: &Robot) -> Self {
        Self {
            sole: robot.sole,
            palm_radius: robot.palm_radius,
        }
    }
}

/// Runs the passes in order on `poses`, a walk generated on the flat ground at the origin and
/// meant for `environment` (in the walk's frame); `contact` is the robot's. Allocation-free
/// (after the first call).
pub fn run_passes(
    poses: &mut PoseSequence,
    environment: &Environment,
    params: &PostProcessParams,
    contact: &ContactGeometry,
) {
    run_passes_observed(poses, environment, params, contact, |_, _| {});
}

/// [`run_passes`], calling `after` with each pass and the poses it produced (for Fig. 3).
pub fn run_passes_observed(
    poses: &mut PoseSequence,
    environment: &Environment,
    params: &PostProcessParams,
    contact: &ContactGeometry,
    mut after: impl FnMut(Pass, &PoseSequence),
) {
    let sole = &contact.sole;
    if poses.is_empty() {
        return;
    }
    let flat = flat_ground();
    move_stances_up(poses, flat);
    after(Pass::MoveStancesUp, poses);
    unify_contacts(poses, params.contact_unification);
    after(Pass::UnifyContacts, poses);
    contact_feet_parallel_to_surface(poses, flat);
    after(Pass::ContactFeetParallelToSurface, poses);
    contact_feet_to_surface_elevation(poses, flat);
    after(Pass::ContactFeetToSurfaceElevation, poses);
    // The walking path, once the contacts are unified: no later pass changes a contact's yaw.
    let path = path_of(poses).expect("a non-empty sequence has a path");
    limit_swing_foot_rotation(poses, flat, &path, params.alpha());
    after(Pass::LimitSwingFootRotation, poses);
    scale_translation(poses, &path, params.scf);
    after(Pass::ScaleTranslation, poses);
    limit_to_max_step_size(poses, &path, params.s_max);
    after(Pass::LimitToMaxStepSize, poses);
    limit_orthogonal_feet_distance(poses, &path, params.o_min, params.o_max);
    after(Pass::LimitOrthogonalFeetDistance, poses);
    place_on_terrain(poses, environment, sole, params);
    after(Pass::PlaceOnTerrain, poses);
    hold_hand_affordances(poses, environment, contact.palm_radius);
    after(Pass::HoldHandAffordances, poses);
    limit_swing_foot_height(poses, environment, sole.length, params.h_min, params.h_max);
    after(Pass::LimitSwingFootHeight, poses);
}

/// Hand-made pose sequences for the passes' unit tests.
#[cfg(test)]
pub(crate) mod fixtures {
    use kinematics::robot::{EndEffector, SoleRectangle};
    use nalgebra::{Isometry3, UnitQuaternion, Vector3};

    use super::ContactGeometry;
    use crate::environment::SupportSurface;
    use crate::geometry::PathFrame;
    use crate::poses::PoseSequence;

    /// A sole of JVRC-1's size.
    pub const SOLE: SoleRectangle = SoleRectangle {
        length: 0.2,
        width: 0.08,
    };

    /// JVRC-1's sole and palm.
    pub const CONTACT: ContactGeometry = ContactGeometry {
        sole: SOLE,
        palm_radius: 0.04,
    };

    /// A walking path along +x from the origin.
    pub fn x_path() -> PathFrame {
        PathFrame::new(&Vector3::zeros(), &Vector3::x()).unwrap()
    }

    /// A horizontal surface 1 m wide from x = `from` to `to` at elevation `z`.
    pub fn block(name: &str, from: f64, to: f64, z: f64) -> SupportSurface {
        let half = (to - from) / 2.0;
        SupportSurface {
            name: name.into(),
            pose: Isometry3::translation(from + half, 0.0, z),
            polygon: Some(vec![[-half, -0.5], [half, -0.5], [half, 0.5], [-half, 0.5]]),
        }
    }

    pub const BOTH: [bool; 4] = [true, true, false, false];
    pub const LEFT: [bool; 4] = [true, false, false, false];
    pub const RIGHT: [bool; 4] = [false, true, false, false];

    /// One stance: left and right foot positions (identity rotation) and contact flags.
    pub fn stance(
        left: [f64; 3],
        right: [f64; 3],
        contacts: [bool; 4],
    ) -> ([f64; 3], [f64; 3], [bool; 4]) {
        (left, right, contacts)
    }

    /// A pose sequence from stances; the root sits 0.8 m above the feet's midpoint and the hands
    /// 0.3 m to either side of the root.
    pub fn walk(stances: &[([f64; 3], [f64; 3], [bool; 4])]) -> PoseSequence {
        let mut poses = PoseSequence::default();
        for &(left, right, contacts) in stances {
            let (l, r) = (Vector3::from(left), Vector3::from(right));
            let root = (l + r) / 2.0 + Vector3::new(0.0, 0.0, 0.8);
            let at = |p: Vector3<f64>| Isometry3::translation(p.x, p.y, p.z);
            poses.push(
                at(root),
                [
                    at(l),
                    at(r),
                    at(root + Vector3::new(0.0, 0.3, 0.0)),
                    at(root - Vector3::new(0.0, 0.3, 0.0)),
                ],
                contacts,
            );
        }
        poses
    }

    /// Sets `e`'s rotation in stance `i` from roll/pitch/yaw.
    pub fn rotated(poses: &mut PoseSequence, i: usize, e: EndEffector, rpy: [f64; 3]) {
        poses.end_effectors[i][e as usize].rotation =
            UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]);
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::fixtures::{BOTH, CONTACT, block, rotated, stance, walk};
    use super::*;
    use crate::geometry::roll_pitch_yaw;
    use crate::params::ContactUnification;
    use kinematics::robot::EndEffector::{LeftFoot, RightFoot};

    pub(crate) fn params() -> PostProcessParams {
        PostProcessParams {
            scf: 0.5,
            s_max: 0.3,
            o_min: 0.18,
            o_max: 0.3,
            alpha_x: 0.1,
            alpha_y: 0.1,
            alpha_z: 0.1,
            h_min: 0.03,
            h_max: 0.1,
            rise_weight: 1.0,
            stair_s_max: None,
            contact_unification: ContactUnification::First,
            gait: crate::Gait::Static,
        }
    }

    #[test]
    fn single_stance_sequence_is_made_executable() {
        let mut p = walk(&[stance([0.0, 0.05, -0.2], [0.0, -0.05, -0.17], BOTH)]);
        rotated(&mut p, 0, LeftFoot, [0.2, 0.1, 0.3]);
        run_passes(&mut p, &Environment::default(), &params(), &CONTACT);
        for foot in [LeftFoot, RightFoot] {
            let pose = p.pose(0, foot);
            let [roll, pitch, _] = roll_pitch_yaw(&pose.rotation);
            assert!(pose.translation.z.abs() < 1e-12 && roll.abs() < 1e-12 && pitch.abs() < 1e-12);
        }
        // No root motion: the walking direction is the feet's mean heading (yaw 0.15).
        let path = path_of(&p).unwrap();
        assert!((path.heading() - 0.15).abs() < 1e-12);
        let o = crate::derived::orthogonal_distances(&p, &path)[0];
        assert!((o - 0.18).abs() < 1e-12, "{o}");
    }

    #[test]
    fn passes_run_in_the_papers_order() {
        let lines: Vec<usize> = Pass::ALL.iter().filter_map(|p| p.line()).collect();
        assert_eq!(lines, (2..=10).collect::<Vec<_>>());
        let mut seen = Vec::new();
        let mut p = walk(&[stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH)]);
        run_passes_observed(
            &mut p,
            &Environment::default(),
            &params(),
            &CONTACT,
            |pass, _| seen.push(pass),
        );
        assert_eq!(seen, Pass::ALL);
        let terrain = Pass::ALL.iter().position(|&p| p == Pass::PlaceOnTerrain);
        assert_eq!(terrain, Some(8), "after pass 8, before pass 9");
        let hands = Pass::ALL
            .iter()
            .position(|&p| p == Pass::HoldHandAffordances);
        assert_eq!(hands, Some(9), "after the terrain pass, before pass 9");
    }

    /// Passes 1–5 work on the flat ground whatever the walk's environment: the walk is
    /// generated there.
    #[test]
    fn passes_before_the_terrain_pass_work_on_the_flat_ground() {
        let env = Environment {
            surfaces: vec![block("step", -1.0, 1.0, 0.1)],
            hand_affordances: Vec::new(),
        };
        let mut p = walk(&[stance([0.0, 0.1, -0.2], [0.0, -0.1, -0.2], BOTH)]);
        run_passes_observed(&mut p, &env, &params(), &CONTACT, |pass, poses| {
            let z = poses.pose(0, LeftFoot).translation.z;
            let expected = if pass.environment(&env) == &env {
                0.1
            } else {
                0.0
            };
            assert_eq!(z, expected, "after {}", pass.name());
        });
    }
}
