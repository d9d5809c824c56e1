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
//! Every study is a [`Study`]: independent runs, each a pure function of its key, played by
//! the one [`Runner`] (thread pool, progress bar, a checkpoint saved as each run ends, and
//! resume). Shared by them besides: statistics ([`stats`]), figures ([`plots`]), output files
//! ([`output`]) and CSV fields ([`csv_fields`]). Every study's output depends only on its
//! inputs, never on the thread count or on resuming.
//!
//! The crate depends on the planner core (`agent` without its runtime) and `world-sim`, not
//! on Zenoh. `gapfleet study` links it behind the coordinator's default-on cargo feature
//! `studies`; built without it (`--no-default-features`), the coordinator links no plotting,
//! font or CSV.

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
pub mod runner;
pub mod runs;
pub mod stats;
pub mod summary;
pub mod traffic;

pub use output::{StudyError, write_json};
pub use runner::{Finished, RunError, Runner, Study};
