//! The hand-support part of the model: where a hand affordance is available, how likely a hand
//! joins a foot stance, learned on the demonstrations that recorded hands (the walking corpus has
//! no railing, so the foot n-gram alone never reaches hand stances from walking).

use serde::{Deserialize, Serialize};

use super::segment::{Keyframe, RelativePose};

/// The hand-contact model that complements the foot n-gram where a hand affordance is available:
/// for a foot support (`[lf, rf]`) and a hand, how often the hand supported given whether it did
/// in the previous stance, and the mean grasp pose relative to the root. Counted on the
/// demonstrations that recorded hands.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandSupport {
    /// Foot contacts `[lf, rf]` of the stance.
    pub feet: [bool; 2],
    /// 0 left hand, 1 right hand.
    pub hand: usize,
    /// `[grasping, all]` stances after a stance where the hand did not support.
    pub after_free: [u32; 2],
    /// `[grasping, all]` stances after a stance where the hand supported.
    pub after_grasp: [u32; 2],
    /// Mean grasp pose relative to the root (`None` if the hand never supported).
    pub pose: Option<RelativePose>,
}

impl HandSupport {
    /// P(hand supports | feet, previous stance grasping), add-one smoothed.
    pub fn probability(&self, previously_grasping: bool) -> f64 {
        let [on, all] = if previously_grasping {
            self.after_grasp
        } else {
            self.after_free
        };
        (f64::from(on) + 1.0) / (f64::from(all) + 2.0)
    }
}

/// Counts hand support per foot support and hand over the sequences that recorded hands.
pub(super) fn count_hand_support(sequences: &[Vec<Keyframe>]) -> Vec<HandSupport> {
    let mut table = Vec::new();
    for feet in [[true, true], [true, false], [false, true]] {
        for hand in 0..2 {
            let e = 2 + hand;
            let mut entry = HandSupport {
                feet,
                hand,
                after_free: [0, 0],
                after_grasp: [0, 0],
                pose: None,
            };
            let mut grasps: Vec<RelativePose> = Vec::new();
            for sequence in sequences
                .iter()
                .filter(|s| s.iter().all(|k| k.effectors[e].is_some()))
            {
                for k in 1..sequence.len() {
                    let stance = &sequence[k];
                    if stance.contacts[..2] != feet {
                        continue;
                    }
                    let grasping = stance.contacts[e];
                    let counts = if sequence[k - 1].contacts[e] {
                        &mut entry.after_grasp
                    } else {
                        &mut entry.after_free
                    };
                    counts[0] += u32::from(grasping);
                    counts[1] += 1;
                    if grasping {
                        grasps.extend(stance.effectors[e]);
                    }
                }
            }
            entry.pose = RelativePose::mean(&grasps);
            table.push(entry);
        }
    }
    table
}
