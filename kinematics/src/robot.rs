//! A robot = a model plus what the `[robot]` section of `configs/<robot>.toml` says about it:
//! end-effector frames, sole size, FT sensor frames, joint groups and the standing posture.
//!
//! The section (every key required unless marked optional; unknown keys are errors):
//! ```toml
//! [robot]
//! name = "jvrc1"
//! urdf = "robots/jvrc1/jvrc1.urdf"      # optional, relative to the TOML; `--urdf` overrides
//! base_link = "PELVIS_S"
//! sole = { length = 0.20, width = 0.08 }
//!
//! [robot.frames]                          # link + translation + rpy (the pose in the link frame)
//! left_foot = { link = "L_ANKLE_P_S", translation = [0.03, 0.0, -0.1077], rpy = [0.0, 0.0, 0.0] }
//! # right_foot, left_hand, right_hand likewise
//!
//! palm_radius = 0.04                     # optional, default half the sole width
//!
//! [robot.ft_sensors]
//! left = { link = "lfsensor" }            # translation / rpy default to zero
//! right = { link = "rfsensor" }
//! left_hand = { link = "lhsensor" }       # optional wrist sensors; default: the origin of the
//! right_hand = { link = "rhsensor" }      # link the hand's frame is on (its wrist)
//!
//! [robot.joint_groups]
//! legs = ["R_HIP_P", ...]
//! arms = [...]
//! torso = [...]
//! head = [...]
//!
//! [robot.standing]                        # joint name → angle; joints not named are 0
//! R_KNEE = 0.6
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;

use crate::bounds::{Bound, Number, Range, first_outside};
use crate::config_file::{ConfigFile, ConfigFileError, toml_message};
use crate::configuration::Configuration;
use crate::kinematics::Kinematics;
use crate::model::{FrameId, LinkId, Model, ModelError, pose_from_xyz_rpy};

/// The four end-effectors a stance can put in contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EndEffector {
    /// Left sole.
    LeftFoot = 0,
    /// Right sole.
    RightFoot = 1,
    /// Left palm.
    LeftHand = 2,
    /// Right palm.
    RightHand = 3,
}

impl EndEffector {
    /// All end-effectors, in index order.
    pub const ALL: [EndEffector; 4] = [
        EndEffector::LeftFoot,
        EndEffector::RightFoot,
        EndEffector::LeftHand,
        EndEffector::RightHand,
    ];

    /// The hands, left then right.
    pub const HANDS: [EndEffector; 2] = [EndEffector::LeftHand, EndEffector::RightHand];

    /// The config key and frame name (`left_foot`, `right_foot`, `left_hand`, `right_hand`).
    pub fn name(self) -> &'static str {
        match self {
            EndEffector::LeftFoot => "left_foot",
            EndEffector::RightFoot => "right_foot",
            EndEffector::LeftHand => "left_hand",
            EndEffector::RightHand => "right_hand",
        }
    }

    /// Whether this is a foot.
    pub fn is_foot(self) -> bool {
        matches!(self, EndEffector::LeftFoot | EndEffector::RightFoot)
    }
}

/// Sole contact rectangle, centred on the sole frame origin, x forward, y left, in the sole
/// frame's xy plane (the sole frame sits on the sole surface, z up when standing flat).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SoleRectangle {
    /// Extent along the sole frame's x axis (m).
    pub length: f64,
    /// Extent along the sole frame's y axis (m).
    pub width: f64,
}

impl SoleRectangle {
    /// The `[robot] sole` table: each extent, its value and its range (docs/kinematics.md).
    pub fn bounds(&self) -> [Bound; 2] {
        [
            Bound::new("sole.length", self.length, 0.01, 1.0),
            Bound::new("sole.width", self.width, 0.01, 1.0),
        ]
    }
}

/// Joint indices (model order) of each body part, for posture tasks and stance retargeting.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointGroups {
    /// Both legs.
    pub legs: Vec<usize>,
    /// Both arms (including hands).
    pub arms: Vec<usize>,
    /// Waist / chest.
    pub torso: Vec<usize>,
    /// Neck and head.
    pub head: Vec<usize>,
}

impl JointGroups {
    /// The groups with their `[robot.joint_groups]` keys, in one fixed order (legs, arms, torso,
    /// head): the order of per-group arrays such as the simulator's actuator load.
    pub fn named(&self) -> [(&'static str, &[usize]); 4] {
        [
            ("legs", &self.legs),
            ("arms", &self.arms),
            ("torso", &self.torso),
            ("head", &self.head),
        ]
    }
}

/// Names of the FT sensor frames added to the model.
pub const FT_SENSOR_FRAMES: [&str; 2] = ["left_ft_sensor", "right_ft_sensor"];

/// Names of the wrist FT sensor frames added to the model.
pub const WRIST_FT_SENSOR_FRAMES: [&str; 2] = ["left_wrist_ft_sensor", "right_wrist_ft_sensor"];

/// The palm's radius when the config gives none, as a fraction of the sole width (0.04 m on
/// JVRC-1, 0.062 m on ARMAR-4; kept within the range of `[robot] palm_radius`): a hand about
/// as wide as half its foot.
pub const PALM_RADIUS_PER_SOLE_WIDTH: f64 = 0.5;

/// The range of `[robot] palm_radius` (m).
const PALM_RADIUS_M: Range = Range::new(0.005, 0.2);

/// A model with its configured frames and standing posture.
#[derive(Debug, Clone)]
pub struct Robot {
    /// Robot name from the config.
    pub name: String,
    /// The URDF file the model was loaded from (physics back-ends need what the kinematic model
    /// does not keep, such as inertia tensors).
    pub urdf: PathBuf,
    /// The kinematic model, with the end-effector and FT sensor frames added.
    pub model: Model,
    /// The link the config calls the floating base (for base orientation tasks).
    pub base_link: LinkId,
    /// End-effector frames, indexed by `EndEffector as usize`.
    pub end_effectors: [FrameId; 4],
    /// Sole contact rectangle (both feet).
    pub sole: SoleRectangle,
    /// FT sensor frames: left foot, right foot.
    pub ft_sensors: [FrameId; 2],
    /// Wrist FT sensor frames, where a hand's contact wrench is measured: left hand, right hand.
    pub wrist_ft_sensors: [FrameId; 2],
    /// Radius (m) of the sphere centred on each hand frame that touches a railing: where a
    /// grasp puts the hand frame (on top of the rail) and the hand's collision geometry.
    pub palm_radius: f64,
    /// Joint groups.
    pub joint_groups: JointGroups,
    /// Standing posture: both soles flat on z = 0, their midpoint at x = y = 0.
    pub standing: Configuration,
}

/// Why a robot config cannot be loaded; each variant names the file and key.
#[derive(Debug, thiserror::Error)]
pub enum RobotError {
    /// The config file could not be read or parsed.
    #[error(transparent)]
    File(#[from] ConfigFileError),
    /// The `[robot]` section is missing or does not match the schema.
    #[error("{path}: invalid [robot] section: {message}")]
    Schema {
        /// The file.
        path: PathBuf,
        /// The parser's message (names the key, line and column).
        message: String,
    },
    /// Neither the config nor the caller gives a URDF.
    #[error(
        "{path}: robot '{robot}' has no `urdf` key in [robot] (its model is not distributed with \
         this project); pass the model with `--urdf PATH` or set `urdf` in the config"
    )]
    MissingUrdf {
        /// The config file.
        path: PathBuf,
        /// The robot name.
        robot: String,
    },
    /// The URDF is invalid.
    #[error("{urdf}: {error}")]
    Model {
        /// The URDF file.
        urdf: PathBuf,
        /// What is wrong with it.
        error: ModelError,
    },
    /// A key names a link the model does not have.
    #[error("{path}: robot.{key}: link '{name}' is not in the model")]
    UnknownLink {
        /// The config file.
        path: PathBuf,
        /// The key.
        key: String,
        /// The missing link.
        name: String,
    },
    /// A key names a joint the model does not have (or a fixed/mimic joint).
    #[error("{path}: robot.{key}: joint '{name}' is not an actuated joint of the model")]
    UnknownJoint {
        /// The config file.
        path: PathBuf,
        /// The key.
        key: String,
        /// The missing joint.
        name: String,
    },
    /// A value is out of range.
    #[error("{path}: robot.{key}: {message}")]
    Invalid {
        /// The config file.
        path: PathBuf,
        /// The key.
        key: String,
        /// What is wrong.
        message: String,
    },
}

/// A frame declared in the config: link + pose in the link frame.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameSpec {
    link: String,
    #[serde(default)]
    translation: [f64; 3],
    #[serde(default)]
    rpy: [f64; 3],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct EndEffectorSpecs {
    left_foot: FrameSpec,
    right_foot: FrameSpec,
    left_hand: FrameSpec,
    right_hand: FrameSpec,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct FtSensorSpecs {
    left: FrameSpec,
    right: FrameSpec,
    left_hand: Option<FrameSpec>,
    right_hand: Option<FrameSpec>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct JointGroupSpecs {
    legs: Vec<String>,
    arms: Vec<String>,
    torso: Vec<String>,
    head: Vec<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RobotSection {
    name: String,
    urdf: Option<PathBuf>,
    base_link: String,
    sole: SoleRectangle,
    palm_radius: Option<f64>,
    frames: EndEffectorSpecs,
    ft_sensors: FtSensorSpecs,
    joint_groups: JointGroupSpecs,
    standing: BTreeMap<String, f64>,
}

/// Each coordinate of a configured frame's offset from its link (m): a robot's frames sit on it.
const FRAME_OFFSET_M: Range = Range::new(-10.0, 10.0);

/// Each roll, pitch and yaw of a configured frame (rad): a turn either way.
const FRAME_ANGLE_RAD: Range = Range::new(-std::f64::consts::TAU, std::f64::consts::TAU);

/// Soles count as flat when their normals are within this angle (rad) of vertical and their
/// heights agree to this distance (m).
const FLAT_TOLERANCE: f64 = 1e-6;

impl Robot {
    /// The robot of `configs/<name>.toml` in this source tree (its vendored model), for the
    /// workspace's tests and benches; panics if it does not load.
    pub fn vendored(name: &str) -> Robot {
        let config = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../configs")
            .join(format!("{name}.toml"));
        Self::load(&config, None)
            .unwrap_or_else(|e| panic!("vendored robot {}: {e}", config.display()))
    }

    /// Loads the config file at `config`, then the robot from it (see [`Robot::from_config`]).
    pub fn load(config: &Path, urdf_override: Option<&Path>) -> Result<Robot, RobotError> {
        Self::from_config(&ConfigFile::load(config)?, urdf_override)
    }

    /// The robot of `file`'s `[robot]` section and its model (`urdf_override` wins over the
    /// section's `urdf`; a relative path is taken relative to the config file).
    pub fn from_config(
        file: &ConfigFile,
        urdf_override: Option<&Path>,
    ) -> Result<Robot, RobotError> {
        let config = file.path();
        let schema = |message: String| RobotError::Schema {
            path: config.to_owned(),
            message,
        };
        let section: RobotSection = file
            .section("robot")
            .ok_or_else(|| schema("the section is missing".to_owned()))?
            .clone()
            .try_into()
            .map_err(|error: toml::de::Error| schema(toml_message(&error)))?;
        let urdf = match (urdf_override, &section.urdf) {
            (Some(path), _) => path.to_owned(),
            (None, Some(relative)) => file.resolve(relative),
            (None, None) => {
                return Err(RobotError::MissingUrdf {
                    path: config.to_owned(),
                    robot: section.name,
                });
            }
        };
        let model = Model::from_urdf_path(&urdf).map_err(|error| RobotError::Model {
            urdf: urdf.clone(),
            error,
        })?;
        Loader {
            path: config,
            model,
        }
        .build(section, urdf)
    }

    /// The frame of an end-effector.
    pub fn frame(&self, e: EndEffector) -> FrameId {
        self.end_effectors[e as usize]
    }
}

/// Resolves config names against the model, attributing errors to the config file.
struct Loader<'a> {
    path: &'a Path,
    model: Model,
}

impl Loader<'_> {
    fn build(mut self, section: RobotSection, urdf: PathBuf) -> Result<Robot, RobotError> {
        let base_link = self.link("base_link", &section.base_link)?;
        self.check_sole(&section.sole)?;
        let frames = &section.frames;
        let specs = [
            &frames.left_foot,
            &frames.right_foot,
            &frames.left_hand,
            &frames.right_hand,
        ];
        let mut end_effectors = [FrameId(0); 4];
        for (slot, (effector, spec)) in end_effectors
            .iter_mut()
            .zip(EndEffector::ALL.iter().zip(specs))
        {
            *slot = self.frame(
                &format!("frames.{}", effector.name()),
                effector.name(),
                spec,
            )?;
        }
        let ft_sensors = [
            self.frame(
                "ft_sensors.left",
                FT_SENSOR_FRAMES[0],
                &section.ft_sensors.left,
            )?,
            self.frame(
                "ft_sensors.right",
                FT_SENSOR_FRAMES[1],
                &section.ft_sensors.right,
            )?,
        ];
        // A wrist sensor not configured is the origin of the hand frame's link.
        let wrist = |hand: &FrameSpec| FrameSpec {
            link: hand.link.clone(),
            translation: [0.0; 3],
            rpy: [0.0; 3],
        };
        let ft = &section.ft_sensors;
        let wrist_ft_sensors = [
            self.frame(
                "ft_sensors.left_hand",
                WRIST_FT_SENSOR_FRAMES[0],
                ft.left_hand.as_ref().unwrap_or(&wrist(&frames.left_hand)),
            )?,
            self.frame(
                "ft_sensors.right_hand",
                WRIST_FT_SENSOR_FRAMES[1],
                ft.right_hand.as_ref().unwrap_or(&wrist(&frames.right_hand)),
            )?,
        ];
        // The default follows the sole, within the range a configured value must keep.
        let palm_radius = section.palm_radius.unwrap_or_else(|| {
            (PALM_RADIUS_PER_SOLE_WIDTH * section.sole.width)
                .clamp(PALM_RADIUS_M.min, PALM_RADIUS_M.max)
        });
        if !PALM_RADIUS_M.contains(palm_radius) {
            return Err(self.invalid(
                "palm_radius",
                format!("{} m must be in {PALM_RADIUS_M} m", Number(palm_radius)),
            ));
        }
        let groups = &section.joint_groups;
        let joint_groups = JointGroups {
            legs: self.joints("joint_groups.legs", &groups.legs)?,
            arms: self.joints("joint_groups.arms", &groups.arms)?,
            torso: self.joints("joint_groups.torso", &groups.torso)?,
            head: self.joints("joint_groups.head", &groups.head)?,
        };
        let standing = self.standing(&section.standing, [end_effectors[0], end_effectors[1]])?;
        Ok(Robot {
            name: section.name,
            urdf,
            model: self.model,
            base_link,
            end_effectors,
            sole: section.sole,
            ft_sensors,
            wrist_ft_sensors,
            palm_radius,
            joint_groups,
            standing,
        })
    }

    fn invalid(&self, key: &str, message: String) -> RobotError {
        RobotError::Invalid {
            path: self.path.to_owned(),
            key: key.to_owned(),
            message,
        }
    }

    fn link(&self, key: &str, name: &str) -> Result<LinkId, RobotError> {
        self.model
            .link_index(name)
            .ok_or_else(|| RobotError::UnknownLink {
                path: self.path.to_owned(),
                key: key.to_owned(),
                name: name.to_owned(),
            })
    }

    fn joint(&self, key: &str, name: &str) -> Result<usize, RobotError> {
        self.model
            .joint_index(name)
            .ok_or_else(|| RobotError::UnknownJoint {
                path: self.path.to_owned(),
                key: key.to_owned(),
                name: name.to_owned(),
            })
    }

    fn joints(&self, key: &str, names: &[String]) -> Result<Vec<usize>, RobotError> {
        names.iter().map(|name| self.joint(key, name)).collect()
    }

    fn check_sole(&self, sole: &SoleRectangle) -> Result<(), RobotError> {
        match first_outside(&sole.bounds()) {
            Some(violation) => Err(self.invalid(
                violation.key,
                format!(
                    "{} m {}",
                    Number(violation.value),
                    violation.range.requirement()
                ),
            )),
            None => Ok(()),
        }
    }

    fn frame(&mut self, key: &str, name: &str, spec: &FrameSpec) -> Result<FrameId, RobotError> {
        let link = self.link(&format!("{key}.link"), &spec.link)?;
        if !spec.translation.iter().all(|&x| FRAME_OFFSET_M.contains(x))
            || !spec.rpy.iter().all(|&x| FRAME_ANGLE_RAD.contains(x))
        {
            return Err(self.invalid(
                key,
                format!(
                    "translation must be in {FRAME_OFFSET_M} m and rpy in {FRAME_ANGLE_RAD} rad"
                ),
            ));
        }
        let offset = pose_from_xyz_rpy(spec.translation, spec.rpy);
        self.model
            .add_frame(name, link, offset)
            .map_err(|error| self.invalid(key, error.to_string()))
    }

    /// The configured posture with the base placed so both soles lie flat on z = 0.
    fn standing(
        &self,
        angles: &BTreeMap<String, f64>,
        soles: [FrameId; 2],
    ) -> Result<Configuration, RobotError> {
        let model = &self.model;
        let mut q = Configuration::neutral(model);
        for (name, &angle) in angles {
            let key = format!("standing.{name}");
            let index = self.joint("standing", name)?;
            let limits = model.joint_limits()[index];
            if !(angle.is_finite() && limits.lower <= angle && angle <= limits.upper) {
                return Err(self.invalid(
                    &key,
                    format!(
                        "{angle} is outside the joint limits [{}, {}]",
                        limits.lower, limits.upper
                    ),
                ));
            }
            q.joints[index] = angle;
        }
        let mut kinematics = Kinematics::new(model);
        kinematics.update(model, &q);
        let left = kinematics.frame_pose(model, soles[0]);
        let right = kinematics.frame_pose(model, soles[1]);
        // Rotate the base so the left sole is level, then split the soles' yaw difference evenly.
        let relative = left.rotation.inverse() * right.rotation;
        let tilt = (relative * Vector3::z()).angle(&Vector3::z());
        if tilt > FLAT_TOLERANCE {
            return Err(self.invalid(
                "standing",
                format!("the posture leaves the soles {tilt:.3e} rad apart from parallel; both must be flat"),
            ));
        }
        let relative_yaw = relative.euler_angles().2;
        let level = UnitQuaternion::from_euler_angles(0.0, 0.0, -relative_yaw / 2.0)
            * left.rotation.inverse();
        q.base = Isometry3::from_parts(Translation3::identity(), level);
        kinematics.update(model, &q);
        let left = kinematics.frame_pose(model, soles[0]).translation.vector;
        let right = kinematics.frame_pose(model, soles[1]).translation.vector;
        if (left.z - right.z).abs() > FLAT_TOLERANCE {
            return Err(self.invalid(
                "standing",
                format!(
                    "the posture puts the soles at different heights ({:.3e} m apart, more than \
                     {FLAT_TOLERANCE:e} m); both must stand on the floor",
                    (left.z - right.z).abs()
                ),
            ));
        }
        q.base.translation = Translation3::from(-(left + right) / 2.0);
        Ok(q)
    }
}
