//! Steps and footholds of a walk, measured on the simulator's truth (never on the controller's
//! estimate): where each swing of a simulated sole came to rest against where the post-processed
//! sequence planned that foot's contacts, how high the walk started and ended, how many steps it
//! took, and how often its legs hit the terrain (`walkctl evaluate`, docs/evaluation.md).
//!
//! A *swing* begins when a sole rises [`STEP_HEIGHT_M`] above the height it rests at (at
//! submission, or where its last swing landed) and ends in a *touchdown* when, having come down
//! [`STEP_HEIGHT_M`] from the swing's highest point, it stays within [`REST_DISTANCE_M`] of one
//! position for [`REST_S`] of simulated time: at rest, wherever that is (a tread higher or lower
//! than the one it left, a ramp). The touchdown's position is the sole frame's at the end of that
//! window.

use kinematics::robot::SoleRectangle;
use serde::Serialize;
use shm_types::SimTruth;

use super::Points;
use super::clearance::{Edge, edge_clearance_m};

/// How far a sole must rise above where it rests for a swing to begin, and come down from the
/// swing's highest point before it may count as landed (m): above the contact compliance, below
/// the lowest swing (`h_min`, 2-3 cm above the surface).
pub(crate) const STEP_HEIGHT_M: f64 = 0.01;

/// A sole is at rest while it stays within this of one position (m) ...
pub(crate) const REST_DISTANCE_M: f64 = 0.005;

/// ... for this long (simulated s). Shorter than the time a landed foot stands (at least a
/// double support plus the other foot's swing: 0.65 s in the fastest gait, ARMAR-4's dynamic
/// one), longer than a swing's slowest moment off the ground.
pub(crate) const REST_S: f64 = 0.1;

/// Largest foothold error of a successful walk on a scene (m). A stair tread is 0.30 m deep
/// (docs/scenes.md) and the soles 0.20 m (JVRC-1) and 0.26 m (ARMAR-4) long: a sole landing
/// 0.10 m from a foothold planned on the middle of a tread keeps its centre (the ankle, over which
/// the single support's ZMP is held) 5 cm inside the tread and 75 % (JVRC-1) or 69 % (ARMAR-4)
/// of its length on it; a sole on the wrong tread is 0.30 m off.
pub const FOOTHOLD_BOUND_M: f64 = 0.10;

/// The feet in the order of the per-foot arrays here (as `stance::poses::FEET`).
pub(crate) const FEET: [&str; 2] = ["left", "right"];

/// The pose `[x, y, z, qx, qy, qz, qw]` of sole `foot` (0 left, 1 right) in `state` (world).
pub(crate) fn sole_pose(state: &SimTruth, foot: usize) -> &[f64; 7] {
    if foot == 0 {
        &state.left_foot
    } else {
        &state.right_foot
    }
}

/// The position of sole `foot` (0 left, 1 right) in `state` (world, m).
fn sole(state: &SimTruth, foot: usize) -> [f64; 3] {
    let pose = sole_pose(state, foot);
    [pose[0], pose[1], pose[2]]
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// A sole coming to rest after a swing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Touchdown {
    /// Simulated time at which it had been at rest for [`REST_S`] (s).
    pub(crate) time_s: f64,
    /// Where it rests (world, m).
    pub(crate) position: [f64; 3],
}

/// One swing of a simulated sole.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Swing {
    /// 0 left, 1 right ([`FEET`]).
    pub(crate) foot: usize,
    /// Simulated time at which the sole rose [`STEP_HEIGHT_M`] above its rest (s): the lift-off.
    pub(crate) lift_s: f64,
    /// Its touchdown; `None` when it had not come to rest by the last state.
    pub(crate) touchdown: Option<Touchdown>,
}

/// One sole's swing under way.
#[derive(Clone, Copy)]
struct Airborne {
    lift_s: f64,
    peak_z: f64,
    /// Where and since when the sole has stayed (within [`REST_DISTANCE_M`]) on its way down.
    still: Option<([f64; 3], f64)>,
}

/// The swings of both soles in `states` (in the order published; the first state is where they
/// rest at the start), ordered by lift-off.
pub(crate) fn swings(states: &[SimTruth]) -> Vec<Swing> {
    let mut swings = Vec::new();
    let Some(first) = states.first() else {
        return swings;
    };
    for foot in 0..FEET.len() {
        let mut rest_z = sole(first, foot)[2];
        let mut airborne: Option<Airborne> = None;
        for state in &states[1..] {
            let (p, t) = (sole(state, foot), state.sim_time_s);
            let Some(swing) = &mut airborne else {
                if p[2] > rest_z + STEP_HEIGHT_M {
                    airborne = Some(Airborne {
                        lift_s: t,
                        peak_z: p[2],
                        still: None,
                    });
                }
                continue;
            };
            swing.peak_z = swing.peak_z.max(p[2]);
            if p[2] > swing.peak_z - STEP_HEIGHT_M {
                swing.still = None;
                continue;
            }
            match swing.still {
                Some((at, since)) if distance(p, at) <= REST_DISTANCE_M => {
                    if t - since >= REST_S {
                        swings.push(Swing {
                            foot,
                            lift_s: swing.lift_s,
                            touchdown: Some(Touchdown {
                                time_s: t,
                                position: p,
                            }),
                        });
                        rest_z = p[2];
                        airborne = None;
                    }
                }
                _ => swing.still = Some((p, t)),
            }
        }
        if let Some(swing) = airborne {
            swings.push(Swing {
                foot,
                lift_s: swing.lift_s,
                touchdown: None,
            });
        }
    }
    swings.sort_by(|a, b| a.lift_s.total_cmp(&b.lift_s));
    swings
}

/// The states of a walk submitted at `submitted_ns` (monotonic): from the newest state read
/// before the submission (the first recorded if none was) to the last.
pub(crate) fn since_submission(states: &[SimTruth], submitted_ns: u64) -> &[SimTruth] {
    let before = states.partition_point(|s| s.timestamp_ns <= submitted_ns);
    &states[before.saturating_sub(1)..]
}

/// The contacts the post-processed sequence plans for the feet, in the world.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct PlannedFootholds {
    /// Per foot ([`FEET`]): the horizontal position of its target in every stance it is in
    /// contact in.
    pub(crate) footholds: [Vec<[f64; 2]>; 2],
    /// Touchdowns the sequence plans: a foot in contact in a stance and not in the one before.
    pub(crate) steps: usize,
}

impl PlannedFootholds {
    /// From each stance's contact flags (indexed by `EndEffector`, feet first) and its targets
    /// in the world (`align_targets`, as the controller aligns the sequence).
    pub(crate) fn new(contacts: impl IntoIterator<Item = [bool; 4]>, targets: &[Points]) -> Self {
        let mut planned = Self::default();
        let mut before: Option<[bool; 4]> = None;
        for (contacts, target) in contacts.into_iter().zip(targets) {
            for (foot, position) in [target.left_foot, target.right_foot].iter().enumerate() {
                if !contacts[foot] {
                    continue;
                }
                planned.footholds[foot].push([position.x, position.y]);
                if before.is_some_and(|before| !before[foot]) {
                    planned.steps += 1;
                }
            }
            before = Some(contacts);
        }
        planned
    }

    /// Horizontal distance from `position` to the nearest planned foothold of `foot` (m); `None`
    /// when that foot has none.
    fn nearest(&self, foot: usize, position: [f64; 3]) -> Option<f64> {
        self.footholds[foot]
            .iter()
            .map(|f| (f[0] - position[0]).hypot(f[1] - position[1]))
            .min_by(f64::total_cmp)
    }
}

/// The largest horizontal distance of a simulated touchdown from the nearest planned foothold of
/// the same foot (m); `None` when no touchdown could be compared.
pub(crate) fn foothold_error_m(swings: &[Swing], planned: &PlannedFootholds) -> Option<f64> {
    swings
        .iter()
        .filter_map(|swing| planned.nearest(swing.foot, swing.touchdown?.position))
        .max_by(f64::total_cmp)
}

/// The mean height of the two simulated soles (m).
pub(crate) fn elevation_m(state: &SimTruth) -> f64 {
    (state.left_foot[2] + state.right_foot[2]) / 2.0
}

/// Two sole heights within this (m) are on one level: soles at rest on a tread lie within
/// millimetres of each other, and a riser is 0.10 m or more.
const LEVEL_TOLERANCE_M: f64 = 0.02;

/// The time per stair of a walk over stairs from its swings (s): the levels its soles come to
/// rest on are taken in the order first reached, after `start_z`, the level it starts on; the
/// time from the first touchdown on the first new level (the first stair) to the first on the
/// last, over the stairs between. One foot per stair, a stair a step; both feet on each, a
/// stair two steps. `None` on fewer than two new levels.
pub(crate) fn time_per_stair_s(swings: &[Swing], start_z: f64) -> Option<f64> {
    let mut touchdowns: Vec<Touchdown> = swings.iter().filter_map(|s| s.touchdown).collect();
    touchdowns.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    let mut levels = vec![start_z];
    let mut reached = Vec::new();
    for touchdown in touchdowns {
        let z = touchdown.position[2];
        if levels
            .iter()
            .all(|level| (z - level).abs() > LEVEL_TOLERANCE_M)
        {
            levels.push(z);
            reached.push(touchdown.time_s);
        }
    }
    let (first, last) = (reached.first()?, reached.last()?);
    (reached.len() >= 2).then(|| (last - first) / (reached.len() - 1) as f64)
}

/// What the simulator's truth says about the steps of one walk.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StepReport {
    /// Mean height of the two soles at submission (m).
    pub start_elevation_m: f64,
    /// Mean height of the two soles in the last state (m).
    pub end_elevation_m: f64,
    /// Touchdowns of the simulated soles.
    pub steps: usize,
    /// Touchdowns the sequence plans.
    pub planned_steps: usize,
    /// Simulated time from the first lift-off to the walk's end over `steps` (s); `None`
    /// without a step.
    pub time_per_step_s: Option<f64>,
    /// On stairs, the simulated time per stair climbed or descended ([`time_per_stair_s`], s);
    /// `None` off stairs (no swing passed over an edge: `edge_clearance_m` is `None`, as on the
    /// flat floor and the ramps, whose levels are every step's) or over fewer than two stairs.
    pub time_per_stair_s: Option<f64>,
    /// Leg-terrain collisions in the last state (the whole life of that simulator).
    pub terrain_collisions: u64,
    /// The largest horizontal distance of a touchdown from the nearest planned foothold of the
    /// same foot (m); `None` without a touchdown.
    pub foothold_error_m: Option<f64>,
    /// The least clearance of a swinging sole over a terrain edge, a stair's nosing
    /// ([`super::clearance`], m); `None` when no swing passed over one (always on the flat
    /// floor).
    pub edge_clearance_m: Option<f64>,
}

impl StepReport {
    /// The report on the recorded `states` of a walk submitted at `submitted_ns` that ended
    /// `walk_s` of simulated time later, against its `planned` footholds and over the terrain's
    /// `edges` for soles of size `sole`; `None` when nothing was recorded.
    pub(crate) fn of(
        states: &[SimTruth],
        submitted_ns: u64,
        walk_s: f64,
        planned: &PlannedFootholds,
        (edges, sole): (&[Edge], &SoleRectangle),
    ) -> Option<Self> {
        let walk = since_submission(states, submitted_ns);
        let (start, end) = (walk.first()?, walk.last()?);
        let swings = swings(walk);
        let steps = swings.iter().filter(|s| s.touchdown.is_some()).count();
        let edge_clearance = edge_clearance_m(walk, &swings, edges, sole);
        let walking_s = swings
            .first()
            .map(|first| walk_s - (first.lift_s - start.sim_time_s));
        Some(Self {
            start_elevation_m: elevation_m(start),
            end_elevation_m: elevation_m(end),
            steps,
            planned_steps: planned.steps,
            time_per_step_s: walking_s
                .filter(|&t| t > 0.0 && steps > 0)
                .map(|t| t / steps as f64),
            time_per_stair_s: edge_clearance
                .and_then(|_| time_per_stair_s(&swings, elevation_m(start))),
            terrain_collisions: end.terrain_collisions,
            foothold_error_m: foothold_error_m(&swings, planned),
            edge_clearance_m: edge_clearance,
        })
    }

    /// Why a walk on a scene that otherwise succeeded fails: its feet did not land within
    /// [`FOOTHOLD_BOUND_M`] of the planned footholds, or no touchdown could be measured.
    pub(crate) fn missed_footholds(&self) -> Option<String> {
        match self.foothold_error_m {
            Some(error) if error <= FOOTHOLD_BOUND_M => None,
            Some(error) => Some(format!(
                "missed a foothold by {error:.3} m (> {FOOTHOLD_BOUND_M} m)"
            )),
            None => Some("no touchdown measured".to_owned()),
        }
    }
}

/// The success and outcome of a walk judged `success` with `outcome` by today's rule, on a scene
/// (`on_scene`) also by its footholds ([`StepReport::missed_footholds`]); on the flat floor
/// unchanged.
pub(crate) fn judged_on_terrain(
    on_scene: bool,
    (success, outcome): (bool, String),
    report: &StepReport,
) -> (bool, String) {
    if !on_scene || !success {
        return (success, outcome);
    }
    match report.missed_footholds() {
        Some(why) => (false, format!("{why} (daemon: {outcome})")),
        None => (success, outcome),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluate::clearance;
    use nalgebra::{Isometry3, Vector3};
    use stance::{Environment, SupportSurface};

    const SOLE: SoleRectangle = SoleRectangle {
        length: 0.2,
        width: 0.08,
    };

    const DT: f64 = 0.01;

    /// A stream of states every [`DT`] s (time stamps 1000 ns apart from 1000), with the soles at
    /// `left(t)` and `right(t)`.
    fn walk(
        duration_s: f64,
        left: impl Fn(f64) -> [f64; 3],
        right: impl Fn(f64) -> [f64; 3],
    ) -> Vec<SimTruth> {
        let n = (duration_s / DT).round() as usize;
        (0..=n)
            .map(|k| {
                let t = k as f64 * DT;
                let mut state = SimTruth {
                    seq: k as u64 + 1,
                    timestamp_ns: (k as u64 + 1) * 1000,
                    sim_time_s: t,
                    ..SimTruth::ZERO
                };
                state.left_foot[..3].copy_from_slice(&left(t));
                state.right_foot[..3].copy_from_slice(&right(t));
                state
            })
            .collect()
    }

    /// A sole standing at `from` until `t0`, swinging in `swing_s` to `to` over an arc `apex` m
    /// above the higher of the two, standing there afterwards.
    fn step(
        from: [f64; 3],
        to: [f64; 3],
        t0: f64,
        swing_s: f64,
        apex: f64,
    ) -> impl Fn(f64) -> [f64; 3] {
        move |t| {
            let s = ((t - t0) / swing_s).clamp(0.0, 1.0);
            let lift = apex * (std::f64::consts::PI * s).sin()
                + (to[2] - from[2]).max(0.0) * (s * 4.0).min(1.0)
                - (from[2] - to[2]).max(0.0) * ((s - 0.75) * 4.0).clamp(0.0, 1.0);
            [
                from[0] + (to[0] - from[0]) * s,
                from[1] + (to[1] - from[1]) * s,
                from[2] + lift,
            ]
        }
    }

    fn still(at: [f64; 3]) -> impl Fn(f64) -> [f64; 3] {
        move |_| at
    }

    #[test]
    fn a_swing_up_a_stair_lands_where_it_comes_to_rest() {
        // The left sole climbs a 0.185 m riser 0.3 m ahead, apex 3 cm over the tread.
        let states = walk(
            2.0,
            step([0.0, 0.1, 0.0], [0.3, 0.1, 0.185], 0.5, 0.6, 0.03),
            still([0.0, -0.1, 0.0]),
        );
        let swings = swings(&states);
        assert_eq!(swings.len(), 1, "{swings:?}");
        let swing = swings[0];
        assert_eq!(swing.foot, 0);
        assert!((0.5..0.55).contains(&swing.lift_s), "{swing:?}");
        let touchdown = swing.touchdown.unwrap();
        // At rest from 1.1 s on: confirmed REST_S later.
        assert!(
            (touchdown.time_s - (1.1 + REST_S)).abs() < 1.5 * DT,
            "{touchdown:?}"
        );
        assert!(distance(touchdown.position, [0.3, 0.1, 0.185]) < 1e-9);
    }

    #[test]
    fn a_swing_down_and_one_still_in_the_air_at_the_end() {
        // The right sole steps down a riser, then lifts again and the record ends mid-swing.
        let down = step([0.0, -0.1, 0.185], [0.3, -0.1, 0.0], 0.2, 0.5, 0.02);
        let again = step([0.3, -0.1, 0.0], [0.6, -0.1, 0.0], 1.5, 0.5, 0.05);
        let right = move |t: f64| if t < 1.5 { down(t) } else { again(t) };
        let states = walk(1.8, still([0.0, 0.1, 0.185]), right);
        let swings = swings(&states);
        assert_eq!(swings.len(), 2, "{swings:?}");
        assert!(swings.iter().all(|s| s.foot == 1));
        let landed = swings[0].touchdown.unwrap();
        assert!(distance(landed.position, [0.3, -0.1, 0.0]) < 1e-9);
        assert_eq!(swings[1].touchdown, None);
        assert!(swings[1].lift_s > 1.5);
    }

    #[test]
    fn a_sole_that_hovers_at_its_apex_has_not_landed() {
        // Lifts 5 cm and stays there: a swing without a touchdown.
        let left = |t: f64| [0.0, 0.1, if t < 0.5 { 0.0 } else { 0.05 }];
        let states = walk(2.0, left, still([0.0, -0.1, 0.0]));
        let swings = swings(&states);
        assert_eq!(swings.len(), 1);
        assert_eq!(swings[0].touchdown, None);
        // A sole that never rises 1 cm does not swing.
        let shuffling = |t: f64| [0.05 * t, 0.1, 0.008 * (t * 10.0).sin().abs()];
        assert!(super::swings(&walk(2.0, shuffling, still([0.0, -0.1, 0.0]))).is_empty());
    }

    fn points(left: [f64; 2], right: [f64; 2]) -> Points {
        Points {
            com: Vector3::zeros(),
            left_foot: Vector3::new(left[0], left[1], 0.0),
            right_foot: Vector3::new(right[0], right[1], 0.0),
        }
    }

    /// Standing, the left foot swinging to x = 0.3, standing, the right foot swinging to 0.3.
    fn planned_walk() -> PlannedFootholds {
        let both = [true, true, false, false];
        let contacts = [
            both,
            [false, true, false, false],
            both,
            [true, false, false, false],
            both,
        ];
        let targets = [
            points([0.0, 0.1], [0.0, -0.1]),
            points([0.2, 0.1], [0.0, -0.1]),
            points([0.3, 0.1], [0.0, -0.1]),
            points([0.3, 0.1], [0.2, -0.1]),
            points([0.3, 0.1], [0.3, -0.1]),
        ];
        PlannedFootholds::new(contacts, &targets)
    }

    #[test]
    fn planned_footholds_are_the_contact_targets_per_foot() {
        let planned = planned_walk();
        assert_eq!(planned.steps, 2);
        // The swing targets (x = 0.2) are no footholds.
        assert_eq!(
            planned.footholds[0],
            [[0.0, 0.1], [0.3, 0.1], [0.3, 0.1], [0.3, 0.1]]
        );
        assert_eq!(
            planned.footholds[1],
            [[0.0, -0.1], [0.0, -0.1], [0.0, -0.1], [0.3, -0.1]]
        );
    }

    #[test]
    fn the_foothold_error_is_the_worst_touchdown_against_its_own_foots_plan() {
        let planned = planned_walk();
        let landed = |foot, x: f64, y: f64| Swing {
            foot,
            lift_s: 0.0,
            touchdown: Some(Touchdown {
                time_s: 1.0,
                position: [x, y, 0.0],
            }),
        };
        let swings = [
            landed(0, 0.32, 0.1),
            landed(1, 0.3, -0.15),
            // Never landed: not compared.
            Swing {
                foot: 0,
                lift_s: 2.0,
                touchdown: None,
            },
        ];
        assert!((foothold_error_m(&swings, &planned).unwrap() - 0.05).abs() < 1e-12);
        // The right foot near the left one's foothold is still measured against its own plan.
        let crossed = [landed(1, 0.3, 0.1)];
        assert!((foothold_error_m(&crossed, &planned).unwrap() - 0.2).abs() < 1e-12);
        assert_eq!(foothold_error_m(&swings[2..], &planned), None);
        assert_eq!(
            foothold_error_m(&swings, &PlannedFootholds::default()),
            None
        );
    }

    #[test]
    fn the_report_of_a_climb_counts_steps_heights_and_collisions() {
        let left = step([0.0, 0.1, 0.0], [0.3, 0.1, 0.185], 0.5, 0.6, 0.03);
        let right = step([0.0, -0.1, 0.0], [0.36, -0.1, 0.185], 1.5, 0.6, 0.03);
        let mut states = walk(3.0, left, right);
        states.last_mut().unwrap().terrain_collisions = 3;
        let planned = planned_walk();
        // Submitted at the state stamped 11000 ns (t = 0.1 s); the walk ends 2.9 s later.
        // A stair whose nosing is at x = 0.15: the right sole's swing (its centre 0.36 m on)
        // rises onto it too slowly and passes through it, 7 cm low, as its toe reaches it.
        let stair = Environment {
            surfaces: vec![SupportSurface {
                name: "tread".to_owned(),
                pose: Isometry3::translation(0.3, 0.0, 0.185),
                polygon: Some(vec![[-0.15, -0.5], [0.15, -0.5], [0.15, 0.5], [-0.15, 0.5]]),
            }],
            hand_affordances: Vec::new(),
        };
        let terrain = (clearance::edges(&stair), SOLE);
        let report =
            StepReport::of(&states, 11_000, 2.9, &planned, (&terrain.0, &terrain.1)).unwrap();
        let edge = report.edge_clearance_m.unwrap();
        assert!((-0.075..-0.055).contains(&edge), "{edge}");
        assert_eq!(report.start_elevation_m, 0.0);
        assert!((report.end_elevation_m - 0.185).abs() < 1e-12);
        assert_eq!((report.steps, report.planned_steps), (2, 2));
        // First lift-off just after 0.5 s, 0.4 s after submission: 2.5 s for two steps.
        let per_step = report.time_per_step_s.unwrap();
        assert!((per_step - 1.25).abs() < DT, "{per_step}");
        assert_eq!(report.terrain_collisions, 3);
        assert!((report.foothold_error_m.unwrap() - 0.06).abs() < 1e-9);
        // One stair: no time per stair.
        assert_eq!(report.time_per_stair_s, None);
        assert_eq!(StepReport::of(&[], 0, 1.0, &planned, (&[], &SOLE)), None);
    }

    /// Swings landing at `(time, height)` in turn, feet alternating.
    fn landings(at: &[(f64, f64)]) -> Vec<Swing> {
        at.iter()
            .enumerate()
            .map(|(k, &(time_s, z))| Swing {
                foot: k % 2,
                lift_s: time_s - 0.5,
                touchdown: Some(Touchdown {
                    time_s,
                    position: [0.3 * k as f64, 0.0, z],
                }),
            })
            .collect()
    }

    #[test]
    fn the_time_per_stair_counts_levels_not_steps() {
        // One foot per stair: a stair a step, 1 s apart (a few millimetres of settling on
        // each tread are one level).
        let one = landings(&[(1.0, 0.1), (2.0, 0.203), (3.0, 0.3), (4.0, 0.398)]);
        assert!((time_per_stair_s(&one, 0.0).unwrap() - 1.0).abs() < 1e-12);
        // Both feet on each stair: the second foot's touchdown on a tread is no new level.
        let both = landings(&[(1.0, 0.1), (2.0, 0.1), (3.0, 0.2), (4.0, 0.2), (5.0, 0.3)]);
        assert!((time_per_stair_s(&both, 0.0).unwrap() - 2.0).abs() < 1e-12);
        // Down from a landing at 0.3 m, unordered swings taken in order of touchdown.
        let mut down = landings(&[(1.5, 0.2), (3.0, 0.1), (4.5, 0.0)]);
        down.reverse();
        assert!((time_per_stair_s(&down, 0.3).unwrap() - 1.5).abs() < 1e-12);
        // One stair, the flat floor, nothing landed: no time per stair.
        assert_eq!(
            time_per_stair_s(&landings(&[(1.0, 0.1), (2.0, 0.1)]), 0.0),
            None
        );
        assert_eq!(
            time_per_stair_s(&landings(&[(1.0, 0.0), (2.0, 0.0)]), 0.0),
            None
        );
        assert_eq!(time_per_stair_s(&[], 0.0), None);
    }

    #[test]
    fn the_time_per_stair_needs_a_swing_over_an_edge() {
        // Two stairs up: the left sole onto a tread 0.185 m up, the right past it 0.37 m up,
        // touching down (at rest REST_S) about 1.3 s apart.
        let left = step([0.0, 0.1, 0.0], [0.3, 0.1, 0.185], 0.5, 0.6, 0.03);
        let right = step([0.0, -0.1, 0.0], [0.6, -0.1, 0.37], 1.8, 0.6, 0.05);
        let states = walk(4.0, left, right);
        let tread = |x: f64| Environment {
            surfaces: vec![SupportSurface {
                name: "tread".to_owned(),
                pose: Isometry3::translation(x, 0.0, 0.185),
                polygon: Some(vec![[-0.15, -0.5], [0.15, -0.5], [0.15, 0.5], [-0.15, 0.5]]),
            }],
            hand_affordances: Vec::new(),
        };
        let report = |environment: &Environment| {
            let edges = clearance::edges(environment);
            StepReport::of(&states, 1000, 3.9, &planned_walk(), (&edges, &SOLE)).unwrap()
        };
        let stairs = report(&tread(0.3));
        assert!(stairs.edge_clearance_m.is_some());
        let per_stair = stairs.time_per_stair_s.unwrap();
        assert!((per_stair - 1.3).abs() < 2.0 * DT, "{per_stair}");
        // Edges no swing passes over (as a ramp's sides): no stairs walked, no time per stair.
        let elsewhere = report(&tread(10.0));
        assert_eq!(elsewhere.edge_clearance_m, None);
        assert_eq!(elsewhere.time_per_stair_s, None);
    }

    #[test]
    fn a_standing_walk_has_no_steps() {
        let states = walk(1.0, still([0.0, 0.1, 0.5]), still([0.0, -0.1, 0.5]));
        let report = StepReport::of(&states, 1000, 1.0, &planned_walk(), (&[], &SOLE)).unwrap();
        assert_eq!(report.steps, 0);
        assert_eq!(report.edge_clearance_m, None);
        assert_eq!(report.time_per_step_s, None);
        assert_eq!(report.foothold_error_m, None);
        assert_eq!(report.start_elevation_m, 0.5);
    }

    #[test]
    fn on_a_scene_a_walk_must_also_land_on_its_footholds() {
        let report = |error| StepReport {
            start_elevation_m: 0.0,
            end_elevation_m: 0.0,
            steps: 2,
            planned_steps: 2,
            time_per_step_s: Some(1.0),
            time_per_stair_s: None,
            terrain_collisions: 0,
            foothold_error_m: error,
            edge_clearance_m: None,
        };
        let done = || (true, "done".to_owned());
        let near = report(Some(FOOTHOLD_BOUND_M));
        let far = report(Some(0.15));
        assert_eq!(judged_on_terrain(true, done(), &near), done());
        assert_eq!(
            judged_on_terrain(true, done(), &far),
            (
                false,
                "missed a foothold by 0.150 m (> 0.1 m) (daemon: done)".to_owned()
            )
        );
        assert_eq!(
            judged_on_terrain(true, done(), &report(None)),
            (false, "no touchdown measured (daemon: done)".to_owned())
        );
        // The flat floor keeps today's rule; a failed walk keeps its outcome.
        assert_eq!(judged_on_terrain(false, done(), &far), done());
        let fell = (false, "fell at 1.0 s (daemon: done)".to_owned());
        assert_eq!(judged_on_terrain(true, fell.clone(), &far), fell);
    }
}
