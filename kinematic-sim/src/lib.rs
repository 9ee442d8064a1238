//! A deterministic kinematic simulator shared by `walk-sim --physics kinematic` and `walkd bench`.
//!
//! The model is quasi-static and exact where a rigid-body simulator is not:
//! - **Joints** follow the commanded positions ideally (a perfect position servo); a command beyond
//!   a joint limit stops at the limit and is counted as a violation.
//! - **Floating base**: feet in contact are anchored at the world pose where they touched down.
//!   Each step the base pose is recomputed from the anchored feet: a blend of the per-foot
//!   solutions weighted by each foot's lever-rule share of the weight, faded out as a foot is
//!   lifted towards release. A foot in contact therefore stays where it is up to the
//!   inconsistency of the command, which is reported as slip.
//! - **Contacts** are derived from kinematics: a free foot touches down when a sole corner reaches
//!   the ground under it; an anchored foot is released when lifted more than a tolerance above
//!   its anchor. The ground is a plane, or a scene's support surfaces ([`Ground`]: stairs, ramps).
//!   Hands carry no load (railings are not modelled).
//! - **Force-torque readings** come from static equilibrium: the weight `m·g` is split between the
//!   feet in contact by the lever rule on the CoM ground projection, plus a stiff ground
//!   compliance that moves load onto a foot pressed into the ground; the wrench is expressed at
//!   each FT frame origin in world-aligned axes (the force the ground exerts on the robot).
//! - **Safety metrics**: stability margin (signed distance of the CoM ground projection to the
//!   support polygon; negative = fall), contact slip, penetration, joint limit violations.
//! - **Dynamic walks** ([`SimOptions::judge_by_zmp`]): a walk that is not statically stable is
//!   judged by its ZMP, `p = c − (z_c / g) c̈` (`c̈` by finite differences over the last steps,
//!   low-pass filtered; `z_c` the CoM height above the ground), instead of the CoM; the
//!   synthetic forces carry `m (g + z̈)` and are split between the feet so that their centres of
//!   pressure make that ZMP.
//!
//! [`Simulator`] is the interface every simulated robot offers (this one and MuJoCo's), so one
//! closed loop and one adapter wrapper serve both.

mod simulator;

pub use simulator::Simulator;

use std::sync::Arc;

use kinematics::configuration::Configuration;
use kinematics::ground::{GRAVITY, SupportPolygon, sole_corners};
use kinematics::kinematics::Kinematics;
use kinematics::robot::{EndEffector, Robot};
use nalgebra::{DVector, Isometry3, Translation3, UnitQuaternion, Vector3};

const FEET: [EndEffector; 2] = [EndEffector::LeftFoot, EndEffector::RightFoot];

/// The support surfaces a walk stands on, beyond the flat plane of [`SimOptions::ground_height`]
/// (a scene's stairs and ramps, [`KinematicSim::on_ground`]).
pub trait Ground: std::fmt::Debug + Send + Sync {
    /// Height (m, world z) of the highest support surface under (`x`, `y`); `None` where there is
    /// none (a foot there finds nothing to land on).
    fn height_at(&self, x: f64, y: f64) -> Option<f64>;
}

/// Tunable contact model; the defaults suit the vendored humanoids.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimOptions {
    /// Height of the ground plane (m), unless the simulator stands on a [`Ground`].
    pub ground_height: f64,
    /// A free foot touches down when its lowest sole corner is this close to the ground (m).
    pub touchdown_tolerance: f64,
    /// An anchored foot is released once lifted this far above its anchor (m).
    pub release_tolerance: f64,
    /// Ground stiffness that shifts load onto a foot pressed into the ground (N/m).
    pub ground_stiffness: f64,
    /// Judge stability, and synthesise the forces, from the ZMP of the CoM's motion instead of
    /// the CoM (for dynamic walks, whose CoM leaves the support polygon by design).
    pub judge_by_zmp: bool,
    /// Time constant of the low-pass filter on the CoM acceleration of the ZMP (s). The ideal
    /// servos change velocity from one step to the next, which a real robot's inertia smooths.
    pub zmp_filter_s: f64,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            ground_height: 0.0,
            touchdown_tolerance: 1e-4,
            release_tolerance: 5e-4,
            ground_stiffness: 2e6,
            judge_by_zmp: false,
            zmp_filter_s: 0.02,
        }
    }
}

/// Errors of the simulator API (bad commands or initial states), naming what is wrong.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SimError {
    /// The initial configuration does not stand: no foot touches the ground.
    #[error(
        "initial configuration: no foot sole touches the ground (lowest sole corner {lowest_m:.4} m above it)"
    )]
    NotStanding {
        /// Height of the lowest sole corner above the ground.
        lowest_m: f64,
    },
    /// A command vector has the wrong length or a non-finite entry.
    #[error("command {0}")]
    Command(#[from] JointVectorError),
    /// The time step is not positive and finite.
    #[error("time step {0} s is not positive and finite")]
    BadTimeStep(f64),
}

/// Why a joint vector handed to a simulator (a command, an initial posture) is unusable; every
/// simulator back-end carries it in its own error type.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum JointVectorError {
    /// Not one entry per model joint.
    #[error("`{field}` has {actual} entries, the model has {expected} joints")]
    Length {
        /// Which vector (`q_des`, `qd_des`, `initial.joints`).
        field: &'static str,
        /// The model's joint count.
        expected: usize,
        /// The length given.
        actual: usize,
    },
    /// An entry is NaN or infinite.
    #[error("`{field}` joint {index} ({joint}) is not finite")]
    NonFinite {
        /// Which vector.
        field: &'static str,
        /// Joint index in model order.
        index: usize,
        /// Joint name.
        joint: String,
    },
}

/// Checks that `values` has one finite entry per joint of `model`.
pub fn check_joint_vector(
    model: &kinematics::Model,
    field: &'static str,
    values: &[f64],
) -> Result<(), JointVectorError> {
    let expected = model.dof();
    if values.len() != expected {
        return Err(JointVectorError::Length {
            field,
            expected,
            actual: values.len(),
        });
    }
    if let Some(index) = values.iter().position(|v| !v.is_finite()) {
        return Err(JointVectorError::NonFinite {
            field,
            index,
            joint: model.joint_names()[index].clone(),
        });
    }
    Ok(())
}

/// Safety metrics of the current state; the simulator also keeps their worst values.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SafetyMetrics {
    /// Signed distance of the CoM ground projection (the ZMP with [`SimOptions::judge_by_zmp`])
    /// to the support polygon (m, < 0 = falling).
    pub stability_margin: f64,
    /// Largest horizontal displacement of a foot in contact from its touchdown pose (m).
    pub contact_slip: f64,
    /// Deepest sole corner below the ground (m, 0 when none is below).
    pub penetration: f64,
    /// Number of joints whose command was beyond a limit this step.
    pub limit_violations: usize,
}

/// Worst values over the whole run, for pass/fail checks and reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SafetySummary {
    /// Smallest stability margin seen (m).
    pub min_stability_margin: f64,
    /// Largest contact slip seen (m).
    pub max_contact_slip: f64,
    /// Deepest penetration seen (m).
    pub max_penetration: f64,
    /// Total joint-limit violations (joint × step).
    pub joint_limit_violations: u64,
    /// Whether the CoM ever left the support polygon.
    pub fell: bool,
    /// Number of states evaluated: the initial state and one per step.
    pub steps: u64,
}

impl Default for SafetySummary {
    fn default() -> Self {
        Self {
            min_stability_margin: f64::INFINITY,
            max_contact_slip: 0.0,
            max_penetration: 0.0,
            joint_limit_violations: 0,
            fell: false,
            steps: 0,
        }
    }
}

/// What sensors would report, plus ground truth the controller never sees.
#[derive(Clone, Debug)]
pub struct SimMeasurement {
    /// Joint angles (model order).
    pub q: DVector<f64>,
    /// Joint velocities over the last step.
    pub qd: DVector<f64>,
    /// Force (xyz) and torque (xyz) at each FT frame, world-aligned axes, ordered by
    /// [`EndEffector`] (hands read zero: no hand support is modelled).
    pub wrenches: [[f64; 6]; 4],
    /// The base orientation (an ideal IMU).
    pub base_orientation: UnitQuaternion<f64>,
    /// Ground truth: base pose in the world.
    pub base: Isometry3<f64>,
    /// Ground truth: centre of mass in the world.
    pub com: Vector3<f64>,
    /// Ground truth: which end-effectors are in contact, by [`EndEffector`].
    pub contacts: [bool; 4],
    /// Safety metrics of this state.
    pub safety: SafetyMetrics,
}

impl SimMeasurement {
    /// The reading of a robot at rest in `initial` with its CoM at `com`, before the first step:
    /// no velocity, no load, no contact yet.
    pub fn at_rest(initial: &Configuration, com: Vector3<f64>) -> Self {
        Self {
            q: initial.joints.clone(),
            qd: DVector::zeros(initial.joints.len()),
            wrenches: [[0.0; 6]; 4],
            base_orientation: initial.base.rotation,
            base: initial.base,
            com,
            contacts: [false; 4],
            safety: SafetyMetrics::default(),
        }
    }
}

/// The base pose blended from the anchored feet's `candidates` by their `shares` (equal halves
/// when both shares are zero); `None` when no foot is anchored.
fn blend(candidates: &[Option<Isometry3<f64>>; 2], shares: &[f64; 2]) -> Option<Isometry3<f64>> {
    let mut blended: Option<(Isometry3<f64>, f64)> = None;
    for (candidate, share) in candidates.iter().zip(shares) {
        let Some(candidate) = candidate else {
            continue;
        };
        blended = Some(match blended {
            None => (*candidate, *share),
            Some((previous, weight)) => {
                let total = weight + share;
                let t = if total > 0.0 { share / total } else { 0.5 };
                let translation = previous
                    .translation
                    .vector
                    .lerp(&candidate.translation.vector, t);
                let rotation = previous.rotation.nlerp(&candidate.rotation, t);
                (
                    Isometry3::from_parts(Translation3::from(translation), rotation),
                    total,
                )
            }
        });
    }
    blended.map(|(mut pose, _)| {
        // Composing with inverses assumes unit quaternions; without renormalising, a norm
        // error doubles every step.
        pose.rotation.renormalize();
        pose
    })
}

/// The simulator: holds the robot state, the contact anchors and the metrics.
pub struct KinematicSim {
    robot: Arc<Robot>,
    options: SimOptions,
    /// The support surfaces; `None`: the plane at `options.ground_height`.
    ground: Option<Arc<dyn Ground>>,
    configuration: Configuration,
    kinematics: Kinematics,
    anchors: [Option<Isometry3<f64>>; 2],
    measurement: SimMeasurement,
    summary: SafetySummary,
    corners: [[f64; 2]; 8],
    /// Simulated time since the start (s).
    time: f64,
    /// The CoM of the last state and its velocity from the motion over the step before it, for
    /// the ZMP's acceleration.
    com_history: Option<(Vector3<f64>, Option<Vector3<f64>>)>,
    /// The anchors and load shares (after the lift fade) the base was last placed with.
    placement: ([Option<Isometry3<f64>>; 2], [f64; 2]),
    /// With `judge_by_zmp`: how far the last base placement moved the CoM by changing the feet's
    /// shares rather than by the joints' motion (see `place_base`).
    replacement: Vector3<f64>,
    /// The filtered CoM acceleration.
    com_acceleration: Vector3<f64>,
    /// Where the ground reaction acted in the last step (see `resultant`).
    support_point: Vector3<f64>,
    /// The last setpoint applied (joint angles, rates), to recognise one given again.
    setpoint: (DVector<f64>, DVector<f64>),
}

impl KinematicSim {
    /// Starts a simulation from `initial` with default options (see [`KinematicSim::with_options`]).
    pub fn new(robot: Arc<Robot>, initial: Configuration) -> Result<Self, SimError> {
        Self::with_options(robot, initial, SimOptions::default())
    }

    /// Starts a simulation from `initial`; feet whose soles touch the ground are anchored there.
    pub fn with_options(
        robot: Arc<Robot>,
        initial: Configuration,
        options: SimOptions,
    ) -> Result<Self, SimError> {
        Self::start(robot, initial, options, None)
    }

    /// [`KinematicSim::with_options`] on `ground`'s support surfaces instead of the plane.
    pub fn on_ground(
        robot: Arc<Robot>,
        initial: Configuration,
        options: SimOptions,
        ground: Arc<dyn Ground>,
    ) -> Result<Self, SimError> {
        Self::start(robot, initial, options, Some(ground))
    }

    fn start(
        robot: Arc<Robot>,
        initial: Configuration,
        options: SimOptions,
        ground: Option<Arc<dyn Ground>>,
    ) -> Result<Self, SimError> {
        let mut kinematics = Kinematics::new(&robot.model);
        kinematics.update(&robot.model, &initial);
        let measurement = SimMeasurement::at_rest(&initial, kinematics.com());
        let setpoint = (initial.joints.clone(), DVector::zeros(initial.joints.len()));
        let mut sim = Self {
            robot,
            options,
            ground,
            configuration: initial,
            kinematics,
            anchors: [None, None],
            measurement,
            summary: SafetySummary::default(),
            corners: [[0.0; 2]; 8],
            time: 0.0,
            com_history: None,
            placement: ([None; 2], [0.0; 2]),
            replacement: Vector3::zeros(),
            com_acceleration: Vector3::zeros(),
            support_point: Vector3::zeros(),
            setpoint,
        };
        sim.support_point = sim.kinematics.com();
        let mut lowest = f64::INFINITY;
        for (slot, foot) in FEET.iter().enumerate() {
            let height = sim.lowest_corner_height(*foot);
            lowest = lowest.min(height);
            if height <= options.touchdown_tolerance {
                sim.anchors[slot] = Some(sim.pose(*foot));
            }
        }
        if sim.anchors.iter().all(Option::is_none) {
            return Err(SimError::NotStanding { lowest_m: lowest });
        }
        sim.finish_step(0, Some(0.0));
        Ok(sim)
    }

    /// The full configuration (ground truth base and joints).
    pub fn configuration(&self) -> &Configuration {
        &self.configuration
    }

    fn check_command(&self, field: &'static str, values: &[f64]) -> Result<(), SimError> {
        Ok(check_joint_vector(&self.robot.model, field, values)?)
    }

    /// Whether the setpoint `q_des` / `qd_des` is the last one given again with a non-zero rate:
    /// a command that did not come (see `Simulator::step`). Remembers it as the last one.
    fn missed_command(&mut self, q_des: &[f64], qd_des: &[f64]) -> bool {
        let (q, qd) = &mut self.setpoint;
        let missed = q.as_slice() == q_des
            && qd.as_slice() == qd_des
            && qd_des.iter().any(|rate| *rate != 0.0);
        q.copy_from_slice(q_des);
        qd.copy_from_slice(qd_des);
        missed
    }

    fn pose(&self, e: EndEffector) -> Isometry3<f64> {
        self.kinematics
            .frame_pose(&self.robot.model, self.robot.frame(e))
    }

    /// Height of the ground under (`x`, `y`): minus infinity off every surface.
    fn ground_height_at(&self, x: f64, y: f64) -> f64 {
        match &self.ground {
            Some(ground) => ground.height_at(x, y).unwrap_or(f64::NEG_INFINITY),
            None => self.options.ground_height,
        }
    }

    /// Height of `foot`'s lowest sole corner above the ground under it (negative: below it).
    fn lowest_corner_height(&self, foot: EndEffector) -> f64 {
        sole_corners(&self.pose(foot), &self.robot.sole)
            .iter()
            .map(|c| c.z - self.ground_height_at(c.x, c.y))
            .fold(f64::INFINITY, f64::min)
    }

    /// Lever-rule share of the weight carried by each anchored foot when the resultant acts at
    /// `com`'s ground projection (sums to 1 when any is anchored).
    fn lever_shares(&self, com: &Vector3<f64>) -> [f64; 2] {
        match self.anchors {
            [Some(_), None] => [1.0, 0.0],
            [None, Some(_)] => [0.0, 1.0],
            [Some(left), Some(right)] => {
                let (a, b) = (left.translation.vector, right.translation.vector);
                let ab = (b - a).xy();
                let t = ((com.xy() - a.xy()).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                [1.0 - t, t]
            }
            [None, None] => [0.0, 0.0],
        }
    }

    /// Recomputes the base so the anchored feet stay put (blended by load share).
    fn place_base(&mut self) {
        // FK with the previous base gives every foot's pose relative to the base.
        self.kinematics
            .update(&self.robot.model, &self.configuration);
        let base = self.configuration.base;
        // Each foot holds the base in proportion to its lever-rule share of the weight, faded
        // out as the foot is lifted towards release: the foot the CoM stands over stays put, a
        // foot pressed into the ground beside it only penetrates, and a foot being unloaded
        // stops dragging the base (and so the other foot) before it leaves the ground.
        // The weight acts at the ground reaction's point of the last step: the CoM's projection,
        // or with `judge_by_zmp` the ZMP (a dynamic walk's CoM passes between the feet while the
        // ZMP stays under the stance foot, and a swing foot touching down carries nothing yet).
        let point = if self.options.judge_by_zmp {
            self.support_point
        } else {
            self.kinematics.com()
        };
        let mut shares = self.lever_shares(&point);
        for (slot, foot) in FEET.iter().enumerate() {
            if let Some(anchor) = self.anchors[slot] {
                let lift = self.pose(*foot).translation.z - anchor.translation.z;
                shares[slot] *= (1.0 - lift / self.options.release_tolerance).clamp(0.0, 1.0);
            }
        }
        // Zero unless this placement re-places the base (below).
        self.replacement = Vector3::zeros();
        let candidates = |anchors: &[Option<Isometry3<f64>>; 2]| {
            let mut candidates = [None; 2];
            for (slot, foot) in FEET.iter().enumerate() {
                if let Some(anchor) = anchors[slot] {
                    let foot_in_base = base.inverse() * self.pose(*foot);
                    candidates[slot] = Some(anchor * foot_in_base.inverse());
                }
            }
            candidates
        };
        if let Some(pose) = blend(&candidates(&self.anchors), &shares) {
            if self.options.judge_by_zmp {
                // Where the base would be had the feet kept last step's anchors and shares: the
                // difference is the base re-placed between inconsistent anchors (a foot touching
                // down or released, a load shift), not motion, and must not reach the ZMP's
                // acceleration (at a touchdown it fed back through the ZMP's lever rule into the
                // shares until the ZMP left the support).
                let (anchors, held_shares) = self.placement;
                let held = blend(&candidates(&anchors), &held_shares).unwrap_or(pose);
                let com_in_base = base.inverse() * nalgebra::Point3::from(self.kinematics.com());
                self.replacement = pose * com_in_base - held * com_in_base;
            }
            self.configuration.base = pose;
        }
        self.placement = (self.anchors, shares);
        self.kinematics
            .update(&self.robot.model, &self.configuration);
    }

    /// Releases lifted feet and anchors feet that reached the ground.
    fn update_contacts(&mut self) {
        for (slot, foot) in FEET.iter().enumerate() {
            match self.anchors[slot] {
                Some(anchor) => {
                    let other_anchored = self.anchors[1 - slot].is_some();
                    let lift = self.pose(*foot).translation.z - anchor.translation.z;
                    if other_anchored && lift > self.options.release_tolerance {
                        self.anchors[slot] = None;
                    }
                }
                None => {
                    if self.lowest_corner_height(*foot) <= self.options.touchdown_tolerance {
                        self.anchors[slot] = Some(self.pose(*foot));
                    }
                }
            }
        }
    }

    /// The point the ground reaction acts at (the CoM's ground projection, or the ZMP of its
    /// motion with `judge_by_zmp`) and the total normal force, in the state after a step of
    /// `elapsed` (`None`: a missed command, which the motion history skips).
    fn resultant(&mut self, com: &Vector3<f64>, elapsed: Option<f64>) -> (Vector3<f64>, f64) {
        let mass = self.robot.model.total_mass();
        if !self.options.judge_by_zmp {
            return (*com, mass * GRAVITY);
        }
        let accelerating = match elapsed {
            Some(dt) => self.track_acceleration(com, dt),
            None => matches!(self.com_history, Some((_, Some(_)))),
        };
        if !accelerating {
            return (*com, mass * GRAVITY);
        }
        let acceleration = self.com_acceleration;
        let ground = self.ground_height_at(com.x, com.y);
        let height = com.z
            - if ground.is_finite() {
                ground
            } else {
                self.options.ground_height
            };
        // The ground carries m (g + z̈); with none to carry (the CoM falling faster than g) the
        // feet are unloaded and the ZMP is undefined: keep it under the CoM.
        let support = GRAVITY + acceleration.z;
        if support <= 0.0 {
            return (*com, 0.0);
        }
        let mut zmp = com - acceleration * (height / support);
        zmp.z = com.z;
        (zmp, mass * support)
    }

    /// Records the CoM `com` reached in a step of `dt` and low-pass filters its acceleration
    /// (finite differences, less the base re-placement); false until two velocities are known.
    fn track_acceleration(&mut self, com: &Vector3<f64>, dt: f64) -> bool {
        let history = self.com_history;
        let velocity = match history {
            Some((last, _)) if dt > 0.0 => Some((com - self.replacement - last) / dt),
            _ => None,
        };
        self.com_history = Some((*com, velocity));
        let (Some(velocity), Some((_, Some(previous_velocity)))) = (velocity, history) else {
            return false;
        };
        let raw = (velocity - previous_velocity) / dt;
        let blend = dt / (self.options.zmp_filter_s + dt);
        self.com_acceleration += (raw - self.com_acceleration) * blend;
        true
    }

    /// Forces, metrics and the measurement record of the new state, `elapsed` after the last
    /// (`None`: a missed command, see `resultant`).
    fn finish_step(&mut self, limit_violations: usize, elapsed: Option<f64>) {
        let com = self.kinematics.com();
        let (support_point, weight) = self.resultant(&com, elapsed);
        self.support_point = support_point;
        let shares = self.lever_shares(&support_point);
        let mut loads = [0.0; 2];
        let mut slip: f64 = 0.0;
        let mut corner_count = 0;
        for (slot, foot) in FEET.iter().enumerate() {
            let Some(anchor) = self.anchors[slot] else {
                continue;
            };
            let pose = self.pose(*foot);
            let offset = pose.translation.vector - anchor.translation.vector;
            slip = slip.max(offset.xy().norm());
            // Pressing into the ground adds load, lifting off removes it (never below zero).
            let compression = -offset.z;
            loads[slot] =
                (shares[slot] * weight + self.options.ground_stiffness * compression).max(0.0);
            for corner in sole_corners(&pose, &self.robot.sole) {
                self.corners[corner_count] = [corner.x, corner.y];
                corner_count += 1;
            }
        }
        let total: f64 = loads.iter().sum();
        // Centres of pressure: each sole centre shifted by one common offset chosen so the
        // resultant acts below the CoM (moment equilibrium about the CoM's vertical).
        let mut loaded_centre = Vector3::zeros();
        for (slot, foot) in FEET.iter().enumerate() {
            if total > 0.0 && self.anchors[slot].is_some() {
                loaded_centre += loads[slot] / total * self.pose(*foot).translation.vector;
            }
        }
        let cop_offset = Vector3::new(
            support_point.x - loaded_centre.x,
            support_point.y - loaded_centre.y,
            0.0,
        );
        let mut wrenches = [[0.0; 6]; 4];
        for (slot, foot) in FEET.iter().enumerate() {
            if self.anchors[slot].is_none() || total <= 0.0 {
                continue;
            }
            let force = Vector3::new(0.0, 0.0, loads[slot] / total * weight);
            let cop = self.pose(*foot).translation.vector + cop_offset;
            let sensor = self
                .kinematics
                .frame_pose(&self.robot.model, self.robot.ft_sensors[slot]);
            let torque = (cop - sensor.translation.vector).cross(&force);
            wrenches[*foot as usize] = [force.x, force.y, force.z, torque.x, torque.y, torque.z];
        }
        let polygon = SupportPolygon::from_points(&self.corners[..corner_count]);
        let penetration = FEET
            .iter()
            .map(|foot| (-self.lowest_corner_height(*foot)).max(0.0))
            .fold(0.0, f64::max);
        let safety = SafetyMetrics {
            stability_margin: polygon.signed_distance([support_point.x, support_point.y]),
            contact_slip: slip,
            penetration,
            limit_violations,
        };
        let m = &mut self.measurement;
        m.q.copy_from(&self.configuration.joints);
        m.wrenches = wrenches;
        m.base_orientation = self.configuration.base.rotation;
        m.base = self.configuration.base;
        m.com = com;
        m.contacts = [
            self.anchors[0].is_some(),
            self.anchors[1].is_some(),
            false,
            false,
        ];
        m.safety = safety;
        let s = &mut self.summary;
        s.min_stability_margin = s.min_stability_margin.min(safety.stability_margin);
        s.max_contact_slip = s.max_contact_slip.max(safety.contact_slip);
        s.max_penetration = s.max_penetration.max(safety.penetration);
        s.joint_limit_violations += limit_violations as u64;
        s.fell |= safety.stability_margin < 0.0;
        s.steps += 1;
    }
}
