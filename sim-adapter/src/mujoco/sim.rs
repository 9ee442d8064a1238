//! [`MujocoSim`]: the robot under rigid-body dynamics with contacts, stepped like the kinematic
//! simulator (`step(q_des, q̇_des, dt)`, then read [`MujocoSim::measurement`]).

use std::path::Path;
use std::sync::Arc;

use kinematic_sim::{SafetyMetrics, SafetySummary, SimMeasurement, Simulator, check_joint_vector};
use kinematics::configuration::Configuration;
use kinematics::ground::{SupportPolygon, sole_corners};
use kinematics::robot::{EndEffector, Robot};
use mujoco_rs::prelude::{MjData, MjModel, MjtObjBase, MjtWarning};
use nalgebra::{Isometry3, Matrix3, Quaternion, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::actuators::ActuatorRecord;
use super::bodies::RigidBodies;
use super::collisions::{CollisionWatch, TerrainCollisions};
use super::contact::{self, ContactIds, Contacts};
use super::mjcf;
use super::{MujocoError, MujocoOptions, Terrain};

/// The MuJoCo version mujoco-rs 7.0.0 is built for (it refuses any other).
const MUJOCO_VERSION: &str = "3.17.0";
const FEET: [EndEffector; 2] = [EndEffector::LeftFoot, EndEffector::RightFoot];
/// MuJoCo warnings that mean the state was unusable and MuJoCo reset it.
const FATAL_WARNINGS: [MjtWarning; 3] = [
    MjtWarning::mjWARN_BADQPOS,
    MjtWarning::mjWARN_BADQVEL,
    MjtWarning::mjWARN_BADQACC,
];

/// Where each quantity lives in MuJoCo's arrays, resolved once at construction.
#[derive(Debug)]
struct Layout {
    /// `qpos` / `qvel` address of each actuated joint, model order.
    joint_qpos: Vec<usize>,
    joint_dof: Vec<usize>,
    /// Body id of the floating base (the free joint's body) and its `qpos` / `qvel` address.
    base_body: usize,
    base_qpos: usize,
    /// Site of each end-effector frame, by [`EndEffector`].
    effector_sites: [usize; 4],
    /// Collision geom and FT site of each end-effector, by [`EndEffector`].
    contacts: ContactIds,
    /// The body the robot's `base_link` belongs to, and the link's pose in that body.
    base_link_body: usize,
    base_link_offset: Isometry3<f64>,
}

/// A robot standing on a flat floor, or in a scene's [`Terrain`], under MuJoCo's rigid-body
/// dynamics, driven by joint servos.
///
/// Deterministic: the same robot, options, initial state and commands give bit-identical states.
/// Not real-time safe to construct (it compiles a model); [`MujocoSim::step`] does not allocate.
pub struct MujocoSim {
    robot: Arc<Robot>,
    options: MujocoOptions,
    data: MjData<Box<MjModel>>,
    layout: Layout,
    /// Contact readings of the last constraint solve (or the last `step`'s mean).
    contacts: Contacts,
    /// Sole pose of each foot when it last touched down (for the slip metric).
    anchors: [Option<Isometry3<f64>>; 2],
    polygon: SupportPolygon,
    measurement: SimMeasurement,
    summary: SafetySummary,
    initial_base_height: f64,
    /// Sum of the `dt`s stepped so far; the physics time follows it to within one time step.
    commanded_time: f64,
    /// Torque and speed of every joint against its URDF limits.
    actuators: ActuatorRecord,
    /// Each servo's position reference over the current command period: from, to.
    servo_ramps: Vec<(f64, f64)>,
    /// The scene the robot is in (`None`: the flat floor).
    terrain: Option<Terrain>,
    /// Leg contacts with the terrain other than the soles'.
    collisions: CollisionWatch,
}

impl MujocoSim {
    /// Builds the physics model of `robot` (kinematics and inertials from `urdf`, the file the
    /// robot was loaded from) on the flat floor and places it in `initial`, at rest.
    pub fn new(
        robot: Arc<Robot>,
        urdf: &Path,
        initial: &Configuration,
        options: MujocoOptions,
    ) -> Result<Self, MujocoError> {
        Self::build(robot, urdf, initial, options, None)
    }

    /// Like [`MujocoSim::new`], in `terrain` instead of on the flat floor, with collision
    /// capsules on the legs; `initial` is in the world (see [`Terrain::place`] for the scene's
    /// start).
    pub fn on_terrain(
        robot: Arc<Robot>,
        urdf: &Path,
        initial: &Configuration,
        options: MujocoOptions,
        terrain: Terrain,
    ) -> Result<Self, MujocoError> {
        Self::build(robot, urdf, initial, options, Some(terrain))
    }

    fn build(
        robot: Arc<Robot>,
        urdf: &Path,
        initial: &Configuration,
        options: MujocoOptions,
        terrain: Option<Terrain>,
    ) -> Result<Self, MujocoError> {
        check_library_version()?;
        options.check()?;
        check_joint_vector(&robot.model, "initial.joints", initial.joints.as_slice())?;
        let base = &initial.base;
        if !(base
            .translation
            .vector
            .iter()
            .chain(base.rotation.coords.iter()))
        .all(|v| v.is_finite())
        {
            return Err(MujocoError::NonFiniteBase);
        }
        let parsed = urdf_rs::read_file(urdf).map_err(|error| MujocoError::Urdf {
            path: urdf.to_owned(),
            message: error.to_string(),
        })?;
        let bodies = RigidBodies::from_urdf(&parsed, &robot.model)?;
        let xml = mjcf::write(&robot, &bodies, &options, terrain.as_ref())?;
        let model = MjModel::from_xml_string(&xml)
            .map_err(|error| MujocoError::Compile(error.to_string()))?;
        let layout = Layout::resolve(&model, &robot, &bodies)?;
        let collisions = CollisionWatch::new(&model);
        let data = MjData::new(Box::new(model));
        let measurement = SimMeasurement::at_rest(initial, Vector3::zeros());
        let actuators = ActuatorRecord::new(&robot);
        let dof = robot.model.dof();
        let mut sim = Self {
            robot,
            options,
            data,
            layout,
            contacts: Contacts::default(),
            anchors: [None, None],
            polygon: SupportPolygon::empty(),
            measurement,
            summary: SafetySummary::default(),
            initial_base_height: 0.0,
            commanded_time: 0.0,
            actuators,
            servo_ramps: vec![(0.0, 0.0); dof],
            terrain,
            collisions,
        };
        sim.place(initial);
        sim.initial_base_height = sim.base_height();
        Ok(sim)
    }

    /// The options the model was built with.
    pub fn options(&self) -> &MujocoOptions {
        &self.options
    }

    /// The legs' contacts with the terrain other than the soles' since the start (always none
    /// on the flat floor, where the legs have no collision geometry).
    pub fn terrain_collisions(&self) -> &TerrainCollisions {
        self.collisions.record()
    }

    /// The compiled MuJoCo model (e.g. to count its geoms or build a renderer for it).
    pub fn model(&self) -> &MjModel {
        self.data.model()
    }

    /// The MuJoCo state, for the renderer (which reads the model and the current state).
    #[cfg(feature = "render")]
    pub(crate) fn data_mut(&mut self) -> &mut MjData<Box<MjModel>> {
        &mut self.data
    }

    /// The IMU at the floating base origin (the URDF root link): angular velocity (rad/s) and
    /// specific force (m/s², from the last constraint solve), both in the base frame.
    pub fn imu_rates(&self) -> (Vector3<f64>, Vector3<f64>) {
        let s = self.data.sensordata();
        (
            Vector3::from_column_slice(&s[mjcf::IMU_GYRO]),
            Vector3::from_column_slice(&s[mjcf::IMU_ACCEL]),
        )
    }

    /// Height of the `base_link` origin above the floor, or above the terrain straight under it
    /// ([`Terrain::elevation_at`]) (m).
    pub fn base_height(&self) -> f64 {
        let base = self.base_link_pose().translation.vector;
        let ground = self
            .terrain
            .as_ref()
            .map_or(0.0, |terrain| terrain.elevation_at(base.x, base.y));
        base.z - ground
    }

    /// Angle between the `base_link` z axis and the world vertical (rad).
    pub fn torso_tilt(&self) -> f64 {
        crate::truth::tilt(&self.base_link_pose())
    }

    /// Whether the robot has fallen: the base dropped below `fall_height_fraction` of its initial
    /// height or tilted more than `fall_tilt`. Also recorded in [`SafetySummary::fell`].
    pub fn has_fallen(&self) -> bool {
        self.base_height() < self.options.fall_height_fraction * self.initial_base_height
            || self.torso_tilt() > self.options.fall_tilt
    }

    /// Applies `force` (N, world frame) at the centre of mass of the pelvis (the body holding the
    /// configured `base_link`) from the next step on, until changed; zero removes it. An
    /// experiment's push.
    pub fn set_pelvis_force(&mut self, force: Vector3<f64>) {
        let body = self.layout.base_link_body;
        self.data.xfrc_applied_mut()[body] = [force.x, force.y, force.z, 0.0, 0.0, 0.0];
    }

    /// Puts the robot in `initial`, at rest, and evaluates it.
    fn place(&mut self, initial: &Configuration) {
        let base = &initial.base;
        let q = base.rotation.quaternion();
        let (base_qpos, joint_qpos) = (self.layout.base_qpos, &self.layout.joint_qpos);
        let qpos = self.data.qpos_mut();
        qpos[base_qpos..base_qpos + 3].copy_from_slice(base.translation.vector.as_slice());
        qpos[base_qpos + 3..base_qpos + 7].copy_from_slice(&[q.w, q.i, q.j, q.k]);
        for (&address, &value) in joint_qpos.iter().zip(initial.joints.iter()) {
            qpos[address] = value;
        }
        self.data.qvel_mut().fill(0.0);
        let ctrl = self.data.ctrl_mut();
        for (j, &value) in initial.joints.iter().enumerate() {
            ctrl[2 * j] = value;
            ctrl[2 * j + 1] = 0.0;
        }
        self.data.forward();
        self.contacts = contact::read(&self.data, &self.layout.contacts);
        self.collisions.observe(&self.data, self.data.time());
        self.record(0);
    }

    /// Physics steps that bring the simulated time up to the commanded time plus `dt`
    /// (`dt` need not be a multiple of the time step: the remainder carries over).
    fn substeps(&mut self, dt: f64) -> Result<usize, MujocoError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(MujocoError::BadTimeStep(dt));
        }
        self.commanded_time += dt;
        let behind = (self.commanded_time - self.data.time()) / self.options.timestep;
        // The tolerance absorbs rounding in the two accumulated clocks.
        Ok((behind + 1e-6).floor().max(0.0) as usize)
    }

    fn check_command(&self, field: &'static str, values: &[f64]) -> Result<(), MujocoError> {
        Ok(check_joint_vector(&self.robot.model, field, values)?)
    }

    fn fatal_warning_count(&self) -> i64 {
        let warnings = self.data.warning();
        FATAL_WARNINGS
            .iter()
            .map(|&w| i64::from(warnings[w as usize].number))
            .sum()
    }

    /// Fills the measurement and the safety record from the evaluated state.
    fn record(&mut self, limit_violations: usize) {
        let qpos = self.data.qpos();
        let qvel = self.data.qvel();
        let m = &mut self.measurement;
        for (j, (&qa, &da)) in self
            .layout
            .joint_qpos
            .iter()
            .zip(&self.layout.joint_dof)
            .enumerate()
        {
            m.q[j] = qpos[qa];
            m.qd[j] = qvel[da];
        }
        let b = self.layout.base_qpos;
        m.base = Isometry3::from_parts(
            Translation3::new(qpos[b], qpos[b + 1], qpos[b + 2]),
            UnitQuaternion::from_quaternion(Quaternion::new(
                qpos[b + 3],
                qpos[b + 4],
                qpos[b + 5],
                qpos[b + 6],
            )),
        );
        let s = self.data.sensordata();
        let imu = &s[mjcf::IMU_QUAT];
        m.base_orientation =
            UnitQuaternion::from_quaternion(Quaternion::new(imu[0], imu[1], imu[2], imu[3]));
        m.com = Vector3::from(self.data.subtree_com()[self.layout.base_body]);
        m.wrenches = self.contacts.wrenches;
        m.contacts = self.contacts.touching;
        let safety = self.safety(limit_violations);
        self.measurement.safety = safety;
        let fell = self.has_fallen();
        let summary = &mut self.summary;
        summary.min_stability_margin = summary.min_stability_margin.min(safety.stability_margin);
        summary.max_contact_slip = summary.max_contact_slip.max(safety.contact_slip);
        summary.max_penetration = summary.max_penetration.max(safety.penetration);
        summary.joint_limit_violations += limit_violations as u64;
        summary.fell |= fell;
    }

    /// Support-polygon margin, slip of feet in contact since touchdown, penetration.
    fn safety(&mut self, limit_violations: usize) -> SafetyMetrics {
        let mut corners = [[0.0; 2]; 8];
        let mut count = 0;
        let mut slip: f64 = 0.0;
        for (slot, foot) in FEET.iter().enumerate() {
            if !self.contacts.touching[slot] {
                self.anchors[slot] = None;
                continue;
            }
            let sole = self.end_effector_pose(*foot);
            let anchor = *self.anchors[slot].get_or_insert(sole);
            slip = slip.max(
                (sole.translation.vector - anchor.translation.vector)
                    .xy()
                    .norm(),
            );
            for corner in sole_corners(&sole, &self.robot.sole) {
                corners[count] = [corner.x, corner.y];
                count += 1;
            }
        }
        self.polygon.set_hull(&corners[..count]);
        let com = self.measurement.com;
        SafetyMetrics {
            stability_margin: self.polygon.signed_distance([com.x, com.y]),
            contact_slip: slip,
            penetration: self.contacts.penetration,
            limit_violations,
        }
    }
}

impl crate::MotorLoad for MujocoSim {
    /// How hard the motors have worked since the start, against the URDF's limits.
    fn actuator_load(&self) -> shm_types::ActuatorLoad {
        *self.actuators.load()
    }
}

impl crate::TerrainContacts for MujocoSim {
    /// [`MujocoSim::terrain_collisions`]' count (0 on the flat floor).
    fn terrain_collision_count(&self) -> u64 {
        self.terrain_collisions().count
    }
}

impl Layout {
    fn resolve(model: &MjModel, robot: &Robot, bodies: &RigidBodies) -> Result<Self, MujocoError> {
        let id = |kind: MjtObjBase, name: &str| {
            model.name_to_id(kind, name).ok_or_else(|| {
                MujocoError::Compile(format!(
                    "the generated model has no {kind:?} named '{name}'"
                ))
            })
        };
        let qpos_addresses = model.jnt_qposadr();
        let dof_addresses = model.jnt_dofadr();
        let mut joint_qpos = Vec::with_capacity(robot.model.dof());
        let mut joint_dof = Vec::with_capacity(robot.model.dof());
        for name in robot.model.joint_names() {
            let joint = id(MjtObjBase::mjOBJ_JOINT, name)?;
            joint_qpos.push(qpos_addresses[joint] as usize);
            joint_dof.push(dof_addresses[joint] as usize);
        }
        let free = id(MjtObjBase::mjOBJ_JOINT, mjcf::FREE_JOINT)?;
        let base_body = id(MjtObjBase::mjOBJ_BODY, &bodies.bodies[0].name)?;
        let mut effector_sites = [0; 4];
        for effector in EndEffector::ALL {
            effector_sites[effector as usize] =
                id(MjtObjBase::mjOBJ_SITE, mjcf::end_effector_site(effector))?;
        }
        let mut contacts = ContactIds {
            geoms: [0; 4],
            ft_sites: [0; 4],
        };
        for effector in 0..4 {
            contacts.geoms[effector] = id(MjtObjBase::mjOBJ_GEOM, mjcf::CONTACT_GEOMS[effector])?;
            contacts.ft_sites[effector] = id(MjtObjBase::mjOBJ_SITE, mjcf::FT_SITES[effector])?;
        }
        let base_link_name = robot.model.link_name(robot.base_link);
        let base_link = bodies.links.get(base_link_name).ok_or_else(|| {
            MujocoError::ModelMismatch(format!(
                "base link '{base_link_name}' is not a link of the URDF"
            ))
        })?;
        Ok(Self {
            joint_qpos,
            joint_dof,
            base_body,
            base_qpos: qpos_addresses[free] as usize,
            effector_sites,
            contacts,
            base_link_body: id(MjtObjBase::mjOBJ_BODY, &bodies.bodies[base_link.body].name)?,
            base_link_offset: base_link.offset,
        })
    }
}

fn check_library_version() -> Result<(), MujocoError> {
    let found = mujoco_rs::mujoco_version();
    if found != MUJOCO_VERSION {
        return Err(MujocoError::LibraryVersion {
            found: found.to_owned(),
            expected: MUJOCO_VERSION,
        });
    }
    Ok(())
}

/// The servos track `q_des` (clamped into the joint limits, each clamp counted as a violation)
/// and `qd_des`; a step runs the physics steps that fit in `dt` and carries the remainder into
/// the next call (a call with no step due leaves the measurement as it was). The measurement is
/// the same record as the kinematic simulator's: joint `q`/`q̇`, foot FT wrenches (hands read
/// zero: only the floor is modelled), the IMU orientation, and the true base pose, CoM and
/// contacts; the summary's `fell` is set by [`MujocoSim::has_fallen`]'s rule.
impl Simulator for MujocoSim {
    type Error = MujocoError;

    fn robot(&self) -> &Arc<Robot> {
        &self.robot
    }

    fn step(&mut self, q_des: &[f64], qd_des: &[f64], dt: f64) -> Result<(), MujocoError> {
        self.check_command("q_des", q_des)?;
        self.check_command("qd_des", qd_des)?;
        let substeps = self.substeps(dt)?;
        let mut violations = 0;
        let limits = self.robot.model.joint_limits();
        let ctrl = self.data.ctrl_mut();
        for (j, ((&q, &qd), limit)) in q_des.iter().zip(qd_des).zip(limits).enumerate() {
            let target = q.clamp(limit.lower, limit.upper);
            violations += usize::from(target != q);
            // The servo's reference moves no faster than the motor's rated speed.
            let (from, reach) = (ctrl[2 * j], limit.velocity * dt);
            self.servo_ramps[j] = (from, target.clamp(from - reach, from + reach));
            ctrl[2 * j + 1] = qd.clamp(-limit.velocity, limit.velocity);
        }
        let warnings_before = self.fatal_warning_count();
        let mut period = Contacts::default();
        for substep in 0..substeps {
            // The servo drive ramps its position reference over the command period (a
            // first-order hold) rather than jumping at its start: with kp 1e5 N·m/rad a jump of
            // a milliradian is 100 N·m for one physics step.
            let along = (substep + 1) as f64 / substeps as f64;
            let ctrl = self.data.ctrl_mut();
            for (j, &(from, to)) in self.servo_ramps.iter().enumerate() {
                ctrl[2 * j] = from + (to - from) * along;
            }
            // Forward dynamics of the current state, the constraint solve and the integration.
            let time = self.data.time();
            self.data.step2();
            let (torques, speeds) = (self.data.qfrc_actuator(), self.data.qvel());
            let dofs = &self.layout.joint_dof;
            self.actuators.observe(
                dofs.iter().map(|&d| torques[d]),
                dofs.iter().map(|&d| speeds[d]),
                self.options.timestep,
            );
            // The contact list, solved forces and poses still describe the same state here.
            self.collisions.observe(&self.data, time);
            if self.options.average_ft_over_step {
                let reading = contact::read(&self.data, &self.layout.contacts);
                period.add(&reading, 1.0 / substeps as f64);
            } else if substep + 1 == substeps {
                self.contacts = contact::read(&self.data, &self.layout.contacts);
            }
            // Kinematics, collisions and position/velocity sensors of the new state.
            self.data.step1();
        }
        if self.options.average_ft_over_step && substeps > 0 {
            self.contacts = period;
        }
        if substeps == 0 {
            return Ok(());
        }
        if self.fatal_warning_count() != warnings_before {
            return Err(MujocoError::Unstable {
                time: self.data.time(),
            });
        }
        self.record(violations);
        self.summary.steps += 1;
        Ok(())
    }

    fn measurement(&self) -> &SimMeasurement {
        &self.measurement
    }

    fn summary(&self) -> &SafetySummary {
        &self.summary
    }

    fn end_effector_pose(&self, effector: EndEffector) -> Isometry3<f64> {
        let site = self.layout.effector_sites[effector as usize];
        let position = Vector3::from(self.data.site_xpos()[site]);
        let rotation =
            Rotation3::from_matrix_unchecked(Matrix3::from_row_slice(&self.data.site_xmat()[site]));
        Isometry3::from_parts(
            Translation3::from(position),
            UnitQuaternion::from_rotation_matrix(&rotation),
        )
    }

    fn base_link_pose(&self) -> Isometry3<f64> {
        let body = self.layout.base_link_body;
        let [x, y, z] = self.data.xpos()[body];
        let [w, i, j, k] = self.data.xquat()[body];
        let pose = Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_quaternion(Quaternion::new(w, i, j, k)),
        );
        pose * self.layout.base_link_offset
    }

    fn time(&self) -> f64 {
        self.data.time()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// Lowest point of each leg capsule above the lower sole, standing in the configured posture
    /// on the flat ground of the railing scene (m).
    fn leg_clearances(name: &str) -> Vec<f64> {
        let configs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs");
        let robot = Arc::new(Robot::load(&configs.join(format!("{name}.toml")), None).unwrap());
        let scene = stance::Scene::from_path(&configs.join("scenes/railing.toml")).unwrap();
        let terrain = Terrain::from_scene(&scene).unwrap();
        let (urdf, initial) = (robot.urdf.clone(), terrain.place(&robot.standing));
        let sim = MujocoSim::on_terrain(robot, &urdf, &initial, MujocoOptions::default(), terrain)
            .unwrap();
        let sole = FEET
            .map(|foot| sim.end_effector_pose(foot).translation.z)
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        let (model, data) = (sim.model(), &sim.data);
        (0..model.ngeom() as usize)
            .filter(|&g| sim.collisions.is_leg(g))
            .map(|g| {
                // A capsule's axis is its frame's z; size = (radius, half length).
                let [radius, half, _] = model.geom_size()[g];
                let axis_z = data.geom_xmat()[g][8];
                data.geom_xpos()[g][2] - axis_z.abs() * half - radius - sole
            })
            .collect()
    }

    #[test]
    fn standing_legs_clear_the_ground() {
        for (name, expected) in [("jvrc1", 0.0677), ("armar4", 0.0269)] {
            let clearances = leg_clearances(name);
            assert_eq!(clearances.len(), 4, "{name}: two bones a leg");
            let lowest = clearances.iter().copied().fold(f64::INFINITY, f64::min);
            assert!((lowest - expected).abs() < 1e-3, "{name}: {clearances:?}");
        }
    }
}
