//! The standing posture guess: knees bent, soles flat and parallel to the pelvis.
//!
//! Each knee bends by [`KNEE_BEND_RAD`] (JVRC-1's hand-tuned 0.76 rad), at most half its range on
//! the bending side, in the direction of its larger limit. The hip and the ankle each turn
//! back half of that about the lateral axis, so hip + knee + ankle pitch sum to zero and the
//! foot keeps its zero-configuration orientation with the ankle below the hip: over the hip's
//! (and the ankle's) joints, the least-norm angles θⱼ = t·aⱼ / Σ aᵢ² with aⱼ the joint axis'
//! lateral component and t = −(knee's lateral component · knee angle)/2 — the plain
//! `hip pitch = ankle pitch = −knee/2` when the axes are parallel. Every angle stays
//! [`LIMIT_MARGIN_RAD`] inside its limits. A hip whose axes are skewed (ARMAR-4's) leaves the
//! foot tilted after that: the posture is then refined by the IK (fixed pelvis, each foot at
//! its zero-configuration orientation, directly below where it stood, raised as the first guess
//! raised it, the first guess as the posture reference). Arms, torso and head stay at zero
//! (clamped into their limits, as `[robot.standing]` leaves unnamed joints).

use kinematics::{Configuration, IkOptions, IkSolver, IkTarget, Isometry3, Translation3, Vector3};

use super::legs::{Leg, Legs};
use super::model::{Posed, UrdfModel};

/// How far each knee bends when standing (rad): JVRC-1's hand-tuned value.
pub const KNEE_BEND_RAD: f64 = 0.76;
/// Standing angles stay this far inside the joint limits (rad): `[controller]
/// joint_limit_margin_rad`, so the controller can hold them.
pub const LIMIT_MARGIN_RAD: f64 = 0.02;
/// A foot counts as level when it is turned less than this from its zero-configuration
/// orientation (rad); tighter than `Robot::load`'s 1e-6 so the check there passes.
const LEVEL_RAD: f64 = 1e-9;

/// The guessed posture.
#[derive(Debug, Clone)]
pub struct Standing {
    /// The posture (base at the identity).
    pub q: Configuration,
    /// The leg joints it sets (model order, non-zero).
    pub angles: Vec<(usize, f64)>,
    /// How it was found (for the table of guesses).
    pub basis: String,
}

/// The standing posture of `legs`.
pub fn standing(model: &UrdfModel, legs: &Legs) -> anyhow::Result<Standing> {
    let zero = Configuration::neutral(&model.model);
    let mut q = zero.clone();
    for leg in legs.both() {
        bend(model, legs, leg, &zero, &mut q);
    }
    let at_zero = Posed::new(model, &zero);
    let bent = Posed::new(model, &q);
    let tilt = legs
        .both()
        .iter()
        .map(|leg| {
            let before = at_zero.link(leg.foot).rotation;
            bent.link(leg.foot).rotation.angle_to(&before)
        })
        .fold(0.0, f64::max);
    let mut basis = format!(
        "knees {:.2} rad, hips and ankles half back each (hip + knee + ankle pitch = 0)",
        KNEE_BEND_RAD
    );
    if tilt > LEVEL_RAD {
        q = refine(model, legs, &zero, &q).map_err(|e| {
            anyhow::anyhow!(
                "{}: the standing posture: bending the knees tilts the feet by {tilt:.3} rad and \
                 the IK could not level them: {e}",
                model.path.display()
            )
        })?;
        basis.push_str(&format!(
            "; the feet tilted {tilt:.3} rad (skewed axes), levelled by the IK"
        ));
    }
    let leg_joints: Vec<usize> = {
        let mut all: Vec<usize> = legs.both().iter().flat_map(|l| l.joints.clone()).collect();
        all.sort_unstable();
        all
    };
    let angles = leg_joints
        .into_iter()
        .filter(|&j| q.joints[j] != zero.joints[j])
        .map(|j| (j, q.joints[j]))
        .collect();
    Ok(Standing { q, angles, basis })
}

/// Bends one leg's knee and turns its hip and ankle back (the first guess).
fn bend(model: &UrdfModel, legs: &Legs, leg: &Leg, zero: &Configuration, q: &mut Configuration) {
    let posed = Posed::new(model, zero);
    let limits = model.model.joint_limits();
    let knee_limits = limits[leg.knee];
    let range = if leg.knee_bend > 0.0 {
        knee_limits.upper
    } else {
        -knee_limits.lower
    };
    let knee = leg.knee_bend * KNEE_BEND_RAD.min(0.5 * range.max(0.0));
    q.joints[leg.knee] = clamp(knee, limits[leg.knee]);
    let lateral = |j: usize| posed.joint_axis(j).dot(&legs.axes.left);
    let turn = -lateral(leg.knee) * q.joints[leg.knee] / 2.0;
    for joints in [&leg.hip, &leg.ankle] {
        let norm: f64 = joints.iter().map(|&j| lateral(j).powi(2)).sum();
        if norm < 1e-12 {
            continue;
        }
        for &j in joints.iter() {
            // Roll and yaw joints get nothing (not 1e-17 from rounding in their axes).
            let share = lateral(j) / norm;
            if share.abs() > 1e-9 {
                q.joints[j] = clamp(turn * share, limits[j]);
            }
        }
    }
}

fn clamp(angle: f64, limits: kinematics::JointLimits) -> f64 {
    let (low, high) = (
        limits.lower + LIMIT_MARGIN_RAD,
        limits.upper - LIMIT_MARGIN_RAD,
    );
    if low > high {
        (limits.lower + limits.upper) / 2.0
    } else {
        angle.clamp(low, high)
    }
}

/// Levels the feet with the IK: fixed pelvis, each foot at its zero-configuration orientation,
/// directly below its zero-configuration place, raised by the first guess' mean rise.
fn refine(
    model: &UrdfModel,
    legs: &Legs,
    zero: &Configuration,
    guess: &Configuration,
) -> anyhow::Result<Configuration> {
    let mut ik_model = model.model.clone();
    let at_zero = Posed::new(model, zero);
    let bent = Posed::new(model, guess);
    let rise: f64 = legs
        .both()
        .iter()
        .map(|leg| {
            (bent.link(leg.foot).translation.vector - at_zero.link(leg.foot).translation.vector)
                .dot(&legs.axes.up)
        })
        .sum::<f64>()
        / 2.0;
    let mut targets = Vec::new();
    for leg in legs.both() {
        let frame = ik_model.add_frame(
            &format!("init_robot_{}_foot", leg.side.name()),
            leg.foot,
            Isometry3::identity(),
        )?;
        let start = at_zero.link(leg.foot);
        let position: Vector3<f64> = start.translation.vector + legs.axes.up * rise;
        targets.push(IkTarget {
            frame,
            pose: Isometry3::from_parts(Translation3::from(position), start.rotation),
            position_weight: 1.0,
            orientation_weight: 1.0,
        });
    }
    let options = IkOptions {
        max_iterations: 2000,
        tolerance: 1e-11,
        fixed_base: true,
        ..IkOptions::default()
    };
    let solution = IkSolver::new(&ik_model).solve(
        &ik_model,
        &targets,
        guess,
        Some(&guess.joints),
        &options,
    )?;
    Ok(solution.configuration)
}
