//! gapfleet's command line and the work behind it: batch experiments, the fleet coordinator
//! (a warehouse world served over Zenoh) and the in-process demo.

pub mod bench;
pub mod dashboard;
pub mod demo;
pub mod experiment;
pub mod machine;
pub mod plots;
pub mod replay_study;
pub mod server;
pub mod stats;
