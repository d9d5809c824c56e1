//! gapfleet's world: a deterministic fixed-step simulation of people and robots sharing
//! space, the scenarios that describe it, and the social metrics that judge the robots.
//!
//! People walk by PySocialForce's Social Force Model ([`crowd`]; the force law is shared with
//! the planner core, see `agent::social_force`), in groups, reacting to robots as to other people. Robots execute
//! planner commands within their limits. Everything random is drawn from seeded streams; there
//! is no clock and no transport here.

pub mod crowd;
pub mod dataset;
pub mod efficiency;
pub mod episode;
pub mod fleet;
pub mod floor_plan;
pub mod impact;
pub mod metrics;
pub mod playback;
pub mod robot;
pub mod scenario;
pub mod stuck;
pub mod traffic;
pub mod traffic_policy;
pub mod warehouse;
pub mod world;
