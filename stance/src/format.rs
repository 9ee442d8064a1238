//! The versioned JSON stance file (DESIGN.md §3) and its strict reader.
//!
//! ```json
//! { "format_version": 2, "kind": "raw" | "post_processed", "robot": "armar4",
//!   "joint_names": ["..."],
//!   "environment": { "surfaces": [{ "name": "ground",
//!                                   "pose": { "translation": [0, 0, 0], "rotation": [0, 0, 0, 1] },
//!                                   "polygon": null }],
//!                    "hand_affordances": [{ "name": "railing", "start": [..], "end": [..],
//!                                           "radius": 0.02, "available": [0.0, 5.0] }] },
//!   "stances": [{ "q": [..], "contacts": ["left_foot", "right_foot"],
//!                 "translation": [x, y, z], "root_orientation": [x, y, z, w], "duration_s": 0.4,
//!                 "targets": { "left_foot": { "translation": [..], "rotation": [..] }, .. } }] }
//! ```
//! Version 2 (written; 1 is still read) adds each stance's optional `"duration_s"`: how long the
//! walk stays in it (s, in (0, 60]); absent, the gait's configured timing applies.
//! `targets` is present exactly in post-processed files; so is the optional `"gait": "static" |
//! "dynamic"`, the gait whose limits post-processed the sequence and that walks it (absent: the
//! robot config's default). `root_orientation` defaults to the identity. A hand affordance's
//! `radius` (m, ≥ 0: a railing's, around the axis from `start` to `end`) is optional and 0 when
//! absent (a stance source's own railing, and files written before it existed); a radius of 0 is
//! not written. Unknown fields are errors;
//! a top-level value other than an object is refused as such. Quaternions are `[x, y, z, w]`.

use kinematics::robot::{EndEffector, Robot};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::environment::{Environment, HandAffordance, SupportSurface};
use crate::error::{FormatError, Location};
use crate::json_path::{location_at, offset_of};
use crate::params::Gait;
use crate::sequence::{PostProcessedSequence, RawSequence, Stance, StanceSequence};

/// The file format version this build writes; it reads this one and every earlier one.
/// Version 2 added the stances' optional `duration_s`.
pub const FORMAT_VERSION: u32 = 2;

/// The oldest version this build still reads.
const OLDEST_VERSION: u64 = 1;

/// Whether this build reads files of `version`.
fn readable(version: u64) -> bool {
    (OLDEST_VERSION..=u64::from(FORMAT_VERSION)).contains(&version)
}

#[derive(Serialize, Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "snake_case")]
enum Kind {
    Raw,
    PostProcessed,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Raw => "raw",
            Kind::PostProcessed => "post_processed",
        }
    }
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct FileDto {
    format_version: u64,
    kind: Kind,
    robot: String,
    joint_names: Vec<String>,
    environment: EnvironmentDto,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    gait: Option<Gait>,
    stances: Vec<StanceDto>,
}

#[derive(Deserialize)]
struct VersionProbe {
    format_version: u64,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct StanceDto {
    q: Vec<f64>,
    contacts: Vec<String>,
    translation: [f64; 3],
    #[serde(default)]
    root_orientation: Option<[f64; 4]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    targets: Option<TargetsDto>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    duration_s: Option<f64>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct TargetsDto {
    left_foot: PoseDto,
    right_foot: PoseDto,
    left_hand: PoseDto,
    right_hand: PoseDto,
}

#[derive(Serialize, Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
struct PoseDto {
    translation: [f64; 3],
    rotation: [f64; 4],
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct EnvironmentDto {
    surfaces: Vec<SurfaceDto>,
    #[serde(default)]
    hand_affordances: Vec<HandAffordanceDto>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SurfaceDto {
    name: String,
    pose: PoseDto,
    #[serde(default)]
    polygon: Option<Vec<[f64; 2]>>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct HandAffordanceDto {
    name: String,
    start: [f64; 3],
    end: [f64; 3],
    #[serde(default, skip_serializing_if = "is_zero")]
    radius: f64,
    available: [f64; 2],
}

/// Whether an optional number is at its default, 0, and so not written.
fn is_zero(value: &f64) -> bool {
    *value == 0.0
}

fn quaternion(xyzw: [f64; 4]) -> UnitQuaternion<f64> {
    // Unchecked on purpose: the validator reports a non-unit norm with its location.
    UnitQuaternion::new_unchecked(Quaternion::new(xyzw[3], xyzw[0], xyzw[1], xyzw[2]))
}

fn xyzw(rotation: &UnitQuaternion<f64>) -> [f64; 4] {
    let c = rotation.coords;
    [c.x, c.y, c.z, c.w]
}

impl From<PoseDto> for Isometry3<f64> {
    fn from(pose: PoseDto) -> Self {
        Isometry3::from_parts(
            Translation3::from(Vector3::from(pose.translation)),
            quaternion(pose.rotation),
        )
    }
}

impl From<&Isometry3<f64>> for PoseDto {
    fn from(pose: &Isometry3<f64>) -> Self {
        PoseDto {
            translation: pose.translation.vector.into(),
            rotation: xyzw(&pose.rotation),
        }
    }
}

impl From<EnvironmentDto> for Environment {
    fn from(dto: EnvironmentDto) -> Self {
        Environment {
            surfaces: dto
                .surfaces
                .into_iter()
                .map(|s| SupportSurface {
                    name: s.name,
                    pose: s.pose.into(),
                    polygon: s.polygon,
                })
                .collect(),
            hand_affordances: dto
                .hand_affordances
                .into_iter()
                .map(|h| HandAffordance {
                    name: h.name,
                    start: h.start.into(),
                    end: h.end.into(),
                    radius: h.radius,
                    available: h.available,
                })
                .collect(),
        }
    }
}

impl From<&Environment> for EnvironmentDto {
    fn from(env: &Environment) -> Self {
        EnvironmentDto {
            surfaces: env
                .surfaces
                .iter()
                .map(|s| SurfaceDto {
                    name: s.name.clone(),
                    pose: (&s.pose).into(),
                    polygon: s.polygon.clone(),
                })
                .collect(),
            hand_affordances: env
                .hand_affordances
                .iter()
                .map(|h| HandAffordanceDto {
                    name: h.name.clone(),
                    start: h.start.into(),
                    end: h.end.into(),
                    radius: h.radius,
                    available: h.available,
                })
                .collect(),
        }
    }
}

fn contact_flags(stance: usize, names: &[String]) -> Result<[bool; 4], FormatError> {
    let mut flags = [false; 4];
    for name in names {
        let e = EndEffector::ALL
            .into_iter()
            .find(|e| e.name() == name)
            .filter(|e| !flags[*e as usize])
            .ok_or_else(|| FormatError::BadContact {
                stance,
                name: name.clone(),
            })?;
        flags[e as usize] = true;
    }
    Ok(flags)
}

fn contact_names(flags: &[bool; 4]) -> Vec<String> {
    EndEffector::ALL
        .into_iter()
        .filter(|e| flags[*e as usize])
        .map(|e| e.name().to_owned())
        .collect()
}

/// The value token around byte `offset`: from the last delimiter before it to the next one.
fn token_at(text: &str, offset: usize) -> &str {
    let delimiter = |c: char| c.is_whitespace() || matches!(c, ',' | ':' | '[' | ']' | '{' | '}');
    let offset = offset.min(text.len());
    let start = text[..offset].rfind(delimiter).map_or(0, |i| i + 1);
    let end = text[offset..]
        .find(delimiter)
        .map_or(text.len(), |i| offset + i);
    &text[start..end]
}

/// Whether a token is one of the non-JSON spellings of NaN or an infinity.
fn is_non_finite_literal(token: &str) -> bool {
    let unsigned = token.trim_start_matches(['-', '+']);
    ["nan", "inf", "infinity"]
        .iter()
        .any(|t| unsigned.eq_ignore_ascii_case(t))
}

/// Refuses a document whose top-level value is not an object before serde reads it: serde reads a
/// struct from an array too (the fields in order), so an array would be refused for the type of
/// its first element, or even accepted.
fn top_level_object(text: &str) -> Result<(), FormatError> {
    if text.trim_start().starts_with('{') {
        return Ok(());
    }
    // Not an object: only now is it worth a parse, to name what it is (or where it breaks).
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|error| json_error(text, error))?;
    let found = match value {
        serde_json::Value::Array(_) => "an array",
        serde_json::Value::String(_) => "a string",
        serde_json::Value::Number(_) => "a number",
        serde_json::Value::Bool(_) => "a boolean",
        serde_json::Value::Null => "null",
        serde_json::Value::Object(_) => return Ok(()),
    };
    Err(FormatError::NotAnObject { found })
}

/// The number of stances in a stance file, counted without building them: a reader can bound a
/// submission before it parses it (the pass skips every value and allocates nothing per stance).
pub fn count_stances(text: &str) -> Result<usize, FormatError> {
    #[derive(Deserialize)]
    struct Count {
        #[serde(deserialize_with = "count_elements")]
        stances: usize,
    }
    fn count_elements<'de, D: serde::Deserializer<'de>>(d: D) -> Result<usize, D::Error> {
        struct Counter;
        impl<'de> serde::de::Visitor<'de> for Counter {
            type Value = usize;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an array of stances")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<usize, A::Error> {
                let mut count = 0;
                while seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
                    count += 1;
                }
                Ok(count)
            }
        }
        d.deserialize_seq(Counter)
    }
    top_level_object(text)?;
    serde_json::from_str::<Count>(text)
        .map(|count| count.stances)
        .map_err(|error| json_error(text, error))
}

/// `sequence` if it is for `robot` (name, joint names and order).
fn for_robot<S: std::ops::Deref<Target = StanceSequence>>(
    sequence: S,
    robot: &Robot,
) -> Result<S, FormatError> {
    sequence.check_robot(robot)?;
    Ok(sequence)
}

/// The file form of `sequence`, with the targets of stance `i` from `targets(i)`.
fn file_dto<'a>(
    sequence: &StanceSequence,
    kind: Kind,
    gait: Option<Gait>,
    targets: impl Fn(usize) -> Option<&'a [Isometry3<f64>; 4]>,
) -> FileDto {
    FileDto {
        format_version: FORMAT_VERSION.into(),
        kind,
        robot: sequence.robot.clone(),
        joint_names: sequence.joint_names.clone(),
        environment: (&sequence.environment).into(),
        gait,
        stances: sequence
            .stances
            .iter()
            .enumerate()
            .map(|(i, s)| stance_dto(s, targets(i)))
            .collect(),
    }
}

/// Maps a serde_json error to a located [`FormatError`].
fn json_error(text: &str, error: serde_json::Error) -> FormatError {
    let (line, column) = (error.line(), error.column());
    let offset = offset_of(text, line, column);
    let location = location_at(text, offset);
    let message = error.to_string();
    let non_finite =
        message.contains("number out of range") || is_non_finite_literal(token_at(text, offset));
    match error.classify() {
        serde_json::error::Category::Eof => FormatError::Truncated {
            line,
            column,
            location,
        },
        _ if non_finite => FormatError::NonFinite { location },
        serde_json::error::Category::Data => FormatError::Structure {
            line,
            column,
            location,
            // serde_json appends " at line L column C"; the location already says it.
            message: message
                .rsplit_once(" at line ")
                .map_or(message.as_str(), |(m, _)| m)
                .to_owned(),
        },
        _ => FormatError::Syntax {
            line,
            column,
            location,
            message,
        },
    }
}

fn parse_file(text: &str, expected: Kind) -> Result<FileDto, FormatError> {
    top_level_object(text)?;
    let file: FileDto = serde_json::from_str(text).map_err(|error| {
        match serde_json::from_str::<VersionProbe>(text) {
            Ok(probe) if !readable(probe.format_version) => FormatError::UnsupportedVersion {
                found: probe.format_version,
                supported: FORMAT_VERSION,
            },
            _ => json_error(text, error),
        }
    })?;
    if !readable(file.format_version) {
        return Err(FormatError::UnsupportedVersion {
            found: file.format_version,
            supported: FORMAT_VERSION,
        });
    }
    if file.format_version < 2
        && let Some(i) = file.stances.iter().position(|s| s.duration_s.is_some())
    {
        return Err(FormatError::Invalid {
            location: Location::stance(i, "duration_s"),
            message: format!(
                "a stance duration needs format_version 2 (the file says {})",
                file.format_version
            ),
        });
    }
    if file.kind != expected {
        return Err(FormatError::WrongKind {
            expected: expected.name(),
            found: file.kind.name(),
        });
    }
    Ok(file)
}

type Parts = (String, Vec<String>, Environment, Vec<Stance>);

/// The stances, their targets if any, and the gait if the file names one.
type FileParts = (Parts, Vec<Option<TargetsDto>>, Option<Gait>);

fn into_parts(file: FileDto) -> Result<FileParts, FormatError> {
    let mut stances = Vec::with_capacity(file.stances.len());
    let mut targets = Vec::with_capacity(file.stances.len());
    for (i, dto) in file.stances.into_iter().enumerate() {
        stances.push(Stance {
            q: dto.q,
            contacts: contact_flags(i, &dto.contacts)?,
            translation: dto.translation.into(),
            root_orientation: dto
                .root_orientation
                .map_or_else(UnitQuaternion::identity, quaternion),
            duration_s: dto.duration_s,
        });
        targets.push(dto.targets);
    }
    let parts = (
        file.robot,
        file.joint_names,
        file.environment.into(),
        stances,
    );
    Ok((parts, targets, file.gait))
}

fn stance_dto(stance: &Stance, targets: Option<&[Isometry3<f64>; 4]>) -> StanceDto {
    let identity = stance.root_orientation == UnitQuaternion::identity();
    StanceDto {
        q: stance.q.clone(),
        contacts: contact_names(&stance.contacts),
        translation: stance.translation.into(),
        root_orientation: (!identity).then(|| xyzw(&stance.root_orientation)),
        targets: targets.map(|t| TargetsDto {
            left_foot: (&t[EndEffector::LeftFoot as usize]).into(),
            right_foot: (&t[EndEffector::RightFoot as usize]).into(),
            left_hand: (&t[EndEffector::LeftHand as usize]).into(),
            right_hand: (&t[EndEffector::RightHand as usize]).into(),
        }),
        duration_s: stance.duration_s,
    }
}

fn write(file: &FileDto) -> String {
    serde_json::to_string_pretty(file).expect("a stance file always serialises")
}

impl RawSequence {
    /// Reads and validates a raw stance file without checking it against a robot.
    pub fn parse_json_str(text: &str) -> Result<Self, FormatError> {
        let (parts, targets, gait) = into_parts(parse_file(text, Kind::Raw)?)?;
        if let Some(i) = targets.iter().position(Option::is_some) {
            return Err(FormatError::Invalid {
                location: Location::stance(i, "targets"),
                message: "a raw stance has no targets (is this a post-processed file?)".into(),
            });
        }
        if gait.is_some() {
            return Err(FormatError::Invalid {
                location: Location::file("gait"),
                message: "a raw sequence has no gait: the gait is chosen when it is \
                          post-processed"
                    .into(),
            });
        }
        let (robot, joint_names, environment, stances) = parts;
        RawSequence::new(robot, joint_names, environment, stances)
    }

    /// Reads a raw stance file and checks that it is for `robot` (name, joint names and order).
    pub fn from_json_str(text: &str, robot: &Robot) -> Result<Self, FormatError> {
        for_robot(Self::parse_json_str(text)?, robot)
    }

    /// The sequence as a (pretty-printed) stance file.
    pub fn to_json_string(&self) -> String {
        write(&file_dto(self, Kind::Raw, None, |_| None))
    }
}

impl PostProcessedSequence {
    /// Reads and validates a post-processed stance file without checking it against a robot.
    pub fn parse_json_str(text: &str) -> Result<Self, FormatError> {
        let (parts, targets, gait) = into_parts(parse_file(text, Kind::PostProcessed)?)?;
        let targets = targets
            .into_iter()
            .enumerate()
            .map(|(i, t)| {
                let t = t.ok_or_else(|| FormatError::Invalid {
                    location: Location::stance(i, "targets"),
                    message:
                        "missing: a post-processed stance needs targets for all four end-effectors"
                            .into(),
                })?;
                Ok([t.left_foot, t.right_foot, t.left_hand, t.right_hand].map(Isometry3::from))
            })
            .collect::<Result<Vec<_>, FormatError>>()?;
        let (robot, joint_names, environment, stances) = parts;
        Ok(
            PostProcessedSequence::new(robot, joint_names, environment, stances, targets)?
                .with_gait(gait),
        )
    }

    /// Reads a post-processed stance file and checks that it is for `robot`. This is the
    /// validator a daemon applies to sequences it receives as JSON bytes.
    pub fn from_json_str(text: &str, robot: &Robot) -> Result<Self, FormatError> {
        for_robot(Self::parse_json_str(text)?, robot)
    }

    /// The sequence as a (pretty-printed) stance file.
    pub fn to_json_string(&self) -> String {
        write(&file_dto(self, Kind::PostProcessed, self.gait, |i| {
            Some(&self.targets[i])
        }))
    }
}
