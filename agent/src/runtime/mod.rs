//! The agent runtime: one robot's planner stack on the fleet's Zenoh network (feature
//! `runtime`; the planner core never depends on it).
//!
//! An agent declares a liveliness token `…/alive/<id>`, subscribes to its observations, plans on
//! the newest one (a slow plan skips the observations that arrived meanwhile) and publishes its
//! command and intent. It fetches the static map from the
//! coordinator's queryable whenever an observation names a map version it does not hold, and
//! keeps the robot stopped until it has one. If observations stop for longer than
//! [`AgentConfig::obs_timeout`], or the coordinator's liveliness token `…/coordinator`
//! disappears, it publishes a safe-stop command; on shutdown it publishes one more and
//! withdraws its token. Bad messages are counted and logged, never fatal.

mod agent;
mod faults;
pub mod ros;
pub mod standalone;
pub mod wire;

pub use agent::run_agent;

use crate::planner::PlannerSpec;
use crate::safety::SafetyLimits;
use schemas::Keys;
use std::sync::Arc;
use std::sync::atomic::AtomicU64;
use std::time::Duration;

/// Observations may pause this long before the agent stops its robot: 0.4 s, four control
/// periods, so that the stop command is out within 0.5 s of the last observation even when a
/// loaded machine wakes the agent's timer late (50 ms late was seen with ten debug-build agents
/// on two cores) or one last observation was already on its way when the coordinator stopped.
pub const DEFAULT_OBS_TIMEOUT: Duration = Duration::from_millis(400);

/// In ROS mode, how long a plan waits for the robot's odometry of the observation's instant
/// when the two share a clock (`ros::RosLink::wait_for_odometry`).
const ODOMETRY_WAIT: Duration = Duration::from_millis(20);

/// How long an agent waits for the coordinator's map before trying again (1 s later).
const MAP_QUERY_TIMEOUT: Duration = Duration::from_millis(500);

/// Everything an agent needs besides its session.
#[derive(Debug, Clone)]
pub struct AgentConfig {
    /// The robot it drives.
    pub robot_id: u32,
    /// The site's keys (its name is the second chunk of every key).
    pub keys: Keys,
    /// Planner stack.
    pub planner: PlannerSpec,
    /// Safe-stop when no observation arrived for this long.
    pub obs_timeout: Duration,
    /// Publish PGP's candidate fan with every plan (`…/robot/<id>/fan`, for dashboards).
    pub share_fan: bool,
    /// The safety layer under the planner, with the base's limits (its control period is the
    /// observation's step); `None` runs the planner's commands as they are, as the papers do.
    pub safety: Option<SafetyLimits>,
    /// Fault injection for tests: every plan holds the agent's thread this much longer, as a
    /// slow planner would (zero in normal use). It wraps the planner (`faults`); the agent's
    /// loop does not know of it.
    pub fault_plan_delay: Duration,
    /// Drive a ROS 2 robot ([`ros`]): its own odometry, people and scan replace the
    /// observation's ego state and people, and each command also goes to its `cmd_vel`. The
    /// goal, the other robots and their intents still come from the coordinator.
    pub ros: Option<ros::RosConfig>,
    /// The robot's drive: a differential base gets its velocity commands as forward speed and
    /// turn rate, checked by the safety layer as such.
    pub base: crate::model::Base,
}

impl AgentConfig {
    /// Robot `robot_id` of the site of `keys` with `planner` and the default observation
    /// timeout.
    pub fn new(robot_id: u32, keys: Keys, planner: PlannerSpec) -> Self {
        Self {
            robot_id,
            keys,
            planner,
            obs_timeout: DEFAULT_OBS_TIMEOUT,
            share_fan: false,
            safety: Some(SafetyLimits::SIMULATED_ROBOT),
            fault_plan_delay: Duration::ZERO,
            ros: None,
            base: crate::model::Base::Holonomic,
        }
    }
}

/// Counters an agent keeps; shared so that tests and the demo can read them while it runs.
#[derive(Debug, Default)]
pub struct AgentCounters {
    /// Valid observations received (planned on, superseded or stale).
    pub received: AtomicU64,
    /// Observations planned on.
    pub plans: AtomicU64,
    /// Messages the decoder rejected.
    pub rejected: AtomicU64,
    /// Observations dropped as older than one already planned on.
    pub stale: AtomicU64,
    /// Observations replaced by a newer one before the planner got to them (a planner slower
    /// than the tick plans on the newest only).
    pub superseded: AtomicU64,
    /// Observations that never arrived: gaps in the sequence numbers of those that did (an
    /// observation lost after the last one that arrived is not seen here).
    pub missed: AtomicU64,
    /// Safe-stop commands sent (timeouts and shutdown).
    pub safe_stops: AtomicU64,
    /// Maps fetched.
    pub maps: AtomicU64,
    /// Commands the safety layer slowed in its warning field.
    pub warned: AtomicU64,
    /// Commands the safety layer slowed further or stopped in its protective field.
    pub protective: AtomicU64,
    /// Commands the safety layer replaced with a way out (yields).
    pub yielded: AtomicU64,
    /// What came from the robot in ROS mode ([`ros`]).
    pub ros: Arc<ros::RosCounters>,
}

/// The runtime failed to set itself up.
#[derive(Debug, thiserror::Error)]
pub enum AgentError {
    /// The session refused a declaration.
    #[error("agent: {what}: {source}")]
    Zenoh {
        /// What was being declared.
        what: &'static str,
        /// Zenoh's error.
        source: zenoh::Error,
    },
    /// The ROS 2 side could not be declared.
    #[error("agent: ROS 2: {0}")]
    Ros(#[from] ros::RosError),
}

/// 99th percentile (nearest rank) of `values`, 0 when empty.
pub fn p99(values: &mut [u32]) -> f64 {
    percentile(values, 0.99)
}

/// Nearest-rank percentile `q` ∈ (0, 1] of `values` (sorted in place), 0 when empty.
pub fn percentile(values: &mut [u32], q: f64) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_unstable();
    let rank = ((q * values.len() as f64).ceil() as usize).clamp(1, values.len());
    f64::from(values[rank - 1])
}
