//! Batch studies with the planners in-process, one module per study:
//! - [`open_space`]: the PGP paper's open-space study (its rows and `runs.csv` in [`runs`],
//!   summarised by [`summary`]);
//! - [`playback`]: planners in recorded pedestrians' places (the foIGP paper's protocol);
//! - [`intent_sharing`]: a warehouse fleet with and without shared intents;
//! - [`hallway`] and [`laned`]: the peek-and-pass paper's hallway (Fig. 6) and laned crowd
//!   (Fig. 4);
//! - [`anticipatory`]: the anticipatory Social Force paper's two-body experiment;
//! - [`estimates`]: anticipatory Social Force's avoidance estimates on recorded and simulated
//!   crowds;
//! - [`traffic`]: fleet sizes × traffic policy × safety layer on the fleet sites, with fleet
//!   efficiency, stuck time by cause, gridlocks and deadlocks.
//!
//! Shared by them: statistics ([`stats`]), figures ([`plots`]), output folders ([`output`]) and
//! CSV fields ([`csv_fields`]). Every study's output depends only on its inputs, never on the
//! thread count.
//!
//! Behind the default-on cargo feature `studies`: a coordinator built without it
//! (`--no-default-features`) links no plotting, font or CSV, and has no `gapfleet study`.

pub mod anticipatory;
pub mod csv_fields;
pub mod estimates;
pub mod hallway;
pub mod intent_sharing;
pub mod laned;
pub mod open_space;
pub mod output;
pub mod playback;
pub mod plots;
pub mod runs;
pub mod stats;
pub mod summary;
pub mod traffic;

pub use output::{StudyError, write_json};

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
