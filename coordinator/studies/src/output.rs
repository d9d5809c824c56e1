//! Where the studies' outputs go: their error type and JSON files.

use super::plots::PlotError;
use std::path::{Path, PathBuf};

/// Why a study could not write its outputs.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A file or folder could not be written.
    #[error("writing {path}: {source}")]
    Io {
        /// Where.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A figure could not be drawn.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// The scenario has no warehouse.
    #[error(transparent)]
    NotAWarehouse(#[from] world_sim::fleet::NotAWarehouse),
}

impl StudyError {
    /// `map_err` for I/O on `path`.
    pub fn io(path: &Path) -> impl FnOnce(std::io::Error) -> Self + '_ {
        move |source| Self::Io {
            path: path.to_owned(),
            source,
        }
    }
}

/// Writes `value` as pretty JSON with a final newline.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<(), StudyError> {
    // Plain data (numbers, strings, lists) always serialises.
    let text = serde_json::to_string_pretty(value).expect("study outputs serialise to JSON");
    std::fs::write(path, text + "\n").map_err(StudyError::io(path))
}
