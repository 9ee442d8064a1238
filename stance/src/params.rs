//! Algorithm 1's parameters: the `[postprocess]` section of a robot config, with the
//! `[postprocess.dynamic]` overrides a dynamic walk post-processes with.

use std::path::{Path, PathBuf};

use kinematics::bounds::{Bound, Number, first_outside};
use kinematics::config_file::toml_message;
use kinematics::{ConfigFile, ConfigFileError};
use serde::{Deserialize, Serialize};

/// How a run of contacts of one end-effector is made static (pass 2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactUnification {
    /// Every stance of the run takes the run's first contact pose (the paper's choice).
    #[default]
    First,
    /// Every stance of the run takes the mean of the run's poses (the interpolation variant).
    Mean,
}

/// How a sequence is walked: each gait post-processes with its own limits (a dynamic walk
/// takes longer steps than a statically stable one), so the choice is made before
/// post-processing and travels with the sequence to the controller. Read from its name only
/// (anything else is refused as not `"static"` or `"dynamic"`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Gait {
    /// Quasi-static: the CoM stays over the support polygon; contact changes wait for targets
    /// and force-torque confirmation (the paper's controller, the safe fallback).
    #[default]
    Static,
    /// Timed steps on a linear-inverted-pendulum walking pattern with a stabilizer.
    Dynamic,
}

impl Gait {
    /// Lower-case name (`static`, `dynamic`), as in the configs.
    pub fn name(self) -> &'static str {
        match self {
            Self::Static => "static",
            Self::Dynamic => "dynamic",
        }
    }

    /// The gait a walk on the robot of `file` uses: `choice`, else the config's `[gait]
    /// default`, refused when the robot cannot walk it ([`Gait::available_in`]). Every client
    /// command that takes `--gait` resolves it here right after loading the config, so a
    /// refusal comes before any process is started or file written, not from walkd.
    pub fn for_walk(choice: Option<Self>, file: &ConfigFile) -> Result<Self, ParamsError> {
        let gait = Self::chosen_or_configured(choice, file)?;
        gait.available_in(file)?;
        Ok(gait)
    }

    /// Whether the robot of `file` can walk this gait: the static gait always, the dynamic gait
    /// only with a `[gait.dynamic]` table (its tuning; an empty one takes the defaults). The one
    /// home of this rule and of its message, shared by the client (which refuses up front) and
    /// walkd (`daemon::controller::GaitConfig::dynamic`, which refuses a submitted sequence).
    pub fn available_in(self, file: &ConfigFile) -> Result<(), GaitUnavailable> {
        let tuned = || {
            file.section("gait")
                .and_then(|gait| gait.get("dynamic"))
                .is_some_and(toml::Value::is_table)
        };
        match self {
            Self::Static => Ok(()),
            Self::Dynamic if tuned() => Ok(()),
            Self::Dynamic => Err(GaitUnavailable {
                path: file.path().to_owned(),
            }),
        }
    }

    /// `choice`, or the config's `[gait] default` when the user made none (a walk resolves its
    /// gait with [`Gait::for_walk`], which also checks that the robot can walk it).
    pub fn chosen_or_configured(
        choice: Option<Self>,
        file: &ConfigFile,
    ) -> Result<Self, ParamsError> {
        match choice {
            Some(gait) => Ok(gait),
            None => Self::configured_default(file),
        }
    }

    /// `[gait] default` of a robot config: the gait of a walk that does not ask for one
    /// (static when absent). Read here because both sides need it: the client post-processes
    /// with that gait's limits, the daemon walks a file that names no gait with it. The rest of
    /// `[gait]` is the daemon's.
    pub fn configured_default(file: &ConfigFile) -> Result<Self, ParamsError> {
        let Some(value) = file.section("gait").and_then(|gait| gait.get("default")) else {
            return Ok(Self::Static);
        };
        let fail = |message: String| ParamsError::Key {
            path: file.path().to_owned(),
            section: "gait",
            message,
        };
        value
            .as_str()
            .ok_or_else(|| fail(format!("`default` must be a string, not {value}")))?
            .parse()
            .map_err(|e: String| fail(format!("`default`: {e}")))
    }
}

impl<'de> Deserialize<'de> for Gait {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        /// Takes a name; says what is expected instead of anything else (serde's derived enum
        /// reader answers a number with "expected value", as if the JSON were broken).
        struct Name;
        impl serde::de::Visitor<'_> for Name {
            type Value = Gait;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("\"static\" or \"dynamic\"")
            }
            fn visit_str<E: serde::de::Error>(self, name: &str) -> Result<Gait, E> {
                name.parse()
                    .map_err(|_| E::invalid_value(serde::de::Unexpected::Str(name), &self))
            }
        }
        deserializer.deserialize_any(Name)
    }
}

impl std::str::FromStr for Gait {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        match text {
            "static" => Ok(Self::Static),
            "dynamic" => Ok(Self::Dynamic),
            other => Err(format!("unknown gait `{other}` (static or dynamic)")),
        }
    }
}

/// Parameters of Algorithm 1 (names as in the paper). Lengths in metres, angles in radians.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PostProcessParams {
    /// Sequence scaling factor `scf` ∈ (0, 1]: along-path displacements are multiplied by it.
    pub scf: f64,
    /// Maximal step size `s_max` (along-path distance between consecutive contacts of one foot).
    pub s_max: f64,
    /// Minimal orthogonal (lateral) distance between the feet centres `o_min`.
    pub o_min: f64,
    /// Maximal orthogonal (lateral) distance between the feet centres `o_max`.
    pub o_max: f64,
    /// Swing-foot roll limit `α_x` (relative to its surface).
    pub alpha_x: f64,
    /// Swing-foot pitch limit `α_y` (relative to its surface).
    pub alpha_y: f64,
    /// Swing-foot yaw limit `α_z` (relative to the walking direction).
    pub alpha_z: f64,
    /// Minimal swing-foot height above its surface `h_min`.
    pub h_min: f64,
    /// Maximal swing-foot height above its surface `h_max`.
    pub h_max: f64,
    /// How much a step's rise or drop `h` counts against `s_max` on terrain: a step of `d` along
    /// the path is `√(d² + (rise_weight · h)²)` long. 1 (the default): the step in space. More:
    /// shorter steps up and down, for knees that lift or lower the whole body over the step
    /// (docs/scenes.md, "Step length up and down").
    #[serde(default = "PostProcessParams::default_rise_weight")]
    pub rise_weight: f64,
    /// The longest step, in space, from one stair tread to the next but one (two risers up or
    /// down): where the treads keep a foot's steps within it, one foot per stair, as people
    /// climb; both feet on each stair otherwise. Absent: a stair is stepped over only within
    /// `s_max` (with `rise_weight`), which on 0.30 m treads means both feet on each stair
    /// (docs/scenes.md, "One foot per stair").
    #[serde(default)]
    pub stair_s_max: Option<f64>,
    /// Pass 2 variant; `first` unless the config says `contact_unification = "mean"`.
    #[serde(default)]
    pub contact_unification: ContactUnification,
    /// The gait these limits are for (`[postprocess]`: static, with `[postprocess.dynamic]`:
    /// dynamic); the post-processed sequence carries it to the controller.
    #[serde(skip)]
    pub gait: Gait,
}

/// Why a robot cannot walk a gait: the dynamic gait needs its tuning, `[gait.dynamic]`, and the
/// robot config has none. A type of its own so the client and walkd refuse with one message,
/// which names the file, the missing section and the fix.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "the robot config {path} has no [gait.dynamic] section, so this robot walks statically \
     only; add a [gait.dynamic] section to {path}: an empty one takes the defaults \
     (docs/controller.md, \"Dynamic gait\"), or derive one for the robot with \
     `walkctl init-robot`",
    path = path.display()
)]
pub struct GaitUnavailable {
    /// The robot config without `[gait.dynamic]`.
    pub path: PathBuf,
}

/// Why the `[postprocess]` section, or the gait a walk asks for, could not be used.
#[derive(Debug, thiserror::Error)]
pub enum ParamsError {
    /// The config file could not be read or parsed.
    #[error(transparent)]
    File(#[from] ConfigFileError),
    /// No `[postprocess]` table.
    #[error("{path}: missing section [postprocess]")]
    MissingSection { path: PathBuf },
    /// A missing, unknown or mistyped key in `[postprocess]` or `[postprocess.dynamic]`.
    #[error("{path}: [{section}]: {message}")]
    Key {
        path: PathBuf,
        section: &'static str,
        message: String,
    },
    /// The robot cannot walk the gait asked for ([`Gait::for_walk`]).
    #[error(transparent)]
    Unavailable(#[from] GaitUnavailable),
    /// A value outside its domain.
    #[error("{origin}: [postprocess] key `{key}`: {message}")]
    Invalid {
        origin: String,
        key: &'static str,
        message: String,
    },
}

/// The table of per-gait overrides inside `[postprocess]`.
const DYNAMIC_OVERRIDES: &str = "dynamic";

impl PostProcessParams {
    /// `rise_weight` unless configured: a step's limit is on its length in space.
    fn default_rise_weight() -> f64 {
        1.0
    }

    /// Reads the `[postprocess]` section of the robot config at `path` (the static gait's).
    pub fn from_config_path(path: &Path) -> Result<Self, ParamsError> {
        Self::from_config(&ConfigFile::load(path)?)
    }

    /// Reads the `[postprocess]` section of a robot config's text (`path` names it in errors).
    pub fn from_config_str(text: &str, path: &Path) -> Result<Self, ParamsError> {
        Self::from_config(&ConfigFile::parse(text, path)?)
    }

    /// Reads the `[postprocess]` section of a loaded robot config (the static gait's).
    pub fn from_config(file: &ConfigFile) -> Result<Self, ParamsError> {
        Self::from_config_for(file, Gait::Static)
    }

    /// Reads the parameters `gait` post-processes with: `[postprocess]`, for the dynamic gait
    /// with the keys of `[postprocess.dynamic]` replacing their `[postprocess]` values. The
    /// overrides are checked whichever gait is asked for, so a typo in them never waits for a
    /// dynamic walk.
    pub fn from_config_for(file: &ConfigFile, gait: Gait) -> Result<Self, ParamsError> {
        let path = file.path();
        let mut section = file
            .section("postprocess")
            .and_then(toml::Value::as_table)
            .ok_or_else(|| ParamsError::MissingSection {
                path: path.to_owned(),
            })?
            .clone();
        let overrides = match section.remove(DYNAMIC_OVERRIDES) {
            None => toml::Table::new(),
            Some(toml::Value::Table(overrides)) => overrides,
            Some(_) => {
                return Err(ParamsError::Key {
                    path: path.to_owned(),
                    section: "postprocess",
                    message: format!("`{DYNAMIC_OVERRIDES}` must be a table of overrides"),
                });
            }
        };
        let parse = |table: toml::Table, section: &'static str, origin: String| {
            let params: Self =
                toml::Value::Table(table)
                    .try_into()
                    .map_err(|e: toml::de::Error| ParamsError::Key {
                        path: path.to_owned(),
                        section,
                        message: toml_message(&e),
                    })?;
            params.validate(&origin)?;
            Ok::<_, ParamsError>(params)
        };
        let origin = file.origin();
        let static_params = parse(section.clone(), "postprocess", origin.clone())?;
        section.extend(overrides);
        let dynamic_origin = format!("{origin} (with [postprocess.{DYNAMIC_OVERRIDES}])");
        let dynamic_params = Self {
            gait: Gait::Dynamic,
            ..parse(section, "postprocess.dynamic", dynamic_origin)?
        };
        Ok(match gait {
            Gait::Static => static_params,
            Gait::Dynamic => dynamic_params,
        })
    }

    /// Checks every value against its documented range (docs/stance.md, "[postprocess]") and
    /// each minimum against its maximum; `origin` names the source in the error (the file, or
    /// the file with command-line overrides).
    pub fn validate(&self, origin: &str) -> Result<(), ParamsError> {
        let invalid = |key: &'static str, message: String| {
            Err(ParamsError::Invalid {
                origin: origin.to_owned(),
                key,
                message,
            })
        };
        if let Some(violation) = first_outside(&self.bounds()) {
            return invalid(
                violation.key,
                format!(
                    "{} {}",
                    Number(violation.value),
                    violation.range.requirement()
                ),
            );
        }
        if self.o_min > self.o_max {
            return invalid("o_min", "must not exceed o_max".to_owned());
        }
        if self.h_min > self.h_max {
            return invalid("h_min", "must not exceed h_max".to_owned());
        }
        Ok(())
    }

    /// The section's table: every numeric key, its value and its range, one line a key.
    pub fn bounds(&self) -> Vec<Bound> {
        vec![
            Bound::new("scf", self.scf, 0.01, 1.0),
            Bound::new("s_max", self.s_max, 0.01, 2.0),
            Bound::new("o_min", self.o_min, 0.0, 1.0),
            Bound::new("o_max", self.o_max, 0.0, 1.0),
            // Below π/2: a swing foot turned upright or further is no foot to step on.
            Bound::new("alpha_x", self.alpha_x, 0.0, 1.5),
            Bound::new("alpha_y", self.alpha_y, 0.0, 1.5),
            Bound::new("alpha_z", self.alpha_z, 0.0, 1.5),
            Bound::new("h_min", self.h_min, 0.0, 0.5),
            Bound::new("h_max", self.h_max, 0.0, 0.5),
            Bound::new("rise_weight", self.rise_weight, 1.0, 10.0),
            Bound::optional("stair_s_max", self.stair_s_max, 0.01, 2.0),
        ]
    }

    /// The swing-foot rotation limits `[α_x, α_y, α_z]`.
    pub fn alpha(&self) -> [f64; 3] {
        [self.alpha_x, self.alpha_y, self.alpha_z]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SECTION: &str = "[postprocess]\nscf = 0.4\ns_max = 0.3\no_min = 0.18\no_max = 0.3\n\
        alpha_x = 0.1\nalpha_y = 0.2\nalpha_z = 0.3\nh_min = 0.03\nh_max = 0.1\n";

    #[test]
    fn reads_the_section() {
        let p = PostProcessParams::from_config_str(SECTION, Path::new("r.toml")).unwrap();
        assert_eq!((p.scf, p.h_max), (0.4, 0.1));
        assert_eq!(p.contact_unification, ContactUnification::First);
    }

    #[test]
    fn typo_names_file_and_key() {
        let text = SECTION.replace("s_max", "smax");
        let err = PostProcessParams::from_config_str(&text, Path::new("r.toml")).unwrap_err();
        let message = err.to_string();
        assert!(
            message.contains("r.toml") && message.contains("smax"),
            "{message}"
        );
    }

    #[test]
    fn dynamic_overrides_replace_their_keys_only() {
        let text = format!("{SECTION}\n[postprocess.dynamic]\ns_max = 0.45\nscf = 0.3\n");
        let path = Path::new("r.toml");
        let dynamic = PostProcessParams::from_config_for(
            &ConfigFile::parse(&text, path).unwrap(),
            Gait::Dynamic,
        )
        .unwrap();
        assert_eq!(
            (dynamic.s_max, dynamic.scf, dynamic.h_max, dynamic.gait),
            (0.45, 0.3, 0.1, Gait::Dynamic)
        );
        let fixed = PostProcessParams::from_config_str(&text, path).unwrap();
        assert_eq!(
            (fixed.s_max, fixed.scf, fixed.gait),
            (0.3, 0.4, Gait::Static)
        );
        let without = PostProcessParams::from_config_for(
            &ConfigFile::parse(SECTION, path).unwrap(),
            Gait::Dynamic,
        )
        .unwrap();
        assert_eq!(
            without,
            PostProcessParams {
                gait: Gait::Dynamic,
                ..fixed
            }
        );
    }

    #[test]
    fn the_default_gait_is_static_unless_the_config_says_otherwise() {
        let read = |text: &str| {
            Gait::configured_default(&ConfigFile::parse(text, Path::new("r.toml")).unwrap())
        };
        assert_eq!(read("").unwrap(), Gait::Static);
        assert_eq!(read("[gait]\n").unwrap(), Gait::Static);
        assert_eq!(
            read("[gait]\ndefault = \"dynamic\"\n").unwrap(),
            Gait::Dynamic
        );
        for bad in ["[gait]\ndefault = \"fast\"\n", "[gait]\ndefault = 1\n"] {
            let error = read(bad).unwrap_err().to_string();
            assert!(
                error.contains("r.toml") && error.contains("[gait]") && error.contains("default"),
                "{error}"
            );
        }
    }

    #[test]
    fn the_dynamic_gait_needs_its_section_and_the_refusal_names_the_file_and_the_fix() {
        let path = Path::new("configs/robot.toml");
        let file = |text: &str| ConfigFile::parse(text, path).unwrap();
        for text in ["", "[gait]\n", "[gait]\ndefault = \"static\"\n"] {
            assert_eq!(Gait::Static.available_in(&file(text)), Ok(()), "{text:?}");
            let error = Gait::Dynamic.available_in(&file(text)).unwrap_err();
            assert_eq!(error.path, path);
            let message = error.to_string();
            for part in [
                "the robot config configs/robot.toml has no [gait.dynamic] section",
                "add a [gait.dynamic] section to configs/robot.toml: an empty one takes the \
                 defaults (docs/controller.md, \"Dynamic gait\")",
                "`walkctl init-robot`",
            ] {
                assert!(message.contains(part), "{part:?} not in {message:?}");
            }
        }
        for text in [
            "[gait.dynamic]\n",
            "[gait]\n[gait.dynamic]\nsingle_support_s = 0.6\n",
        ] {
            for gait in [Gait::Static, Gait::Dynamic] {
                assert_eq!(gait.available_in(&file(text)), Ok(()), "{gait:?} {text:?}");
            }
        }
        // Not a table: no tuning either.
        assert!(
            Gait::Dynamic
                .available_in(&file("[gait]\ndynamic = 1\n"))
                .is_err()
        );
    }

    #[test]
    fn a_walk_takes_the_chosen_or_the_default_gait_if_the_robot_can_walk_it() {
        let file = |text: &str| ConfigFile::parse(text, Path::new("r.toml")).unwrap();
        let statically = file("[gait]\ndefault = \"static\"\n");
        assert_eq!(Gait::for_walk(None, &statically).unwrap(), Gait::Static);
        let refused = Gait::for_walk(Some(Gait::Dynamic), &statically).unwrap_err();
        assert!(
            matches!(&refused, ParamsError::Unavailable(GaitUnavailable { path }) if path == Path::new("r.toml")),
            "{refused:?}"
        );
        let dynamic = file("[gait]\ndefault = \"dynamic\"\n[gait.dynamic]\n");
        assert_eq!(Gait::for_walk(None, &dynamic).unwrap(), Gait::Dynamic);
        assert_eq!(
            Gait::for_walk(Some(Gait::Static), &dynamic).unwrap(),
            Gait::Static
        );
        // A dynamic default without its section (walkd refuses such a config at load).
        assert!(Gait::for_walk(None, &file("[gait]\ndefault = \"dynamic\"\n")).is_err());
    }

    #[test]
    fn an_unknown_override_names_its_table_for_every_gait() {
        let text = format!("{SECTION}\n[postprocess.dynamic]\nsmax = 0.45\n");
        let err = PostProcessParams::from_config_str(&text, Path::new("r.toml")).unwrap_err();
        let message = err.to_string();
        assert!(
            message.contains("[postprocess.dynamic]") && message.contains("smax"),
            "{message}"
        );
    }

    #[test]
    fn out_of_domain_value_is_refused() {
        let text = SECTION.replace("scf = 0.4", "scf = 1.5");
        let err = PostProcessParams::from_config_str(&text, Path::new("r.toml")).unwrap_err();
        assert!(err.to_string().contains("`scf`"), "{err}");
    }

    #[test]
    fn the_rise_weight_defaults_to_the_step_in_space_and_is_checked() {
        let path = Path::new("r.toml");
        let params = PostProcessParams::from_config_str(SECTION, path).unwrap();
        assert_eq!(params.rise_weight, 1.0);
        let text = format!("{SECTION}\n[postprocess.dynamic]\nrise_weight = 3.5\n");
        let file = ConfigFile::parse(&text, path).unwrap();
        let dynamic = PostProcessParams::from_config_for(&file, Gait::Dynamic).unwrap();
        assert_eq!(dynamic.rise_weight, 3.5);
        for bad in ["0.5", "nan", "11"] {
            let text = format!("{SECTION}\nrise_weight = {bad}\n");
            let err = PostProcessParams::from_config_str(&text, path).unwrap_err();
            assert!(err.to_string().contains("`rise_weight`"), "{bad}: {err}");
        }
    }
}
