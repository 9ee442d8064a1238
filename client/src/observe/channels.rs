//! The observer's Foxglove channels: one per topic, created on a [`foxglove::Context`] whose sinks
//! (an MCAP file, a WebSocket server) receive whatever is logged. `docs/observe.md` lists every
//! topic with its schema, rate and units.
//!
//! Every message is stamped (and logged at) the time of what it shows, on the Unix clock:
//! sensor-derived and per-tick channels at the answered sample's time stamp, commands at their
//! send time, statuses at their assembly time ([`Clock`] maps walkd's monotonic clock).

use std::sync::Arc;

use foxglove::messages::{
    FrameTransform, FrameTransforms, JointState, JointStates, Log, Pose, PoseInFrame, PosesInFrame,
    Quaternion, SceneUpdate, Timestamp, Vector3,
};
use foxglove::{Channel, Context, RawChannel, Schema};
use kinematics::robot::Robot;
use nalgebra::{Isometry3, Quaternion as NaQuaternion, Translation3, UnitQuaternion};
use shm_types::{CommandMode, DaemonStatus, JointCommand, SensorSample, Telemetry, WRENCH_ORDER};

use super::links::{LinkPoser, WORLD_FRAME};
use super::scene;
use super::schemas::{
    WalkCommandInfo, WalkLatency, WalkStatus, WalkTick, WalkWrench, WalkWrenches,
};

/// Topic names.
pub mod topic {
    /// The robot's URDF (primitive shapes, no meshes).
    pub const ROBOT_DESCRIPTION: &str = "/robot_description";
    /// A transform per link and configured frame.
    pub const TF: &str = "/tf";
    /// Measured joint angles and velocities.
    pub const JOINT_STATES: &str = "/joint_states";
    /// Commanded joint angles and velocities.
    pub const JOINT_COMMANDS: &str = "/joint_commands";
    /// Sequence number, answered sample and mode of each command.
    pub const COMMAND_INFO: &str = "/joint_commands/info";
    /// The four measured wrenches.
    pub const WRENCHES: &str = "/wrenches";
    /// The controller's tick: state, phase, stance, contacts, CoM target, ZMP/DCM, timing.
    pub const TICK: &str = "/controller/tick";
    /// Estimated floating-base pose.
    pub const BASE: &str = "/controller/base";
    /// Estimated centre of mass.
    pub const COM: &str = "/controller/com";
    /// Estimated end-effector poses.
    pub const END_EFFECTORS: &str = "/controller/end_effectors";
    /// End-effector targets.
    pub const TARGETS: &str = "/controller/targets";
    /// Support polygon, CoM projection and target, ZMP and DCM, drawn.
    pub const SCENE_BALANCE: &str = "/scene/balance";
    /// End-effector targets, drawn.
    pub const SCENE_TARGETS: &str = "/scene/targets";
    /// Foot and hand forces, drawn as arrows.
    pub const SCENE_WRENCHES: &str = "/scene/wrenches";
    /// walkd's status.
    pub const STATUS: &str = "/status";
    /// Faults and state changes.
    pub const FAULTS: &str = "/faults";
}

const _: () = assert!(SCENE_DECIMATION % TF_DECIMATION == 0);

/// The drawn `/scene/*` channels carry one message per this many ticks (50 Hz at 500 Hz).
pub const SCENE_DECIMATION: u64 = 10;

/// `/tf` carries one message per this many ticks (100 Hz at 500 Hz): enough for a viewer, which
/// interpolates, at a fifth of the size (the joint angles themselves are on `/joint_states` at
/// every sample).
pub const TF_DECIMATION: u64 = 5;

/// The JSON schema of `std_msgs/String`, the schema Foxglove's URDF layer reads a robot
/// description from.
const STRING_SCHEMA: &str =
    r#"{"type":"object","properties":{"data":{"type":"string"}},"required":["data"]}"#;

/// Converts walkd's [`shm_types::monotonic_ns`] time stamps to Unix time (ns).
#[derive(Debug, Clone, Copy)]
pub struct Clock {
    offset_ns: i128,
}

impl Clock {
    /// Reads both clocks now.
    pub fn now() -> Self {
        let unix = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos() as i128);
        Self {
            offset_ns: unix - i128::from(shm_types::monotonic_ns()),
        }
    }

    /// The Unix time of a monotonic time stamp (ns).
    pub fn unix_ns(&self, monotonic_ns: u64) -> u64 {
        (i128::from(monotonic_ns) + self.offset_ns).max(0) as u64
    }
}

/// A Foxglove timestamp of `unix_ns`.
pub fn timestamp(unix_ns: u64) -> Timestamp {
    Timestamp::new(
        (unix_ns / 1_000_000_000) as u32,
        (unix_ns % 1_000_000_000) as u32,
    )
}

/// A pose `[x, y, z, qx, qy, qz, qw]` as an isometry.
pub fn isometry(pose: &[f64; 7]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(pose[0], pose[1], pose[2]),
        UnitQuaternion::from_quaternion(NaQuaternion::new(pose[6], pose[3], pose[4], pose[5])),
    )
}

/// A Foxglove pose of an isometry.
pub fn pose(pose: &Isometry3<f64>) -> Pose {
    let t = pose.translation.vector;
    let q = pose.rotation.coords;
    Pose {
        position: Some(Vector3 {
            x: t.x,
            y: t.y,
            z: t.z,
        }),
        orientation: Some(Quaternion {
            x: q.x,
            y: q.y,
            z: q.z,
            w: q.w,
        }),
    }
}

/// A Foxglove vector of (x, y, z).
pub fn vector(x: f64, y: f64, z: f64) -> Vector3 {
    Vector3 { x, y, z }
}

/// Every channel of the observer.
pub struct Channels {
    description: Arc<RawChannel>,
    tf: Channel<FrameTransforms>,
    joint_states: Channel<JointStates>,
    joint_commands: Channel<JointStates>,
    command_info: Channel<WalkCommandInfo>,
    wrenches: Channel<WalkWrenches>,
    tick: Channel<WalkTick>,
    base: Channel<PoseInFrame>,
    com: Channel<PoseInFrame>,
    end_effectors: Channel<PosesInFrame>,
    targets: Channel<PosesInFrame>,
    scene_balance: Channel<SceneUpdate>,
    scene_targets: Channel<SceneUpdate>,
    scene_wrenches: Channel<SceneUpdate>,
    status: Channel<WalkStatus>,
    faults: Channel<Log>,
    joint_names: Vec<String>,
    robot: Arc<Robot>,
    clock: Clock,
}

impl Channels {
    /// Creates the channels on `context` for `robot`.
    pub fn new(context: &Arc<Context>, robot: Arc<Robot>, clock: Clock) -> anyhow::Result<Self> {
        let description = context
            .channel_builder(topic::ROBOT_DESCRIPTION)
            .message_encoding("json")
            .schema(Schema::new(
                "std_msgs/String",
                "jsonschema",
                STRING_SCHEMA.as_bytes(),
            ))
            .build_raw()?;
        Ok(Self {
            description,
            tf: context.channel_builder(topic::TF).build(),
            joint_states: context.channel_builder(topic::JOINT_STATES).build(),
            joint_commands: context.channel_builder(topic::JOINT_COMMANDS).build(),
            command_info: context.channel_builder(topic::COMMAND_INFO).build(),
            wrenches: context.channel_builder(topic::WRENCHES).build(),
            tick: context.channel_builder(topic::TICK).build(),
            base: context.channel_builder(topic::BASE).build(),
            com: context.channel_builder(topic::COM).build(),
            end_effectors: context.channel_builder(topic::END_EFFECTORS).build(),
            targets: context.channel_builder(topic::TARGETS).build(),
            scene_balance: context.channel_builder(topic::SCENE_BALANCE).build(),
            scene_targets: context.channel_builder(topic::SCENE_TARGETS).build(),
            scene_wrenches: context.channel_builder(topic::SCENE_WRENCHES).build(),
            status: context.channel_builder(topic::STATUS).build(),
            faults: context.channel_builder(topic::FAULTS).build(),
            joint_names: robot.model.joint_names().to_vec(),
            robot,
            clock,
        })
    }

    /// The clock the channels stamp with.
    pub fn clock(&self) -> Clock {
        self.clock
    }

    /// Logs the robot description (`urdf`) at `unix_ns`.
    pub fn log_description(&self, urdf: &str, unix_ns: u64) {
        let message = serde_json::json!({ "data": urdf }).to_string();
        self.description.log_with_meta(
            message.as_bytes(),
            foxglove::PartialMetadata::with_log_time(unix_ns),
        );
    }

    /// Logs a sensor sample: joint states and wrenches.
    pub fn log_sample(&self, sample: &SensorSample) {
        let t = self.clock.unix_ns(sample.timestamp_ns);
        self.joint_states
            .log_with_time(&self.joints(t, sample.q(), sample.qd()), t);
        let wrenches = WRENCH_ORDER
            .iter()
            .zip(&sample.wrenches)
            .map(|(name, w)| WalkWrench {
                end_effector: (*name).to_owned(),
                force: vector(w[0], w[1], w[2]),
                torque: vector(w[3], w[4], w[5]),
            })
            .collect();
        let message = WalkWrenches {
            timestamp: timestamp(t),
            sample_seq: sample.seq,
            wrenches,
        };
        self.wrenches.log_with_time(&message, t);
    }

    /// Logs a joint command.
    pub fn log_command(&self, command: &JointCommand) {
        let t = self.clock.unix_ns(command.timestamp_ns);
        self.joint_commands
            .log_with_time(&self.joints(t, command.q_des(), command.qd_des()), t);
        let mode = command.mode.get().map_or("invalid", CommandMode::name);
        let info = WalkCommandInfo {
            timestamp: timestamp(t),
            seq: command.seq,
            answers_seq: command.answers_seq,
            mode: mode.to_owned(),
        };
        self.command_info.log_with_time(&info, t);
    }

    fn joints(&self, t: u64, q: &[f64], qd: &[f64]) -> JointStates {
        JointStates {
            timestamp: Some(timestamp(t)),
            joints: self
                .joint_names
                .iter()
                .zip(q.iter().zip(qd))
                .map(|(name, (&position, &velocity))| JointState {
                    name: name.clone(),
                    position: Some(position),
                    velocity: Some(velocity),
                    ..Default::default()
                })
                .collect(),
        }
    }

    /// Logs a tick's telemetry; `sample` is the sample it answered, if the observer has it (then
    /// the link transforms are logged too, posed by `poser`).
    pub fn log_tick(
        &self,
        telemetry: &Telemetry,
        sample: Option<&SensorSample>,
        poser: &mut LinkPoser,
    ) -> anyhow::Result<()> {
        let t = self.clock.unix_ns(telemetry.sample_timestamp_ns);
        let stamp = timestamp(t);
        let base = isometry(&telemetry.base);
        if let Some(sample) = sample.filter(|_| telemetry.seq % TF_DECIMATION == 0) {
            let mut transforms = Vec::with_capacity(self.robot.model.link_count() + 6);
            poser.pose(sample.q(), &base, |edge| {
                let p = pose(&edge.pose);
                transforms.push(FrameTransform {
                    timestamp: Some(stamp),
                    parent_frame_id: edge.parent.to_owned(),
                    child_frame_id: edge.child.to_owned(),
                    translation: p.position,
                    rotation: p.orientation,
                });
            })?;
            self.tf.log_with_time(&FrameTransforms { transforms }, t);
        }
        self.tick.log_with_time(&tick_message(telemetry, stamp), t);
        let in_world = |p: Pose| PoseInFrame {
            timestamp: Some(stamp),
            frame_id: WORLD_FRAME.to_owned(),
            pose: Some(p),
        };
        self.base.log_with_time(&in_world(pose(&base)), t);
        let com = &telemetry.com;
        let com_pose = Isometry3::translation(com[0], com[1], com[2]);
        self.com.log_with_time(&in_world(pose(&com_pose)), t);
        let poses = |all: &[[f64; 7]; 4]| PosesInFrame {
            timestamp: Some(stamp),
            frame_id: WORLD_FRAME.to_owned(),
            poses: all.iter().map(|p| pose(&isometry(p))).collect(),
        };
        self.end_effectors
            .log_with_time(&poses(&telemetry.end_effectors), t);
        self.targets.log_with_time(&poses(&telemetry.targets), t);
        if telemetry.seq % SCENE_DECIMATION == 0 {
            self.scene_balance
                .log_with_time(&scene::balance(telemetry, stamp), t);
            self.scene_targets
                .log_with_time(&scene::targets(telemetry, &self.robot, stamp), t);
            if let Some(sample) = sample {
                // SCENE_DECIMATION is a multiple of TF_DECIMATION: the poser holds this sample's
                // posture (posed for the transforms above).
                let origins = self
                    .robot
                    .ft_sensors
                    .map(|frame| poser.frame_pose(frame).translation.vector);
                let weight = self.robot.model.total_mass() * GRAVITY;
                self.scene_wrenches
                    .log_with_time(&scene::wrenches(sample, origins, weight, stamp), t);
            }
        }
        Ok(())
    }

    /// Logs a status.
    pub fn log_status(&self, status: &DaemonStatus) {
        let t = self.clock.unix_ns(status.timestamp_ns);
        let latency = |s: &shm_types::LatencySummary| WalkLatency {
            p50: f64::from(s.p50),
            p99: f64::from(s.p99),
            max: f64::from(s.max),
        };
        let message = WalkStatus {
            timestamp: timestamp(t),
            state: status.state.name().to_owned(),
            sequence_id: status.sequence_id,
            stance_index: status.stance_index,
            stance_count: status.stance_count,
            phase: status.phase.as_str().to_owned(),
            fault: status.fault.as_str().to_owned(),
            link: status.link.name().to_owned(),
            rate_hz: status.rate_hz,
            ticks: status.ticks,
            deadline_misses: status.deadline_misses,
            stale_periods: status.stale_periods,
            watchdog_trips: status.watchdog_trips,
            tick_us: latency(&status.tick_us),
            latency_us: latency(&status.latency_us),
            jitter_us: latency(&status.jitter_us),
        };
        self.status.log_with_time(&message, t);
    }

    /// Logs a line on `/faults` at `unix_ns`.
    pub fn log_fault(&self, level: foxglove::messages::log::Level, message: String, unix_ns: u64) {
        let log = Log {
            timestamp: Some(timestamp(unix_ns)),
            level: level as i32,
            message,
            name: "walkd".to_owned(),
            ..Default::default()
        };
        self.faults.log_with_time(&log, unix_ns);
    }
}

/// Standard gravity (m/s²), for scaling force arrows by the robot's weight.
const GRAVITY: f64 = 9.81;

/// The `/controller/tick` message of a telemetry.
fn tick_message(telemetry: &Telemetry, stamp: Timestamp) -> WalkTick {
    let flags = |flags: &[shm_types::Flag; 4]| flags.iter().map(|f| f.is_set()).collect();
    let planar = |p: &[f64; 2]| vector(p[0], p[1], 0.0);
    let commanded = telemetry.command_seq != 0;
    WalkTick {
        timestamp: stamp,
        telemetry_seq: telemetry.seq,
        tick: telemetry.tick,
        sample_seq: telemetry.sample_seq,
        command_seq: telemetry.command_seq,
        state: telemetry.state.name().to_owned(),
        phase: telemetry.phase.name().to_owned(),
        stance_index: telemetry.stance_index,
        stance_count: telemetry.stance_count,
        contacts: flags(&telemetry.contacts),
        target_set: flags(&telemetry.target_set),
        com_target_set: telemetry.com_target_set.is_set(),
        com_target: planar(&telemetry.com_target),
        dynamics_valid: telemetry.dynamics_valid.is_set(),
        zmp_reference: planar(&telemetry.zmp_reference),
        zmp_measured: planar(&telemetry.zmp_measured),
        dcm_reference: planar(&telemetry.dcm_reference),
        dcm_measured: planar(&telemetry.dcm_measured),
        phase_duration_s: telemetry.phase_duration_s,
        phase_timing: telemetry.phase_timing.name().to_owned(),
        hand_forces_desired: telemetry.hand_forces_desired.to_vec(),
        compute_us: telemetry.compute_ns as f64 / 1e3,
        latency_us: if commanded {
            telemetry
                .sent_ns
                .saturating_sub(telemetry.sample_timestamp_ns) as f64
                / 1e3
        } else {
            0.0
        },
        deadline_misses: telemetry.deadline_misses,
    }
}
