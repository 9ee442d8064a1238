//! The robot config file (`configs/<robot>.toml`), read and parsed once.
//!
//! One file, one section per consumer: `[robot]` (this crate), `[postprocess]` (stance),
//! `[controller]` and `[gait]` (the daemon's controller), `[runtime]` (the daemon and its
//! adapters). [`ConfigFile::load`] reads and parses it and refuses a section nobody reads (a
//! typo such as `[runtme]` would otherwise leave its keys silently unused); each crate then
//! validates its own section from [`ConfigFile::section`], naming the file and the key in its
//! errors.

use std::path::{Path, PathBuf};

/// The sections a robot config may have.
pub const SECTIONS: [&str; 5] = ["robot", "postprocess", "controller", "gait", "runtime"];

/// A parsed robot config file.
#[derive(Debug, Clone)]
pub struct ConfigFile {
    path: PathBuf,
    table: toml::Table,
}

/// Why a config file cannot be read at all (each section's own errors are its crate's).
#[derive(Debug, thiserror::Error)]
pub enum ConfigFileError {
    /// The file could not be read.
    #[error("cannot read robot config {path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        error: std::io::Error,
    },
    /// The file is not TOML.
    #[error("{path} is not valid TOML: {message}")]
    Toml {
        /// The file.
        path: PathBuf,
        /// The parser's message (line and column).
        message: String,
    },
    /// An override (`section.key=value`) is malformed or names no section.
    #[error("{path}: override `{assignment}`: {message}")]
    Override {
        /// The file overridden.
        path: PathBuf,
        /// The override as given.
        assignment: String,
        /// What is wrong.
        message: String,
    },
    /// A top-level key is not one of [`SECTIONS`].
    #[error("{path}: unknown section [{name}] (a robot config has {})", SECTIONS.join(", "))]
    UnknownSection {
        /// The file.
        path: PathBuf,
        /// The unknown key.
        name: String,
    },
}

/// A TOML value error as one line that names the key: `toml` keeps the key path out of
/// [`toml::de::Error::message`] ("invalid value: integer `-1`, expected u32") and adds it on a
/// line of its own in the error's text; this joins the two ("... expected u32 in `spin_us`").
pub fn toml_message(error: &toml::de::Error) -> String {
    error.to_string().trim_end().replace('\n', " ")
}

impl ConfigFile {
    /// Reads and parses the file at `path`.
    pub fn load(path: &Path) -> Result<Self, ConfigFileError> {
        let text = std::fs::read_to_string(path).map_err(|error| ConfigFileError::Io {
            path: path.to_owned(),
            error,
        })?;
        Self::parse(&text, path)
    }

    /// Parses `text`; `path` names it in errors and anchors relative paths in it.
    pub fn parse(text: &str, path: &Path) -> Result<Self, ConfigFileError> {
        let table: toml::Table =
            text.parse()
                .map_err(|e: toml::de::Error| ConfigFileError::Toml {
                    path: path.to_owned(),
                    message: e.to_string(),
                })?;
        if let Some(name) = table.keys().find(|key| !SECTIONS.contains(&key.as_str())) {
            return Err(ConfigFileError::UnknownSection {
                path: path.to_owned(),
                name: name.clone(),
            });
        }
        Ok(Self {
            path: path.to_owned(),
            table,
        })
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The file's path for error messages.
    pub fn origin(&self) -> String {
        self.path.display().to_string()
    }

    /// `relative` resolved against the file's directory (absolute paths stay as they are).
    pub fn resolve(&self, relative: &Path) -> PathBuf {
        self.path.parent().unwrap_or(Path::new(".")).join(relative)
    }

    /// Replaces one value, `assignment` being `section.key=value` with a dotted path into the
    /// file (`gait.dynamic.single_support_s=0.5`, `postprocess.dynamic.s_max=0.45`) and a TOML
    /// value (a bare word is taken as a string). Tables on the way are created; the section
    /// must be one of [`SECTIONS`]. The key is checked when its section is read, like the
    /// file's own keys. For experiments and sweeps that vary a parameter without editing the
    /// config.
    pub fn set(&mut self, assignment: &str) -> Result<(), ConfigFileError> {
        let fail = |message: &str| ConfigFileError::Override {
            path: self.path.clone(),
            assignment: assignment.to_owned(),
            message: message.to_owned(),
        };
        let (key, text) = assignment
            .split_once('=')
            .ok_or_else(|| fail("expected section.key=value"))?;
        let path: Vec<&str> = key.trim().split('.').collect();
        if path.len() < 2 || path.iter().any(|part| part.is_empty()) {
            return Err(fail("expected section.key=value"));
        }
        if !SECTIONS.contains(&path[0]) {
            return Err(fail(&format!(
                "unknown section [{}] (a robot config has {})",
                path[0],
                SECTIONS.join(", ")
            )));
        }
        let text = text.trim();
        let value = format!("v = {text}")
            .parse::<toml::Table>()
            .ok()
            .and_then(|mut table| table.remove("v"))
            .unwrap_or_else(|| toml::Value::String(text.to_owned()));
        let (last, tables) = path.split_last().expect("at least two parts");
        let mut table = &mut self.table;
        for part in tables {
            let entry = table
                .entry(part.to_string())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            table = entry
                .as_table_mut()
                .ok_or_else(|| fail(&format!("`{part}` is a value, not a table")))?;
        }
        table.insert(last.to_string(), value);
        Ok(())
    }

    /// A section, if the file has it.
    pub fn section(&self, name: &str) -> Option<&toml::Value> {
        debug_assert!(SECTIONS.contains(&name), "unknown section {name}");
        self.table.get(name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unknown_section_is_named() {
        let error = ConfigFile::parse("[robot]\n[runtme]\nx = 1\n", Path::new("r.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("r.toml") && error.contains("[runtme]"),
            "{error}"
        );
        let file = ConfigFile::parse("[runtime]\nx = 1\n", Path::new("dir/r.toml")).unwrap();
        assert!(file.section("runtime").is_some() && file.section("robot").is_none());
        assert_eq!(file.resolve(Path::new("a.urdf")), Path::new("dir/a.urdf"));
    }

    #[test]
    fn overrides_replace_or_add_values_in_known_sections() {
        let mut file = ConfigFile::parse(
            "[gait.dynamic]\nsingle_support_s = 0.7\n",
            Path::new("r.toml"),
        )
        .unwrap();
        file.set("gait.dynamic.single_support_s=0.5").unwrap();
        file.set("gait.default = dynamic").unwrap();
        file.set("postprocess.dynamic.s_max=0.45").unwrap();
        let gait = file.section("gait").unwrap();
        assert_eq!(gait["dynamic"]["single_support_s"].as_float(), Some(0.5));
        assert_eq!(gait["default"].as_str(), Some("dynamic"));
        let postprocess = file.section("postprocess").unwrap();
        assert_eq!(postprocess["dynamic"]["s_max"].as_float(), Some(0.45));
        for (bad, named) in [
            ("gait.dynamic.single_support_s", "section.key=value"),
            ("gaet.default=static", "[gaet]"),
            ("gait.dynamic.single_support_s.x=1", "is a value"),
        ] {
            let error = file.set(bad).unwrap_err().to_string();
            assert!(error.contains(named) && error.contains("r.toml"), "{error}");
        }
    }

    #[test]
    fn a_badly_typed_value_is_described_with_its_key() {
        #[derive(Debug, serde::Deserialize)]
        #[allow(dead_code)]
        struct Section {
            spin_us: u32,
        }
        let table: toml::Table = "spin_us = -1".parse().unwrap();
        let error = toml::Value::Table(table).try_into::<Section>().unwrap_err();
        assert_eq!(
            toml_message(&error),
            "invalid value: integer `-1`, expected u32 in `spin_us`"
        );
    }

    #[test]
    fn toml_errors_name_the_file() {
        let error = ConfigFile::parse("[robot\n", Path::new("r.toml")).unwrap_err();
        assert!(
            error.to_string().starts_with("r.toml is not valid TOML"),
            "{error}"
        );
    }
}
