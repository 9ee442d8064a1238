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
    /// A top-level key is not one of [`SECTIONS`].
    #[error("{path}: unknown section [{name}] (a robot config has {})", SECTIONS.join(", "))]
    UnknownSection {
        /// The file.
        path: PathBuf,
        /// The unknown key.
        name: String,
    },
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
    fn toml_errors_name_the_file() {
        let error = ConfigFile::parse("[robot\n", Path::new("r.toml")).unwrap_err();
        assert!(
            error.to_string().starts_with("r.toml is not valid TOML"),
            "{error}"
        );
    }
}
