//! The coordinator: runs a warehouse [`Fleet`] in (scaled) real time and connects it to the
//! agents over Zenoh.
//!
//! Every tick it: takes in liveliness changes (an agent joined, left or crashed: its robot is
//! held and stops), the newest command per robot, and intents; applies each robot's newest
//! command unless it is stale (answers an observation more than `stale_ticks` old: the robot
//! stops); steps the world; dispatches tasks to idle robots; publishes each live robot's
//! observation (with the intents of the robots it sees); and once per simulated second a
//! fleet metrics frame. A queryable serves the static map.

use agent::map::StaticMap;
use agent::math::{Real, vec2};
use agent::model::Command;
use agent::runtime::{percentile, wire};
use schemas::{
    Channel, CommandMsg, FleetMetrics, IntentMsg, Keys, Observation, RobotRow, StationMsg,
    TaskAssignment, TaskRef, TaskStage, decode, encode,
};
use std::collections::VecDeque;
use std::future::Future;
use std::time::{Duration, Instant};
use world_sim::fleet::{Fleet, FleetEvent, Stage};
use zenoh::sample::SampleKind;

/// Round-trip samples kept (the oldest half is dropped beyond this).
const MAX_ROUND_TRIP_SAMPLES: usize = 400_000;

/// Version of the map the coordinator serves (the generated map never changes during a run).
pub const MAP_VERSION: u32 = 1;

/// How a coordinator runs.
#[derive(Debug, Clone)]
pub struct CoordinatorConfig {
    /// Site name.
    pub site: String,
    /// Simulated seconds per wall second (1 = real time).
    pub speed: f64,
    /// Stop after this many simulated seconds (None: until shutdown).
    pub seconds: Option<f64>,
    /// A command answering an observation older than this many ticks is stale.
    pub stale_ticks: u64,
    /// Receives every event the moment it happens (tests, dashboards).
    pub events: Option<std::sync::mpsc::Sender<(Instant, Event)>>,
    /// Receives every timed round trip (benchmarks), when it is counted at the next tick.
    pub round_trips: Option<std::sync::mpsc::Sender<RoundTrip>>,
    /// Observations go out in this many slices spread over the first 90 % of each tick.
    pub stagger: usize,
    /// Hold the coordinator's liveliness token `…/coordinator` while running (agents stop
    /// their robots the moment it goes). Off when the caller holds it instead, through
    /// [`declare_presence`], to outlive the run: the demo keeps it until its agents have
    /// shut down, so that a planned end is not a lost coordinator to them.
    pub announce_presence: bool,
}

impl CoordinatorConfig {
    /// Real time on `site`, until shutdown, 3-tick staleness (0.3 s at 10 Hz).
    pub fn new(site: &str) -> Self {
        Self {
            site: site.to_owned(),
            speed: 1.0,
            seconds: None,
            stale_ticks: 3,
            events: None,
            round_trips: None,
            stagger: 100,
            announce_presence: true,
        }
    }
}

/// Declares the coordinator's liveliness token of `site` on `session`: agents stop their
/// robots the moment it is dropped.
pub async fn declare_presence(
    session: &zenoh::Session,
    site: &str,
) -> Result<zenoh::liveliness::LivelinessToken, CoordinatorError> {
    let keys = Keys::new(site)?;
    session
        .liveliness()
        .declare_token(keys.coordinator())
        .await
        .map_err(zerr("coordinator liveliness token"))
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
    /// A robot finished a task.
    TaskDone {
        /// Robot.
        robot: u32,
        /// Task.
        task: u64,
    },
}

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
    /// Observation published → its command received, milliseconds: p50 and p99 since start.
    pub round_trip_ms: (f64, f64),
    /// Commands received.
    pub commands: u64,
    /// Observations published.
    pub observations: u64,
    /// Observations answered by a command (each counted once).
    pub answered: u64,
    /// Ticks in which a robot with a task had no fresh command (it stopped).
    pub stale_commands: u64,
    /// Messages rejected by the decoder or for naming the wrong robot.
    pub rejected: u64,
    /// Events so far.
    pub events: Vec<Event>,
    /// Largest planning-time p99 reported by a live agent in its last heartbeat (µs).
    pub planner_p99_us: f64,
    /// The newest candidate fan of each robot whose agent shares it (index = robot id).
    pub fans: Vec<Option<schemas::FanMsg>>,
    /// Robots flagged (agent crashed or left), by id.
    pub flagged: Vec<u32>,
}

/// Why the coordinator could not run.
#[derive(Debug, thiserror::Error)]
pub enum CoordinatorError {
    /// The session refused a declaration.
    #[error("zenoh: {0}")]
    Zenoh(String),
    /// Bad site name.
    #[error(transparent)]
    Key(#[from] schemas::KeyError),
}

fn zerr(what: &'static str) -> impl Fn(zenoh::Error) -> CoordinatorError {
    move |e| CoordinatorError::Zenoh(format!("{what}: {e}"))
}

/// Per-robot bookkeeping.
#[derive(Debug, Clone, Default)]
struct Link {
    alive: bool,
    flagged: bool,
    /// Newest command: the observation it answers, the command, whether it was a safe stop.
    command: Option<(u64, Command, bool)>,
    /// Next observation sequence number.
    next_seq: u64,
    /// Recent observations: sequence number, wall time published, whether answered.
    sent: VecDeque<(u64, Instant, bool)>,
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

/// Runs the coordinator on `session` until `seconds` have been simulated or `shutdown`
/// completes, reporting to `observer`.
pub async fn run_coordinator(
    session: &zenoh::Session,
    mut fleet: Fleet,
    config: CoordinatorConfig,
    shutdown: impl Future<Output = ()>,
    observer: &mut impl Observer,
) -> Result<Status, CoordinatorError> {
    let keys = Keys::new(&config.site)?;
    let n = fleet.robots();
    let dt = fleet.world.dt;

    let map_bytes = encode(&map_message(&fleet));
    let map_key = keys.map();
    let queryable = session
        .declare_queryable(&map_key)
        .await
        .map_err(zerr("map queryable"))?;
    // Map queries are answered by a task of their own, whatever the tick loop is doing.
    let map_server = tokio::spawn(async move {
        while let Ok(query) = queryable.recv_async().await {
            if let Err(e) = query
                .reply(query.key_expr().clone(), map_bytes.clone())
                .await
            {
                tracing::warn!("map reply failed: {e}");
            }
        }
    });
    // While this token lives, agents know the coordinator does; when it goes (shutdown, crash,
    // lost link) they stop their robots at once instead of waiting for observations to time out.
    let coordinator_token = if config.announce_presence {
        Some(declare_presence(session, &config.site).await?)
    } else {
        None
    };
    let alive_sub = session
        .liveliness()
        .declare_subscriber(keys.every_alive())
        .history(true)
        .with(zenoh::handlers::FifoChannel::new(16 * 1024))
        .await
        .map_err(zerr("liveliness subscriber"))?;
    // Commands are stamped on arrival (round trips are measured to there, not to the tick that
    // applies them); a full queue drops and counts rather than blocking the session.
    let (cmd_tx, cmd_rx) =
        std::sync::mpsc::sync_channel::<(Instant, zenoh::sample::Sample)>(64 * 1024);
    let overflow = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
    let overflow_in = overflow.clone();
    let cmd_sub = session
        .declare_subscriber(keys.every_robot(Channel::Cmd))
        .callback(move |sample| {
            if cmd_tx.try_send((Instant::now(), sample)).is_err() {
                overflow_in.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            }
        })
        .await
        .map_err(zerr("command subscriber"))?;
    let intent_sub = session
        .declare_subscriber(keys.every_robot(Channel::Intent))
        // A ring drops the oldest intents if the loop falls behind; a full FIFO would block
        // the session for everyone.
        .with(zenoh::handlers::RingChannel::new(64 * 1024))
        .await
        .map_err(zerr("intent subscriber"))?;
    let info_sub = session
        .declare_subscriber(keys.every_robot(Channel::Info))
        .with(zenoh::handlers::RingChannel::new(4 * 1024))
        .await
        .map_err(zerr("info subscriber"))?;
    let mut planner_p99 = vec![0.0_f64; n];
    let fan_sub = session
        .declare_subscriber(keys.every_robot(Channel::Fan))
        .with(zenoh::handlers::RingChannel::new(1024))
        .await
        .map_err(zerr("fan subscriber"))?;
    let mut obs_pubs = Vec::with_capacity(n);
    let mut task_pubs = Vec::with_capacity(n);
    for i in 0..n as u32 {
        obs_pubs.push(
            session
                .declare_publisher(keys.robot(i, Channel::Obs))
                .await
                .map_err(zerr("observation publisher"))?,
        );
        task_pubs.push(
            session
                .declare_publisher(keys.robot(i, Channel::Task))
                .await
                .map_err(zerr("task publisher"))?,
        );
    }
    let metrics_pub = session
        .declare_publisher(keys.metrics())
        .await
        .map_err(zerr("metrics publisher"))?;

    let mut links = vec![Link::default(); n];
    // Robots without a live agent are held until one joins.
    for i in 0..n {
        fleet.set_held(i, true);
    }
    let mut status = Status {
        robots: n,
        fans: vec![None; n],
        ..Status::default()
    };
    let mut round_trips = RoundTrips {
        us: Vec::new(),
        log: config.round_trips.clone(),
    };
    let tick_wall = Duration::from_secs_f64(dt / config.speed);
    let mut ticker = tokio::time::interval(tick_wall);
    ticker.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let mut last_status = Instant::now();
    let ticks_per_metrics = (1.0 / dt).round().max(1.0) as u64;
    let end_tick = config.seconds.map(|s| (s / dt).round() as u64);
    tokio::pin!(shutdown);

    loop {
        // A shutdown wins over a due tick: once asked to stop, nothing more goes out.
        tokio::select! {
            biased;
            () = &mut shutdown => break,
            _ = ticker.tick() => {}
        }
        let tick_started = tokio::time::Instant::now();
        // Liveliness.
        while let Ok(Some(sample)) = alive_sub.try_recv() {
            let Some(id) = keys.parse_alive(sample.key_expr().as_str()) else {
                continue;
            };
            let Some(link) = links.get_mut(id as usize) else {
                tracing::warn!("agent {id} has no robot here ({n} robots)");
                continue;
            };
            match sample.kind() {
                SampleKind::Put => {
                    link.alive = true;
                    link.flagged = false;
                    link.command = None;
                    fleet.set_held(id as usize, false);
                    tracing::info!(robot = id, "agent joined");
                    emit(&mut status, &config, Event::Joined(id));
                }
                SampleKind::Delete => {
                    link.alive = false;
                    link.flagged = true;
                    fleet.set_held(id as usize, true);
                    let clean = link.command.is_some_and(|c| c.2);
                    let event = if clean {
                        Event::Left(id)
                    } else {
                        Event::Crashed(id)
                    };
                    tracing::warn!(
                        robot = id,
                        "agent gone: {event:?}; robot stopped and flagged"
                    );
                    emit(&mut status, &config, event);
                }
            }
        }
        // Commands: keep the newest per robot.
        take_commands(&cmd_rx, &keys, &mut links, &mut status, &mut round_trips);
        status.rejected += overflow.swap(0, std::sync::atomic::Ordering::Relaxed);
        // The end comes after the last observations had a tick to be answered.
        if end_tick.is_some_and(|end| status.tick >= end) {
            tokio::time::sleep(tick_wall).await;
            take_commands(&cmd_rx, &keys, &mut links, &mut status, &mut round_trips);
            break;
        }
        // Agents' heartbeats: their planning time.
        while let Ok(Some(sample)) = info_sub.try_recv() {
            match decode::<schemas::AgentInfo>(&sample.payload().to_bytes()) {
                Ok(info) if (info.robot_id as usize) < n => {
                    planner_p99[info.robot_id as usize] = info.plan_p99_us;
                }
                _ => status.rejected += 1,
            }
        }
        status.planner_p99_us = (0..n)
            .filter(|&i| links[i].alive)
            .map(|i| planner_p99[i])
            .fold(0.0, f64::max);
        // Fans (dashboards only).
        while let Ok(Some(sample)) = fan_sub.try_recv() {
            match decode::<schemas::FanMsg>(&sample.payload().to_bytes()) {
                Ok(fan) if (fan.robot_id as usize) < n => {
                    let id = fan.robot_id as usize;
                    status.fans[id] = Some(fan);
                }
                _ => status.rejected += 1,
            }
        }
        // Intents.
        while let Ok(Some(sample)) = intent_sub.try_recv() {
            match decode::<IntentMsg>(&sample.payload().to_bytes()) {
                Ok(intent) if (intent.robot_id as usize) < n => {
                    let samples = wire::samples_from_wire(&intent.trajectory);
                    fleet.set_intent(intent.robot_id as usize, intent.stamp, samples);
                }
                _ => status.rejected += 1,
            }
        }
        // Apply the newest fresh command per robot.
        let mut commands = vec![Command::STOP; n];
        for (i, link) in links.iter().enumerate() {
            let fresh = link
                .command
                .filter(|c| !c.2 && link.next_seq.saturating_sub(c.0 + 1) <= config.stale_ticks);
            match fresh {
                Some((_, command, _)) => commands[i] = command,
                None if link.alive && fleet.job(i).is_some() && link.next_seq > 0 => {
                    status.stale_commands += 1;
                }
                None => {}
            }
        }
        let mut events = fleet.step(&commands);
        events.extend(fleet.dispatch());
        status.tick += 1;
        status.sim_time = fleet.world.time;
        for event in &events {
            match *event {
                FleetEvent::Assigned { robot, task } => {
                    let site = fleet.site();
                    let assignment = TaskAssignment {
                        robot_id: robot as u32,
                        task_id: task.id,
                        pick_station: task.pick as u32,
                        pick: wire::p2(site.stations[task.pick].position),
                        drop_station: task.drop as u32,
                        drop: wire::p2(site.stations[task.drop].position),
                        assigned_at: fleet.world.time,
                    };
                    if let Err(e) = task_pubs[robot].put(encode(&assignment)).await {
                        tracing::warn!(robot, "task not sent: {e}");
                    }
                }
                FleetEvent::Done { robot, task } => {
                    status.tasks_done += 1;
                    let done = Event::TaskDone {
                        robot: robot as u32,
                        task,
                    };
                    emit(&mut status, &config, done);
                }
                FleetEvent::Picked { .. } => {}
            }
        }
        // Observations for robots with a live agent, all of this tick's state, published in
        // `stagger` slices at fixed offsets over the first 90 % of the tick, so that agents
        // sharing a machine do not all plan in the same instant (real robots' sensors are not
        // in phase either) and the last slice's commands still arrive before the next tick.
        // Offsets are absolute (timer rounding never accumulates), and each slice's
        // observations are built just before it goes out (the world does not change within a
        // tick), which spreads the perception work over the tick as well.
        let live: Vec<usize> = (0..n).filter(|&i| links[i].alive).collect();
        let window = tick_wall.mul_f64(0.9);
        // Slices at least 2 ms apart: the timer wakes up to 1 ms late.
        let max_slices = (window.as_millis() / 2).max(1) as usize;
        let per_slice = live
            .len()
            .div_ceil(config.stagger.clamp(1, max_slices))
            .max(1);
        let slices = live.len().div_ceil(per_slice).max(1);
        let offset = window / slices as u32;
        let mut previous: Option<tokio::time::Instant> = None;
        let mut shut_down = false;
        for (k, chunk) in live.chunks(per_slice).enumerate() {
            // A slice that is late after a stall catches up at half the spacing, never back to
            // back: slices sent at once would make their agents plan all at once.
            let due = tick_started + offset * k as u32;
            let at = previous.map_or(due, |p| due.max(p + offset / 2));
            // A shutdown during the tick stops the remaining slices too.
            tokio::select! {
                biased;
                () = &mut shutdown => {
                    shut_down = true;
                    break;
                }
                () = tokio::time::sleep_until(at) => {}
            }
            previous = Some(tokio::time::Instant::now());
            for &i in chunk {
                let obs = observation(&mut fleet, i, links[i].next_seq);
                let bytes = encode(&obs);
                let link = &mut links[i];
                link.next_seq += 1;
                link.sent.push_back((obs.seq, Instant::now(), false));
                if link.sent.len() > 16 {
                    link.sent.pop_front();
                }
                status.observations += 1;
                if let Err(e) = obs_pubs[i].put(bytes).await {
                    tracing::warn!(robot = i, "observation not sent: {e}");
                }
            }
        }
        if shut_down {
            break;
        }
        observer.tick(&fleet, &status, &events);
        if status.tick.is_multiple_of(ticks_per_metrics) {
            let frame = metrics_frame(&fleet, &links, &status);
            if let Err(e) = metrics_pub.put(encode(&frame)).await {
                tracing::warn!("metrics not sent: {e}");
            }
            status.metrics = Some(frame);
        }
        if last_status.elapsed() >= Duration::from_secs(1) {
            last_status = Instant::now();
            refresh(&mut status, &links, &round_trips.us);
            observer.status(&fleet, &status);
        }
    }
    // Final frame and status.
    let frame = metrics_frame(&fleet, &links, &status);
    let _ = metrics_pub.put(encode(&frame)).await;
    status.metrics = Some(frame);
    refresh(&mut status, &links, &round_trips.us);
    observer.status(&fleet, &status);
    map_server.abort();
    drop(cmd_sub);
    drop(coordinator_token);
    Ok(status)
}

fn emit(status: &mut Status, config: &CoordinatorConfig, event: Event) {
    if let Some(tx) = &config.events {
        let _ = tx.send((Instant::now(), event.clone()));
    }
    status.events.push(event);
}

/// Round trips timed so far (µs, in arrival order) and where each one goes as it is counted.
struct RoundTrips {
    us: Vec<u32>,
    log: Option<std::sync::mpsc::Sender<RoundTrip>>,
}

impl RoundTrips {
    fn record(&mut self, trip: RoundTrip) {
        let us = trip
            .arrived
            .saturating_duration_since(trip.published)
            .as_micros();
        if self.us.len() >= MAX_ROUND_TRIP_SAMPLES {
            self.us.drain(..MAX_ROUND_TRIP_SAMPLES / 2);
        }
        self.us.push(us.min(u32::MAX as u128) as u32);
        if let Some(log) = &self.log {
            let _ = log.send(trip);
        }
    }
}

/// Takes in every command that arrived: the newest per robot is kept; answers to recent
/// observations are counted once and timed.
fn take_commands(
    cmd_rx: &std::sync::mpsc::Receiver<(Instant, zenoh::sample::Sample)>,
    keys: &Keys,
    links: &mut [Link],
    status: &mut Status,
    round_trips: &mut RoundTrips,
) {
    let n = links.len();
    while let Ok((arrived, sample)) = cmd_rx.try_recv() {
        let key_id = keys.parse_robot(sample.key_expr().as_str()).map(|k| k.0);
        match decode::<CommandMsg>(&sample.payload().to_bytes()) {
            Ok(cmd) if Some(cmd.robot_id) == key_id && (cmd.robot_id as usize) < n => {
                let link = &mut links[cmd.robot_id as usize];
                status.commands += 1;
                if let Some(entry) = link.sent.iter_mut().find(|e| e.0 == cmd.obs_seq)
                    && !entry.2
                    && !cmd.safe_stop
                {
                    entry.2 = true;
                    status.answered += 1;
                    round_trips.record(RoundTrip {
                        robot: cmd.robot_id,
                        published: entry.1,
                        arrived,
                    });
                }
                if link.command.is_none_or(|c| cmd.obs_seq >= c.0) {
                    link.command = Some((cmd.obs_seq, wire::command(cmd.motion), cmd.safe_stop));
                }
            }
            Ok(_) => status.rejected += 1,
            Err(e) => {
                status.rejected += 1;
                tracing::debug!("bad command: {e}");
            }
        }
    }
}

/// Updates the derived fields; round trips are kept in arrival order (percentiles sort a copy).
fn refresh(status: &mut Status, links: &[Link], round_trips_us: &[u32]) {
    status.alive = links.iter().filter(|l| l.alive).count();
    status.flagged = (0..links.len() as u32)
        .filter(|&i| links[i as usize].flagged)
        .collect();
    let mut sorted = round_trips_us.to_vec();
    status.round_trip_ms = (
        percentile(&mut sorted, 0.5) / 1000.0,
        percentile(&mut sorted, 0.99) / 1000.0,
    );
}

/// Robot `i`'s observation with sequence number `seq`.
pub fn observation(fleet: &mut Fleet, i: usize, seq: u64) -> Observation {
    let (ego, seen) = fleet.observe(i);
    let task = fleet.job(i).map(|job| TaskRef {
        task_id: job.task.id,
        stage: match job.stage {
            Stage::ToPick => TaskStage::Pick,
            Stage::ToDrop => TaskStage::Drop,
        },
    });
    Observation {
        robot_id: i as u32,
        seq,
        sim_time: fleet.world.time,
        dt: fleet.world.dt,
        map_version: MAP_VERSION,
        p: wire::p2(ego.position),
        heading: ego.heading,
        vel: wire::p2(ego.velocity),
        yaw_rate: ego.yaw_rate,
        radius: ego.radius,
        goal: fleet.goal(i).map(wire::p2),
        task,
        neighbours: seen.iter().map(wire::perceived).collect(),
    }
}

/// The site's static map and stations as served by the `…/map` queryable.
pub fn map_message(fleet: &Fleet) -> schemas::MapMsg {
    let site = fleet.site();
    let stations = site
        .stations
        .iter()
        .map(|s| StationMsg {
            id: s.id as u32,
            p: wire::p2(s.position),
        })
        .collect();
    let map: &StaticMap = &fleet.world.map;
    wire::map_to_wire(map, MAP_VERSION, stations, [vec2(0.0, 0.0), site.size])
}

fn metrics_frame(fleet: &Fleet, links: &[Link], status: &Status) -> FleetMetrics {
    let metrics: Vec<_> = (0..fleet.robots()).map(|i| fleet.metrics(i)).collect();
    let per_robot: Vec<RobotRow> = metrics
        .iter()
        .enumerate()
        .map(|(i, m)| RobotRow {
            robot_id: i as u32,
            alive: links[i].alive,
            tasks_done: fleet.tasks_done(i),
            collision_rate: m.collision_rate,
            svr: m.svr,
            min_human_distance: m
                .min_human_distance_m
                .is_finite()
                .then_some(m.min_human_distance_m),
            social_force: m.social_force,
        })
        .collect();
    let mean = |f: &dyn Fn(&RobotRow) -> Real| {
        if per_robot.is_empty() {
            0.0
        } else {
            per_robot.iter().map(f).sum::<Real>() / per_robot.len() as Real
        }
    };
    FleetMetrics {
        tick: status.tick,
        sim_time: fleet.world.time,
        robots: fleet.robots() as u32,
        alive: links.iter().filter(|l| l.alive).count() as u32,
        humans: fleet.world.humans.crowd.len() as u32,
        tasks_done: status.tasks_done,
        collision_rate: mean(&|r| r.collision_rate),
        svr: mean(&|r| r.svr),
        near_misses: metrics.iter().map(|m| m.robot_near_misses).sum(),
        dropped_commands: status.stale_commands,
        per_robot,
    }
}
