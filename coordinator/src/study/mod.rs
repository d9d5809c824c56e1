//! Batch studies with the planners in-process, one module per study: the PGP paper's
//! open-space study ([`open_space`], summarised by [`summary`]), planners in recorded
//! pedestrians' places ([`replay`], the foIGP paper's protocol) and a warehouse fleet with and
//! without shared intents ([`intent_sharing`]); their statistics ([`stats`]) and figures
//! ([`plots`]). Every study's output depends only on its inputs, never on the thread count.
//!
//! Behind the default-on cargo feature `studies`: a coordinator built without it
//! (`--no-default-features`) links no plotting, font, rayon or progress bars.

pub mod csv_fields;
pub mod intent_sharing;
pub mod open_space;
pub mod plots;
pub mod replay;
pub mod stats;
pub mod summary;

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
    Plot(#[from] plots::PlotError),
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

/// Runs `work` on a pool of `threads` (all cores when `None`) with a progress bar of `total`
/// runs on stderr; `work` gets the callback to call after each run. Returns its result and the
/// number of threads used.
pub fn with_progress<T: Send>(
    threads: Option<usize>,
    total: u64,
    work: impl FnOnce(&(dyn Fn() + Sync)) -> T + Send,
) -> Result<(T, usize), rayon::ThreadPoolBuildError> {
    let threads =
        threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let bar = indicatif::ProgressBar::new(total).with_style(
        indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} runs, eta {eta}",
        )
        .expect("a valid progress template")
        .progress_chars("=> "),
    );
    let result = pool.install(|| work(&|| bar.inc(1)));
    bar.finish();
    Ok((result, threads))
}
