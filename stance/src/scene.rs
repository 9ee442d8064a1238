//! Scene files (docs/scenes.md): the versioned TOML description of where a walk happens, read
//! and validated strictly into a [`Scene`], whose [`Environment`] is what the stance crate plans
//! on.
//!
//! ```toml
//! format_version = 1
//! name = "stairs-up-10cm"
//!
//! [path]
//! start = [0.5, 0.0]          # x, y (m); z is the surface's under the point
//! goal = [5.2, 0.0]
//! start_yaw_deg = 0.0         # optional; default: facing the goal
//!
//! [[surface]]                 # a rectangular tread; its top face is the support plane
//! name = "floor"
//! center = [0.75, 0.0, 0.0]   # centre of the top face, world (m)
//! size = [1.5, 1.0]           # length along the surface's x, width along its y (m, in its plane)
//! pitch_deg = 0.0             # optional: slope, > 0 rises along the surface's +x
//! yaw_deg = 0.0               # optional: heading of the surface's x about world z
//!
//! [[railing]]                 # optional, any number
//! name = "railing"
//! start = [0.0, -0.45, 0.8]
//! end = [5.0, -0.45, 0.8]
//! radius = 0.02
//! available = [0.0, 5.0]      # optional; default: the whole path
//! ```

use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector2, Vector3};
use serde::Deserialize;

use kinematics::configuration::Configuration;

use crate::environment::{Environment, HandAffordance, SupportSurface};

/// The scene format version this build reads; a file with another `format_version` is refused
/// by name, so a newer file never loads as if it meant what version 1 means.
pub const FORMAT_VERSION: i64 = 1;

/// The highest vertical step (m) between two consecutive surfaces along the path: above it a
/// stair is a wall (the 18.5 cm riser of the hardest committed stairs is well inside).
pub const MAX_RISE_M: f64 = 0.30;

/// Two footprints may overlap by this much (m) and still count as touching: floating-point
/// coordinates of stairs laid edge to edge.
pub const OVERLAP_TOLERANCE_M: f64 = 0.001;

/// Surfaces whose footprints are within this distance (m) touch: each is reachable from the
/// other and the path may cross the gap between them.
pub const TOUCH_DISTANCE_M: f64 = 0.01;

/// Spacing (m) of the samples along the path that must all lie over a surface.
pub const PATH_SAMPLE_M: f64 = 0.01;

/// The steepest slope a surface may have (degrees, exclusive).
pub const MAX_PITCH_DEG: f64 = 45.0;

/// A validated scene: the environment a walk happens in and the walk's start and goal.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The scene's `name`, for reports and file names.
    pub name: String,
    /// The support surfaces (one per `[[surface]]`, in file order, bounded by their rectangles)
    /// and the railings as hand affordances (one per `[[railing]]`, in file order, with their
    /// radii).
    pub environment: Environment,
    /// Where the walk starts: on the surface under `path.start`, facing `start_yaw_deg` about
    /// world z (x forward, z up).
    pub start: Isometry3<f64>,
    /// Where the walk ends: `path.goal` on the surface under it.
    pub goal: Vector3<f64>,
}

/// Why a scene file is refused. Every message starts with the file and names the key or the
/// surfaces at fault (`surface[3] "tread-3"`: index in file order from 0, and name).
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file cannot be read.
    #[error("{}: cannot read the scene: {error}", origin.display())]
    Io {
        origin: PathBuf,
        error: std::io::Error,
    },
    /// Not TOML, or TOML of another shape: a syntax error, an unknown or missing key, a value of
    /// the wrong type.
    #[error("{}: {location}: {message}", origin.display())]
    Toml {
        origin: PathBuf,
        /// The key (`surface[1].colour`, `path.goal`) or table, line and column.
        location: String,
        message: String,
    },
    /// A `format_version` other than [`FORMAT_VERSION`].
    #[error(
        "{}: format_version = {found} is not supported (this build reads {FORMAT_VERSION})",
        origin.display()
    )]
    UnsupportedVersion { origin: PathBuf, found: i64 },
    /// A number outside its domain: NaN or infinite, a size or radius ≤ 0, a slope ≥ 45°, a
    /// reversed `available` interval.
    #[error("{}: {item}: {key} = {value}: {rule}", origin.display())]
    BadNumber {
        origin: PathBuf,
        /// `surface[3] "tread-3"`, `railing[0] "railing"` or `path`.
        item: String,
        /// The key inside the item, with the index in an array (`size[0]`).
        key: String,
        value: f64,
        rule: &'static str,
    },
    /// Two surfaces, or two railings, with the same name (names identify them in messages,
    /// plots and the simulator's world).
    #[error("{}: {item}: the name is already used by {first}", origin.display())]
    DuplicateName {
        origin: PathBuf,
        item: String,
        first: String,
    },
    /// Two surfaces whose footprints overlap by more than [`OVERLAP_TOLERANCE_M`].
    #[error(
        "{}: {first} and {second} overlap: their footprints (xy) overlap by {depth:.3} m, more \
         than {OVERLAP_TOLERANCE_M} m (surfaces may only touch edge to edge)",
        origin.display()
    )]
    Overlap {
        origin: PathBuf,
        first: String,
        second: String,
        depth: f64,
    },
    /// `path.start` or `path.goal` is not over any surface.
    #[error(
        "{}: path: {key} = [{}, {}] is not over any surface",
        origin.display(), point[0], point[1]
    )]
    EndOffSurfaces {
        origin: PathBuf,
        /// `start` or `goal`.
        key: &'static str,
        point: [f64; 2],
    },
    /// The straight path from start to goal passes over a point no surface covers.
    #[error(
        "{}: path: the straight line from start to goal leaves the surfaces at ({:.3}, {:.3}), \
         {along:.2} m from the start",
        origin.display(), point[0], point[1]
    )]
    PathLeavesSurfaces {
        origin: PathBuf,
        point: [f64; 2],
        along: f64,
    },
    /// Two consecutive surfaces along the path whose elevations differ by more than
    /// [`MAX_RISE_M`] where the path crosses from one to the other.
    #[error(
        "{}: path: the step from {from} to {to} is {rise:+.3} m at {along:.2} m from the start, \
         higher than {MAX_RISE_M} m",
        origin.display()
    )]
    RiseTooHigh {
        origin: PathBuf,
        from: String,
        to: String,
        /// Elevation of `to` minus that of `from` (m).
        rise: f64,
        along: f64,
    },
    /// A surface no chain of touching surfaces connects to the surface under the start.
    #[error(
        "{}: {item} is unreachable: its footprint is {gap:.3} m from the nearest surface \
         connected to the start's {start} (surfaces within {TOUCH_DISTANCE_M} m of each other \
         connect)",
        origin.display()
    )]
    Unreachable {
        origin: PathBuf,
        item: String,
        start: String,
        /// Horizontal distance to the nearest surface reachable from the start (m).
        gap: f64,
    },
    /// A railing whose start and end are the same point.
    #[error(
        "{}: {item}: start and end are the same point {point:?}: a railing is a segment",
        origin.display()
    )]
    DegenerateRailing {
        origin: PathBuf,
        item: String,
        point: [f64; 3],
    },
}

/// `N` numbers, exactly: `toml` reads a fixed-size array from a longer one and drops the rest,
/// so `size = [1.0, 1.0, 0.2]` would load as if the thickness meant something.
struct Numbers<const N: usize>([f64; N]);

impl<'de, const N: usize> Deserialize<'de> for Numbers<N> {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let values = Vec::<f64>::deserialize(deserializer)?;
        let found = values.len();
        let expected = format!("an array of {N} numbers");
        values
            .try_into()
            .map(Numbers)
            .map_err(|_| serde::de::Error::invalid_length(found, &expected.as_str()))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneDto {
    format_version: i64,
    name: String,
    path: PathDto,
    surface: Vec<SurfaceDto>,
    #[serde(default)]
    railing: Vec<RailingDto>,
}

/// Reads only the version, whatever else the file holds, to refuse another version as such.
#[derive(Deserialize)]
struct VersionProbe {
    format_version: i64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PathDto {
    start: Numbers<2>,
    goal: Numbers<2>,
    start_yaw_deg: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SurfaceDto {
    name: String,
    center: Numbers<3>,
    size: Numbers<2>,
    #[serde(default)]
    pitch_deg: f64,
    #[serde(default)]
    yaw_deg: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RailingDto {
    name: String,
    start: Numbers<3>,
    end: Numbers<3>,
    radius: f64,
    available: Option<Numbers<2>>,
}

/// What a number must be.
#[derive(Clone, Copy)]
enum Rule {
    Finite,
    Positive,
    Slope,
}

impl Rule {
    fn holds(self, value: f64) -> bool {
        match self {
            Rule::Finite => value.is_finite(),
            Rule::Positive => value.is_finite() && value > 0.0,
            Rule::Slope => value.is_finite() && value.abs() < MAX_PITCH_DEG,
        }
    }

    fn text(self) -> &'static str {
        match self {
            Rule::Finite => "must be finite",
            Rule::Positive => "must be finite and > 0",
            Rule::Slope => "must be finite and within (-45, 45) degrees",
        }
    }
}

/// A surface being validated: its message label, the surface and its footprint (the world xy
/// projection of its rectangle, counter-clockwise).
struct Placed {
    label: String,
    surface: SupportSurface,
    footprint: Vec<Vector2<f64>>,
}

impl Placed {
    /// Elevation of the surface's plane above `point` (inside the footprint or not).
    fn elevation(&self, point: Vector2<f64>) -> f64 {
        self.surface
            .plane_elevation_at(point.x, point.y)
            .expect("a surface less than 45° steep is never vertical")
    }
}

impl Scene {
    /// Reads and validates the scene file at `path`.
    pub fn from_path(path: &Path) -> Result<Self, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|error| SceneError::Io {
            origin: path.to_owned(),
            error,
        })?;
        Self::from_toml_str(&text, path)
    }

    /// Reads and validates a scene from its TOML `text`; `origin` names it in messages.
    pub fn from_toml_str(text: &str, origin: &Path) -> Result<Self, SceneError> {
        let parsed = toml::from_str::<SceneDto>(text);
        let version = match &parsed {
            Ok(dto) => Some(dto.format_version),
            Err(_) => toml::from_str::<VersionProbe>(text)
                .ok()
                .map(|probe| probe.format_version),
        };
        if let Some(found) = version.filter(|&v| v != FORMAT_VERSION) {
            return Err(SceneError::UnsupportedVersion {
                origin: origin.to_owned(),
                found,
            });
        }
        let dto = parsed.map_err(|error| toml_error(text, origin, &error))?;
        Validator { origin }.scene(dto)
    }

    /// The scene's surfaces and railings in the frame of [`Scene::start`]: the start at the
    /// origin on z = 0, heading +x. Stance sources generate a walk there, on flat ground; with
    /// this environment attached, post-processing fits it to the scene
    /// ([`crate::passes::place_on_terrain`]). Railing availability (metres along the path) is
    /// kept: the path starts at the start either way.
    pub fn walk_environment(&self) -> Environment {
        let to_walk = self.start.inverse();
        Environment {
            surfaces: self
                .environment
                .surfaces
                .iter()
                .map(|surface| SupportSurface {
                    pose: to_walk * surface.pose,
                    ..surface.clone()
                })
                .collect(),
            hand_affordances: self
                .environment
                .hand_affordances
                .iter()
                .map(|railing| HandAffordance {
                    start: to_walk.transform_point(&railing.start.into()).coords,
                    end: to_walk.transform_point(&railing.end.into()).coords,
                    ..railing.clone()
                })
                .collect(),
        }
    }

    /// `posture`, a configuration standing at the origin (the soles' midpoint there, as
    /// `Robot::standing` is), moved to the scene's start: at its (x, y), turned by its yaw, on
    /// the surface under it. Both simulators stand the robot there.
    pub fn place(&self, posture: &Configuration) -> Configuration {
        Configuration {
            base: self.start * posture.base,
            joints: posture.joints.clone(),
        }
    }

    /// How far the walk goes: the horizontal distance from the start to the goal along the
    /// start's heading. A walk for the scene is asked for this distance (generated for
    /// `path_length / scf`, like any walk of a given length).
    pub fn path_length(&self) -> f64 {
        let heading = self.start.rotation * Vector3::x();
        let to_goal = self.goal - self.start.translation.vector;
        to_goal.xy().dot(&heading.xy())
    }

    /// How far a walk through the scene goes: the whole path (`None`), or its first `requested`
    /// metres, never past the goal (the scene checked its surfaces only as far as the goal).
    pub fn walk_length(&self, requested: Option<f64>) -> Result<f64, BeyondPath> {
        let length = self.path_length();
        match requested {
            None => Ok(length),
            // Rounding in the length, not a longer walk.
            Some(distance) if distance <= length + 1e-6 => Ok(distance.min(length)),
            Some(distance) => Err(BeyondPath {
                scene: self.name.clone(),
                distance,
                length,
            }),
        }
    }
}

/// A walk asked to go further than a scene's path ([`Scene::walk_length`]).
#[derive(Debug, thiserror::Error)]
#[error(
    "scene \"{scene}\": a walk of {distance} m goes past its goal, {length:.3} m along the path; \
     ask for at most that"
)]
pub struct BeyondPath {
    /// The scene's name.
    pub scene: String,
    /// The distance asked for (m).
    pub distance: f64,
    /// The path's length (m).
    pub length: f64,
}

/// A located [`SceneError::Toml`] from a `toml` error.
fn toml_error(text: &str, origin: &Path, error: &toml::de::Error) -> SceneError {
    // A key missing at the top level comes with the empty span at the start.
    let location = match error.span().filter(|span| *span != (0..0)) {
        None => "the top level".to_owned(),
        Some(span) => {
            let offset = span.start.min(text.len());
            let before = &text[..offset];
            let line = before.matches('\n').count() + 1;
            let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
            match key_at(text, offset) {
                Some(key) => format!("{key} (line {line}, column {column})"),
                None => format!("line {line}, column {column}"),
            }
        }
    };
    SceneError::Toml {
        origin: origin.to_owned(),
        location,
        message: error.message().trim_end().replace('\n', " "),
    }
}

/// The key on the line holding byte `offset`, with its table: `surface[1].colour` for a key of
/// the second `[[surface]]`, `path.goal`, `name`; just the table on a table's header line;
/// `None` at the top level outside any key.
fn key_at(text: &str, offset: usize) -> Option<String> {
    let line_start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let line_end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    let mut counts: Vec<(&str, usize)> = Vec::new();
    let mut table = None;
    for line in text[..line_end].lines().map(str::trim_start) {
        if let Some(rest) = line.strip_prefix("[[") {
            let name = rest.split("]]").next().unwrap_or_default().trim();
            let index = match counts.iter_mut().find(|(n, _)| *n == name) {
                Some((_, count)) => {
                    *count += 1;
                    *count - 1
                }
                None => {
                    counts.push((name, 1));
                    0
                }
            };
            table = Some(format!("{name}[{index}]"));
        } else if let Some(rest) = line.strip_prefix('[') {
            table = Some(rest.split(']').next().unwrap_or_default().trim().to_owned());
        }
    }
    let line = text[line_start..line_end].trim_start();
    let key = (!line.starts_with('['))
        .then(|| line.split_once('=').map(|(key, _)| key.trim()))
        .flatten();
    match (table, key) {
        (Some(table), Some(key)) => Some(format!("{table}.{key}")),
        (table, key) => table.or(key.map(str::to_owned)),
    }
}

/// `surface[3] "tread-3"`: how messages name an entry of an array of tables.
fn label(table: &str, index: usize, name: &str) -> String {
    format!("{table}[{index}] {name:?}")
}

/// The checks, with the file they report for.
struct Validator<'a> {
    origin: &'a Path,
}

impl Validator<'_> {
    fn scene(&self, dto: SceneDto) -> Result<Scene, SceneError> {
        // Values first, then names, then geometry: a NaN is reported as such, not as the odd
        // geometry it makes.
        let placed = dto
            .surface
            .iter()
            .enumerate()
            .map(|(i, surface)| self.surface(i, surface))
            .collect::<Result<Vec<_>, _>>()?;
        let path = &dto.path;
        self.numbers("path", "start", &path.start.0, Rule::Finite)?;
        self.numbers("path", "goal", &path.goal.0, Rule::Finite)?;
        let (start, goal) = (Vector2::from(path.start.0), Vector2::from(path.goal.0));
        let start_yaw = match path.start_yaw_deg {
            Some(yaw) => self
                .number("path", "start_yaw_deg", yaw, Rule::Finite)?
                .to_radians(),
            None => (goal - start).y.atan2((goal - start).x),
        };
        let hand_affordances = dto
            .railing
            .iter()
            .enumerate()
            .map(|(i, railing)| self.railing(i, railing, (goal - start).norm()))
            .collect::<Result<Vec<_>, _>>()?;

        self.unique_names("surface", dto.surface.iter().map(|s| s.name.as_str()))?;
        self.unique_names("railing", dto.railing.iter().map(|r| r.name.as_str()))?;

        self.no_overlap(&placed)?;
        let start_surface = self.end_surface(&placed, "start", start)?;
        let goal_surface = self.end_surface(&placed, "goal", goal)?;
        self.walk(&placed, start, goal)?;
        self.reachable(&placed, start_surface)?;

        let on = |index: usize, p: Vector2<f64>| Vector3::new(p.x, p.y, placed[index].elevation(p));
        Ok(Scene {
            name: dto.name,
            start: Isometry3::from_parts(
                Translation3::from(on(start_surface, start)),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), start_yaw),
            ),
            goal: on(goal_surface, goal),
            environment: Environment {
                surfaces: placed.into_iter().map(|p| p.surface).collect(),
                hand_affordances,
            },
        })
    }

    fn number(&self, item: &str, key: &str, value: f64, rule: Rule) -> Result<f64, SceneError> {
        if rule.holds(value) {
            return Ok(value);
        }
        Err(SceneError::BadNumber {
            origin: self.origin.to_owned(),
            item: item.to_owned(),
            key: key.to_owned(),
            value,
            rule: rule.text(),
        })
    }

    /// Every number of `values` (the key `key[i]`) obeys `rule`.
    fn numbers(&self, item: &str, key: &str, values: &[f64], rule: Rule) -> Result<(), SceneError> {
        for (i, &value) in values.iter().enumerate() {
            self.number(item, &format!("{key}[{i}]"), value, rule)?;
        }
        Ok(())
    }

    /// The surface of `[[surface]]` number `index`: a rectangle `size` centred on `center`,
    /// turned by `yaw_deg` about world z, then tilted by `pitch_deg` about its own y axis.
    fn surface(&self, index: usize, dto: &SurfaceDto) -> Result<Placed, SceneError> {
        let item = label("surface", index, &dto.name);
        self.numbers(&item, "center", &dto.center.0, Rule::Finite)?;
        self.numbers(&item, "size", &dto.size.0, Rule::Positive)?;
        let pitch = self.number(&item, "pitch_deg", dto.pitch_deg, Rule::Slope)?;
        let yaw = self.number(&item, "yaw_deg", dto.yaw_deg, Rule::Finite)?;
        // Rotating by −pitch about y tips the surface's +x up for a positive pitch.
        let rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw.to_radians())
            * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -pitch.to_radians());
        let pose = Isometry3::from_parts(Translation3::from(Vector3::from(dto.center.0)), rotation);
        let [x, y] = dto.size.0.map(|s| s / 2.0);
        let polygon = vec![[-x, -y], [x, -y], [x, y], [-x, y]];
        let footprint = polygon
            .iter()
            .map(|&[u, v]| (pose * Point3::new(u, v, 0.0)).xy().coords)
            .collect();
        Ok(Placed {
            label: item,
            surface: SupportSurface {
                name: dto.name.clone(),
                pose,
                polygon: Some(polygon),
            },
            footprint,
        })
    }

    /// A railing; `available` defaults to the whole path (`[0, length]`).
    fn railing(
        &self,
        index: usize,
        dto: &RailingDto,
        length: f64,
    ) -> Result<HandAffordance, SceneError> {
        let item = label("railing", index, &dto.name);
        self.numbers(&item, "start", &dto.start.0, Rule::Finite)?;
        self.numbers(&item, "end", &dto.end.0, Rule::Finite)?;
        let radius = self.number(&item, "radius", dto.radius, Rule::Positive)?;
        let available = dto.available.as_ref().map_or([0.0, length], |a| a.0);
        self.numbers(&item, "available", &available, Rule::Finite)?;
        if available[1] < available[0] {
            return Err(SceneError::BadNumber {
                origin: self.origin.to_owned(),
                item,
                key: "available[1]".into(),
                value: available[1],
                rule: "must not be less than available[0]",
            });
        }
        if dto.start.0 == dto.end.0 {
            return Err(SceneError::DegenerateRailing {
                origin: self.origin.to_owned(),
                item,
                point: dto.start.0,
            });
        }
        Ok(HandAffordance {
            name: dto.name.clone(),
            start: dto.start.0.into(),
            end: dto.end.0.into(),
            radius,
            available,
        })
    }

    fn unique_names<'n>(
        &self,
        table: &str,
        names: impl Iterator<Item = &'n str>,
    ) -> Result<(), SceneError> {
        let names: Vec<&str> = names.collect();
        for (i, name) in names.iter().enumerate() {
            if let Some(first) = names[..i].iter().position(|n| n == name) {
                return Err(SceneError::DuplicateName {
                    origin: self.origin.to_owned(),
                    item: label(table, i, name),
                    first: label(table, first, name),
                });
            }
        }
        Ok(())
    }

    fn no_overlap(&self, placed: &[Placed]) -> Result<(), SceneError> {
        for (j, second) in placed.iter().enumerate() {
            for first in &placed[..j] {
                let depth = overlap_depth(&first.footprint, &second.footprint);
                if depth > OVERLAP_TOLERANCE_M {
                    return Err(SceneError::Overlap {
                        origin: self.origin.to_owned(),
                        first: first.label.clone(),
                        second: second.label.clone(),
                        depth,
                    });
                }
            }
        }
        Ok(())
    }

    /// The surface under the path's `key` end (`start` or `goal`).
    fn end_surface(
        &self,
        placed: &[Placed],
        key: &'static str,
        point: Vector2<f64>,
    ) -> Result<usize, SceneError> {
        surface_under(placed, point).ok_or_else(|| SceneError::EndOffSurfaces {
            origin: self.origin.to_owned(),
            key,
            point: point.into(),
        })
    }

    /// Samples the straight path every [`PATH_SAMPLE_M`]: each sample over a surface, and no
    /// step higher than [`MAX_RISE_M`] where the path crosses from one surface to the next
    /// (measured on both planes halfway between the last sample on one and the first on the
    /// other, so a ramp joining a floor has none).
    fn walk(
        &self,
        placed: &[Placed],
        start: Vector2<f64>,
        goal: Vector2<f64>,
    ) -> Result<(), SceneError> {
        let length = (goal - start).norm();
        let samples = (length / PATH_SAMPLE_M).ceil().max(1.0) as usize;
        let mut previous: Option<(usize, Vector2<f64>)> = None;
        for i in 0..=samples {
            let fraction = i as f64 / samples as f64;
            let (point, along) = (start + (goal - start) * fraction, length * fraction);
            let Some(current) = surface_under(placed, point) else {
                return Err(SceneError::PathLeavesSurfaces {
                    origin: self.origin.to_owned(),
                    point: point.into(),
                    along,
                });
            };
            if let Some((last, last_point)) = previous.filter(|&(last, _)| last != current) {
                let middle = (point + last_point) / 2.0;
                let rise = placed[current].elevation(middle) - placed[last].elevation(middle);
                if rise.abs() > MAX_RISE_M {
                    return Err(SceneError::RiseTooHigh {
                        origin: self.origin.to_owned(),
                        from: placed[last].label.clone(),
                        to: placed[current].label.clone(),
                        rise,
                        along,
                    });
                }
            }
            previous = Some((current, point));
        }
        Ok(())
    }

    /// Every surface is connected to the start's by a chain of surfaces that touch (footprints
    /// within [`TOUCH_DISTANCE_M`]).
    fn reachable(&self, placed: &[Placed], start: usize) -> Result<(), SceneError> {
        let mut reached = vec![false; placed.len()];
        reached[start] = true;
        let mut frontier = vec![start];
        while let Some(from) = frontier.pop() {
            for (to, surface) in placed.iter().enumerate() {
                if !reached[to]
                    && footprint_gap(&placed[from].footprint, &surface.footprint)
                        <= TOUCH_DISTANCE_M
                {
                    reached[to] = true;
                    frontier.push(to);
                }
            }
        }
        let Some(lost) = reached.iter().position(|&r| !r) else {
            return Ok(());
        };
        let gap = placed
            .iter()
            .zip(&reached)
            .filter(|(_, r)| **r)
            .map(|(p, _)| footprint_gap(&p.footprint, &placed[lost].footprint))
            .fold(f64::INFINITY, f64::min);
        Err(SceneError::Unreachable {
            origin: self.origin.to_owned(),
            item: placed[lost].label.clone(),
            start: placed[start].label.clone(),
            gap,
        })
    }
}

/// The surface whose footprint is nearest to `point`, if within [`TOUCH_DISTANCE_M`] (the
/// first in file order of equally near ones).
fn surface_under(placed: &[Placed], point: Vector2<f64>) -> Option<usize> {
    placed
        .iter()
        .map(|p| distance_to_footprint(&p.footprint, point))
        .enumerate()
        .filter(|&(_, distance)| distance <= TOUCH_DISTANCE_M)
        .min_by(|(i, a), (j, b)| a.total_cmp(b).then(i.cmp(j)))
        .map(|(i, _)| i)
}

/// The edges of a closed polygon, each as (from, to).
fn edges(polygon: &[Vector2<f64>]) -> impl Iterator<Item = (Vector2<f64>, Vector2<f64>)> + '_ {
    polygon
        .iter()
        .zip(polygon.iter().cycle().skip(1))
        .map(|(&a, &b)| (a, b))
}

/// Horizontal distance from `point` to a convex counter-clockwise footprint (0 inside).
fn distance_to_footprint(footprint: &[Vector2<f64>], point: Vector2<f64>) -> f64 {
    if edges(footprint).all(|(a, b)| (b - a).perp(&(point - a)) >= 0.0) {
        return 0.0;
    }
    edges(footprint)
        .map(|(a, b)| {
            let edge = b - a;
            let t = ((point - a).dot(&edge) / edge.norm_squared()).clamp(0.0, 1.0);
            (a + edge * t - point).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Horizontal distance between two convex footprints that do not overlap (beyond the
/// tolerance): the nearest vertex of one to the other.
fn footprint_gap(a: &[Vector2<f64>], b: &[Vector2<f64>]) -> f64 {
    let nearest = |from: &[Vector2<f64>], to: &[Vector2<f64>]| {
        from.iter()
            .map(|&v| distance_to_footprint(to, v))
            .fold(f64::INFINITY, f64::min)
    };
    nearest(a, b).min(nearest(b, a))
}

/// How deep two convex footprints overlap: the smallest overlap of their projections on the
/// edge normals of both (separating axes); ≤ 0 when they only touch or are apart.
fn overlap_depth(a: &[Vector2<f64>], b: &[Vector2<f64>]) -> f64 {
    let project = |polygon: &[Vector2<f64>], axis: Vector2<f64>| {
        polygon
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                let s = v.dot(&axis);
                (lo.min(s), hi.max(s))
            })
    };
    edges(a)
        .chain(edges(b))
        .map(|(from, to)| {
            let axis = Vector2::new(from.y - to.y, to.x - from.x).normalize();
            let ((a_lo, a_hi), (b_lo, b_hi)) = (project(a, axis), project(b, axis));
            a_hi.min(b_hi) - a_lo.max(b_lo)
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn committed(name: &str) -> Scene {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../configs/scenes")
            .join(format!("{name}.toml"));
        Scene::from_path(&path).unwrap()
    }

    #[test]
    fn the_walk_environment_starts_at_the_origin() {
        let scene = committed("stairs-down-10cm");
        let env = scene.walk_environment();
        // The walk starts on the landing (z = 1 m in the scene), 1 m before its edge.
        let (start, z) = env.support_at(&Vector3::zeros()).unwrap();
        assert_eq!((start.name.as_str(), z), ("landing", 0.0));
        let (floor, z) = env.support_at(&Vector3::new(4.7, 0.0, -1.0)).unwrap();
        assert_eq!(floor.name, "floor");
        assert!((z + 1.0).abs() < 1e-12, "{z}");
        let lowest = env
            .surfaces
            .iter()
            .map(|s| s.pose.translation.z)
            .fold(f64::INFINITY, f64::min);
        assert!((lowest + 1.0).abs() < 1e-12, "{lowest}");
        // The first riser down, 1 m ahead.
        assert!(
            env.support_at(&Vector3::new(0.99, 0.0, 0.0))
                .unwrap()
                .0
                .name
                == "landing"
        );
        assert!(
            env.support_at(&Vector3::new(1.01, 0.0, 0.0))
                .unwrap()
                .0
                .name
                == "tread-9"
        );
    }

    #[test]
    fn the_walk_environment_turns_with_the_start_and_keeps_the_railings() {
        let mut scene = committed("railing");
        scene.start = Isometry3::from_parts(
            Translation3::new(1.0, 0.0, 0.0),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2),
        );
        let env = scene.walk_environment();
        let railing = &env.hand_affordances[0];
        let original = &scene.environment.hand_affordances[0];
        // Facing world +y from (1, 0): walk x = world y, walk y = 1 − world x.
        assert!(
            (railing.start - Vector3::new(-0.45, 1.5, 0.8)).norm() < 1e-12,
            "{railing:?}"
        );
        assert!(
            (railing.end - Vector3::new(-0.45, -4.5, 0.8)).norm() < 1e-12,
            "{railing:?}"
        );
        assert_eq!(
            (railing.radius, railing.available),
            (original.radius, original.available)
        );
    }

    #[test]
    fn the_path_length_is_measured_along_the_start_heading() {
        let scene = committed("stairs-down-10cm");
        assert!((scene.path_length() - 4.7).abs() < 1e-12);
        let mut turned = scene.clone();
        turned.start.rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.5);
        assert!((turned.path_length() - 4.7 * 0.5f64.cos()).abs() < 1e-12);
    }

    #[test]
    fn a_walk_goes_the_whole_path_or_its_first_metres_never_past_the_goal() {
        let scene = committed("railing");
        assert_eq!(scene.walk_length(None).unwrap(), 5.0);
        assert_eq!(scene.walk_length(Some(1.0)).unwrap(), 1.0);
        // Rounding in the length is the whole path.
        assert_eq!(scene.walk_length(Some(5.0 + 1e-9)).unwrap(), 5.0);
        let error = scene.walk_length(Some(5.5)).unwrap_err().to_string();
        assert!(
            error.contains("\"railing\"") && error.contains("5.5 m") && error.contains("5.000 m"),
            "{error}"
        );
    }
}
