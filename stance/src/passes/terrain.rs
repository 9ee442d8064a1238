//! The terrain pass: puts the flat walk of passes 1–8 onto the environment's surfaces.
//!
//! The raw walk is generated on flat ground, at the human-to-robot scale, and passes 1–5 keep
//! it there; pass 6 scales it to the robot's steps and passes 7–8 fix step length and width.
//! Only then are the footholds where they will be, so only then can they be fitted to the
//! surfaces they land on: this pass, right after pass 8 and before pass 9 (which then measures
//! swing heights on the real surfaces).

use kinematics::ground::planar_frame;
use kinematics::robot::{EndEffector, SoleRectangle};
use nalgebra::{Isometry3, Vector3};

use super::orientation::flattened;
use super::path::{LandingRule, shift_landings};
use super::path_of;
use crate::derived::swing_reference;
use crate::environment::Environment;
use crate::geometry::PathFrame;
use crate::params::PostProcessParams;
use crate::poses::{FEET, HANDS, PoseSequence};

/// Room (m) left between a foothold's heel and the back edge of its surface: the edge the
/// foot comes over. Under MuJoCo a dynamic JVRC-1 landing falls 3–4 cm short of its foothold
/// late in a walk (odometry drift); with 0.02 m the heel of the step off the last stair came
/// down on the stair's edge.
pub const HEEL_MARGIN_M: f64 = 0.05;

/// Room (m) left between a foothold's toe and the front edge of its surface: more than at the
/// heel, because there the toe meets the next riser of a stair going up. Not at a drop
/// ([`DROP_M`]): there is no riser ahead to meet, and the step down from the edge is the shorter
/// for it. ARMAR-4's static gait, whose standing leg reaches no lower with its ankle at its
/// bound, stopped 38 mm above the first tread down after a 0.33 m step (MuJoCo,
/// `stairs-down-10cm`, 2 of 10 walks).
pub const TOE_MARGIN_M: f64 = 0.03;

/// A surface whose next one along the path begins at least this much (m) lower ends at a drop,
/// the nosing of a stair going down; a ramp's kink or a floor's seam does not.
const DROP_M: f64 = 0.02;

/// Room (m) left at a kink, in place of [`HEEL_MARGIN_M`] or [`TOE_MARGIN_M`]: where the
/// neighbouring surface meets this one edge to edge at the same height (within [`DROP_M`] and
/// [`SEAM_M`]), at another slope or the same. There is no riser to meet and no edge to land on:
/// a sole that overshoots the kink by d only tilts onto the neighbour, by at most d · sin of the
/// kink's angle (5 mm for 3 cm across a 10° ramp's foot). With the stair margins the step across
/// the foot of a 5° ramp was 0.35 m, and ARMAR-4's static gait stopped there standing in 3 of 4
/// walks, its landing foot 1–2 mm above the floor with the standing ankle and waist pitch at their
/// bounds (MuJoCo); with 0.01 m 19 of 20 walks end `done`.
pub const KINK_MARGIN_M: f64 = 0.01;

/// Two surfaces whose edges along the path are this close (m) meet: a kink or a seam, not a gap.
const SEAM_M: f64 = 1e-3;

/// A foot this close (m) to the end of its surface's fit interval has come up to the edge.
const EDGE_REACHED_M: f64 = 0.01;

/// A surface shorter than this many sole lengths along the path is *short* (a stair tread):
/// two feet side by side fit on it, but a step from one to the other on it does not, so a
/// walker puts one foot per stair.
pub const SHORT_SURFACE_SOLES: f64 = 2.0;

/// The terrain pass, `placeOnTerrain`: fits the flat walk's footholds to the surfaces of
/// `environment` and lifts the walk onto them. Runs after pass 8 on poses that lie on the flat
/// plane z = 0 through the start (the environment is expressed in the walk's frame, start at
/// the origin: [`crate::Scene::walk_environment`]).
///
/// 0. **The walk starts where the scene starts.** The whole walk is moved (x, y, yaw) so its
///    first stance's feet in contact have their mean at the origin, heading +x: the controller
///    aligns a sequence by putting those feet onto the robot's standing feet, and the robot
///    stands at the scene's start. The flat walk's first feet are a few centimetres off the
///    origin (about 5 cm behind it on JVRC-1), and a foothold fitted to a tread that many
///    centimetres from where the robot puts it lands on the riser.
/// 1. **Footholds fit their surfaces.** Landings are taken in order of touchdown, each on the
///    surface under its sole centre (the nearest along the path if none), with three rules, in
///    order: (i) no surface is skipped: the foot lands on the other foot's surface or the next
///    one forward along the path; (ii) one foot per short surface ([`SHORT_SURFACE_SOLES`]): not
///    on the one the other foot stands on, but on the next — unless that step would be longer
///    than the stair limit (`stair_s_max` in space where set, else `s_max` with
///    `rise_weight`) and the foot is not on the other's surface yet: then it joins the other foot
///    there, both feet on each stair (the lead foot goes up, the other follows onto the same
///    tread, as the anchors' controllers climb), each step one tread long; (iii) the sole
///    centre is clamped into
///    its surface's fit interval along the path: where the sole, lengthened by
///    [`HEEL_MARGIN_M`] behind and [`TOE_MARGIN_M`] ahead, lies over the surface — for a sole
///    along the path and a surface edge across it, `[start + HEEL_MARGIN_M + L/2, end −
///    TOE_MARGIN_M − L/2]`, no toe margin before a drop and [`KINK_MARGIN_M`] at either end
///    where a neighbouring surface meets this one at its height; a toed-out sole's corners
///    reach further (its middle if the sole does not fit). A landing the clamp would take back
///    by more than half its advance on the other foot goes on to the next surface instead:
///    short steps would otherwise stall at an edge, each landing short of it.
///    A landing's shift moves everything after it, as pass 7's do (`shift_landings`), so a
///    step made longer by rule (ii) can exceed `s_max`: a tread deeper than `s_max` is a step
///    of its depth whatever the rule.
/// 2. **Elevation and orientation.** Every contact sole is put on its surface's elevation, and
///    on a tilted surface made parallel to it (yaw kept; passes 3 and 4 on the real surface).
///    Each stance's root and free hands rise by its support elevation (the mean elevation of
///    its feet in contact, interpolated over a stance with none), a held hand's contact run by
///    that of its first stance (so it does not jump), and a swing foot by the higher of the
///    surfaces under its lift-off and landing soles ([`swing_reference`]), from which pass 9
///    measures its height.
///
/// Surfaces must tile the walk without one under another, as a scene's do. On the flat ground
/// the walk was generated on (unbounded planes z = 0) there is nothing to fit and nothing to
/// lift: the pass returns at once (and on a bounded floor at z = 0 around the walk it changes
/// nothing either).
pub fn place_on_terrain(
    poses: &mut PoseSequence,
    environment: &Environment,
    sole: &SoleRectangle,
    params: &PostProcessParams,
) {
    if environment.is_flat_ground() {
        return;
    }
    start_at_the_origin(poses);
    let path = &path_of(poses).expect("a walk on terrain has stances");
    shift_landings(
        poses,
        path,
        &mut Footholds {
            environment,
            path,
            sole,
            s_max: params.s_max,
            rise_weight: params.rise_weight,
            stair_s_max: params.stair_s_max,
            surface: [None; 2],
            along: [None; 2],
        },
    );
    raise_onto_surfaces(poses, environment);
}

/// Moves every pose of the walk by the same planar transform, so the first stance's feet in
/// contact have their mean at the origin, heading +x.
fn start_at_the_origin(poses: &mut PoseSequence) {
    let first = FEET
        .iter()
        .filter(|&&foot| poses.in_contact(0, foot))
        .map(|&foot| poses.pose(0, foot));
    let to_start = planar_frame(first).inverse();
    for root in &mut poses.roots {
        *root = to_start * *root;
    }
    for stance in &mut poses.end_effectors {
        for pose in stance {
            *pose = to_start * *pose;
        }
    }
}

/// A surface's extent along the walking path on one line parallel to the path.
#[derive(Clone, Copy, Debug)]
struct Extent {
    /// Index in the environment's surfaces.
    surface: usize,
    from: f64,
    to: f64,
}

impl Extent {
    /// Along-path distance from `along` to the extent (0 inside).
    fn distance(&self, along: f64) -> f64 {
        (along - along.clamp(self.from, self.to)).abs()
    }
}

/// What lies past an end of a surface along the path, which sets the room a sole keeps from it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Edge {
    /// The next surface begins [`DROP_M`] or more lower: no room at the toe.
    Drop,
    /// The neighbouring surface meets it edge to edge at its height: [`KINK_MARGIN_M`].
    Kink,
    /// A riser, a gap or the end of the terrain: the full margin.
    Other,
}

/// The edge where one surface ends at `(to, end)` (along the path, elevation) and the next
/// begins at `(from, start)`: a kink if they meet there, within [`SEAM_M`] and [`DROP_M`].
fn edge_between(to: f64, end: f64, from: f64, start: f64) -> Edge {
    if (from - to).abs() <= SEAM_M && (end - start).abs() < DROP_M {
        Edge::Kink
    } else {
        Edge::Other
    }
}

/// The landing rule of the terrain pass (rules i–iii of [`place_on_terrain`]).
struct Footholds<'a> {
    environment: &'a Environment,
    path: &'a PathFrame,
    sole: &'a SoleRectangle,
    /// The step limit (pass 7's `s_max`): one foot per stair only where its steps keep to it.
    s_max: f64,
    /// How much a step's rise or drop counts against `s_max` (`[postprocess] rise_weight`).
    rise_weight: f64,
    /// The step limit from a tread to the next but one (`[postprocess] stair_s_max`), if set.
    stair_s_max: Option<f64>,
    /// Index of the surface each foot last landed on.
    surface: [Option<usize>; 2],
    /// Along-path position of each foot's last landing.
    along: [Option<f64>; 2],
}

impl Footholds<'_> {
    /// Extent of surface `k` along the line `lateral` to the left of the path.
    fn extent(&self, k: usize, lateral: f64) -> Option<Extent> {
        let from = self.path.point(0.0, lateral);
        let [start, end] =
            self.environment.surfaces[k].extent_along(&from, self.path.direction())?;
        Some(Extent {
            surface: k,
            from: start,
            to: end,
        })
    }

    /// Whether the surface of `extent` is short along the path, a stair tread
    /// ([`SHORT_SURFACE_SOLES`]).
    fn is_short(&self, extent: &Extent) -> bool {
        extent.to - extent.from < SHORT_SURFACE_SOLES * self.sole.length
    }

    /// Every surface's extent on the line `lateral` to the left of the path.
    fn extents(&self, lateral: f64) -> impl Iterator<Item = Extent> + '_ {
        (0..self.environment.surfaces.len()).filter_map(move |k| self.extent(k, lateral))
    }

    /// The surface a foot landing at `along`, `lateral` lands on, before rules (i)–(iii).
    fn under(&self, along: f64, lateral: f64) -> Option<Extent> {
        self.extents(lateral)
            .min_by(|a, b| a.distance(along).total_cmp(&b.distance(along)))
    }

    /// The surface after `behind` along the line `lateral`: the first to start after it.
    fn next(&self, behind: &Extent, lateral: f64) -> Option<Extent> {
        self.extents(lateral)
            .filter(|e| e.from > behind.from)
            .min_by(|a, b| a.from.total_cmp(&b.from))
    }

    /// The surface before `ahead` along the line `lateral`: the last to start before it.
    fn previous(&self, ahead: &Extent, lateral: f64) -> Option<Extent> {
        self.extents(lateral)
            .filter(|e| e.from < ahead.from)
            .max_by(|a, b| a.from.total_cmp(&b.from))
    }

    /// The surface foot `f` lands on (rules i and ii), and whether it lands there beside the
    /// other foot on purpose (both feet on a stair), where an edge does not stall it.
    fn choose(
        &self,
        f: usize,
        along: f64,
        lateral: f64,
        sole: &Isometry3<f64>,
    ) -> Option<(Extent, bool)> {
        let candidate = self.under(along, lateral)?;
        let Some(other) = self.surface[1 - f].and_then(|k| self.extent(k, lateral)) else {
            return Some((candidate, false));
        };
        let next = self.next(&other, lateral);
        let chosen = match next {
            Some(next) if candidate.from > next.from => next,
            _ if candidate.from < other.from => other,
            _ => candidate,
        };
        if !self.is_short(&other) {
            return Some((chosen, false));
        }
        let Some(next) = next else {
            return Some((other, false));
        };
        if self.joins_the_other(f, &other, &next, along, lateral, sole) {
            return Some((other, true));
        }
        Some((next, false))
    }

    /// Both feet on each stair: foot `f`, not yet on the other foot's short surface `other`,
    /// joins it there when going on to `next` (one foot per stair) would make its step longer
    /// than `s_max`.
    fn joins_the_other(
        &self,
        f: usize,
        other: &Extent,
        next: &Extent,
        along: f64,
        lateral: f64,
        sole: &Isometry3<f64>,
    ) -> bool {
        self.surface[f] != Some(other.surface)
            && self.along[f].is_some()
            && self.fit(next.surface, along, sole) > self.farthest_over_a_stair(f, next, lateral)
    }

    /// The farthest landing of foot `f` on `next`, the tread after the one the other foot
    /// stands on: within `stair_s_max` in space where it is set, else within `s_max` as any step.
    fn farthest_over_a_stair(&self, f: usize, next: &Extent, lateral: f64) -> f64 {
        match self.stair_s_max {
            Some(limit) => self.reach(f, next.surface, lateral, limit, 1.0),
            None => self.farthest(f, next.surface, lateral),
        }
    }

    /// The farthest along-path landing of foot `f` on surface `k` (on the line `lateral`) that
    /// keeps its step within `s_max`. With `rise_weight` 1 the limit is on the step in space, as
    /// the controller's `max_step_m` measures it: a step that also rises or falls by `h` reaches
    /// `√(s_max² − h²)` along the path (a 0.48 m limit, 0.456 m down a 0.15 m stair); a rise
    /// weighted by `w` leaves `√(s_max² − (w h)²)` (JVRC-1's dynamic 3.5: 0.33 m up a 0.10 m
    /// stair).
    fn farthest(&self, f: usize, k: usize, lateral: f64) -> f64 {
        self.reach(f, k, lateral, self.s_max, self.rise_weight)
    }

    /// The farthest along-path landing of foot `f` on surface `k` (on the line `lateral`) whose
    /// step is at most `limit` long, its rise counted `weight` times.
    fn reach(&self, f: usize, k: usize, lateral: f64, limit: f64, weight: f64) -> f64 {
        let (Some(from), Some(at)) = (self.along[f], self.surface[f]) else {
            return f64::INFINITY;
        };
        let reach = |rise: f64| (limit.powi(2) - (weight * rise).powi(2)).max(0.0).sqrt();
        let flat = from + limit;
        match (
            self.elevation(at, from, lateral),
            self.elevation(k, flat, lateral),
        ) {
            (Some(start), Some(end)) => from + reach(end - start),
            _ => flat,
        }
    }

    /// The elevation of surface `k`'s plane at `along` on the line `lateral`.
    fn elevation(&self, k: usize, along: f64, lateral: f64) -> Option<f64> {
        let point = self.path.point(along, lateral);
        self.environment.surfaces[k].plane_elevation_at(point.x, point.y)
    }

    /// What ends surface `k` ahead along the line `lateral`: a drop ([`DROP_M`]) where the surface
    /// after it begins that much lower, a kink where it meets it at its own height.
    fn edge_ahead(&self, k: usize, lateral: f64) -> Edge {
        self.extent(k, lateral)
            .and_then(|extent| {
                let next = self.next(&extent, lateral)?;
                let end = self.elevation(k, extent.to, lateral)?;
                let start = self.elevation(next.surface, next.from, lateral)?;
                Some(if end - start >= DROP_M {
                    Edge::Drop
                } else {
                    edge_between(extent.to, end, next.from, start)
                })
            })
            .unwrap_or(Edge::Other)
    }

    /// What begins surface `k` behind along the line `lateral`: a kink where the surface before
    /// it ends at its own height.
    fn edge_behind(&self, k: usize, lateral: f64) -> Edge {
        self.extent(k, lateral)
            .and_then(|extent| {
                let previous = self.previous(&extent, lateral)?;
                let end = self.elevation(previous.surface, previous.to, lateral)?;
                let start = self.elevation(k, extent.from, lateral)?;
                Some(edge_between(previous.to, end, extent.from, start))
            })
            .unwrap_or(Edge::Other)
    }

    /// Rule (iii): `along` clamped into surface `k`'s fit interval for `sole`: the sole centre
    /// positions where each corner of the sole lengthened by the margins lies over the surface
    /// (on the corner's own line parallel to the path; exact for convex surfaces). On a short
    /// surface (a tread), the interval's middle: the most room at both edges for the error of
    /// the foot's landing.
    fn fit(&self, k: usize, along: f64, sole: &Isometry3<f64>) -> f64 {
        let lateral = self.path.lateral(&sole.translation.vector);
        let toe_margin = match self.edge_ahead(k, lateral) {
            Edge::Drop => 0.0,
            Edge::Kink => KINK_MARGIN_M,
            Edge::Other => TOE_MARGIN_M,
        };
        let heel_margin = match self.edge_behind(k, lateral) {
            Edge::Kink => KINK_MARGIN_M,
            Edge::Drop | Edge::Other => HEEL_MARGIN_M,
        };
        let (back, front) = (
            -self.sole.length / 2.0 - heel_margin,
            self.sole.length / 2.0 + toe_margin,
        );
        let side = self.sole.width / 2.0;
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for (x, y) in [(back, side), (back, -side), (front, side), (front, -side)] {
            let corner = sole.rotation * Vector3::new(x, y, 0.0);
            let ahead = corner.dot(self.path.direction());
            let aside = corner.dot(self.path.lateral_axis());
            if let Some(extent) = self.extent(k, lateral + aside) {
                lo = lo.max(extent.from - ahead);
                hi = hi.min(extent.to - ahead);
            }
        }
        let short = self.extent(k, lateral).is_some_and(|e| self.is_short(&e));
        if lo <= hi && !short {
            along.clamp(lo, hi)
        } else {
            (lo + hi) / 2.0
        }
    }
}

impl Footholds<'_> {
    /// A landing of foot `f` fitted to surface `k` at `fitted`, beyond the step limit (the
    /// surface's fit interval starts further than the foot reaches, as past the gap between
    /// two fit intervals at a ramp's top), while the foot can still come up to the edge of the
    /// surface it stands on: that edge and surface (the foot goes on from there next time).
    fn short_of(
        &self,
        f: usize,
        k: usize,
        fitted: f64,
        along: f64,
        lateral: f64,
        sole: &Isometry3<f64>,
    ) -> Option<(f64, usize)> {
        let (own, from) = (self.surface[f]?, self.along[f]?);
        if own == k || fitted <= self.farthest(f, k, lateral) {
            return None;
        }
        let edge = self.fit(own, along, sole);
        (edge > from + EDGE_REACHED_M).then_some((edge, own))
    }
}

impl LandingRule for Footholds<'_> {
    type Placed = Option<usize>;

    fn place(&self, f: usize, flat: f64, sole: &Isometry3<f64>) -> (f64, Option<usize>) {
        // The landings shifted before this one can stretch its step past `s_max` (another
        // foot's landing pushed on to a tread moves it too): held to the limit first, as
        // pass 7 held the flat walk; a surface then takes it further only where it must.
        let along = self.along[f].map_or(flat, |from| flat.min(from + self.s_max));
        let lateral = self.path.lateral(&sole.translation.vector);
        let Some((extent, beside)) = self.choose(f, along, lateral, sole) else {
            return (0.0, None);
        };
        // Coming up to the edge of its own surface is a step on the level: within `s_max`
        // whatever the rise beyond the edge.
        let level = along;
        let along = along.min(self.farthest(f, extent.surface, lateral));
        let fitted = self.fit(extent.surface, along, sole);
        if let Some((edge, own)) = self.short_of(f, extent.surface, fitted, level, lateral, sole) {
            return (edge - flat, Some(own));
        }
        // Clamped back by more than half its advance on the other foot, on the surface that
        // foot stands on, the walk would stall at the edge (each landing again short of it):
        // on to the next surface instead (which rule (i) allows) — unless that is so far ahead
        // of this foot that the step would be longer than `s_max`, and this foot can still come
        // up to the edge: it does, and goes on from there next time (onto the first stair,
        // JVRC-1's static steps reached 0.37 m where its s_max is 0.24 m; from a ramp's top on
        // to its landing, dynamic steps 0.64 m where it is 0.48 m).
        let stalled = !beside
            && self.surface[1 - f] == Some(extent.surface)
            && self.along[1 - f]
                .is_some_and(|other| along > other && fitted - other < (along - other) / 2.0);
        let at_the_edge = self.along[f].is_none_or(|from| from >= fitted - EDGE_REACHED_M);
        let onward = self
            .next(&extent, lateral)
            .filter(|_| stalled)
            .map(|next| (self.fit(next.surface, along, sole), next))
            .filter(|(at, next)| at_the_edge || *at <= self.farthest(f, next.surface, lateral));
        match onward {
            Some((at, next)) => (at - flat, Some(next.surface)),
            None => (fitted - flat, Some(extent.surface)),
        }
    }

    fn landed(&mut self, f: usize, along: f64, placed: Option<usize>) {
        self.surface[f] = placed;
        self.along[f] = Some(along);
    }
}

/// Step 2 of [`place_on_terrain`]: the fitted flat walk lifted onto its surfaces.
fn raise_onto_surfaces(poses: &mut PoseSequence, environment: &Environment) {
    let mut previous: Option<(usize, f64)> = None;
    let mut held = [0.0; 2];
    for i in 0..poses.len() {
        let support = support_elevation(poses, environment, i);
        let elevation = support.unwrap_or_else(|| {
            let next = (i + 1..poses.len())
                .find_map(|j| support_elevation(poses, environment, j).map(|e| (j, e)));
            match (previous, next) {
                (Some((a, ea)), Some((b, eb))) => ea + (eb - ea) * (i - a) as f64 / (b - a) as f64,
                (Some((_, e)), None) | (None, Some((_, e))) => e,
                (None, None) => 0.0,
            }
        });
        if support.is_some() {
            previous = Some((i, elevation));
        }
        let swing_lift = FEET.map(|foot| {
            if poses.in_contact(i, foot) {
                0.0
            } else {
                swing_reference(poses, environment, i, foot).unwrap_or(elevation)
            }
        });
        poses.roots[i].translation.vector.z += elevation;
        for (f, foot) in FEET.into_iter().enumerate() {
            if poses.in_contact(i, foot) {
                lay(poses, i, foot, environment);
            } else {
                poses.end_effectors[i][foot as usize].translation.vector.z += swing_lift[f];
            }
        }
        for (h, hand) in HANDS.into_iter().enumerate() {
            if poses.contact_starts(i, hand) {
                held[h] = elevation;
            }
            let lift = if poses.in_contact(i, hand) {
                held[h]
            } else {
                elevation
            };
            poses.end_effectors[i][hand as usize].translation.vector.z += lift;
        }
    }
}

/// Mean elevation of the surfaces under the feet in contact in stance `i` (a foot over none
/// counts with its own height); `None` without a foot in contact.
fn support_elevation(poses: &PoseSequence, environment: &Environment, i: usize) -> Option<f64> {
    let (sum, count) = FEET
        .iter()
        .filter(|&&foot| poses.in_contact(i, foot))
        .map(|&foot| {
            let p = poses.pose(i, foot).translation.vector;
            environment.support_at(&p).map_or(p.z, |(_, z)| z)
        })
        .fold((0.0, 0), |(sum, n), z| (sum + z, n + 1));
    (count > 0).then(|| sum / count as f64)
}

/// Puts foot `foot`'s contact sole of stance `i` on the surface under it: on its elevation
/// and, on a tilted surface, parallel to it with its yaw kept (on a horizontal one it keeps its
/// rotation, which pass 3 made level). A sole over no surface is left as is.
fn lay(poses: &mut PoseSequence, i: usize, foot: EndEffector, environment: &Environment) {
    let pose = poses.pose(i, foot);
    let Some((surface, z)) = environment.support_at(&pose.translation.vector) else {
        return;
    };
    let rotation = if surface.pose.rotation * Vector3::z() == Vector3::z() {
        None
    } else {
        flattened(&surface.pose.rotation, &pose.rotation)
    };
    let target = &mut poses.end_effectors[i][foot as usize];
    target.translation.vector.z = z;
    if let Some(rotation) = rotation {
        target.rotation = rotation;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::environment::SupportSurface;
    use crate::geometry::roll_pitch_yaw;
    use crate::passes::fixtures::{BOTH, LEFT, RIGHT, SOLE, block, rotated, stance, walk};
    use kinematics::robot::EndEffector::{LeftFoot, LeftHand, RightFoot, RightHand};
    use nalgebra::{Translation3, UnitQuaternion};

    /// A step limit that lets the walk put one foot per stair on [`stairs`] (steps of two
    /// treads, 0.6 m).
    const ONE_FOOT: f64 = 1.0;

    /// A floor to x = 0.5, three 0.3 m treads rising 0.1 m each, a landing from x = 1.4.
    fn stairs() -> Environment {
        Environment {
            surfaces: vec![
                block("floor", -1.0, 0.5, 0.0),
                block("tread-1", 0.5, 0.8, 0.1),
                block("tread-2", 0.8, 1.1, 0.2),
                block("tread-3", 1.1, 1.4, 0.3),
                block("landing", 1.4, 3.0, 0.4),
            ],
            hand_affordances: Vec::new(),
        }
    }

    /// A flat walk: both feet at x = 0, then the `landings` in turn, right foot first; before
    /// each a single support with the swing foot half-way and 0.05 m up, after it a double
    /// support.
    fn flat_walk(landings: &[f64]) -> PoseSequence {
        let mut feet = [0.0, 0.0];
        let mut stances = vec![stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH)];
        for (k, &x) in landings.iter().enumerate() {
            let swing = 1 - k % 2;
            let mut at = feet.map(|x| [x, 0.0]);
            at[swing] = [(feet[swing] + x) / 2.0, 0.05];
            let contacts = if swing == 1 { LEFT } else { RIGHT };
            stances.push(stance(
                [at[0][0], 0.1, at[0][1]],
                [at[1][0], -0.1, at[1][1]],
                contacts,
            ));
            feet[swing] = x;
            stances.push(stance([feet[0], 0.1, 0.0], [feet[1], -0.1, 0.0], BOTH));
        }
        walk(&stances)
    }

    /// Along-path position and elevation of each contact run's foot, in touchdown order.
    fn footholds(poses: &PoseSequence) -> Vec<[f64; 2]> {
        (0..poses.len())
            .flat_map(|i| FEET.map(|foot| (i, foot)))
            .filter(|&(i, foot)| poses.contact_starts(i, foot))
            .map(|(i, foot)| {
                let p = poses.pose(i, foot).translation.vector;
                [p.x, p.z]
            })
            .collect()
    }

    /// The first footholds of `flat_walk(&[0.2, 0.4, ...])` on [`stairs`]: both feet at the
    /// start, then up to the floor's edge (its fit interval ends at 0.37).
    const TO_THE_FLOOR_EDGE: [[f64; 2]; 4] = [[0.0, 0.0], [0.0, 0.0], [0.2, 0.0], [0.37, 0.0]];

    /// The first footholds of `flat_walk(&[0.12, 0.24, ...])`: both feet at the start, then
    /// two 0.12 m steps.
    const SHORT_STEPS: [[f64; 2]; 4] = [[0.0, 0.0], [0.0, 0.0], [0.12, 0.0], [0.24, 0.0]];

    /// The terrain pass with step limit `s_max` and `rise_weight`, no stair limit.
    fn place(poses: &mut PoseSequence, environment: &Environment, s_max: f64, rise_weight: f64) {
        let params = PostProcessParams {
            s_max,
            rise_weight,
            ..crate::passes::tests::params()
        };
        place_on_terrain(poses, environment, &SOLE, &params);
    }

    fn assert_footholds(poses: &PoseSequence, expected: &[[f64; 2]]) {
        let found = footholds(poses);
        assert_eq!(found.len(), expected.len(), "{found:?}");
        for (f, e) in found.iter().zip(expected) {
            assert!(
                (f[0] - e[0]).abs() < 1e-12 && (f[1] - e[1]).abs() < 1e-12,
                "{found:?}"
            );
        }
    }

    #[test]
    fn on_the_flat_ground_nothing_changes() {
        let mut p = flat_walk(&[0.3, 0.6, 0.9, 1.2]);
        rotated(&mut p, 3, LeftFoot, [0.0, 0.0, 0.2]);
        rotated(&mut p, 4, LeftFoot, [0.0, 0.0, 0.2]);
        p.contacts[2][RightHand as usize] = true;
        let before = p.clone();
        place(&mut p, &Environment::default(), ONE_FOOT, 1.0);
        assert_eq!(p, before);
        // Not by the early return alone: a floor at z = 0 with room around the walk.
        let floor = Environment {
            surfaces: vec![block("floor", -1.0, 3.0, 0.0)],
            hand_affordances: Vec::new(),
        };
        place(&mut p, &floor, ONE_FOOT, 1.0);
        assert_eq!(p, before);
    }

    #[test]
    fn stairs_take_one_foot_per_tread_with_the_toes_clear_of_the_risers() {
        let mut p = flat_walk(&[0.2, 0.4, 0.55, 0.7, 0.85, 1.0, 1.15]);
        place(&mut p, &stairs(), ONE_FOOT, 1.0);
        // Floor: its fit interval ends 0.03 + 0.1 before the riser at 0.5 (0.4 → 0.37). Each
        // tread's interval is [from + 0.15, to − 0.13], and a foot goes to its middle: a
        // landing on the tread the other foot stands on goes on to the next one.
        let up = [
            [0.66, 0.1],
            [0.96, 0.2],
            [1.26, 0.3],
            [1.55, 0.4],
            [1.70, 0.4],
        ];
        assert_footholds(&p, &[&TO_THE_FLOOR_EDGE[..], &up].concat());
        // The left foot swings from the floor (0.37) to tread-2 (0.96) in stance 7: half-way,
        // 0.05 m above tread-2. The root of the double support that follows rises by the mean
        // of tread-1 and tread-2.
        let swing = p.pose(7, LeftFoot).translation.vector;
        assert!(
            (swing.x - 0.665).abs() < 1e-12 && (swing.z - 0.25).abs() < 1e-12,
            "{swing:?}"
        );
        let root = p.roots[8].translation.vector;
        assert!((root.z - (0.8 + 0.15)).abs() < 1e-12, "{root:?}");
    }

    #[test]
    fn a_step_limit_shorter_than_two_treads_puts_both_feet_on_each_stair() {
        let mut p = flat_walk(&[0.2, 0.4, 0.55, 0.7, 0.85, 1.0, 1.15]);
        place(&mut p, &stairs(), 0.4, 1.0);
        // The right foot, 0.46 m from tread-1's middle (0.66), first comes up to the floor's
        // edge (0.37) beside the left; the left goes up to tread-1 (0.29 m); the right, 0.59 m
        // on to tread-2 with one foot per stair, joins it on tread-1 instead, beside it, not
        // stalled; the left leads on, one tread (0.30 m) per step.
        let up = [
            [0.37, 0.0],
            [0.66, 0.1],
            [0.66, 0.1],
            [0.96, 0.2],
            [0.96, 0.2],
        ];
        assert_footholds(&p, &[&TO_THE_FLOOR_EDGE[..], &up].concat());
    }

    #[test]
    fn a_stair_limit_puts_one_foot_per_stair_where_s_max_would_put_both() {
        let limits = |stair_s_max| PostProcessParams {
            s_max: 0.4,
            stair_s_max,
            ..crate::passes::tests::params()
        };
        let flat = flat_walk(&[0.2, 0.4, 0.55, 0.7, 0.85, 1.0, 1.15]);
        let mut p = flat.clone();
        place_on_terrain(&mut p, &stairs(), &SOLE, &limits(Some(0.64)));
        // The right foot comes up to the floor's edge first (0.46 m onto tread-1 is a step
        // beyond s_max, not over a stair), the left goes up to tread-1, and from then on each
        // foot goes two treads, 0.59–0.60 m along and 0.2 m up (0.623–0.632 m in space).
        let up = [
            [0.37, 0.0],
            [0.66, 0.1],
            [0.96, 0.2],
            [1.26, 0.3],
            [1.55, 0.4],
        ];
        assert_footholds(&p, &[&TO_THE_FLOOR_EDGE[..], &up].concat());
        // Below the step in space: both feet on each stair, as without a stair limit.
        let mut both = flat.clone();
        place(&mut both, &stairs(), 0.4, 1.0);
        let mut p = flat;
        place_on_terrain(&mut p, &stairs(), &SOLE, &limits(Some(0.62)));
        assert_eq!(footholds(&p), footholds(&both));
    }

    #[test]
    fn short_steps_do_not_stall_at_an_edge() {
        let mut p = flat_walk(&[0.12, 0.24, 0.36, 0.48, 0.6, 0.72, 0.84, 0.96]);
        place(&mut p, &stairs(), ONE_FOOT, 1.0);
        // 0.48 is clamped back to the floor's 0.37, 1 cm of its 12 cm advance on the right foot
        // (0.36): tread-1 instead, then one foot per tread.
        let on = [
            [0.36, 0.0],
            [0.66, 0.1],
            [0.96, 0.2],
            [1.26, 0.3],
            [1.55, 0.4],
        ];
        assert_footholds(&p, &[&SHORT_STEPS[..], &on, &[[1.67, 0.4]]].concat());
    }

    #[test]
    fn a_foot_comes_up_to_the_edge_before_a_step_onto_a_tread_longer_than_s_max() {
        let mut p = flat_walk(&[0.12, 0.24, 0.4, 0.48, 0.6, 0.72]);
        place(&mut p, &stairs(), 0.25, 1.0);
        // The left foot, stalled at the floor's edge (0.37) beside the right, would go on to
        // tread-1 (0.66), 0.42 m from 0.24: it comes up to the edge instead. The right,
        // already there, goes on (0.29 m, the shortest step onto the tread), and the left
        // joins it.
        let on = [[0.37, 0.0], [0.37, 0.0], [0.66, 0.1], [0.66, 0.1]];
        assert_footholds(&p, &[&SHORT_STEPS[..], &on].concat());
    }

    /// A 0.15 m drop at x = 0.5 from a landing whose fit interval ends at 0.4 onto a floor whose
    /// fit interval starts at 0.65.
    fn drop() -> Environment {
        Environment {
            surfaces: vec![
                block("landing", -1.0, 0.5, 0.15),
                block("floor", 0.5, 3.0, 0.0),
            ],
            hand_affordances: Vec::new(),
        }
    }

    #[test]
    fn the_step_limit_holds_in_space_down_a_stair() {
        let mut p = flat_walk(&[0.2, 0.37, 0.9]);
        place(&mut p, &drop(), 0.48, 1.0);
        // The right foot's 0.48 m step from 0.2 would be 0.503 m in space: it lands
        // √(0.48² − 0.15²) = 0.456 m along instead, on the floor.
        let found = footholds(&p);
        let [x, z] = found[found.len() - 1];
        let along = (0.48f64.powi(2) - 0.15f64.powi(2)).sqrt();
        assert!((x - (0.2 + along)).abs() < 1e-12 && z == 0.0, "{found:?}");
    }

    #[test]
    fn a_foot_comes_up_to_a_drop_with_its_toe_at_the_edge() {
        // The left foot's landing at 0.45 is clamped to the landing's fit interval: it ends at
        // the edge less half the sole (0.4), no toe margin, since no riser lies ahead. Before a
        // step up the same edge keeps the margin (`TO_THE_FLOOR_EDGE`: 0.37).
        let mut p = flat_walk(&[0.2, 0.45]);
        place(&mut p, &drop(), 0.48, 1.0);
        let found = footholds(&p);
        assert_eq!(found[found.len() - 1], [0.4, 0.15], "{found:?}");
    }

    /// A 10° ramp down to x = 0.5, where it meets a floor at its height: a kink.
    fn ramp_to_floor() -> Environment {
        let pitch = 10f64.to_radians();
        let half = 0.75 / pitch.cos();
        Environment {
            surfaces: vec![
                SupportSurface {
                    name: "ramp".into(),
                    pose: Isometry3::from_parts(
                        Translation3::new(-0.25, 0.0, 0.75 * pitch.tan()),
                        UnitQuaternion::from_euler_angles(0.0, pitch, 0.0),
                    ),
                    polygon: Some(vec![[-half, -0.5], [half, -0.5], [half, 0.5], [-half, 0.5]]),
                },
                block("floor", 0.5, 3.0, 0.0),
            ],
            hand_affordances: Vec::new(),
        }
    }

    #[test]
    fn a_foot_keeps_the_kink_margin_at_a_ramp_foot() {
        // The left foot's landing at 0.45 on the ramp is clamped to end with its toe 0.01 m
        // short of the kink (KINK_MARGIN_M, not the stair's 0.03 m): 0.39, on the ramp's plane.
        // That shift takes the right foot's landing back to 0.56, and the floor's interval
        // brings it to its heel 0.01 m past the kink: 0.61, where a stair's heel margin would
        // have made it 0.65 and the step across the kink 0.28 m instead of 0.22 m.
        let mut p = flat_walk(&[0.2, 0.45, 0.62]);
        place(&mut p, &ramp_to_floor(), 0.48, 1.0);
        let found = footholds(&p);
        let ahead = 0.5 - SOLE.length / 2.0 - KINK_MARGIN_M;
        let [x, z] = found[found.len() - 2];
        assert!((x - ahead).abs() < 1e-9, "{found:?}");
        assert!(
            (z - (0.5 - ahead) * 10f64.to_radians().tan()).abs() < 1e-9,
            "{found:?}"
        );
        let [x, z] = found[found.len() - 1];
        let behind = 0.5 + KINK_MARGIN_M + SOLE.length / 2.0;
        assert!((x - behind).abs() < 1e-9 && z == 0.0, "{found:?}");
    }

    #[test]
    fn a_weighted_rise_shortens_a_step_down() {
        // The drop above with the rise weighted 1.5: the right foot's step from 0.3 reaches
        // √(0.48² − (1.5 · 0.15)²) = 0.424 m along instead of 0.456 m.
        let mut p = flat_walk(&[0.3, 0.37, 0.9]);
        place(&mut p, &drop(), 0.48, 1.5);
        let found = footholds(&p);
        let [x, z] = found[found.len() - 1];
        let along = (0.48f64.powi(2) - (1.5f64 * 0.15).powi(2)).sqrt();
        assert!((x - (0.3 + along)).abs() < 1e-12 && z == 0.0, "{found:?}");
    }

    /// A floor to x = 1.0 (its fit interval ends at 0.87) and a long platform 0.05 m up (its
    /// interval starts at 1.15), as a ramp's top meets its landing.
    fn platform() -> Environment {
        Environment {
            surfaces: vec![
                block("floor", -1.0, 1.0, 0.0),
                block("platform", 1.0, 3.0, 0.05),
            ],
            hand_affordances: Vec::new(),
        }
    }

    #[test]
    fn a_landing_its_surface_takes_past_s_max_comes_up_to_the_edge_first() {
        let mut p = flat_walk(&[0.2, 0.4, 0.6, 0.75, 1.05]);
        place(&mut p, &platform(), 0.48, 1.0);
        // The right foot's landing at 1.05 is on the platform, whose fit interval starts 0.55 m
        // from the foot's 0.6: it comes up to the floor's edge instead.
        let found = footholds(&p);
        assert_eq!(found[found.len() - 1], [0.87, 0.0], "{found:?}");
    }

    #[test]
    fn a_foot_comes_up_to_the_edge_on_the_level_whatever_the_weighted_rise_beyond() {
        // The platform 0.185 m up with the rise weighted 3.5: no step up reaches (3.5 · 0.185 >
        // 0.48), yet the right foot at 0.6 comes up to the floor's edge, 0.27 m on the level,
        // instead of jumping on to the platform.
        let riser = Environment {
            surfaces: vec![
                block("floor", -1.0, 1.0, 0.0),
                block("platform", 1.0, 3.0, 0.185),
            ],
            hand_affordances: Vec::new(),
        };
        let mut p = flat_walk(&[0.2, 0.4, 0.6, 0.75, 1.05]);
        place(&mut p, &riser, 0.48, 3.5);
        let found = footholds(&p);
        assert_eq!(found[found.len() - 1], [0.87, 0.0], "{found:?}");
    }

    #[test]
    fn a_stalled_landing_goes_on_to_a_long_surface_only_within_s_max() {
        let mut p = flat_walk(&[0.1, 0.2, 0.35, 0.55, 0.8, 1.0]);
        place(&mut p, &platform(), 0.48, 1.0);
        // The left foot's landing at 1.0 is clamped back to 0.87, stalled beside the right
        // foot (0.8): on to the platform would be 0.60 m from 0.55, so it comes up to the edge.
        let found = footholds(&p);
        assert_eq!(found[found.len() - 1], [0.87, 0.0], "{found:?}");
    }

    #[test]
    fn a_long_step_does_not_skip_a_tread() {
        let mut p = flat_walk(&[0.2, 0.3, 1.0]);
        place(&mut p, &stairs(), ONE_FOOT, 1.0);
        // The right foot would land on tread-2 while the left stands on the floor: tread-1, in
        // the middle of its fit interval.
        let right = p.pose(p.len() - 1, RightFoot).translation.vector;
        assert!(
            (right.x - 0.66).abs() < 1e-12 && (right.z - 0.1).abs() < 1e-12,
            "{right:?}"
        );
    }

    #[test]
    fn hands_rise_with_the_support_and_a_held_hand_as_a_whole() {
        let mut p = flat_walk(&[0.2, 0.4, 0.55, 0.7]);
        for contacts in &mut p.contacts[4..=6] {
            contacts[RightHand as usize] = true;
        }
        let before = p.clone();
        place(&mut p, &stairs(), ONE_FOOT, 1.0);
        let rise =
            |i: usize, e: EndEffector| p.pose(i, e).translation.z - before.pose(i, e).translation.z;
        // Stance 4: both feet on the floor; 6: the left foot on tread-1 (0.1), the right on the
        // floor... then on tread-2: the held right hand keeps the rise of its first stance.
        for i in 4..=6 {
            assert!(
                rise(i, RightHand).abs() < 1e-12,
                "stance {i}: {}",
                rise(i, RightHand)
            );
        }
        let support = (0.1 + 0.0) / 2.0;
        assert!(
            (rise(6, LeftHand) - support).abs() < 1e-12,
            "{}",
            rise(6, LeftHand)
        );
        assert!(
            (rise(8, LeftHand) - 0.15).abs() < 1e-12,
            "{}",
            rise(8, LeftHand)
        );
    }

    #[test]
    fn the_walk_is_moved_so_its_first_feet_stand_at_the_scene_start() {
        let mut p = walk(&[
            stance([-0.05, 0.1, 0.0], [-0.05, -0.1, 0.0], BOTH),
            stance([-0.05, 0.1, 0.0], [0.2, -0.1, 0.0], BOTH),
        ]);
        place(&mut p, &stairs(), ONE_FOOT, 1.0);
        let (left, right) = (p.pose(0, LeftFoot), p.pose(0, RightFoot));
        let middle = (left.translation.vector + right.translation.vector) / 2.0;
        assert!(middle.xy().norm() < 1e-12, "{middle}");
        // The rest of the walk moved with it.
        assert!((p.pose(1, RightFoot).translation.x - 0.25).abs() < 1e-12);
    }

    #[test]
    fn a_sole_on_a_ramp_lies_on_its_plane_pitched_with_it() {
        let slope = 10f64.to_radians();
        let ramp = SupportSurface {
            name: "ramp".into(),
            pose: Isometry3::from_parts(
                Vector3::zeros().into(),
                UnitQuaternion::from_euler_angles(0.0, -slope, 0.0),
            ),
            polygon: Some(vec![[-1.0, -0.5], [1.0, -0.5], [1.0, 0.5], [-1.0, 0.5]]),
        };
        let env = Environment {
            surfaces: vec![ramp],
            hand_affordances: Vec::new(),
        };
        let mut p = walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.3, 0.1, 0.0], [0.3, -0.1, 0.0], BOTH),
        ]);
        rotated(&mut p, 1, LeftFoot, [0.0, 0.0, 0.1]);
        place(&mut p, &env, ONE_FOOT, 1.0);
        let left = p.pose(1, LeftFoot);
        assert!((left.translation.z - 0.3 * slope.tan()).abs() < 1e-12);
        let normal = env.surfaces[0].pose.rotation * Vector3::z();
        assert!(
            (left.rotation * Vector3::z() - normal).norm() < 1e-12,
            "parallel"
        );
        let x = left.rotation * Vector3::x();
        // Its x is the toed-out x projected onto the ramp along the normal.
        let heading = 0.1f64.sin().atan2(0.1f64.cos() * slope.cos().powi(2));
        assert!((x.y.atan2(x.x) - heading).abs() < 1e-12, "toe-out kept");
        let [roll, pitch, yaw] = roll_pitch_yaw(&p.pose(0, RightFoot).rotation);
        assert!(roll.abs() < 1e-12 && yaw.abs() < 1e-12 && (pitch + slope).abs() < 1e-12);
    }

    #[test]
    fn a_stance_without_a_foot_in_contact_rises_by_the_interpolated_support() {
        let mut p = walk(&[
            stance([0.0, 0.1, 0.0], [0.0, -0.1, 0.0], BOTH),
            stance([0.3, 0.1, 0.05], [0.3, -0.1, 0.05], [false; 4]),
            stance([0.6, 0.1, 0.0], [0.6, -0.1, 0.0], BOTH),
        ]);
        let before = p.clone();
        place(&mut p, &stairs(), ONE_FOOT, 1.0);
        let rise = |i: usize| p.roots[i].translation.z - before.roots[i].translation.z;
        assert!(rise(0).abs() < 1e-12 && (rise(2) - 0.1).abs() < 1e-12);
        assert!((rise(1) - 0.05).abs() < 1e-12, "{}", rise(1));
    }
}
