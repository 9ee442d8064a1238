//! A validated floating-base kinematic tree built from URDF.
//!
//! The URDF's root link becomes the floating base. Links are stored in depth-first order from the
//! root (children in the order their joints appear in the file), so a parent always precedes its
//! children and forward kinematics is one pass. Actuated joints (revolute, continuous, prismatic)
//! are numbered in the same order; that is the "model order" of joint vectors.
//!
//! Mimic joints are treated as **fixed** at their `offset` (the value they take when the joint they
//! follow is at zero); they are not part of the joint vector.

mod build;
mod error;
mod inertia;
mod raw;

use std::collections::HashMap;
use std::path::Path;

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

pub use error::ModelError;
pub use inertia::InertiaDefect;

/// Index of a link in a [`Model`] (depth-first order from the floating base, which is link 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct LinkId(pub(crate) usize);

impl LinkId {
    /// The floating-base link (the URDF's root).
    pub const BASE: LinkId = LinkId(0);

    /// Position of this link in [`Model::link_names`].
    pub fn index(self) -> usize {
        self.0
    }
}

/// Index of an operational frame added with [`Model::add_frame`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FrameId(pub(crate) usize);

impl FrameId {
    /// Position of this frame in [`Model::frame_names`].
    pub fn index(self) -> usize {
        self.0
    }
}

/// Limits of one actuated joint, from its URDF `<limit>` element.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimits {
    /// Lower position limit (rad or m); `-INFINITY` for continuous joints.
    pub lower: f64,
    /// Upper position limit (rad or m); `INFINITY` for continuous joints.
    pub upper: f64,
    /// Maximum speed (rad/s or m/s); `INFINITY` when the URDF gives none.
    pub velocity: f64,
    /// Maximum effort (N·m or N); `INFINITY` when the URDF gives none.
    pub effort: f64,
}

/// How a link moves relative to its parent.
#[derive(Debug, Clone, Copy)]
pub(crate) enum JointMotion {
    /// Rigidly attached (fixed and mimic joints).
    Fixed,
    /// Rotation by `q[index]` about the unit `axis` of the joint frame.
    Revolute {
        axis: Unit<Vector3<f64>>,
        index: usize,
    },
    /// Translation by `q[index]` along the unit `axis` of the joint frame.
    Prismatic {
        axis: Unit<Vector3<f64>>,
        index: usize,
    },
}

/// One link with the joint that connects it to its parent.
#[derive(Debug, Clone)]
pub(crate) struct Body {
    /// Parent link index (`None` for the base).
    pub parent: Option<usize>,
    /// Pose of the joint frame (= this link's frame at q = 0) in the parent link frame.
    pub origin: Isometry3<f64>,
    /// The joint's motion.
    pub motion: JointMotion,
    /// Link mass (kg).
    pub mass: f64,
    /// Centre of mass in the link frame.
    pub com: Vector3<f64>,
}

/// An operational frame rigidly attached to a link.
#[derive(Debug, Clone)]
pub(crate) struct Frame {
    pub name: String,
    pub link: usize,
    pub offset: Isometry3<f64>,
}

/// A validated floating-base kinematic tree (see the module documentation for the ordering).
#[derive(Debug, Clone)]
pub struct Model {
    name: String,
    bodies: Vec<Body>,
    link_names: Vec<String>,
    link_lookup: HashMap<String, usize>,
    joint_names: Vec<String>,
    joint_lookup: HashMap<String, usize>,
    joint_limits: Vec<JointLimits>,
    /// The link each actuated joint moves (its child link).
    joint_links: Vec<usize>,
    /// Mass of each link's subtree (the link and all its descendants).
    subtree_masses: Vec<f64>,
    /// Actuated joints supporting each link: `support[support_ranges[l].0..support_ranges[l].1]`.
    support: Vec<usize>,
    support_ranges: Vec<(usize, usize)>,
    frames: Vec<Frame>,
    frame_lookup: HashMap<String, usize>,
    total_mass: f64,
}

impl Model {
    /// Reads and validates a URDF file.
    pub fn from_urdf_path(path: &Path) -> Result<Model, ModelError> {
        let xml = std::fs::read_to_string(path).map_err(|error| ModelError::Io {
            path: path.display().to_string(),
            error,
        })?;
        Self::from_urdf_str(&xml)
    }

    /// Parses and validates a URDF document.
    pub fn from_urdf_str(xml: &str) -> Result<Model, ModelError> {
        let facts = raw::scan(xml)?;
        let robot = urdf_rs::read_from_string(xml).map_err(|e| ModelError::Urdf(e.to_string()))?;
        build::build(robot, &facts)
    }

    /// The URDF's robot name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of actuated joints n.
    pub fn dof(&self) -> usize {
        self.joint_names.len()
    }

    /// Velocity dimension 6 + n (base twist, then joint velocities).
    pub fn nv(&self) -> usize {
        6 + self.dof()
    }

    /// Actuated joint names in model order.
    pub fn joint_names(&self) -> &[String] {
        &self.joint_names
    }

    /// Model-order index of an actuated joint.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joint_lookup.get(name).copied()
    }

    /// Limits of the actuated joints in model order.
    pub fn joint_limits(&self) -> &[JointLimits] {
        &self.joint_limits
    }

    /// Link names in link order (index = [`LinkId::index`]).
    pub fn link_names(&self) -> &[String] {
        &self.link_names
    }

    /// Looks a link up by name.
    pub fn link_index(&self, name: &str) -> Option<LinkId> {
        self.link_lookup.get(name).map(|&i| LinkId(i))
    }

    /// Every link id in link order.
    pub fn link_ids(&self) -> impl ExactSizeIterator<Item = LinkId> + use<> {
        (0..self.bodies.len()).map(LinkId)
    }

    /// Name of a link.
    pub fn link_name(&self, link: LinkId) -> &str {
        &self.link_names[link.0]
    }

    /// Sum of all link masses (kg).
    pub fn total_mass(&self) -> f64 {
        self.total_mass
    }

    /// Attaches a named frame to `link` at `offset` (pose of the frame in the link frame).
    pub fn add_frame(
        &mut self,
        name: &str,
        link: LinkId,
        offset: Isometry3<f64>,
    ) -> Result<FrameId, ModelError> {
        if self.frame_lookup.contains_key(name) {
            return Err(ModelError::DuplicateFrame(name.to_owned()));
        }
        if link.0 >= self.bodies.len() {
            return Err(ModelError::FrameLinkOutOfRange {
                frame: name.to_owned(),
                link: link.0,
            });
        }
        let finite = offset.translation.vector.iter().all(|x| x.is_finite())
            && offset.rotation.coords.iter().all(|x| x.is_finite());
        if !finite {
            return Err(ModelError::FrameNotFinite(name.to_owned()));
        }
        let id = self.frames.len();
        self.frames.push(Frame {
            name: name.to_owned(),
            link: link.0,
            offset,
        });
        self.frame_lookup.insert(name.to_owned(), id);
        Ok(FrameId(id))
    }

    /// Looks a frame up by name.
    pub fn frame_index(&self, name: &str) -> Option<FrameId> {
        self.frame_lookup.get(name).map(|&i| FrameId(i))
    }

    /// Name of a frame.
    pub fn frame_name(&self, frame: FrameId) -> &str {
        &self.frames[frame.0].name
    }

    /// The link a frame is attached to.
    pub fn frame_link(&self, frame: FrameId) -> LinkId {
        LinkId(self.frames[frame.0].link)
    }

    /// Pose of a frame in its link's frame.
    pub fn frame_offset(&self, frame: FrameId) -> &Isometry3<f64> {
        &self.frames[frame.0].offset
    }

    /// Number of links.
    pub fn link_count(&self) -> usize {
        self.bodies.len()
    }

    /// The parent of a link (`None` for the floating base): links form a tree, parents first.
    pub fn link_parent(&self, link: LinkId) -> Option<LinkId> {
        self.bodies[link.0].parent.map(LinkId)
    }

    /// Mass of a link alone (kg).
    pub fn link_mass(&self, link: LinkId) -> f64 {
        self.bodies[link.0].mass
    }

    /// Pose of a link's joint frame in its parent link's frame (the link's pose there at q = 0).
    pub fn link_origin(&self, link: LinkId) -> &Isometry3<f64> {
        &self.bodies[link.0].origin
    }

    /// A link's centre of mass in its own frame.
    pub fn link_com(&self, link: LinkId) -> &Vector3<f64> {
        &self.bodies[link.0].com
    }

    pub(crate) fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    pub(crate) fn joint_link(&self, joint: usize) -> usize {
        self.joint_links[joint]
    }

    pub(crate) fn subtree_mass(&self, link: usize) -> f64 {
        self.subtree_masses[link]
    }

    /// Actuated joints between the base and `link` (inclusive of the link's own joint).
    pub(crate) fn supporting_joints(&self, link: usize) -> &[usize] {
        let (start, end) = self.support_ranges[link];
        &self.support[start..end]
    }
}

/// Pose from URDF `xyz` + `rpy` (fixed-axis roll, pitch, yaw: R = Rz(yaw)·Ry(pitch)·Rx(roll)).
pub fn pose_from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}
