//! How high a swinging sole passed over the terrain's edges (a stair's nosing, the top of a
//! drop): `edge_clearance_m`, measured on the simulator's truth, never on the controller's
//! estimate or the plan.
//!
//! An *edge* is a side of a support surface's polygon beyond which the terrain falls away: just
//! outside the side's middle no surface is within [`DROP_M`] of its height, or none is there at
//! all. A stair's nosing is one, whether it is walked up or down; the foot of a riser (where a
//! higher tread begins) and the kink of a ramp onto its landing are not.
//!
//! During a swing — from its lift-off to the moment its sole came to rest
//! ([`super::footholds::swings`]) — the clearance is the distance from the sole's bottom (the
//! `[robot] sole` rectangle on the sole frame: the bottom face of MuJoCo's foot box) down to each
//! edge the rectangle passes over, vertically, at each end of the part of the edge under the
//! rectangle (a plane and a straight edge: the least is at an end). Negative: the
//! edge is inside the foot box's bottom face, which MuJoCo's contact would not allow but for its
//! compliance. Over an edge no higher than where the swing lifted off (up to [`DROP_M`] above:
//! the nosing of the tread it steps down from) only a sole that is not rising counts: rising, it
//! moves away from the edge, as a toe lifting off over that nosing; a toe rising past the nosing
//! of a higher tread counts. And only while the sole is [`TRAVELLED_M`] or more, horizontally,
//! from where it stood before the swing and from where it came to rest: a sole setting down
//! across a nosing is a foothold's matter (the foothold error), not a clearance. The walk's
//! clearance is the least over its swings.

use kinematics::robot::SoleRectangle;
use nalgebra::{Isometry3, Point2, Point3, Vector2, Vector3};
use shm_types::SimTruth;
use stance::Environment;

use super::footholds::{REST_S, Swing, sole_pose};
use crate::observe::channels::isometry;

/// How far the terrain must fall away beyond a polygon side for the side to be an edge (m):
/// well above MuJoCo's contact compliance and a scene's tolerance between touching surfaces,
/// well below the lowest riser a scene describes.
pub(crate) const DROP_M: f64 = 0.02;

/// How far a swinging sole must be, horizontally, from where it stood before the swing and from
/// where it came to rest, to be passing over the terrain (m): nearer, it is lifting off or setting
/// down, and a toe resting a few millimetres over the nosing it steps down from is no passage.
const TRAVELLED_M: f64 = 0.02;

/// How far outside a side its far side is probed (m): beyond the gap a scene allows between
/// two surfaces that touch (docs/scenes.md), inside any tread.
const PROBE_M: f64 = 0.005;

/// One edge of the terrain: a straight side of a support surface (world, m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Edge {
    pub(crate) from: Point3<f64>,
    pub(crate) to: Point3<f64>,
}

/// The edges of the terrain in `environment` (world frame; none on the unbounded ground).
pub(crate) fn edges(environment: &Environment) -> Vec<Edge> {
    let mut edges = Vec::new();
    for surface in &environment.surfaces {
        let Some(polygon) = &surface.polygon else {
            continue;
        };
        let world = |p: Vector2<f64>| surface.pose * Point3::new(p.x, p.y, 0.0);
        let centroid = polygon
            .iter()
            .map(|&v| Vector2::from(v))
            .sum::<Vector2<f64>>()
            / polygon.len() as f64;
        let mut previous = polygon[polygon.len() - 1];
        for &vertex in polygon {
            let (a, b) = (Vector2::from(previous), Vector2::from(vertex));
            previous = vertex;
            let middle = (a + b) / 2.0;
            let side = b - a;
            let mut outward = Vector2::new(side.y, -side.x).normalize();
            if outward.dot(&(middle - centroid)) < 0.0 {
                outward = -outward;
            }
            let (inner, outer) = (world(middle), world(middle + outward * PROBE_M));
            let falls_away = environment
                .surfaces
                .iter()
                .filter_map(|other| other.elevation_at(outer.x, outer.y))
                .all(|z| z < inner.z - DROP_M);
            if falls_away {
                edges.push(Edge {
                    from: world(a),
                    to: world(b),
                });
            }
        }
    }
    edges
}

/// The least clearance of a swinging sole over `edges` in `states` (m), over the `swings` of
/// those states; `None` when no swinging sole passed over an edge (always on the flat floor).
pub(crate) fn edge_clearance_m(
    states: &[SimTruth],
    swings: &[Swing],
    edges: &[Edge],
    sole: &SoleRectangle,
) -> Option<f64> {
    if edges.is_empty() {
        return None;
    }
    let mut least: Option<f64> = None;
    for swing in swings {
        // Up to the moment the sole came to rest (its touchdown is REST_S later).
        let until = swing
            .touchdown
            .map_or(f64::INFINITY, |touchdown| touchdown.time_s - REST_S);
        let first = states.partition_point(|s| s.sim_time_s < swing.lift_s);
        let last = states.partition_point(|s| s.sim_time_s < until);
        if first >= last {
            continue;
        }
        // Where the sole stood before the swing and where it came to rest: near either, it
        // lifts off or sets down, and an edge under it then is a foothold's matter.
        let at = |k: usize| sole_pose(&states[k], swing.foot);
        let rests = [first.saturating_sub(1), last - 1].map(|k| Point2::new(at(k)[0], at(k)[1]));
        let lift_off_z = at(first.saturating_sub(1))[2];
        for k in first.max(1)..last {
            let p = at(k);
            if rests
                .iter()
                .any(|rest| (Point2::new(p[0], p[1]) - rest).norm() < TRAVELLED_M)
            {
                continue;
            }
            let rising = p[2] > at(k - 1)[2];
            let pose = isometry(p);
            for edge in edges {
                // A sole rising away from an edge no higher than the one it left (the nosing
                // of the tread it steps down from) cannot catch it; a toe rising past the
                // nosing of a higher tread still can.
                let below_lift_off = edge.from.z.max(edge.to.z) <= lift_off_z + DROP_M;
                if rising && below_lift_off {
                    continue;
                }
                if let Some(clearance) = clearance_over(&pose, edge, sole) {
                    least = Some(least.map_or(clearance, |l: f64| l.min(clearance)));
                }
            }
        }
    }
    least
}

/// The least height of the sole rectangle at `pose` over the part of `edge` vertically under it
/// (m); `None` when the edge does not pass under the rectangle. Vertical, not along the sole's
/// normal: a toe-off pitches the sole up to 0.5 rad, and the column along its normal then
/// leans over the nosing ahead of a toe still behind the riser.
fn clearance_over(pose: &Isometry3<f64>, edge: &Edge, sole: &SoleRectangle) -> Option<f64> {
    let normal = pose.rotation * Vector3::z();
    if normal.z <= f64::EPSILON {
        return None;
    }
    // The sole's plane is `height` above a point; the point under the plane is its projection.
    let height = |q: &Point3<f64>| normal.dot(&(pose.translation.vector - q.coords)) / normal.z;
    let (ha, hb) = (height(&edge.from), height(&edge.to));
    let under = |q: &Point3<f64>, h: f64| pose.inverse_transform_point(&(q + Vector3::z() * h));
    let (a, b) = (under(&edge.from, ha), under(&edge.to, hb));
    let half = Vector2::new(sole.length / 2.0, sole.width / 2.0);
    let [t0, t1] = clip(a.xy(), b.xy(), half)?;
    let at = |t: f64| ha + (hb - ha) * t;
    Some(at(t0).min(at(t1)))
}

/// The parameter interval `[t0, t1]` ⊂ [0, 1] of the segment `a → b` inside the rectangle
/// `|x| ≤ half.x, |y| ≤ half.y` (Liang–Barsky); `None` when it misses the rectangle.
fn clip(a: Point2<f64>, b: Point2<f64>, half: Vector2<f64>) -> Option<[f64; 2]> {
    let d = b - a;
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for (p, q) in [
        (-d.x, a.x + half.x),
        (d.x, half.x - a.x),
        (-d.y, a.y + half.y),
        (d.y, half.y - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
            continue;
        }
        let r = q / p;
        if p < 0.0 {
            t0 = t0.max(r);
        } else {
            t1 = t1.min(r);
        }
    }
    (t0 <= t1).then_some([t0, t1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evaluate::footholds::Touchdown;
    use stance::SupportSurface;

    const SOLE: SoleRectangle = SoleRectangle {
        length: 0.2,
        width: 0.08,
    };

    /// A horizontal rectangle `size` centred on `center`.
    fn tread(name: &str, center: [f64; 3], size: [f64; 2]) -> SupportSurface {
        let [hx, hy] = size.map(|s| s / 2.0);
        SupportSurface {
            name: name.to_owned(),
            pose: Isometry3::translation(center[0], center[1], center[2]),
            polygon: Some(vec![[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]]),
        }
    }

    /// A floor up to x = 1 and one 0.15 m stair (a tread from x = 1 to 1.3).
    fn one_stair() -> Environment {
        Environment {
            surfaces: vec![
                tread("floor", [0.5, 0.0, 0.0], [1.0, 1.0]),
                tread("tread", [1.15, 0.0, 0.15], [0.3, 1.0]),
            ],
            hand_affordances: Vec::new(),
        }
    }

    #[test]
    fn a_nosing_is_an_edge_and_the_foot_of_its_riser_is_not() {
        let edges = edges(&one_stair());
        let across_the_path = |e: &&Edge| (e.from.x - e.to.x).abs() < 1e-12;
        let mut xs: Vec<(f64, f64)> = edges
            .iter()
            .filter(across_the_path)
            .map(|e| ((e.from.x * 1e9).round() / 1e9, e.from.z))
            .collect();
        xs.sort_by(|a, b| a.0.total_cmp(&b.0));
        // The floor's far end at x = 0, the stair's nosing at x = 1 (0.15 m up) and its far end
        // at x = 1.3; not the floor's side at x = 1, where the riser rises.
        assert_eq!(xs, vec![(0.0, 0.0), (1.0, 0.15), (1.3, 0.15)]);
        // The sides of both surfaces along the path fall away to nothing.
        assert_eq!(edges.len() - xs.len(), 4);
    }

    #[test]
    fn flat_ground_has_no_edges() {
        assert!(edges(&Environment::default()).is_empty());
    }

    /// States every 10 ms with the left sole at `left(t)` (flat) and the right one far away.
    fn states(duration_s: f64, left: impl Fn(f64) -> [f64; 3]) -> Vec<SimTruth> {
        (0..=(duration_s / 0.01).round() as usize)
            .map(|k| {
                let t = k as f64 * 0.01;
                let mut state = SimTruth {
                    sim_time_s: t,
                    ..SimTruth::ZERO
                };
                state.left_foot[..3].copy_from_slice(&left(t));
                state.right_foot[..3].copy_from_slice(&[-5.0, 0.0, 0.0]);
                state
            })
            .collect()
    }

    /// A swing of the left foot from t = 0 that came to rest at `position` (touchdown at 1.2 s).
    fn landing_at(position: [f64; 3]) -> Swing {
        Swing {
            foot: 0,
            lift_s: 0.0,
            touchdown: Some(Touchdown {
                time_s: 1.2,
                position,
            }),
        }
    }

    #[test]
    fn the_clearance_is_the_lowest_passage_over_the_nosing() {
        // From x = 0.8 on the floor to x = 1.15 on the tread in 1 s: up to 0.2 m, across at that
        // height, down to the tread from s = 0.8 on.
        let edges = edges(&one_stair());
        let z = |s: f64| {
            if s < 0.2 {
                s
            } else if s < 0.8 {
                0.2
            } else {
                0.2 - (s - 0.8) * 0.25
            }
        };
        let left = |t: f64| {
            let s = t.clamp(0.0, 1.0);
            [0.8 + 0.35 * s, 0.0, z(s)]
        };
        let walk = states(1.5, left);
        let swing = landing_at([1.15, 0.0, 0.15]);
        let clearance = edge_clearance_m(&walk, &[swing], &edges, &SOLE).unwrap();
        // The rectangle covers the nosing (x = 1) while its centre is within 0.1 m of it, up to
        // s = 0.3 / 0.35: lowest there, on the way down.
        let lowest = z(0.3 / 0.35) - 0.15;
        assert!(
            (clearance - lowest).abs() < 0.005,
            "{clearance} vs {lowest}"
        );
        // A toe that scrapes the nosing reads as (almost) nothing; one below it as negative.
        let scraping = states(1.5, |t| [0.8 + 0.35 * (t / 1.0).min(1.0), 0.0, 0.15]);
        let c = edge_clearance_m(&scraping, &[swing], &edges, &SOLE).unwrap();
        assert!(c.abs() < 1e-9, "{c}");
        let through = states(1.5, |t| [0.8 + 0.35 * (t / 1.0).min(1.0), 0.0, 0.10]);
        let c = edge_clearance_m(&through, &[swing], &edges, &SOLE).unwrap();
        assert!((c + 0.05).abs() < 1e-9, "{c}");
    }

    #[test]
    fn a_swing_that_passes_no_edge_and_a_resting_sole_measure_nothing() {
        let edges = edges(&one_stair());
        // A short step on the floor, far from the stair.
        let walk = states(1.0, |t| [0.3 + 0.1 * t, 0.0, 0.05 * (t * 3.0).sin().abs()]);
        let swing = Swing {
            foot: 0,
            lift_s: 0.0,
            touchdown: None,
        };
        assert_eq!(edge_clearance_m(&walk, &[swing], &edges, &SOLE), None);
        // A swing that sets down vertically across the nosing passed over it only on its way
        // there, 0.2 m up; its set-down is a foothold's matter.
        let set_down = states(1.5, |t| {
            let s = t.clamp(0.0, 1.0);
            let z = if s < 0.6 {
                0.2
            } else {
                0.2 - (s - 0.6) / 0.4 * 0.05
            };
            [0.8 + 0.25 * (s / 0.6).min(1.0), 0.0, z]
        });
        let c = edge_clearance_m(&set_down, &[landing_at([1.05, 0.0, 0.15])], &edges, &SOLE);
        let c = c.unwrap();
        assert!((c - 0.05).abs() < 1e-9, "{c}");
        // A toe resting 2 mm over the stair's far edge lifts off over it: no passage; the heel
        // passing it 0.04 m up on the way down is.
        let descent = states(1.5, |t| {
            let s = t.clamp(0.0, 1.0);
            let z = if s < 0.7 {
                0.15 + 0.04 * (s / 0.05).min(1.0)
            } else {
                0.19 * (1.0 - (s - 0.7) / 0.3)
            };
            [1.202 + 0.35 * s, 0.0, z]
        });
        let c = edge_clearance_m(&descent, &[landing_at([1.552, 0.0, 0.0])], &edges, &SOLE);
        let c = c.unwrap();
        assert!((c - 0.04).abs() < 1e-9, "{c}");
        // A sole lifting off level with the nosing and rising all the way over it moves away
        // from it: nothing to catch.
        let rising = states(1.0, |t| [0.85 + 0.3 * t, 0.0, 0.16 + 0.09 * t]);
        assert_eq!(edge_clearance_m(&rising, &[swing], &edges, &SOLE), None);
        // One lifting off the floor and still rising as its toe passes the stair's nosing
        // counts: here it passes 0.075 m too low (x = 0.75 → 1.15 while z = 0 → 0.2; its toe
        // reaches the nosing at x = 1 with its centre at 0.9).
        let climbing = states(1.0, |t| [0.75 + 0.4 * t, 0.0, 0.2 * t]);
        let c = edge_clearance_m(&climbing, &[swing], &edges, &SOLE).unwrap();
        assert!((c + 0.075).abs() < 0.005, "{c}");
        // A sole standing across the nosing outside any swing is not measured.
        let standing = states(1.0, |_| [1.0, 0.0, 0.15]);
        let later = Swing {
            foot: 0,
            lift_s: 5.0,
            touchdown: None,
        };
        assert_eq!(edge_clearance_m(&standing, &[later], &edges, &SOLE), None);
        // A sole pitched 0.5 rad toe down about its toe, which rests 3 cm behind the riser
        // (a toe-off): the nosing, 0.15 m up just ahead, is not under it, though the column
        // along the sole's normal leans over it.
        let pitched = Isometry3::new(
            Vector3::new(0.97 - 0.1 * 0.5_f64.cos(), 0.0, 0.1 * 0.5_f64.sin()),
            Vector3::new(0.0, 0.5, 0.0),
        );
        let nosing = edges
            .iter()
            .find(|e| (e.from.x - 1.0).abs() < 1e-6 && (e.to.x - 1.0).abs() < 1e-6)
            .unwrap();
        assert_eq!(clearance_over(&pitched, nosing, &SOLE), None);
        // Raised 0.2 m and moved 5 cm on, its toe (x = 1.02, z = 0.2) is past the nosing: the
        // sole's bottom is 0.02 m · tan 0.5 higher over it, 0.15 m up.
        let over = Isometry3::from_parts(
            (pitched.translation.vector + Vector3::new(0.05, 0.0, 0.2)).into(),
            pitched.rotation,
        );
        let c = clearance_over(&over, nosing, &SOLE).unwrap();
        let expected = 0.2 + 0.02 * 0.5_f64.tan() - 0.15;
        assert!((c - expected).abs() < 1e-9, "{c} vs {expected}");
        // Without edges, nothing either.
        assert_eq!(edge_clearance_m(&standing, &[swing], &[], &SOLE), None);
    }
}
