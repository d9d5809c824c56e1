//! gapfleet's command line and the work behind it: batch experiments now; the fleet
//! coordinator and the demo follow.

pub mod experiment;
pub mod plots;
pub mod stats;
