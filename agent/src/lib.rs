//! gapfleet's planner core: everything a robot needs to decide how to move among people,
//! as pure functions of what it perceives, and, behind the default `runtime` feature, the
//! agent that runs it on a robot over Zenoh ([`runtime`]).
//!
//! A long-term planner, the Probabilistic Gap Planner ([`pgp`]), picks a subgoal towards gaps
//! in the crowd; a short-term planner drives towards it: [`dwa`], [`orca`], [`social_force`],
//! foIGP ([`igp`]), peek-and-pass ([`pnp`]) or anticipatory Social Force ([`asfm`]).
//! [`planner::PlannerStack`] composes them behind one interface, and [`guard::Guard`] puts the
//! safety layer ([`safety`]) under it.
//!
//! Outside [`runtime`], nothing here knows about Zenoh, Tokio, Rerun, clocks or unseeded
//! randomness: the same input gives the same output, bit for bit.

pub mod asfm;
pub mod dwa;
pub mod fastmath;
pub mod guard;
pub mod igp;
pub mod map;
pub mod math;
pub mod model;
pub mod obstacle_points;
pub mod orca;
pub mod pgp;
pub mod planner;
pub mod pnp;
pub mod prediction;
pub mod risk;
pub mod route;
#[cfg(feature = "runtime")]
pub mod runtime;
pub mod safety;
pub mod scan;
pub mod social_force;
pub mod visibility;
