//! The pose-level execution impediments of DESIGN.md §1, injected into a planned human walk
//! before retargeting (so the robot's IK carries them into `q_S`, as a retargeted demonstration
//! would): jumping contacts, tilted and hovering contact soles, swing feet too high or rotated.
//! Steps too long or too wide and feet crossing (big-foot collisions) come from the footprint
//! sampler; the sequence sinking below the floor is applied to the root after IK.

use nalgebra::{UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

use super::gait::{PlannedStance, gaussian};
use crate::poses::FEET;

/// Probability per contact foot and stance (jumping, tilt, hover) or per swing foot (high, rotated).
const P_JUMP: f64 = 0.25;
const P_TILT: f64 = 0.2;
const P_HOVER: f64 = 0.2;
const P_SWING_HIGH: f64 = 0.25;
const P_SWING_ROTATED: f64 = 0.3;

/// Perturbs the feet targets of `stances` in place; `scale` is the human-to-robot length scale.
pub(crate) fn inject(stances: &mut [PlannedStance], scale: f64, rng: &mut ChaCha8Rng) {
    for i in 0..stances.len() {
        for foot in FEET {
            let f = foot as usize;
            let in_contact = stances[i].contacts[f];
            let continues = i > 0 && stances[i - 1].contacts[f] && in_contact;
            let Some(target) = stances[i].targets[f].as_mut() else {
                continue;
            };
            let local = |roll: f64, pitch: f64, yaw: f64| {
                UnitQuaternion::from_euler_angles(roll, pitch, yaw)
            };
            if continues && rng.random_bool(P_JUMP) {
                target.translation.vector +=
                    Vector3::new(gaussian(rng, 0.0, 0.02), gaussian(rng, 0.0, 0.02), 0.0) * scale;
                target.rotation *= local(0.0, 0.0, gaussian(rng, 0.0, 0.05));
            }
            if in_contact {
                if rng.random_bool(P_TILT) {
                    target.rotation *=
                        local(gaussian(rng, 0.0, 0.08), gaussian(rng, 0.0, 0.08), 0.0);
                }
                if rng.random_bool(P_HOVER) {
                    target.translation.vector.z += rng.random_range(0.01..0.05) * scale;
                }
            } else {
                if rng.random_bool(P_SWING_HIGH) {
                    target.translation.vector.z = rng.random_range(0.25..0.4) * scale;
                }
                if rng.random_bool(P_SWING_ROTATED) {
                    target.rotation *= local(
                        gaussian(rng, 0.0, 0.4),
                        gaussian(rng, 0.0, 0.4),
                        gaussian(rng, 0.0, 0.5),
                    );
                }
            }
        }
    }
}

/// How far the whole sequence is sunk below the floor (metres).
pub(crate) fn sink_depth(rng: &mut ChaCha8Rng) -> f64 {
    rng.random_range(0.05..0.3)
}
