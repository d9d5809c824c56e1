//! One agent's event loop on its session ([`Agent`]): its declarations, its planner stack
//! under the safety layer, and its phases (on an observation: accept, refresh the map, sense,
//! plan, send; the coordinator's token; the heartbeat; a safe stop), with the newest-only
//! observation slot the subscriber fills.

use super::{
    AgentConfig, AgentCounters, AgentError, MAP_QUERY_TIMEOUT, ODOMETRY_WAIT, faults, p99, ros,
    wire,
};
use crate::guard::Guard;
use crate::map::StaticMap;
use crate::math::Vec2;
use crate::model::Command;
use crate::planner::{PlannerStack, PlanningInput};
use crate::safety::{SafetyParams, Zone};
use fleet_net::log_rejection;
use schemas::{
    AgentInfo, Channel, CommandMsg, Keys, MapMsg, Observation, SafetyZone, decode, encode,
};
use std::future::Future;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Runs one agent on `session` until `shutdown` completes: `Agent`'s phases, each on the
/// event that calls for it.
pub async fn run_agent(
    session: &zenoh::Session,
    config: AgentConfig,
    counters: Arc<AgentCounters>,
    shutdown: impl Future<Output = ()>,
) -> Result<(), AgentError> {
    let (mut agent, inputs) = Agent::declare(session, config, counters).await?;
    let mut heartbeat = tokio::time::interval(Duration::from_secs(1));
    tokio::pin!(shutdown);
    tracing::info!(robot = agent.id, planner = %agent.planner_name, "agent up");
    loop {
        tokio::select! {
            () = &mut shutdown => break,
            () = inputs.newest.ready.notified() => {
                if let Some(obs) = inputs.newest.take() {
                    agent.on_observation(obs).await;
                }
            }
            () = tokio::time::sleep_until(agent.deadline), if !agent.stopped => {
                tracing::warn!(robot = agent.id, "observations stopped: safe stop");
                agent.stop().await;
            }
            sample = inputs.coordinator.recv_async() => {
                let Ok(sample) = sample else { break };
                agent.on_coordinator(sample.kind()).await;
            }
            _ = heartbeat.tick() => agent.heartbeat().await,
        }
    }
    agent.stop().await;
    let id = agent.id;
    // The liveliness token goes with the agent, then the subscriptions.
    drop(agent);
    drop(inputs);
    tracing::info!(robot = id, "agent down");
    Ok(())
}

/// What wakes an agent: its newest observation (kept by the subscriber's callback) and the
/// coordinator's liveliness. Apart from [`Agent`], which the loop changes while it waits on
/// these.
struct Inputs {
    newest: Arc<NewestObservation>,
    _observations: zenoh::pubsub::Subscriber<()>,
    /// A ring, not a FIFO: a full FIFO would block the session; only the newest changes matter.
    coordinator:
        zenoh::pubsub::Subscriber<zenoh::handlers::RingChannelHandler<zenoh::sample::Sample>>,
}

/// One agent: its declarations on the session, its planner stack under the safety layer, and
/// what it keeps between observations. Its phases, as [`run_agent`] calls them:
/// [`Agent::on_observation`] (accept, refresh the map, sense, plan, send),
/// [`Agent::on_coordinator`], [`Agent::heartbeat`] and [`Agent::stop`].
struct Agent<'s> {
    session: &'s zenoh::Session,
    keys: Keys,
    id: u32,
    config: AgentConfig,
    counters: Arc<AgentCounters>,
    _token: zenoh::liveliness::LivelinessToken,
    cmd_pub: zenoh::pubsub::Publisher<'s>,
    intent_pub: zenoh::pubsub::Publisher<'s>,
    info_pub: zenoh::pubsub::Publisher<'s>,
    fan_pub: zenoh::pubsub::Publisher<'s>,
    ros_link: Option<ros::RosLink>,
    planner_name: String,
    stack: PlannerStack,
    guard: Option<Guard>,
    map: Option<(u32, StaticMap)>,
    last_map_attempt: Option<Instant>,
    /// Sequence number and stamp of the newest observation planned on.
    last: Option<(u64, f64)>,
    /// When the robot is stopped for want of observations.
    deadline: tokio::time::Instant,
    /// Whether the robot stands after a safe stop (or before the first observation).
    stopped: bool,
    plan_times_us: Vec<u32>,
}

/// What the robot senses for one plan: its ego state, the bodies around it, and the age of its
/// odometry (zero off ROS).
type Sensed = (
    crate::model::EgoState,
    Vec<crate::model::Neighbour>,
    Duration,
);

impl<'s> Agent<'s> {
    /// Declares the agent's token, publishers and subscribers, and its ROS 2 side.
    async fn declare(
        session: &'s zenoh::Session,
        config: AgentConfig,
        counters: Arc<AgentCounters>,
    ) -> Result<(Self, Inputs), AgentError> {
        let keys = config.keys.clone();
        let id = config.robot_id;
        let token = session
            .liveliness()
            .declare_token(keys.alive(id))
            .await
            .map_err(zerr("liveliness token"))?;
        let publisher = |channel, what| {
            let key = keys.robot(id, channel);
            async move { session.declare_publisher(key).await.map_err(zerr(what)) }
        };
        let cmd_pub = publisher(Channel::Cmd, "command publisher").await?;
        let intent_pub = publisher(Channel::Intent, "intent publisher").await?;
        let info_pub = publisher(Channel::Info, "info publisher").await?;
        let fan_pub = publisher(Channel::Fan, "fan publisher").await?;
        let newest = Arc::new(NewestObservation::default());
        let observations =
            observation_subscriber(session, &keys, id, newest.clone(), counters.clone()).await?;
        let coordinator = session
            .liveliness()
            .declare_subscriber(keys.coordinator())
            .history(true)
            .with(zenoh::handlers::RingChannel::new(16))
            .await
            .map_err(zerr("coordinator liveliness subscriber"))?;
        let ros_link = match config.ros.clone() {
            Some(ros) => Some(
                ros::RosLink::declare(session, ros, counters.ros.clone())
                    .await
                    .map_err(AgentError::Ros)?,
            ),
            None => None,
        };
        let mut stack = PlannerStack::new(config.planner);
        stack.set_record_fan(config.share_fan);
        if !config.fault_plan_delay.is_zero() {
            stack = faults::slowed(stack, config.fault_plan_delay);
        }
        let guard = config
            .safety
            .map(|limits| Guard::new(limits).on_base(config.base));
        let agent = Self {
            session,
            keys,
            id,
            planner_name: config.planner.to_string(),
            deadline: tokio::time::Instant::now() + config.obs_timeout,
            config,
            counters,
            _token: token,
            cmd_pub,
            intent_pub,
            info_pub,
            fan_pub,
            ros_link,
            stack,
            guard,
            map: None,
            last_map_attempt: None,
            last: None,
            stopped: true,
            plan_times_us: Vec::new(),
        };
        let inputs = Inputs {
            newest,
            _observations: observations,
            coordinator,
        };
        Ok((agent, inputs))
    }

    /// An observation: accept it, refresh the map, sense, plan, and send the command first,
    /// then the intent and the fan.
    async fn on_observation(&mut self, obs: Observation) {
        if !self.accept(&obs) {
            return;
        }
        self.refresh_map(obs.map_version).await;
        let sensed = self.sense(&obs).await;
        // The heading the command is turned into the robot's base frame with.
        let heading = sensed.as_ref().map_or(obs.heading, |(ego, ..)| ego.heading);
        // A real robot reports where its odometry puts it, for a coordinator that does not
        // simulate it.
        let reported = match (&self.ros_link, &sensed) {
            (Some(_), Some((ego, _, age))) => Some(wire::robot_state(ego, *age)),
            _ => None,
        };
        let (mut command, extras) = self.plan(&obs, sensed);
        command.state = reported;
        self.send(command, extras, heading).await;
    }

    /// Whether to plan on `obs`: not older than what was planned on, unless the agent had lost
    /// contact (the coordinator restarted and counts from 0 again).
    fn accept(&mut self, obs: &Observation) -> bool {
        if let Some((seq, _)) = self.last
            && obs.seq <= seq
            && !self.stopped
        {
            self.counters.stale.fetch_add(1, Ordering::Relaxed);
            return false;
        }
        self.last = Some((obs.seq, obs.sim_time));
        self.deadline = tokio::time::Instant::now() + self.config.obs_timeout;
        self.stopped = false;
        true
    }

    /// Fetches the map when the observation names another version, at most once a second.
    async fn refresh_map(&mut self, version: u32) {
        if self.map.as_ref().is_some_and(|(v, _)| *v == version) {
            return;
        }
        let due = self
            .last_map_attempt
            .is_none_or(|t| t.elapsed() > Duration::from_secs(1));
        if !due {
            return;
        }
        self.last_map_attempt = Some(Instant::now());
        let fetched = tokio::time::timeout(
            MAP_QUERY_TIMEOUT,
            fetch_map(self.session, &self.keys, version),
        )
        .await;
        match fetched {
            Ok(Ok(fetched)) => {
                self.counters.maps.fetch_add(1, Ordering::Relaxed);
                // The site's stations are where its people go: foIGP's intents.
                self.stack.set_destinations(&fetched.stations);
                if let Some(guard) = &mut self.guard {
                    guard.set_turn_places(fetched.turn_places);
                    let setting = fetched.safety_layer.as_deref();
                    take_site_layer(guard, setting, &self.counters, self.id);
                }
                self.map = Some((fetched.version, fetched.map));
            }
            Ok(Err(e)) => tracing::warn!(robot = self.id, "no map yet: {e}"),
            Err(_) => tracing::warn!(robot = self.id, "no map yet: the query timed out"),
        }
    }

    /// What the robot senses: the observation's, or in ROS mode the robot's own (without fresh
    /// odometry, before the map or before its scanner is placed, nothing: it stands). (`&mut`:
    /// the agent is not `Sync`, and its phases' futures must be `Send`.)
    async fn sense(&mut self, obs: &Observation) -> Option<Sensed> {
        let Some(link) = &self.ros_link else {
            return Some((wire::ego(obs), wire::neighbours(obs), Duration::ZERO));
        };
        link.wait_for_odometry(obs.sim_time, ODOMETRY_WAIT).await;
        let (_, m) = self.map.as_ref()?;
        link.sensed().map(|s| {
            let age = s.odom_age;
            let (ego, neighbours) = sensed_world(s, obs, m);
            (ego, neighbours, age)
        })
    }

    /// The command for `obs`, with the intent and fan to share; a stop without them when idle
    /// or without a map.
    fn plan(
        &mut self,
        obs: &Observation,
        sensed: Option<Sensed>,
    ) -> (
        CommandMsg,
        Option<(schemas::IntentMsg, Option<schemas::FanMsg>)>,
    ) {
        let (Some((_, m)), Some(goal), Some((ego, neighbours, _))) = (&self.map, obs.goal, sensed)
        else {
            let stop = CommandMsg {
                robot_id: self.id,
                obs_seq: obs.seq,
                stamp: obs.sim_time,
                motion: wire::motion(Command::STOP),
                safe_stop: false,
                safety: SafetyZone::Clear,
                state: None,
            };
            return (stop, None);
        };
        let profile = if self.ros_link.is_some() {
            None
        } else {
            wire::visibility(obs)
        };
        let started = Instant::now();
        let input = PlanningInput {
            ego: &ego,
            neighbours: &neighbours,
            map: m,
            goal: wire::vec(goal),
            dt: obs.dt,
            visibility: profile.as_ref(),
            safety: None,
        };
        let (plan, zone) = match &mut self.guard {
            Some(guard) => {
                let (plan, guarded) = guard.plan(&mut self.stack, &input);
                (plan, Some(guarded.zone))
            }
            None => (self.stack.plan(&input), None),
        };
        let zone = match zone {
            None | Some(Zone::Clear) => SafetyZone::Clear,
            Some(Zone::Warning) => {
                self.counters.warned.fetch_add(1, Ordering::Relaxed);
                SafetyZone::Warning
            }
            Some(Zone::Protective) => {
                self.counters.protective.fetch_add(1, Ordering::Relaxed);
                SafetyZone::Protective
            }
            Some(Zone::Yield) => {
                self.counters.yielded.fetch_add(1, Ordering::Relaxed);
                SafetyZone::Yield
            }
        };
        self.plan_times_us
            .push(started.elapsed().as_micros().min(u32::MAX as u128) as u32);
        self.counters.plans.fetch_add(1, Ordering::Relaxed);
        let (mut cmd, intent) = wire::answer(obs, &self.planner_name, &plan);
        cmd.safety = zone;
        let fan = plan
            .fan
            .as_ref()
            .filter(|_| self.config.share_fan)
            .map(|f| wire::fan(obs, f));
        (cmd, Some((intent, fan)))
    }

    /// Sends the command (to the ROS 2 robot too), then the intent and the fan.
    async fn send(
        &mut self,
        command: CommandMsg,
        extras: Option<(schemas::IntentMsg, Option<schemas::FanMsg>)>,
        heading: f64,
    ) {
        if let Some(link) = &self.ros_link {
            link.drive(wire::command(command.motion), heading).await;
        }
        if let Err(e) = self.cmd_pub.put(encode(&command)).await {
            tracing::warn!(robot = self.id, "command not sent: {e}");
        }
        if let Some((intent, fan)) = extras {
            if let Err(e) = self.intent_pub.put(encode(&intent)).await {
                tracing::warn!(robot = self.id, "intent not sent: {e}");
            }
            if let Some(msg) = fan
                && let Err(e) = self.fan_pub.put(encode(&msg)).await
            {
                tracing::debug!(robot = self.id, "fan not sent: {e}");
            }
        }
    }

    /// The coordinator's liveliness token came or went: gone, the robot stops.
    async fn on_coordinator(&mut self, kind: zenoh::sample::SampleKind) {
        match kind {
            zenoh::sample::SampleKind::Put => tracing::info!(robot = self.id, "coordinator up"),
            zenoh::sample::SampleKind::Delete if self.stopped => {
                tracing::info!(robot = self.id, "coordinator gone");
            }
            zenoh::sample::SampleKind::Delete => {
                tracing::warn!(robot = self.id, "coordinator gone: safe stop");
                self.stop().await;
            }
        }
    }

    /// A safe stop: the command, and the ROS 2 robot stopped.
    async fn stop(&mut self) {
        safe_stop(&self.cmd_pub, self.id, self.last, &self.counters).await;
        if let Some(link) = &self.ros_link {
            link.drive(Command::STOP, 0.0).await;
        }
        self.stopped = true;
    }

    /// Once a second: the agent's info (planner, counts, plan times since the last).
    async fn heartbeat(&mut self) {
        let info = AgentInfo {
            robot_id: self.id,
            planner: self.planner_name.clone(),
            version: env!("CARGO_PKG_VERSION").to_owned(),
            plans: self.counters.plans.load(Ordering::Relaxed),
            rejected: self.counters.rejected.load(Ordering::Relaxed),
            plan_p99_us: p99(&mut self.plan_times_us),
            maps: self.counters.maps.load(Ordering::Relaxed),
            map_version: self.map.as_ref().map_or(0, |(v, _)| *v),
        };
        self.plan_times_us.clear();
        if let Err(e) = self.info_pub.put(encode(&info)).await {
            tracing::debug!(robot = self.id, "info not sent: {e}");
        }
    }
}

fn zerr(what: &'static str) -> impl Fn(zenoh::Error) -> AgentError {
    move |source| AgentError::Zenoh { what, source }
}

/// The agent's observations, decoded as they arrive in Zenoh's own thread (a small
/// MessagePack message: microseconds); only the newest valid one is kept for the planner.
/// Nothing here can block the session, a planner slower than the tick plans on the newest
/// observation rather than working through a backlog, and every bad message is counted.
async fn observation_subscriber(
    session: &zenoh::Session,
    keys: &Keys,
    id: u32,
    newest: Arc<NewestObservation>,
    counters: Arc<AgentCounters>,
) -> Result<zenoh::pubsub::Subscriber<()>, AgentError> {
    let gaps = AtomicU64::new(0);
    session
        .declare_subscriber(keys.robot(id, Channel::Obs))
        .callback(
            move |sample| match decode::<Observation>(&sample.payload().to_bytes()) {
                Ok(obs) if obs.robot_id == id => {
                    counters.received.fetch_add(1, Ordering::Relaxed);
                    let seq = obs.seq;
                    let arrival = newest.put(obs);
                    if arrival.replaced {
                        counters.superseded.fetch_add(1, Ordering::Relaxed);
                    }
                    if arrival.missed > 0 {
                        let n = counters.missed.fetch_add(arrival.missed, Ordering::Relaxed)
                            + arrival.missed;
                        let gap = gaps.fetch_add(1, Ordering::Relaxed) + 1;
                        if log_rejection(gap) {
                            tracing::warn!(
                                robot = id,
                                missed = n,
                                "{} observations before number {seq} never arrived",
                                arrival.missed
                            );
                        }
                    }
                }
                Ok(obs) => reject(
                    &counters,
                    id,
                    &format!("observation for robot {}", obs.robot_id),
                ),
                Err(e) => reject(&counters, id, &e.to_string()),
            },
        )
        .await
        .map_err(zerr("observation subscriber"))
}

/// The newest valid observation, not yet planned on: written by the subscriber's callback,
/// taken by the agent's loop.
#[derive(Debug, Default)]
struct NewestObservation {
    slot: std::sync::Mutex<Slot>,
    /// Signalled on every new observation (a permit is kept when the loop is busy, so none is
    /// missed).
    ready: tokio::sync::Notify,
}

#[derive(Debug, Default)]
struct Slot {
    newest: Option<Observation>,
    /// The sequence number of the last observation that arrived, planned on or not.
    last_seq: Option<u64>,
}

/// What keeping an observation found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Arrival {
    /// It replaced one the loop had not taken.
    replaced: bool,
    /// Observations that never arrived between the previous one and this: the coordinator
    /// numbers each robot's observations 0, 1, 2, … and one link delivers them in order.
    /// A number lower than the last is a restarted coordinator counting again, not a gap.
    missed: u64,
}

impl NewestObservation {
    /// Keeps `obs`.
    fn put(&self, obs: Observation) -> Arrival {
        // A poisoned lock only means a panic elsewhere while holding it; the slot is still
        // whole.
        let mut slot = self.slot.lock().unwrap_or_else(|e| e.into_inner());
        let missed = match slot.last_seq {
            Some(last) if obs.seq > last => obs.seq - last - 1,
            _ => 0,
        };
        slot.last_seq = Some(obs.seq);
        let replaced = slot.newest.replace(obs).is_some();
        drop(slot);
        self.ready.notify_one();
        Arrival { replaced, missed }
    }

    fn take(&self) -> Option<Observation> {
        self.slot
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .newest
            .take()
    }
}

/// The robot's own sensing in ROS mode as the planners' input: its odometry for the ego state,
/// the coordinator's robots (with their intents), its tracked people, and its scan's returns
/// that none of those nor the map explains. For a real robot (`obs.real`) every body the
/// coordinator lists is kept: its simulated people are not in the robot's sensing. (A robot the
/// coordinator simulates as a ROS 2 robot senses the same people the observation lists.)
fn sensed_world(
    sensed: ros::Sensed,
    obs: &Observation,
    map: &StaticMap,
) -> (crate::model::EgoState, Vec<crate::model::Neighbour>) {
    let mut ego = sensed.ego;
    ego.radius = obs.radius;
    let mut neighbours: Vec<_> = wire::neighbours(obs)
        .into_iter()
        .filter(|n| obs.real || n.kind == crate::model::AgentKind::Robot)
        .collect();
    neighbours.extend(sensed.people);
    if let Some(scan) = &sensed.scan {
        let params = crate::scan::ScanParams::default();
        let unexplained = crate::scan::unexplained_bodies(scan, map, &neighbours, &params);
        neighbours.extend(unexplained);
    }
    (ego, neighbours)
}

/// Why the static map could not be had from the coordinator (the agent retries).
#[derive(Debug, thiserror::Error)]
enum MapFetchError {
    /// The query could not be sent.
    #[error("query: {0}")]
    Query(zenoh::Error),
    /// Nobody answered.
    #[error("no reply")]
    NoReply,
    /// The answer was not a map message.
    #[error(transparent)]
    Decode(#[from] schemas::DecodeError),
    /// The coordinator answered with an error.
    #[error("error reply: {0}")]
    ErrorReply(String),
    /// The map is not the version the observations name.
    #[error("the map served is version {got}, the observations name {want}")]
    Version {
        /// The version served.
        got: u32,
        /// The version the observations name.
        want: u32,
    },
    /// The map's geometry is unusable.
    #[error(transparent)]
    Map(#[from] crate::map::MapError),
}

/// The site's safety-layer setting (`MapMsg::safety_layer`) on `guard`: the layer's defaults
/// with the site's changes. A setting that does not read, or has a value out of range, is
/// refused as a bad message, and the layer runs on as it was.
fn take_site_layer(guard: &mut Guard, setting: Option<&str>, counters: &AgentCounters, id: u32) {
    match SafetyParams::default().with_overrides(setting.unwrap_or("")) {
        Ok(params) => {
            if params != *guard.params() {
                tracing::info!(
                    robot = id,
                    "the site's safety layer: {:?}",
                    params.changes()
                );
            }
            guard.set_params(params);
        }
        Err(why) => reject(
            counters,
            id,
            &format!("the site's safety-layer setting: {why}"),
        ),
    }
}

fn reject(counters: &AgentCounters, id: u32, why: &str) {
    let n = counters.rejected.fetch_add(1, Ordering::Relaxed) + 1;
    if log_rejection(n) {
        tracing::warn!(robot = id, rejected = n, "bad message: {why}");
    }
}

async fn safe_stop(
    publisher: &zenoh::pubsub::Publisher<'_>,
    id: u32,
    last: Option<(u64, f64)>,
    counters: &AgentCounters,
) {
    let (obs_seq, stamp) = last.unwrap_or((0, 0.0));
    let stop = CommandMsg {
        robot_id: id,
        obs_seq,
        stamp,
        motion: wire::motion(Command::STOP),
        safe_stop: true,
        safety: SafetyZone::Clear,
        state: None,
    };
    counters.safe_stops.fetch_add(1, Ordering::Relaxed);
    if let Err(e) = publisher.put(encode(&stop)).await {
        tracing::warn!(robot = id, "safe stop not sent: {e}");
    }
}

/// A site's map as an agent takes it from the coordinator.
struct FetchedMap {
    version: u32,
    map: StaticMap,
    /// Where people go: foIGP's intents.
    stations: Vec<Vec2>,
    /// Where people stop and turn, for the safety layer.
    turn_places: Option<Vec<(Vec2, Vec2)>>,
    /// The site's safety-layer setting, as served.
    safety_layer: Option<String>,
}

/// The map of version `want` (the one the coordinator's observations name), the site's
/// stations and turn places: a reply with another version is skipped, whoever sent it.
async fn fetch_map(
    session: &zenoh::Session,
    keys: &Keys,
    want: u32,
) -> Result<FetchedMap, MapFetchError> {
    let replies = session
        .get(keys.map())
        .timeout(MAP_QUERY_TIMEOUT)
        .await
        .map_err(MapFetchError::Query)?;
    let mut last_error = MapFetchError::NoReply;
    while let Ok(reply) = replies.recv_async().await {
        match reply.result() {
            Ok(sample) => match decode::<MapMsg>(&sample.payload().to_bytes()) {
                Ok(msg) if msg.map_version != want => {
                    last_error = MapFetchError::Version {
                        got: msg.map_version,
                        want,
                    };
                }
                Ok(msg) => {
                    return Ok(FetchedMap {
                        version: msg.map_version,
                        map: wire::map_from_wire(&msg)?,
                        stations: msg.stations.iter().map(|s| wire::vec(s.p)).collect(),
                        turn_places: wire::turn_places_from_wire(&msg),
                        safety_layer: msg.safety_layer,
                    });
                }
                Err(e) => last_error = e.into(),
            },
            Err(e) => {
                last_error = MapFetchError::ErrorReply(
                    e.payload()
                        .try_to_string()
                        .map_or_else(|_| format!("{e:?}"), |s| s.into_owned()),
                );
            }
        }
    }
    Err(last_error)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn observation(seq: u64) -> Observation {
        Observation {
            robot_id: 7,
            seq,
            sim_time: seq as f64 * 0.1,
            dt: 0.1,
            map_version: 1,
            p: schemas::P2(1.0, 2.0),
            heading: 0.0,
            vel: schemas::P2(0.0, 0.0),
            yaw_rate: 0.0,
            radius: 0.3,
            goal: None,
            task: None,
            neighbours: Vec::new(),
            visibility: None,
            real: false,
        }
    }

    /// A site's layer setting is taken over the defaults; an unreadable or out-of-range one
    /// is counted as rejected and leaves the layer as it was; none is the defaults.
    #[test]
    fn the_site_sets_the_layer_and_a_bad_setting_leaves_it() {
        let counters = AgentCounters::default();
        let mut guard = Guard::new(crate::safety::SafetyLimits::SIMULATED_ROBOT);
        take_site_layer(&mut guard, Some("warning_time=0.5"), &counters, 7);
        assert_eq!(guard.params().warning_time, 0.5);
        for bad in ["warning_time=-1", "warning_time=inf", "no_such=1", "=,"] {
            take_site_layer(&mut guard, Some(bad), &counters, 7);
            assert_eq!(guard.params().warning_time, 0.5, "{bad}");
        }
        assert_eq!(counters.rejected.load(Ordering::Relaxed), 4);
        take_site_layer(&mut guard, None, &counters, 7);
        assert_eq!(guard.params(), &SafetyParams::default());
    }

    #[test]
    fn gaps_in_the_sequence_are_counted_and_a_restart_is_not_one() {
        let newest = NewestObservation::default();
        let put = |seq| newest.put(observation(seq));
        let arrival = |replaced, missed| Arrival { replaced, missed };
        assert_eq!(put(5), arrival(false, 0));
        assert_eq!(put(6), arrival(true, 0));
        assert_eq!(newest.take().map(|o| o.seq), Some(6));
        assert_eq!(put(9), arrival(false, 2));
        // The coordinator restarted and counts from 0 again.
        assert_eq!(put(0), arrival(true, 0));
        assert_eq!(put(1), arrival(true, 0));
    }
}
