//! The work behind the `gapfleet` binary: the fleet coordinator (a warehouse world served to
//! agents over Zenoh, the in-process demo, the dashboard observer), a secured site's
//! credentials and Zenoh configs, benchmarks that size a deployment, and the batch studies (behind the default-on `studies` feature).

pub mod bench;
pub mod fleet;
pub mod site;
#[cfg(feature = "studies")]
pub mod study;
