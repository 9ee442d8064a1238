//! Why a demonstration could not be read, segmented or learned from. Every variant names the file
//! and the element (marker, parameter, frame, field) that is wrong.

use std::path::PathBuf;

/// An error while reading demonstrations or training/querying/retargeting the stance model.
#[derive(Debug, thiserror::Error)]
pub enum LearnError {
    /// The file could not be read.
    #[error("{path}: {error}")]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    /// The file is shorter than its own header says, or a field lies outside it.
    #[error(
        "{path}: truncated: {what} at byte {offset} lies beyond the end of the file ({len} bytes)"
    )]
    Truncated {
        path: PathBuf,
        what: String,
        offset: usize,
        len: usize,
    },
    /// The file is not in the format its manifest says, or a field has an impossible value.
    #[error("{path}: {message}")]
    Corrupt { path: PathBuf, message: String },
    /// A C3D file lacks a parameter the reader needs.
    #[error("{path}: C3D parameter {group}:{name} is missing")]
    MissingParameter {
        path: PathBuf,
        group: String,
        name: String,
    },
    /// None of the known marker sets (or joint sets) matches the file's labels.
    #[error("{path}: unknown marker set: {message}")]
    UnknownMarkerSet { path: PathBuf, message: String },
    /// A marker needed for segmentation is missing (gap) in a frame.
    #[error("{path}: marker {marker} has no valid position in frame {frame}")]
    MissingMarker {
        path: PathBuf,
        marker: String,
        frame: usize,
    },
    /// A trial loaded but is not a plausible human walk (wrong axes or units, wrong `forward`,
    /// no data, no steps, no progress): refused at load time, naming the reason, rather than
    /// training a model that fails later with an error that says nothing about the trial.
    #[error("{path}: refused trial `{trial}`: {reason}")]
    BadTrial {
        path: PathBuf,
        trial: String,
        reason: String,
    },
    /// The `demo.toml` manifest of a demonstration folder is invalid.
    #[error("{path}: {message}")]
    Manifest { path: PathBuf, message: String },
    /// A model file is malformed or inconsistent.
    #[error("model {path}: {message}")]
    Model { path: PathBuf, message: String },
    /// A query cannot be answered (bad distance, nothing learned, no admissible stance).
    #[error("query: {0}")]
    Query(String),
    /// Retargeting produced an invalid sequence.
    #[error("retargeting: {0}")]
    Retarget(String),
}

impl LearnError {
    pub(crate) fn corrupt(path: &std::path::Path, message: impl Into<String>) -> Self {
        LearnError::Corrupt {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }
}
