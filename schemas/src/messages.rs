//! The messages. Units are SI (metres, seconds, radians, m/s); positions are in the site's world
//! frame; times are simulation (or site) seconds. Field names here are the names on the wire.

use serde::{Deserialize, Serialize};

/// A point or vector in the world frame, on the wire as the array `[x, y]`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct P2(pub f64, pub f64);

/// What kind of body a perceived agent is. On the wire: the string `"human"` or `"robot"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// A person.
    Human,
    /// A robot (of this fleet or not).
    Robot,
}

/// One sample of a planned trajectory.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Seconds after the enclosing message's time reference (see each message).
    pub t: f64,
    /// Mean position.
    pub p: P2,
    /// Standard deviation of the position (metres, isotropic).
    pub sigma: f64,
}

/// A body the robot perceives.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Perceived {
    /// Stable id while perceived: people < 2^32, robots 2^32 + their robot id.
    pub id: u64,
    /// Person or robot.
    pub kind: Kind,
    /// Position.
    pub p: P2,
    /// Velocity.
    pub vel: P2,
    /// Body radius (metres, > 0).
    pub radius: f64,
    /// The trajectory this robot announced, re-stamped so `t` counts from the observation's
    /// `sim_time`; absent for people and for robots without a fresh intent.
    pub intent: Option<Vec<Sample>>,
}

/// What the robot is currently doing, when the coordinator gave it a task.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskRef {
    /// The task's id (see [`TaskAssignment`]).
    pub task_id: u64,
    /// `"pick"` while driving to the pick station, `"drop"` while driving to the drop station.
    pub stage: TaskStage,
}

/// Stage of a pick/drop task. On the wire: `"pick"` or `"drop"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TaskStage {
    /// Driving to the pick station.
    Pick,
    /// Driving to the drop station.
    Drop,
}

/// Coordinator → agent, key `…/robot/<id>/obs`: what one robot perceives, at one tick.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Observation {
    /// The robot this observation is for.
    pub robot_id: u32,
    /// Increases by one per observation of this robot; commands echo it.
    pub seq: u64,
    /// Simulation time of the observation (s). Time reference of every intent inside.
    pub sim_time: f64,
    /// Control period: seconds until the next observation.
    pub dt: f64,
    /// Version of the static map (query `…/map` when it changes).
    pub map_version: u32,
    /// Own position.
    pub p: P2,
    /// Own heading (rad).
    pub heading: f64,
    /// Own velocity.
    pub vel: P2,
    /// Own turn rate (rad/s).
    pub yaw_rate: f64,
    /// Own body radius (m).
    pub radius: f64,
    /// Where to drive; absent when idle (the agent then stops).
    pub goal: Option<P2>,
    /// The task the goal belongs to, if any.
    pub task: Option<TaskRef>,
    /// Bodies within sensor range and line of sight.
    pub neighbours: Vec<Perceived>,
    /// What the sensor sees and what it cannot: present when the world hides bodies behind
    /// bodies (a scenario's `body_occlusion`); absent from older senders.
    #[serde(default)]
    pub visibility: Option<VisibilityProfile>,
    /// True for a real robot the coordinator does not simulate (`--live`): the bodies listed
    /// are the coordinator's, simulated people and robots its own sensors cannot see, and its
    /// agent plans around them beside what it senses. Absent: false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub real: bool,
}

/// The free range along evenly spaced bearings around the robot, as a 2-D laser scan reports
/// it: ray `k` points at world-frame bearing `bearing0 + k·2π/ranges.len()` and is free for
/// `ranges[k]` metres from the robot's centre, ended by a wall, a shelf or a body, or by the
/// sensor's `range`. Everything beyond is unobserved.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VisibilityProfile {
    /// Bearing of ray 0 (rad, world frame).
    pub bearing0: f64,
    /// The sensor's range (m): a ray that meets nothing reports it.
    pub range: f64,
    /// Free range per ray (m), each in [0, `range`]; at most [`crate::codec::MAX_RAYS`].
    pub ranges: Vec<f32>,
}

/// Agent → fleet, key `…/robot/<id>/intent`: where the robot is heading and how it expects to
/// drive there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntentMsg {
    /// The announcing robot.
    pub robot_id: u32,
    /// The observation sequence number this plan answers.
    pub obs_seq: u64,
    /// Time reference of `trajectory`: the `sim_time` of that observation.
    pub stamp: f64,
    /// Planner stack name, e.g. `"pgp+orca"`.
    pub planner: String,
    /// The goal handed to the short-term planner (PGP's subgoal, or the goal itself).
    pub subgoal: P2,
    /// Planned trajectory; `t` is seconds after `stamp`, sorted ascending.
    pub trajectory: Vec<Sample>,
}

/// A motion command. On the wire an externally tagged map: `{"velocity": [vx, vy]}` or
/// `{"unicycle": [speed, yaw_rate]}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Motion {
    /// Holonomic: world-frame velocity (m/s).
    Velocity(P2),
    /// Unicycle: forward speed (m/s) and turn rate (rad/s, counter-clockwise positive).
    Unicycle(f64, f64),
}

/// Agent → coordinator, key `…/robot/<id>/cmd`: what the robot's base should do now.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CommandMsg {
    /// The commanded robot.
    pub robot_id: u32,
    /// The observation sequence number this command answers; a safe-stop sent because
    /// observations stopped repeats the last one answered.
    pub obs_seq: u64,
    /// `sim_time` of that observation.
    pub stamp: f64,
    /// The motion.
    pub motion: Motion,
    /// True when the agent stopped the robot on its own (observations timed out or shutdown).
    pub safe_stop: bool,
    /// Which field of the agent's safety layer acted on this command (absent: `clear`, as
    /// from an agent without the layer).
    #[serde(default)]
    pub safety: SafetyZone,
    /// Where the robot was when it planned this command, from its own odometry: sent by an
    /// agent that drives a real robot (ROS mode). A coordinator that does not simulate the
    /// robot takes its state from here; one that does ignores it. Absent from agents of
    /// simulated robots and from older agents.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub state: Option<RobotState>,
}

/// A real robot's state as its agent reports it, in the site's map frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RobotState {
    /// Position (m).
    pub p: P2,
    /// Heading (rad).
    pub heading: f64,
    /// Velocity (m/s).
    pub vel: P2,
    /// Turn rate (rad/s, counter-clockwise positive).
    pub yaw_rate: f64,
    /// How long before the command was sent the odometry behind this state arrived (s, wall
    /// time): a coordinator judges whether the robot is still heard from by it.
    #[serde(default)]
    pub age: f64,
}

/// The safety layer's verdict on a command. On the wire a string: `"clear"`, `"warning"`,
/// `"protective"`, `"yield"`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SafetyZone {
    /// Neither field acted (or no layer ran).
    #[default]
    Clear,
    /// The warning field slowed the command.
    Warning,
    /// The protective field slowed it further or stopped the robot.
    Protective,
    /// The robot was threatened (someone would walk into it were it to stop) and the layer
    /// took a way out other than the planner's command.
    Yield,
}

/// Agent → fleet, key `…/robot/<id>/info`, once a second: who the agent is and how it fares.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AgentInfo {
    /// The robot it drives.
    pub robot_id: u32,
    /// Planner stack name.
    pub planner: String,
    /// gapfleet version of the agent.
    pub version: String,
    /// Observations planned on since start.
    pub plans: u64,
    /// Messages rejected by the decoder since start.
    pub rejected: u64,
    /// 99th percentile of planning time over the last second (µs).
    pub plan_p99_us: f64,
    /// Maps fetched from the coordinator since start (optional on the wire: 0 when absent).
    #[serde(default)]
    pub maps: u64,
    /// Version of the map it holds (optional on the wire: 0, none, when absent).
    #[serde(default)]
    pub map_version: u32,
}

/// One candidate of PGP's fan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FanCandidate {
    /// Sampled path (t = 0, dt, 2dt, …).
    pub path: Vec<P2>,
    /// Survival probability at the end of the horizon (Eq. 5).
    pub survival: f64,
    /// Expected utility (Eq. 8).
    pub expected_utility: f64,
}

/// Agent → dashboards, key `…/robot/<id>/fan`, only when the agent shares it (debugging,
/// dashboards): PGP's evaluated candidates of one plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FanMsg {
    /// The planning robot.
    pub robot_id: u32,
    /// The observation planned on.
    pub obs_seq: u64,
    /// Its `sim_time`.
    pub stamp: f64,
    /// Index of the chosen candidate.
    pub best: u32,
    /// Every candidate.
    pub candidates: Vec<FanCandidate>,
}

/// Coordinator → agent, key `…/robot/<id>/task`: a pick/drop job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TaskAssignment {
    /// The robot that gets the task.
    pub robot_id: u32,
    /// Unique per site.
    pub task_id: u64,
    /// Pick station index and position.
    pub pick_station: u32,
    /// Where to pick.
    pub pick: P2,
    /// Drop station index.
    pub drop_station: u32,
    /// Where to drop.
    pub drop: P2,
    /// Simulation time of the assignment (s).
    pub assigned_at: f64,
}

/// One robot's row in a [`FleetMetrics`] frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RobotRow {
    /// Robot id.
    pub robot_id: u32,
    /// Whether its agent is alive (liveliness token present and commands fresh).
    pub alive: bool,
    /// Tasks completed.
    pub tasks_done: u64,
    /// Share of moving steps with a body overlap.
    pub collision_rate: f64,
    /// Share of moving steps with any agent closer than 1 m (centre to centre).
    pub svr: f64,
    /// Smallest centre distance to a person so far (m); absent while there are no people.
    pub min_human_distance: Option<f64>,
    /// Mean total social force on the robot (N per kg).
    pub social_force: f64,
    /// Whether it is stuck: a task and no progress for the traffic monitor's 30 s; absent
    /// from older senders.
    #[serde(default)]
    pub stuck: bool,
    /// The robots it waits on now (the wait-for graph's edges from it).
    #[serde(default)]
    pub waits_on: Vec<u32>,
}

/// Coordinator → fleet, key `…/metrics`, once per simulated second: the fleet's social metrics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FleetMetrics {
    /// Simulation tick.
    pub tick: u64,
    /// Simulation time (s).
    pub sim_time: f64,
    /// Robots in the world.
    pub robots: u32,
    /// Robots whose agents are alive.
    pub alive: u32,
    /// People in the world.
    pub humans: u32,
    /// Tasks completed by the whole fleet.
    pub tasks_done: u64,
    /// Collision rate while moving, mean over robots.
    pub collision_rate: f64,
    /// Space-violation rate while moving, mean over robots.
    pub svr: f64,
    /// Robot–robot near misses: robot-steps with another robot within 0.3 m surface gap.
    pub near_misses: u64,
    /// Contacts with people the robots caused so far (onsets: the robot moving toward the
    /// person at more than 0.05 m/s along the line of centres); absent from older senders.
    #[serde(default)]
    pub robot_caused_contacts: u64,
    /// Contacts people caused so far (a person walked into a robot stopped or moving away).
    #[serde(default)]
    pub person_caused_contacts: u64,
    /// Commands that arrived too late or out of order and were dropped.
    pub dropped_commands: u64,
    /// Deadlocks so far: sets of robots each waiting on another in the set for 10 s; absent
    /// from older senders.
    #[serde(default)]
    pub deadlocks: u64,
    /// Robots stuck now.
    #[serde(default)]
    pub stuck_robots: u32,
    /// Robot-seconds spent stuck so far.
    #[serde(default)]
    pub stuck_robot_s: f64,
    /// Per-robot rows.
    pub per_robot: Vec<RobotRow>,
    /// Fleet efficiency so far: tasks per robot-minute over what one robot alone on the same
    /// floor does per minute (`world_sim::efficiency`); absent from older senders and while
    /// it cannot be told.
    #[serde(default)]
    pub efficiency: Option<f64>,
    /// That robot alone's tasks per minute (the free flow); absent as `efficiency` is.
    #[serde(default)]
    pub free_flow_tasks_per_min: Option<f64>,
    /// Gridlocks so far: robots stuck together for a minute, cycle or not; absent from older
    /// senders.
    #[serde(default)]
    pub gridlocks: u64,
    /// Stuck robot-seconds so far by what held the robot; zeros from older senders.
    #[serde(default)]
    pub stuck_causes: StuckCausesMsg,
    /// Robot–robot contacts so far (onsets, each robot counting its own); absent from older
    /// senders.
    #[serde(default)]
    pub robot_robot_contacts: u64,
    /// Contacts with walls and shelves so far (onsets); absent from older senders.
    #[serde(default)]
    pub wall_contacts: u64,
}

/// Stuck robot-seconds by what held the robot (`world_sim::stuck::Hold`).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct StuckCausesMsg {
    /// The traffic policy held it.
    pub policy_s: f64,
    /// A person or a group was in its way.
    pub person_s: f64,
    /// Another robot was in its way.
    pub robot_s: f64,
    /// Its safety layer held it, nobody in its way.
    pub layer_s: f64,
    /// Nothing visible held it: a planner failure.
    pub planner_s: f64,
}

/// What the traffic policy asks of a robot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TrafficConstraint {
    /// Drive to the route's waypoint.
    Free,
    /// Drive along the right-hand lane (keep right), toward `goal`.
    Lane,
    /// Wait at `goal` until `segment` is granted.
    Hold,
    /// Wait in line at `goal` until `station` is granted.
    Queue,
    /// Back off to `goal`: a wait-for cycle lasted.
    Retreat,
    /// Stop at `goal` (where the robot stood) and wait: robots of both directions knotted in
    /// a two-lane corridor, and the other direction passes first.
    #[serde(rename = "give_way")]
    GiveWay,
}

/// Coordinator → agent and dashboards, key `…/robot/<id>/traffic`, every tick while the
/// traffic policy runs: what it asks of the robot and why. The observation's `goal` already is
/// the constrained goal, so an agent that ignores this message still obeys the policy.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrafficMsg {
    /// Simulation tick.
    pub tick: u64,
    /// Simulation time (s).
    pub sim_time: f64,
    /// The constraint.
    pub constraint: TrafficConstraint,
    /// The goal it puts in place of the route's waypoint (absent for `free`).
    pub goal: Option<P2>,
    /// The one-way aisle segment it waits for (`hold`) or holds.
    pub segment: Option<u32>,
    /// The direction the held segment is travelled: +1 along x, −1 against.
    pub direction: Option<i8>,
    /// The station it waits in line for (`queue`) or holds; absent from older senders.
    #[serde(default)]
    pub station: Option<u32>,
}

/// A static obstacle of the map. `{"polygon": [[x,y],...]}` or `{"wall": [[x,y],[x,y]]}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ObstacleMsg {
    /// Closed simple polygon (shelf, pillar).
    Polygon(Vec<P2>),
    /// Zero-thickness wall segment.
    Wall(P2, P2),
}

/// A pick/drop station.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StationMsg {
    /// Station index.
    pub id: u32,
    /// Where robots and people go.
    pub p: P2,
}

/// Coordinator queryable `…/map`: the static map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapMsg {
    /// Version, as in observations.
    pub map_version: u32,
    /// Walls and shelves.
    pub obstacles: Vec<ObstacleMsg>,
    /// Pick/drop stations.
    pub stations: Vec<StationMsg>,
    /// Axis-aligned bounds `[min, max]` of the site.
    pub bounds: [P2; 2],
    /// Where the site's people stop, turn and set off, as boxes `[min, max]` (points where
    /// min = max): on a site whose people walk station to station, its stations. The safety
    /// layer lets a person farther from all of them swerve less hard
    /// (`agent::safety::SafetyParams::person_accel_away`). Absent from older senders and where
    /// people walk to goals anywhere: then every person keeps the full allowance.
    #[serde(default)]
    pub turn_places: Option<Vec<[P2; 2]>>,
    /// The safety layer's parameters on this site, where they differ from the layer's
    /// defaults, as `key=value,…` (`agent::safety::SafetyParams::with_overrides`; a
    /// scenario's `[robot.safety_layer]`), as a safety scanner is given its field set per
    /// site. At most [`MAX_LAYER_SETTING`](crate::codec::MAX_LAYER_SETTING) bytes. An agent
    /// refuses a setting it cannot read or whose values are out of range, and keeps its layer
    /// as it was. Absent from older senders: the defaults.
    #[serde(default)]
    pub safety_layer: Option<String>,
}
