//! The walking pattern: a ZMP reference inside the support polygons and the divergent component
//! of motion (DCM) of the linear inverted pendulum that follows it.
//!
//! The LIPM at constant height `h` above the ground: `c̈ = ω² (c − p)`, `ω² = g / h` (c: CoM,
//! p: ZMP, ground plane). With the DCM `ξ = c + ċ / ω` it splits into a stable and an unstable
//! part: `ċ = ω (ξ − c)` and `ξ̇ = ω (ξ − p)` (Englsberger et al. 2015).
//!
//! The ZMP reference stays at the stance foot's sole centre in single support (or moved inwards,
//! towards the other foot, by `zmp_inward_offset_m`, and ahead by `step_down_zmp_forward_m` while
//! the swing steps down: [`ZmpOffsets`]) and crosses to the next stance foot over the double supports between two steps, from the start point to the
//! first stance foot over the initial double support, and from the last one to the centre of the
//! final feet over the final double support. A crossing follows the minimum-jerk profile
//! (`TRANSFER_PIECES` linear pieces through it): a ZMP that left a foot in a straight line would
//! jerk the CoM, and the jerk sets the robot rocking on its compliant soles.
//!
//! On a linear piece `p(t) = p₀ + ṗ (t − t₀)` of duration `T` ending with ZMP `p₁` and DCM `ξ₁`,
//! the DCM that stays bounded is, in closed form,
//!
//! ```text
//! ξ(t) = p(t) + ṗ/ω + (ξ₁ − p₁ − ṗ/ω) · e^{ω (t − t₀ − T)}
//! ```
//!
//! so the backward recursion from the end of the walk (`ξ = p` at rest on the final ZMP) gives
//! every piece's `ξ₁` in one pass, when the sequence is prepared. At the start the robot stands
//! still: its ZMP and DCM are at the CoM `c₀`. The initial crossing starts from `c₀` and adds a
//! bump `q·b(τ)`, `b = 16 τ² (1 − τ)²`, whose amplitude `q` makes `ξ(0) = c₀` (`ξ(0)` is affine
//! in `q`): the ZMP first moves away from the first stance foot, which starts the CoM towards it.

use kinematics::robot::EndEffector;
use nalgebra::{Isometry3, Point3, Vector2, Vector3};

use super::footsteps::{FEET, Support, SupportPhase};
use crate::controller::machine::STEP_HEIGHT_M;
use crate::controller::trajectory::Profile;

/// One linear piece of the ZMP reference and the DCM at its end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ZmpSegment {
    /// Start on the plan clock (s).
    pub start_s: f64,
    /// Duration (s, > 0).
    pub duration_s: f64,
    /// ZMP at the start and at the end (ground plane, m).
    pub zmp_start: Vector2<f64>,
    pub zmp_end: Vector2<f64>,
    /// DCM at the end (m).
    pub dcm_end: Vector2<f64>,
}

impl ZmpSegment {
    fn end_s(&self) -> f64 {
        self.start_s + self.duration_s
    }

    fn zmp_velocity(&self) -> Vector2<f64> {
        (self.zmp_end - self.zmp_start) / self.duration_s
    }

    /// The DCM at the segment's start.
    fn dcm_start(&self, omega: f64) -> Vector2<f64> {
        let drift = self.zmp_velocity() / omega;
        self.zmp_start
            + drift
            + (self.dcm_end - self.zmp_end - drift) * (-omega * self.duration_s).exp()
    }
}

/// The walking pattern at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PatternSample {
    /// Reference ZMP and its rate.
    pub zmp: Vector2<f64>,
    pub zmp_velocity: Vector2<f64>,
    /// Reference DCM and its rate.
    pub dcm: Vector2<f64>,
    pub dcm_velocity: Vector2<f64>,
}

/// Pieces a double support's ZMP crossing is cut into.
const TRANSFER_PIECES: usize = 8;

/// The ZMP reference and its DCM for a whole walk.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct DcmPattern {
    omega: f64,
    /// The initial crossing's pieces first.
    segments: Vec<ZmpSegment>,
    /// Where the pattern comes to rest.
    rest: Vector2<f64>,
}

impl DcmPattern {
    /// The pattern of `phases` (back to back from time 0) for a pendulum of natural frequency
    /// `omega` (1/s), the single supports' ZMP `offsets` from the stance sole's centre. It starts
    /// from the centre of the first phase's feet until [`start_at_rest`](Self::start_at_rest)
    /// sets the start point.
    pub fn new(phases: &[SupportPhase], omega: f64, offsets: ZmpOffsets) -> Self {
        let first = phases.first().expect("a plan has phases");
        let last = phases.last().expect("a plan has phases");
        let rest = feet_centre(&last.feet);
        // Room for every phase's pieces, and for the crossing a controlled stop appends
        // ([`end_early`](Self::end_early)) without allocating on the control thread.
        let capacity = (TRANSFER_PIECES + 1) * (phases.len() + 2);
        let mut segments: Vec<ZmpSegment> = Vec::with_capacity(capacity);
        // The ZMP where the double supports since the last single support began, and when.
        let mut crossing = (feet_centre(&first.feet), 0.0);
        for phase in phases {
            if let Support::Single(swing) = &phase.support {
                let (foot, stance) = phase
                    .feet
                    .iter()
                    .enumerate()
                    .find_map(|(f, pose)| pose.map(|pose| (f, pose)))
                    .expect("single support stands on a foot");
                let on_stance = single_support_zmp(&stance, FEET[foot], &swing.landing, offsets);
                push_crossing(&mut segments, crossing, (on_stance, phase.start_s));
                push_piece(
                    &mut segments,
                    (on_stance, phase.start_s),
                    (on_stance, phase.end_s()),
                );
                crossing = (on_stance, phase.end_s());
            }
        }
        push_crossing(&mut segments, crossing, (rest, last.end_s()));
        let mut pattern = Self {
            omega,
            segments,
            rest,
        };
        pattern.recurse(pattern.segments.len(), rest);
        pattern
    }

    /// Ends the walk early (a controlled stop): every piece before plan time `from_s` is kept (a
    /// piece running at `from_s` is cut there), then the ZMP crosses from where it is at
    /// `from_s` to `rest` over `duration_s` and the pattern comes to rest there. The backward
    /// recursion runs again from the new rest, so the DCM reference from now on is the one that
    /// stops the pendulum over `rest`. Allocation-free: [`new`](Self::new) reserved the room.
    pub fn end_early(&mut self, from_s: f64, rest: Vector2<f64>, duration_s: f64) {
        let mut keep = self
            .segments
            .partition_point(|segment| segment.end_s() <= from_s + 1e-9);
        let from = match self.segments.get_mut(keep) {
            Some(running) if running.start_s < from_s - 1e-9 => {
                let zmp = running.zmp_start + running.zmp_velocity() * (from_s - running.start_s);
                running.duration_s = from_s - running.start_s;
                running.zmp_end = zmp;
                keep += 1;
                zmp
            }
            Some(next) if keep == 0 => next.zmp_start,
            _ => self.segments[..keep]
                .last()
                .map_or(rest, |kept| kept.zmp_end),
        };
        self.segments.truncate(keep);
        debug_assert!(self.segments.capacity() - self.segments.len() >= TRANSFER_PIECES);
        push_crossing(
            &mut self.segments,
            (from, from_s),
            (rest, from_s + duration_s),
        );
        self.rest = rest;
        self.recurse(self.segments.len(), rest);
    }

    /// The backward recursion over the first `count` pieces, from the DCM `end` at their end.
    fn recurse(&mut self, count: usize, end: Vector2<f64>) {
        let mut dcm = end;
        for segment in self.segments[..count].iter_mut().rev() {
            segment.dcm_end = dcm;
            dcm = segment.dcm_start(self.omega);
        }
    }

    /// Natural frequency ω of the pendulum (1/s).
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// Moves the whole pattern by the planar transform `to_world` (x, y, yaw).
    pub fn transform(&mut self, to_world: &Isometry3<f64>) {
        let map = |p: &mut Vector2<f64>| {
            let world = to_world * Point3::new(p.x, p.y, 0.0);
            *p = world.coords.xy();
        };
        for segment in &mut self.segments {
            map(&mut segment.zmp_start);
            map(&mut segment.zmp_end);
            map(&mut segment.dcm_end);
        }
        map(&mut self.rest);
    }

    /// Starts the pattern at rest at the CoM `com`: the initial crossing leaves from `com`, its
    /// bump sized so that the DCM starts there too. Allocation-free (for the first tick).
    pub fn start_at_rest(&mut self, com: Vector2<f64>) {
        let pieces = TRANSFER_PIECES.min(self.segments.len());
        let Some(last) = self.segments[..pieces].last() else {
            return;
        };
        let (target, end) = (last.zmp_end, last.dcm_end);
        let shape = |k: usize| {
            let tau = k as f64 / pieces as f64;
            (
                minimum_jerk(tau),
                16.0 * tau * tau * (1.0 - tau) * (1.0 - tau),
            )
        };
        // ξ(0) for the crossing without the bump, then the DCM one unit of bump adds.
        let set = |pattern: &mut Self, bump: Vector2<f64>, along: f64, base: Vector2<f64>| {
            for k in 0..pieces {
                let ((s0, b0), (s1, b1)) = (shape(k), shape(k + 1));
                let segment = &mut pattern.segments[k];
                segment.zmp_start = base + (target - com) * (along * s0) + bump * b0;
                segment.zmp_end = base + (target - com) * (along * s1) + bump * b1;
            }
        };
        set(self, Vector2::zeros(), 1.0, com);
        self.recurse(pieces, end);
        let without = self.segments[0].dcm_start(self.omega);
        set(self, Vector2::new(1.0, 1.0), 0.0, Vector2::zeros());
        self.recurse(pieces, Vector2::zeros());
        let gain = self.segments[0].dcm_start(self.omega).x;
        let bump = (com - without) / gain;
        set(self, bump, 1.0, com);
        self.recurse(pieces, end);
    }

    /// The pattern at plan time `t` (s); `cursor` remembers the segment of the last call, so a
    /// walk through time costs O(1) per sample. Before 0 it is the start, after the end at rest.
    pub fn sample(&self, t: f64, cursor: &mut usize) -> PatternSample {
        let at_rest = PatternSample {
            zmp: self.rest,
            zmp_velocity: Vector2::zeros(),
            dcm: self.rest,
            dcm_velocity: Vector2::zeros(),
        };
        *cursor = (*cursor).min(self.segments.len());
        while *cursor > 0 && t < self.segments[*cursor - 1].end_s() {
            *cursor -= 1;
        }
        while *cursor < self.segments.len() && t >= self.segments[*cursor].end_s() {
            *cursor += 1;
        }
        let Some(segment) = self.segments.get(*cursor) else {
            return at_rest;
        };
        let local = (t - segment.start_s).max(0.0);
        let zmp_velocity = segment.zmp_velocity();
        let zmp = segment.zmp_start + zmp_velocity * local;
        let drift = zmp_velocity / self.omega;
        let dcm = zmp
            + drift
            + (segment.dcm_end - segment.zmp_end - drift)
                * (self.omega * (local - segment.duration_s)).exp();
        PatternSample {
            zmp,
            zmp_velocity,
            dcm,
            dcm_velocity: self.omega * (dcm - zmp),
        }
    }

    /// Where the pattern comes to rest: the centre of the final feet.
    pub fn rest(&self) -> Vector2<f64> {
        self.rest
    }
}

/// Appends the linear ZMP piece from `from` (point, time) to `to`, unless it takes no time.
fn push_piece(segments: &mut Vec<ZmpSegment>, from: (Vector2<f64>, f64), to: (Vector2<f64>, f64)) {
    let duration_s = to.1 - from.1;
    if duration_s > 1e-9 {
        segments.push(ZmpSegment {
            start_s: from.1,
            duration_s,
            zmp_start: from.0,
            zmp_end: to.0,
            dcm_end: Vector2::zeros(),
        });
    }
}

/// Appends the crossing from `from` to `to` as [`TRANSFER_PIECES`] pieces through the
/// minimum-jerk profile (none if it takes no time).
fn push_crossing(
    segments: &mut Vec<ZmpSegment>,
    from: (Vector2<f64>, f64),
    to: (Vector2<f64>, f64),
) {
    if to.1 - from.1 <= 1e-9 {
        return;
    }
    let at = |k: usize| {
        let tau = k as f64 / TRANSFER_PIECES as f64;
        (
            from.0 + (to.0 - from.0) * minimum_jerk(tau),
            from.1 + (to.1 - from.1) * tau,
        )
    };
    for k in 0..TRANSFER_PIECES {
        push_piece(segments, at(k), at(k + 1));
    }
}

/// The minimum-jerk profile at `tau` ∈ [0, 1].
fn minimum_jerk(tau: f64) -> f64 {
    Profile::MinimumJerk.sample(tau, 1.0).0
}

/// Where the single supports' ZMP reference sits on the stance sole, from its centre.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct ZmpOffsets {
    /// Towards the other foot along the sole's lateral axis (m): `zmp_inward_offset_m`.
    pub inward: f64,
    /// Ahead along the sole's forward axis while the swing lands more than [`STEP_HEIGHT_M`]
    /// below the stance sole (m): `step_down_zmp_forward_m`.
    pub step_down_forward: f64,
}

/// The single support's ZMP on the stance sole `pose` of `foot` while the swing lands at
/// `landing`: [`stance_zmp`] with `offsets.inward`, and on a step down `offsets.step_down_forward`
/// ahead along the sole. The standing knee lowers the body bent ahead of the ankle, and a ZMP
/// ahead shortens its lever: JVRC-1's knee held its torque limit for half as long.
fn single_support_zmp(
    pose: &Isometry3<f64>,
    foot: EndEffector,
    landing: &Isometry3<f64>,
    offsets: ZmpOffsets,
) -> Vector2<f64> {
    let on_stance = stance_zmp(pose, foot, offsets.inward);
    if landing.translation.z < pose.translation.z - STEP_HEIGHT_M {
        on_stance + (pose.rotation * Vector3::x()).xy() * offsets.step_down_forward
    } else {
        on_stance
    }
}

/// The single support's ZMP on the stance sole `pose` of `foot`: `inward` (m) from its centre
/// along the sole's lateral axis, towards the other foot (the left foot's right, the right
/// foot's left).
pub(crate) fn stance_zmp(pose: &Isometry3<f64>, foot: EndEffector, inward: f64) -> Vector2<f64> {
    let side = if foot == EndEffector::LeftFoot {
        -1.0
    } else {
        1.0
    };
    (pose * Point3::new(0.0, side * inward, 0.0)).coords.xy()
}

/// Mean ground position of the feet on the ground.
fn feet_centre(feet: &[Option<Isometry3<f64>>; 2]) -> Vector2<f64> {
    let (sum, count) = feet
        .iter()
        .flatten()
        .fold((Vector2::zeros(), 0.0), |(sum, n), pose| {
            (sum + pose.translation.vector.xy(), n + 1.0)
        });
    sum / count
}

#[cfg(test)]
mod tests {
    use kinematics::ground::{SupportPolygon, sole_corners};
    use kinematics::robot::{EndEffector, SoleRectangle};
    use nalgebra::{DVector, Translation3};

    use super::*;
    use crate::controller::gait::config::DynamicGaitConfig;
    use crate::controller::gait::footsteps::FootstepPlan;
    use crate::controller::sequence::PreparedStance;

    const OMEGA: f64 = 3.4;
    const SOLE: SoleRectangle = SoleRectangle {
        length: 0.2,
        width: 0.08,
    };

    fn at(x: f64, y: f64, z: f64) -> Isometry3<f64> {
        Isometry3::from_parts(Translation3::new(x, y, z), Default::default())
    }

    /// A four-step walk, 0.2 m per step, feet 0.19 m apart.
    fn plan() -> FootstepPlan {
        plan_down(0.0)
    }

    /// [`plan`] with each landing `drop` (m) below the foot standing, one foot per stair.
    fn plan_down(drop: f64) -> FootstepPlan {
        let (left, right) = (0.095, -0.095);
        let mut feet = [at(0.0, left, 0.0), at(0.0, right, 0.0)];
        let stance = |contacts: [bool; 4], feet: [Isometry3<f64>; 2]| {
            let mut targets = [Isometry3::identity(); 4];
            targets[EndEffector::LeftFoot as usize] = feet[0];
            targets[EndEffector::RightFoot as usize] = feet[1];
            PreparedStance {
                posture: DVector::zeros(1),
                contacts,
                targets,
                duration_s: None,
            }
        };
        let standing = feet;
        let mut stances = vec![stance([true, true, false, false], feet)];
        for step in 0..4 {
            let slot = step % 2;
            let mut air = feet;
            air[slot].translation.vector += nalgebra::Vector3::new(0.1, 0.0, 0.05);
            let mut contacts = [true, true, false, false];
            contacts[slot] = false;
            stances.push(stance(contacts, air));
            feet[slot].translation.x += 0.2 + if step == 0 { -0.1 } else { 0.0 };
            feet[slot].translation.z = -drop * (step + 1) as f64;
            stances.push(stance([true, true, false, false], feet));
        }
        // Fixed timing, not the defaults: the closed-form check's RK4 error grows with the
        // plan's length (the unstable mode), and its bound was set for this plan.
        let timing = DynamicGaitConfig {
            single_support_s: 0.7,
            double_support_s: 0.1,
            ..DynamicGaitConfig::default()
        };
        FootstepPlan::new(&stances, standing, &timing).unwrap()
    }

    fn pattern() -> (FootstepPlan, DcmPattern) {
        let plan = plan();
        let mut pattern = DcmPattern::new(&plan.phases, OMEGA, ZmpOffsets::default());
        pattern.start_at_rest(Vector2::new(0.01, 0.0));
        (plan, pattern)
    }

    /// The LIPM integrated with RK4 under the reference ZMP, from rest at the start.
    fn integrate(
        pattern: &DcmPattern,
        until: f64,
        dt: f64,
    ) -> Vec<(f64, Vector2<f64>, Vector2<f64>)> {
        let mut cursor = 0;
        let mut zmp = |t: f64| pattern.sample(t, &mut cursor).zmp;
        let mut state = (Vector2::new(0.01, 0.0), Vector2::zeros());
        let mut out = Vec::new();
        // Steps on a grid that the segment boundaries lie on, so RK4 never straddles a kink.
        for k in 0..(until / dt).round() as usize {
            let t = k as f64 * dt;
            let f = |c: Vector2<f64>, p: Vector2<f64>| OMEGA * OMEGA * (c - p);
            let (c, v) = state;
            let (p0, p1, p2) = (zmp(t), zmp(t + dt / 2.0), zmp(t + dt));
            let k1 = (v, f(c, p0));
            let k2 = (v + k1.1 * dt / 2.0, f(c + k1.0 * dt / 2.0, p1));
            let k3 = (v + k2.1 * dt / 2.0, f(c + k2.0 * dt / 2.0, p1));
            let k4 = (v + k3.1 * dt, f(c + k3.0 * dt, p2));
            state = (
                c + (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0) * dt / 6.0,
                v + (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1) * dt / 6.0,
            );
            out.push((t + dt, state.0, state.1));
        }
        out
    }

    #[test]
    fn the_closed_form_dcm_is_the_lipm_integrated_from_rest() {
        let (plan, pattern) = pattern();
        let start = pattern.sample(0.0, &mut 0);
        assert!(
            (start.dcm - Vector2::new(0.01, 0.0)).norm() < 1e-12,
            "starts at rest"
        );
        let mut cursor = 0;
        for (t, com, velocity) in integrate(&pattern, plan.duration_s(), 1e-4) {
            let reference = pattern.sample(t, &mut cursor);
            let integrated = com + velocity / OMEGA;
            // The unstable mode amplifies the integration error by e^{ω (T − t)} at most.
            assert!(
                (integrated - reference.dcm).norm() < 1e-6,
                "t = {t:.3}: integrated DCM {integrated:?}, closed form {:?}",
                reference.dcm
            );
        }
    }

    #[test]
    fn the_pattern_ends_at_rest_on_the_centre_of_the_final_feet() {
        let (plan, pattern) = pattern();
        let end = pattern.sample(plan.duration_s(), &mut 0);
        let feet = plan
            .phases
            .last()
            .unwrap()
            .feet
            .map(|f| f.unwrap().translation.vector.xy());
        let centre = (feet[0] + feet[1]) / 2.0;
        assert!((end.dcm - centre).norm() < 1e-12 && (end.zmp - centre).norm() < 1e-12);
        assert_eq!(end.dcm_velocity, Vector2::zeros());
        // The CoM follows the DCM and settles: 1 s after the end it is within a millimetre.
        let trajectory = integrate(&pattern, plan.duration_s() + 1.0, 1e-4);
        let &(_, com, velocity) = trajectory.last().unwrap();
        assert!((com - centre).norm() < 2e-3, "CoM {com:?} vs {centre:?}");
        assert!(velocity.norm() < 1e-2, "velocity {velocity:?}");
    }

    #[test]
    fn the_reference_zmp_stays_inside_the_support_polygons() {
        let (plan, pattern) = pattern();
        let mut cursor = 0;
        for phase in &plan.phases {
            let mut corners = Vec::new();
            for foot in phase.feet.iter().flatten() {
                corners.extend(sole_corners(foot, &SOLE).iter().map(|c| [c.x, c.y]));
            }
            let polygon = SupportPolygon::from_points(&corners);
            for k in 0..=20 {
                let t = phase.start_s + phase.duration_s * f64::from(k) / 20.0;
                let zmp = pattern.sample(t, &mut cursor).zmp;
                assert!(
                    polygon.signed_distance([zmp.x, zmp.y]) >= -1e-9,
                    "t = {t:.3}: ZMP {zmp:?} outside the support"
                );
            }
        }
        // The single supports stand exactly on their foot's centre.
        for phase in &plan.phases {
            if let Support::Single(_) = phase.support {
                let foot = phase.feet.iter().flatten().next().unwrap();
                let middle = pattern.sample(phase.start_s + phase.duration_s / 2.0, &mut cursor);
                assert!((middle.zmp - foot.translation.vector.xy()).norm() < 1e-12);
            }
        }
    }

    #[test]
    fn an_inward_offset_moves_the_single_support_zmp_towards_the_other_foot() {
        let plan = plan();
        let inward = 0.03;
        let offsets = ZmpOffsets {
            inward,
            step_down_forward: 0.05,
        };
        // Level steps: the step-down offset does not apply.
        let mut pattern = DcmPattern::new(&plan.phases, OMEGA, offsets);
        pattern.start_at_rest(Vector2::new(0.01, 0.0));
        let mut cursor = 0;
        let mut singles = 0;
        for phase in &plan.phases {
            let Support::Single(swing) = phase.support else {
                continue;
            };
            singles += 1;
            let foot = phase.feet.iter().flatten().next().unwrap();
            let centre = foot.translation.vector.xy();
            let middle = pattern.sample(phase.start_s + phase.duration_s / 2.0, &mut cursor);
            // The feet stand at y = ±0.095: inward is towards y = 0, by `inward`.
            let towards_midline = -centre.y.signum() * inward;
            let expected = centre + Vector2::new(0.0, towards_midline);
            assert!(
                (middle.zmp - expected).norm() < 1e-12,
                "{:?} swinging: ZMP {:?}, expected {expected:?}",
                swing.foot,
                middle.zmp
            );
            assert!(middle.zmp.y.abs() < centre.y.abs());
        }
        assert!(singles > 0);
        // The pattern still ends at rest on the final feet's centre.
        let end = pattern.sample(plan.duration_s(), &mut 0);
        assert!((end.dcm - pattern.rest()).norm() < 1e-12);
    }

    #[test]
    fn a_step_down_moves_the_single_support_zmp_ahead_on_the_stance_sole() {
        let plan = plan_down(0.1);
        let offsets = ZmpOffsets {
            inward: 0.0,
            step_down_forward: 0.03,
        };
        let pattern = DcmPattern::new(&plan.phases, OMEGA, offsets);
        let mut cursor = 0;
        let mut singles = 0;
        for phase in &plan.phases {
            if let Support::Single(_) = phase.support {
                singles += 1;
                let foot = phase.feet.iter().flatten().next().unwrap();
                let middle = pattern.sample(phase.start_s + phase.duration_s / 2.0, &mut cursor);
                // The soles face +x.
                let ahead = foot.translation.vector.xy() + Vector2::new(0.03, 0.0);
                assert!((middle.zmp - ahead).norm() < 1e-12, "{:?}", middle.zmp);
            }
        }
        assert_eq!(singles, 4);
    }

    #[test]
    fn transforming_the_pattern_moves_every_sample() {
        let (_, pattern) = pattern();
        let to_world = Isometry3::new(
            nalgebra::Vector3::new(1.0, -2.0, 0.0),
            nalgebra::Vector3::z() * 0.3,
        );
        let mut moved = pattern.clone();
        moved.transform(&to_world);
        for t in [0.0, 0.5, 1.7, 3.3, 10.0] {
            let a = pattern.sample(t, &mut 0);
            let b = moved.sample(t, &mut 0);
            let expected = (to_world * nalgebra::Point3::new(a.dcm.x, a.dcm.y, 0.0))
                .coords
                .xy();
            assert!((b.dcm - expected).norm() < 1e-12, "t = {t}");
        }
    }
}
