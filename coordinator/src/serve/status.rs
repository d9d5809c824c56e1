//! What the coordinator's runtime shares with its observers and its own phases: how it is
//! configured, what it reports, what can happen and what can fail.

use schemas::FleetMetrics;
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};
use world_sim::fleet::{Fleet, FleetEvent};

/// How a coordinator runs.
#[derive(Debug, Clone)]
pub struct CoordinatorConfig {
    /// The site's keys.
    pub keys: schemas::Keys,
    /// Simulated seconds per wall second (1 = real time).
    pub speed: f64,
    /// Stop after this many simulated seconds (None: until shutdown).
    pub seconds: Option<f64>,
    /// A robot drives on its newest command while at most this many newer observations have
    /// gone out unanswered; then the command is stale and the robot stops. With 3, a command
    /// answering the observation of tick c drives ticks c + 1 to c + 4 (0.4 s at 10 Hz).
    pub stale_ticks: u64,
    /// Receives every event the moment it happens (tests, dashboards).
    pub events: Option<std::sync::mpsc::Sender<(Instant, Event)>>,
    /// Receives every timed round trip (benchmarks), when it is counted at the next tick.
    pub round_trips: Option<std::sync::mpsc::Sender<RoundTrip>>,
    /// Observations go out in this many slices spread over the first 90 % of each tick.
    pub stagger: usize,
    /// Hold the coordinator's liveliness token `…/coordinator` while running (agents stop
    /// their robots the moment it goes). Off when the caller holds it instead, through
    /// [`declare_presence`](super::declare_presence), to outlive the run: the demo keeps it until its agents have
    /// shut down, so that a planned end is not a lost coordinator to them.
    pub announce_presence: bool,
    /// Where each tick's inputs and the events go (`--state DIR`), when kept.
    pub journal: Option<super::journal::JournalSink>,
    /// The run goes on from a journal: the fleet handed over is the journal's replay, this
    /// many ticks in, with this many tasks done (ticks and `seconds` count from the run's
    /// start).
    pub resume: Option<Resume>,
    /// What one robot alone does on this site (`world_sim::efficiency`): the metrics frames
    /// carry the fleet's efficiency against it once it is set. It may be set while the run
    /// goes on (`gapfleet coordinator` measures it in the background, so that a restart is not
    /// held up by it); empty: no efficiency.
    pub free_flow: Arc<OnceLock<world_sim::efficiency::FreeFlow>>,
    /// Play every robot as a ROS 2 robot over rmw_zenoh (`super::ros_robots`): odometry, scan
    /// and people out, driven by its `cmd_vel`.
    pub ros: Option<super::ros_robots::RosSimConfig>,
    /// Real robots the coordinator does not simulate (by id): each one's body is placed where
    /// its agent reports it ([`schemas::CommandMsg::state`]), and tasks, the traffic policy,
    /// shared intents, metrics, the journal and the dashboards take it from there.
    pub live: Vec<u32>,
    /// A real robot whose agent has reported no state for this long (wall time) is lost: held,
    /// given no task and flagged, until its reports come back.
    pub lost_after: Duration,
    /// The safety layer's parameters on this site (the scenario's `[robot.safety_layer]`),
    /// served to agents with the map (`schemas::MapMsg::safety_layer`) where they differ from
    /// the layer's defaults.
    pub safety_layer: agent::safety::SafetyParams,
}

/// Where a resumed run picks up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Resume {
    /// Ticks already run.
    pub tick: u64,
    /// Tasks already done.
    pub tasks_done: u64,
}

/// How long a real robot may go without a state report before it is lost: five missed
/// reports at 10 Hz, so that a robot is flagged within a second of its last one, tick lag
/// included.
pub const LOST_AFTER: Duration = Duration::from_millis(500);

impl CoordinatorConfig {
    /// Real time on the site of `keys`, until shutdown, 3-tick staleness (0.3 s at 10 Hz).
    pub fn new(keys: schemas::Keys) -> Self {
        Self {
            keys,
            speed: 1.0,
            seconds: None,
            stale_ticks: 3,
            events: None,
            round_trips: None,
            stagger: 100,
            announce_presence: true,
            free_flow: Arc::default(),
            journal: None,
            resume: None,
            ros: None,
            live: Vec::new(),
            lost_after: LOST_AFTER,
            safety_layer: agent::safety::SafetyParams::default(),
        }
    }
}

/// One observation and the command that answered it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RoundTrip {
    /// Robot.
    pub robot: u32,
    /// When the observation was published.
    pub published: Instant,
    /// When its command reached the coordinator's session.
    pub arrived: Instant,
}

/// Something that happened, for logs and dashboards.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// An agent declared its liveliness token.
    Joined(u32),
    /// An agent withdrew its token after a safe stop.
    Left(u32),
    /// An agent's token vanished without a safe stop.
    Crashed(u32),
    /// A real robot's agent stopped reporting where the robot is (its hardware or its
    /// odometry is gone): the robot is held and gets no task.
    Lost(u32),
    /// A lost robot reports again and is released.
    Found(u32),
    /// A robot finished a task.
    TaskDone {
        /// Robot.
        robot: u32,
        /// Task.
        task: u64,
    },
}

/// Events a status keeps: a long run's log would otherwise grow without bound (and be cloned
/// for every observer once a second). The journal (`--state`) keeps them all.
pub const EVENTS_KEPT: usize = 10_000;

/// What the coordinator reports while it runs (once per wall second) and at the end.
#[derive(Debug, Clone, Default)]
pub struct Status {
    /// Simulated seconds.
    pub sim_time: f64,
    /// Ticks run.
    pub tick: u64,
    /// Robots.
    pub robots: usize,
    /// Agents alive.
    pub alive: usize,
    /// Tasks completed.
    pub tasks_done: u64,
    /// The newest metrics frame.
    pub metrics: Option<FleetMetrics>,
    /// The fleet summary that frame was built from: the fleet-wide figures for the
    /// dashboard and the demo's summary.
    pub summary: Option<world_sim::fleet::FleetSummary>,
    /// Observation published → its command received, milliseconds: p50 and p99 since start.
    pub round_trip_ms: (f64, f64),
    /// Commands received.
    pub commands: u64,
    /// Observations published.
    pub observations: u64,
    /// Observations answered by a command (each counted once).
    pub answered: u64,
    /// Ticks in which a robot with a task stopped for want of a fresh command: more than
    /// `stale_ticks` observations went unanswered (counting from its first), or its agent
    /// sent a safe stop.
    pub stale_commands: u64,
    /// The same per robot.
    pub stale_per_robot: Vec<u64>,
    /// Messages rejected by the decoder or for naming the wrong robot.
    pub rejected: u64,
    /// The newest events (at most `EVENTS_KEPT`; older ones are let go in halves and
    /// counted in `events_dropped`). Read them with [`Status::events_since`].
    pub events: Vec<Event>,
    /// Events let go from the front of `events`.
    pub events_dropped: u64,
    /// Largest planning-time p99 reported by a live agent in its last heartbeat (µs).
    pub planner_p99_us: f64,
    /// The newest candidate fan of each robot whose agent shares it (index = robot id).
    pub fans: Vec<Option<schemas::FanMsg>>,
    /// Robots flagged (agent crashed or left), by id.
    pub flagged: Vec<u32>,
    /// Real robots lost (their agents report no state), by id.
    pub lost: Vec<u32>,
    /// Which field of each robot's safety layer acted on its newest command (index = robot
    /// id; `Clear` before any command and for agents without the layer).
    pub safety: Vec<schemas::SafetyZone>,
}

/// Why the coordinator could not run.
#[derive(Debug, thiserror::Error)]
pub enum CoordinatorError {
    /// The session refused a declaration.
    #[error("zenoh: {what}: {source}")]
    Zenoh {
        /// What was being declared.
        what: &'static str,
        /// Zenoh's error.
        source: zenoh::Error,
    },
    /// A real robot named that the site does not have.
    #[error("live robot {robot}: the site has {robots} robots")]
    Live {
        /// The robot named.
        robot: u32,
        /// The site's robots.
        robots: usize,
    },
    /// The session refused a ROS 2 robot's declaration.
    #[error("zenoh: ROS 2 {what}: {source}")]
    Ros {
        /// What was being declared.
        what: String,
        /// Zenoh's error.
        source: zenoh::Error,
    },
}

/// Watches a running coordinator (dashboards, tests, the demo's status line). A closure
/// `FnMut(&Status, &Fleet)` is an observer of the status only.
pub trait Observer {
    /// After every tick, with that tick's fleet events.
    fn tick(&mut self, _fleet: &Fleet, _status: &Status, _events: &[FleetEvent]) {}
    /// About once per wall second, and once at the end.
    fn status(&mut self, _fleet: &Fleet, _status: &Status) {}
}

impl<F: FnMut(&Status, &Fleet)> Observer for F {
    fn status(&mut self, fleet: &Fleet, status: &Status) {
        self(status, fleet);
    }
}

impl<A: Observer, B: Observer> Observer for (A, B) {
    fn tick(&mut self, fleet: &Fleet, status: &Status, events: &[FleetEvent]) {
        self.0.tick(fleet, status, events);
        self.1.tick(fleet, status, events);
    }
    fn status(&mut self, fleet: &Fleet, status: &Status) {
        self.0.status(fleet, status);
        self.1.status(fleet, status);
    }
}

impl<O: Observer> Observer for Option<O> {
    fn tick(&mut self, fleet: &Fleet, status: &Status, events: &[FleetEvent]) {
        if let Some(o) = self {
            o.tick(fleet, status, events);
        }
    }
    fn status(&mut self, fleet: &Fleet, status: &Status) {
        if let Some(o) = self {
            o.status(fleet, status);
        }
    }
}

impl Status {
    /// Events counted from the run's first: how many have happened.
    pub fn events_total(&self) -> u64 {
        self.events_dropped + self.events.len() as u64
    }

    /// The events from the `seen`-th on (counting from the run's first), as many as are still
    /// kept: an observer that read `seen` events last time reads on from there.
    pub fn events_since(&self, seen: u64) -> &[Event] {
        let start = seen.saturating_sub(self.events_dropped) as usize;
        &self.events[start.min(self.events.len())..]
    }

    /// Keeps `event`, letting the oldest half go when [`EVENTS_KEPT`] are kept.
    pub(super) fn push_event(&mut self, event: Event) {
        if self.events.len() >= EVENTS_KEPT {
            let half = EVENTS_KEPT / 2;
            self.events.drain(..half);
            self.events_dropped += half as u64;
        }
        self.events.push(event);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Past the cap the oldest half goes, and a reader that kept its count reads on exactly
    /// where it was (or from the oldest kept, if it fell further behind).
    #[test]
    fn events_are_capped_and_read_on_from_where_the_reader_was() {
        let mut status = Status::default();
        for i in 0..EVENTS_KEPT as u32 {
            status.push_event(Event::Joined(i));
        }
        let seen = status.events_total();
        assert_eq!(status.events_since(seen).len(), 0);
        status.push_event(Event::Left(7));
        assert_eq!(status.events.len(), EVENTS_KEPT / 2 + 1);
        assert_eq!(status.events_total(), EVENTS_KEPT as u64 + 1);
        assert_eq!(status.events_since(seen), &[Event::Left(7)]);
        assert_eq!(
            status.events_since(0)[0],
            Event::Joined(EVENTS_KEPT as u32 / 2)
        );
    }
}
