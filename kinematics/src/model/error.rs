//! Why a URDF cannot be turned into a model.

use super::InertiaDefect;

/// Everything that makes a URDF unusable; each variant names the offending element.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// The file could not be read.
    #[error("cannot read the URDF file: {error}")]
    Io {
        /// The file.
        path: String,
        /// The cause.
        error: std::io::Error,
    },
    /// The XML is malformed.
    #[error("malformed URDF XML at byte {position}: {message}")]
    Xml {
        /// Byte offset of the error (0 if unknown).
        position: u64,
        /// Parser message.
        message: String,
    },
    /// urdf-rs refused the document.
    #[error("invalid URDF: {0}")]
    Urdf(String),
    /// A number is NaN or infinite.
    #[error("{owner}: <{element} {attribute}=\"{value}\"> is not a finite number")]
    NonFinite {
        /// `link 'NAME'` or `joint 'NAME'`.
        owner: String,
        /// The XML element holding the number.
        element: String,
        /// The attribute holding the number.
        attribute: String,
        /// The attribute text.
        value: String,
    },
    /// Two links share a name.
    #[error("duplicate link name '{0}'")]
    DuplicateLink(String),
    /// Two joints share a name.
    #[error("duplicate joint name '{0}'")]
    DuplicateJoint(String),
    /// Two frames share a name.
    #[error("duplicate frame name '{0}'")]
    DuplicateFrame(String),
    /// A joint refers to a link that does not exist.
    #[error("joint '{joint}': {role} link '{link}' does not exist")]
    UnknownLink {
        /// The joint.
        joint: String,
        /// `parent` or `child`.
        role: &'static str,
        /// The missing link name.
        link: String,
    },
    /// A link is the child of more than one joint.
    #[error("link '{link}' is the child of two joints, '{first}' and '{second}'")]
    MultipleParents {
        /// The link.
        link: String,
        /// First joint naming it as child.
        first: String,
        /// Second joint naming it as child.
        second: String,
    },
    /// The joints form a cycle.
    #[error("kinematic cycle through link '{0}'")]
    Cycle(String),
    /// More than one link has no parent.
    #[error(
        "the URDF has several root links: '{0}' and '{1}' (a floating-base tree has exactly one)"
    )]
    MultipleRoots(String, String),
    /// The URDF has no links.
    #[error("the URDF has no links")]
    Empty,
    /// A revolute or prismatic joint lacks its `<limit>` element.
    #[error("joint '{0}': {1} joint without a <limit> element")]
    MissingLimit(String, &'static str),
    /// `lower > upper`, or a negative velocity/effort limit.
    #[error(
        "joint '{joint}': invalid limits (lower {lower}, upper {upper}, velocity {velocity}, effort {effort})"
    )]
    InvalidLimits {
        /// The joint.
        joint: String,
        /// Lower position limit.
        lower: f64,
        /// Upper position limit.
        upper: f64,
        /// Velocity limit.
        velocity: f64,
        /// Effort limit.
        effort: f64,
    },
    /// An actuated joint's velocity limit is zero (it could never move).
    #[error("joint '{joint}': velocity limit {velocity} (an actuated joint needs a positive one)")]
    ZeroVelocityLimit {
        /// The joint.
        joint: String,
        /// The velocity limit found.
        velocity: f64,
    },
    /// The joint axis is the zero vector.
    #[error("joint '{0}': zero-length <axis>")]
    ZeroAxis(String),
    /// Joint types a floating-base tree cannot represent here.
    #[error(
        "joint '{joint}': unsupported joint type {kind} (supported: revolute, continuous, prismatic, fixed)"
    )]
    UnsupportedJoint {
        /// The joint.
        joint: String,
        /// Its type as written.
        kind: String,
    },
    /// Negative mass.
    #[error("link '{link}': negative mass {mass}")]
    NegativeMass {
        /// The link.
        link: String,
        /// The mass.
        mass: f64,
    },
    /// The rotational inertia is not physically valid.
    #[error("link '{link}': {defect}")]
    InvalidInertia {
        /// The link.
        link: String,
        /// What is wrong.
        defect: InertiaDefect,
    },
    /// A frame was attached to a link this model does not have.
    #[error("frame '{frame}': link index {link} out of range")]
    FrameLinkOutOfRange {
        /// The frame.
        frame: String,
        /// The bad index.
        link: usize,
    },
    /// A frame offset has a non-finite entry.
    #[error("frame '{0}': offset is not finite")]
    FrameNotFinite(String),
}
