//! Why a stance file or sequence is refused. Every error names where the problem is: the stance
//! index and field, or the top-level field, plus line and column for JSON-level problems.

use std::fmt;

/// Where in a sequence a problem sits: a stance index (if inside `stances`) and a field path
/// relative to it (e.g. `q[5]`, `contacts`) or to the file (e.g. `environment.surfaces[0]`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    /// Index of the stance, `None` for fields outside `stances`.
    pub stance: Option<usize>,
    /// Field path inside the stance (or the file).
    pub field: String,
}

impl Location {
    /// A field of stance `index`.
    pub fn stance(index: usize, field: impl Into<String>) -> Self {
        Self {
            stance: Some(index),
            field: field.into(),
        }
    }

    /// A field outside the stances.
    pub fn file(field: impl Into<String>) -> Self {
        Self {
            stance: None,
            field: field.into(),
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.stance, self.field.is_empty()) {
            (Some(i), true) => write!(f, "stance {i}"),
            (Some(i), false) => write!(f, "stance {i}, field `{}`", self.field),
            (None, true) => write!(f, "the top-level object"),
            (None, false) => write!(f, "field `{}`", self.field),
        }
    }
}

/// A refused stance file or sequence.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum FormatError {
    /// The input ends before the JSON document does.
    #[error("truncated JSON: input ends at line {line}, column {column}, inside {location}")]
    Truncated {
        line: usize,
        column: usize,
        location: Location,
    },
    /// Not JSON at all at some point.
    #[error("invalid JSON at line {line}, column {column} ({location}): {message}")]
    Syntax {
        line: usize,
        column: usize,
        location: Location,
        message: String,
    },
    /// Valid JSON whose shape is not a stance file (missing/unknown field, wrong type).
    #[error("{location} (line {line}, column {column}): {message}")]
    Structure {
        line: usize,
        column: usize,
        location: Location,
        message: String,
    },
    /// NaN or an infinity (written as `NaN`/`Infinity` or as an overflowing number).
    #[error("{location}: non-finite number (NaN or infinity) is not allowed")]
    NonFinite { location: Location },
    /// The document is JSON, but not an object (serde would read an array as the fields in
    /// order and complain about the first one's type).
    #[error(
        "a stance file is a JSON object ({{\"format_version\": 2, \"kind\": ..., \"stances\": [...]}}), not {found}"
    )]
    NotAnObject { found: &'static str },
    /// A `format_version` this code does not read.
    #[error(
        "field `format_version`: version {found} is not supported (this build reads 1 to {supported})"
    )]
    UnsupportedVersion { found: u64, supported: u32 },
    /// A post-processed file where a raw one is expected or vice versa.
    #[error("field `kind`: expected a {expected} sequence, found a {found} one")]
    WrongKind {
        expected: &'static str,
        found: &'static str,
    },
    /// The file names another robot than the one it is loaded for.
    #[error("the sequence is for robot `{found}`, not for `{expected}` (field `robot`)")]
    RobotMismatch { found: String, expected: String },
    /// `joint_names` has another length than the robot's joint list.
    #[error("field `joint_names`: {found} joints listed, the robot `{robot}` has {expected}")]
    JointNameCount {
        robot: String,
        expected: usize,
        found: usize,
    },
    /// `joint_names[index]` differs from the robot's joint at that index.
    #[error(
        "field `joint_names[{index}]`: expected `{expected}` (robot joint order), found `{found}`"
    )]
    JointName {
        index: usize,
        expected: String,
        found: String,
    },
    /// A joint name listed twice or empty.
    #[error("field `joint_names[{index}]`: `{name}` is empty or listed twice")]
    BadJointName { index: usize, name: String },
    /// A stance whose `q` does not have one value per joint.
    #[error(
        "stance {stance}, field `q`: {found} joint values, expected {expected} (one per entry of `joint_names`)"
    )]
    JointCount {
        stance: usize,
        expected: usize,
        found: usize,
    },
    /// A file with no stance.
    #[error("field `stances`: the sequence is empty")]
    EmptySequence,
    /// A stance with neither foot in contact.
    #[error(
        "stance {stance}, field `contacts`: no foot in contact; every stance needs foot support"
    )]
    NoFootSupport { stance: usize },
    /// A contact name that is not an end-effector, or listed twice.
    #[error(
        "stance {stance}, field `contacts`: `{name}` is not an end-effector or is listed twice (use left_foot, right_foot, left_hand, right_hand)"
    )]
    BadContact { stance: usize, name: String },
    /// A rotation quaternion far from unit length.
    #[error("{location}: quaternion norm {norm} is not 1")]
    NonUnitQuaternion { location: Location, norm: f64 },
    /// Some other value out of its domain (empty name, polygon with < 3 vertices, reversed interval).
    #[error("{location}: {message}")]
    Invalid { location: Location, message: String },
}
