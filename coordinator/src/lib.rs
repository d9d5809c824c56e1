//! The work behind the `gapfleet` binary: [`serve`], the coordinator's loop (a warehouse world,
//! `world_sim::fleet`, served to agents over Zenoh; the in-process demo, the robots' hardware,
//! the journal, the dashboard observer); [`site`], a secured site's credentials and Zenoh
//! configs; [`bench`], benchmarks that size a deployment; and [`study`], the batch studies
//! (behind the default-on `studies` feature).

pub mod bench;
pub mod serve;
pub mod site;
#[cfg(feature = "studies")]
pub mod study;
