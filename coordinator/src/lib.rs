//! The work behind the `gapfleet` binary: [`serve`], the coordinator's loop (a warehouse world,
//! `world_sim::fleet`, served to agents over Zenoh; the in-process demo, the robots' hardware,
//! the journal, the dashboard observer); [`site`], a secured site's credentials and Zenoh
//! configs; and [`bench`](mod@bench), benchmarks that size a deployment. The batch studies are the
//! `studies` crate (`coordinator/studies`), linked behind the default-on `studies` feature.

pub mod bench;
pub mod serve;
pub mod site;
