//! The coordinator's loop (`serve`, apart from `world_sim::fleet`, the fleet it serves): runs a
//! warehouse [`Fleet`] in (scaled) real time and connects it to the agents over Zenoh.
//!
//! Every tick runs these phases, each a function below: take in the newest command per robot
//! and liveliness changes (an agent joined, left or crashed: its robot is held and stops)
//! (`Coordinator::take_arrivals`); take in heartbeats, fans and intents
//! (`Coordinator::take_reports`); apply each robot's newest command unless it is stale
//! (more than `stale_ticks` newer observations went out unanswered: the robot stops), step
//! the world and dispatch tasks to idle robots (`Coordinator::step`); publish each live
//! robot's observation, with the intents of the robots it sees
//! (`Coordinator::publish_observations`); and once per
//! simulated second a fleet metrics frame (`Coordinator::publish_metrics`). A queryable
//! serves the static map. The demo ([`demo`]) runs a coordinator and its agents in one
//! process; [`dashboard`] draws a running fleet.
//!
//! Real robots (`CoordinatorConfig::live`) are not simulated: before each step every one with a
//! new state report from its agent is placed where it reported itself (the reports are
//! journaled), and one whose reports stop is lost until they return (`links::watch_reports`).
//! [`hardware`] plays real robots' hardware in a process of its own.

pub mod dashboard;
pub mod demo;
pub mod hardware;
pub mod journal;
mod links;
mod messages;
pub mod ros_robots;
mod status;

pub use messages::{map_message, map_version, observation, traffic_message};
pub use status::{CoordinatorConfig, CoordinatorError, Event, Observer, Resume, RoundTrip, Status};

use agent::model::Command;
use agent::runtime::wire;
use links::{Link, RoundTrips};
use schemas::{Channel, FleetMetrics, IntentMsg, Keys, SafetyZone, TaskAssignment, decode, encode};
use std::future::Future;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};
use world_sim::fleet::{Fleet, FleetEvent, FleetSummary};
use zenoh::handlers::{FifoChannelHandler, RingChannelHandler};
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::sample::Sample;

/// The free flow to measure a served fleet's efficiency against (`world_sim::efficiency`):
/// one robot alone on `scenario`'s site, planning with `planner` under the scenario's safety
/// layer, with the run's intent sharing and traffic policy (`None`: off), over the run's own
/// `seconds`, as the fleet studies measure it, so that a run's last unfinished task weighs
/// the same on both sides. Over [`FREE_FLOW_S`] for a run with no end, or one so short that
/// the robot alone finishes nothing in it. Runs in-process, about a second on an idle machine.
pub fn free_flow(
    scenario: &world_sim::scenario::Scenario,
    planner: agent::planner::PlannerSpec,
    share_intents: bool,
    policy: Option<world_sim::traffic_policy::PolicyParams>,
    seconds: Option<f64>,
) -> Result<world_sim::efficiency::FreeFlow, world_sim::fleet::NotAWarehouse> {
    let options = world_sim::fleet::FleetOptions {
        share_intents,
        policy,
        human_impact_window_s: None,
    };
    if let Some(seconds) = seconds.filter(|s| s.is_finite() && *s > 0.0) {
        let same = world_sim::efficiency::free_flow(scenario, planner, seconds, options)?;
        if same.tasks > 0 {
            return Ok(same);
        }
    }
    world_sim::efficiency::free_flow(scenario, planner, FREE_FLOW_S, options)
}

/// How long the free flow of a served fleet with no end runs (simulated s).
pub const FREE_FLOW_S: f64 = 600.0;

/// Declares the coordinator's liveliness token of `site` on `session`: agents stop their
/// robots the moment it is dropped.
pub async fn declare_presence(
    session: &zenoh::Session,
    keys: &Keys,
) -> Result<zenoh::liveliness::LivelinessToken, CoordinatorError> {
    session
        .liveliness()
        .declare_token(keys.coordinator())
        .await
        .map_err(zerr("coordinator liveliness token"))
}

fn zerr(what: &'static str) -> impl Fn(zenoh::Error) -> CoordinatorError {
    move |source| CoordinatorError::Zenoh { what, source }
}

/// The coordinator's declarations on its session: what it hears and where it speaks.
struct Wire<'s> {
    keys: Keys,
    alive: Subscriber<FifoChannelHandler<Sample>>,
    /// Commands, stamped on arrival; a full queue drops and counts (`cmd_overflow`) rather
    /// than blocking the session.
    commands: std::sync::mpsc::Receiver<(Instant, Sample)>,
    cmd_overflow: Arc<AtomicU64>,
    _command_subscriber: Subscriber<()>,
    intents: Subscriber<RingChannelHandler<Sample>>,
    infos: Subscriber<RingChannelHandler<Sample>>,
    fans: Subscriber<RingChannelHandler<Sample>>,
    observations: Vec<Publisher<'s>>,
    tasks: Vec<Publisher<'s>>,
    traffic: Vec<Publisher<'s>>,
    metrics: Publisher<'s>,
    map_server: tokio::task::JoinHandle<()>,
    /// The served map's version, named in every observation.
    map_version: u32,
    _presence: Option<zenoh::liveliness::LivelinessToken>,
    /// The robots as ROS 2 robots, when the coordinator plays them (`CoordinatorConfig::ros`).
    ros: Option<ros_robots::RosRobots>,
}

impl<'s> Wire<'s> {
    async fn declare(
        session: &'s zenoh::Session,
        fleet: &Fleet,
        config: &CoordinatorConfig,
    ) -> Result<Self, CoordinatorError> {
        let keys = config.keys.clone();
        let n = fleet.robots();
        let map = map_message(fleet, &config.safety_layer);
        let map_version = map.map_version;
        let map_bytes = encode(&map);
        let queryable = session
            .declare_queryable(keys.map())
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
        // While this token lives, agents know the coordinator does; when it goes (shutdown,
        // crash, lost link) they stop their robots at once instead of waiting for observations
        // to time out.
        let presence = if config.announce_presence {
            Some(declare_presence(session, &config.keys).await?)
        } else {
            None
        };
        let alive = session
            .liveliness()
            .declare_subscriber(keys.every_alive())
            .history(true)
            .with(zenoh::handlers::FifoChannel::new(16 * 1024))
            .await
            .map_err(zerr("liveliness subscriber"))?;
        // Commands are stamped on arrival (round trips are measured to there, not to the tick
        // that applies them); a full queue drops and counts rather than blocking the session.
        let (cmd_tx, commands) = std::sync::mpsc::sync_channel::<(Instant, Sample)>(64 * 1024);
        let cmd_overflow = Arc::new(AtomicU64::new(0));
        let overflow_in = cmd_overflow.clone();
        let command_subscriber = session
            .declare_subscriber(keys.every_robot(Channel::Cmd))
            .callback(move |sample| {
                if cmd_tx.try_send((Instant::now(), sample)).is_err() {
                    overflow_in.fetch_add(1, Ordering::Relaxed);
                }
            })
            .await
            .map_err(zerr("command subscriber"))?;
        // Rings drop the oldest reports if the loop falls behind; a full FIFO would block the
        // session for everyone.
        let ring = |capacity| zenoh::handlers::RingChannel::new(capacity);
        let intents = session
            .declare_subscriber(keys.every_robot(Channel::Intent))
            .with(ring(64 * 1024))
            .await
            .map_err(zerr("intent subscriber"))?;
        let infos = session
            .declare_subscriber(keys.every_robot(Channel::Info))
            .with(ring(4 * 1024))
            .await
            .map_err(zerr("info subscriber"))?;
        let fans = session
            .declare_subscriber(keys.every_robot(Channel::Fan))
            .with(ring(1024))
            .await
            .map_err(zerr("fan subscriber"))?;
        let mut observations = Vec::with_capacity(n);
        let mut tasks = Vec::with_capacity(n);
        let mut traffic = Vec::with_capacity(n);
        for i in 0..n as u32 {
            traffic.push(
                session
                    .declare_publisher(keys.robot(i, Channel::Traffic))
                    .await
                    .map_err(zerr("traffic publisher"))?,
            );
            observations.push(
                session
                    .declare_publisher(keys.robot(i, Channel::Obs))
                    .await
                    .map_err(zerr("observation publisher"))?,
            );
            tasks.push(
                session
                    .declare_publisher(keys.robot(i, Channel::Task))
                    .await
                    .map_err(zerr("task publisher"))?,
            );
        }
        let metrics = session
            .declare_publisher(keys.metrics())
            .await
            .map_err(zerr("metrics publisher"))?;
        let ros = match &config.ros {
            Some(ros) => Some(
                ros_robots::RosRobots::declare(session, n, fleet.world.map.clone(), ros)
                    .await
                    .map_err(|(what, source)| CoordinatorError::Ros { what, source })?,
            ),
            None => None,
        };
        Ok(Self {
            keys,
            alive,
            commands,
            cmd_overflow,
            _command_subscriber: command_subscriber,
            intents,
            infos,
            fans,
            observations,
            tasks,
            traffic,
            metrics,
            map_server,
            map_version,
            _presence: presence,
            ros,
        })
    }
}

/// A running coordinator: the fleet, its links to the agents and what it has counted.
struct Coordinator<'s> {
    fleet: Fleet,
    config: CoordinatorConfig,
    wire: Wire<'s>,
    links: Vec<Link>,
    status: Status,
    round_trips: RoundTrips,
    /// Each robot's planning-time p99 from its agent's last heartbeat (µs).
    planner_p99: Vec<f64>,
    /// Wall time of one tick.
    tick_wall: Duration,
    /// The journal gets a snapshot of the fleet every this many ticks.
    snapshot_every: u64,
    /// Each robot's held flag as the journal last recorded it.
    journal_held: Vec<bool>,
    /// Intents set since the last tick's step, for the journal.
    journal_intents: Vec<journal::IntentInput>,
}

/// How a tick's observations went out.
enum Published {
    All,
    /// A shutdown came while they were going out.
    ShutDown,
}

impl Coordinator<'_> {
    /// Commands, then liveliness changes. An agent that shuts down sends its safe stop and
    /// then withdraws its token; the two travel on different priorities, so the stop may
    /// arrive in the same tick as the token's end or in the next. An exit is therefore classed
    /// (clean leave or crash) one tick after the token went, once that tick's commands are in.
    /// (A join resets the robot's command, so a previous agent's last commands never carry
    /// over to a new one.)
    fn take_arrivals(&mut self) {
        self.take_commands();
        links::settle_exits(&mut self.links, &mut self.status, &self.config);
        while let Ok(Some(sample)) = self.wire.alive.try_recv() {
            links::liveliness_change(
                &sample,
                &self.wire.keys,
                &mut self.links,
                &mut self.fleet,
                &mut self.status,
                &self.config,
            );
        }
        links::watch_reports(
            &mut self.links,
            &mut self.fleet,
            &mut self.status,
            &self.config,
            Instant::now(),
        );
        self.status.rejected += self.wire.cmd_overflow.swap(0, Ordering::Relaxed);
    }

    /// Commands: the newest per robot is kept.
    fn take_commands(&mut self) {
        links::take_commands(
            &self.wire.commands,
            &self.wire.keys,
            &mut self.links,
            &mut self.status,
            &mut self.round_trips,
        );
    }

    /// Agents' heartbeats (their planning time), fans (dashboards only) and intents.
    fn take_reports(&mut self) {
        let n = self.links.len();
        let keys = &self.wire.keys;
        // The robot a per-robot key names, on `channel`: a payload naming another robot (or
        // one that is not here) is rejected, as for commands.
        let sender = |sample: &Sample, channel: Channel| {
            keys.parse_robot(sample.key_expr().as_str())
                .filter(|&(id, c)| c == channel && (id as usize) < n)
                .map(|(id, _)| id)
        };
        // Why a report was rejected, for the (rate-limited) log.
        let why = |sample: &Sample, decoded: Result<u32, schemas::DecodeError>| match decoded {
            Ok(id) => format!("{} names robot {id}", sample.key_expr()),
            Err(e) => format!("{}: {e}", sample.key_expr()),
        };
        while let Ok(Some(sample)) = self.wire.infos.try_recv() {
            match decode::<schemas::AgentInfo>(&sample.payload().to_bytes()) {
                Ok(info) if Some(info.robot_id) == sender(&sample, Channel::Info) => {
                    self.planner_p99[info.robot_id as usize] = info.plan_p99_us;
                }
                other => {
                    let why = why(&sample, other.map(|m| m.robot_id));
                    links::reject(&mut self.status, format_args!("{why}"));
                }
            }
        }
        self.status.planner_p99_us = (0..n)
            .filter(|&i| self.links[i].alive)
            .map(|i| self.planner_p99[i])
            .fold(0.0, f64::max);
        while let Ok(Some(sample)) = self.wire.fans.try_recv() {
            match decode::<schemas::FanMsg>(&sample.payload().to_bytes()) {
                Ok(fan) if Some(fan.robot_id) == sender(&sample, Channel::Fan) => {
                    let id = fan.robot_id as usize;
                    self.status.fans[id] = Some(fan);
                }
                other => {
                    let why = why(&sample, other.map(|m| m.robot_id));
                    links::reject(&mut self.status, format_args!("{why}"));
                }
            }
        }
        while let Ok(Some(sample)) = self.wire.intents.try_recv() {
            match decode::<IntentMsg>(&sample.payload().to_bytes()) {
                Ok(intent) if Some(intent.robot_id) == sender(&sample, Channel::Intent) => {
                    let samples = wire::samples_from_wire(&intent.trajectory);
                    self.fleet
                        .set_intent(intent.robot_id as usize, intent.stamp, samples);
                    if self.config.journal.is_some() {
                        self.journal_intents.push(journal::IntentInput {
                            robot: intent.robot_id,
                            stamp: intent.stamp,
                            trajectory: intent.trajectory,
                        });
                    }
                }
                other => {
                    let why = why(&sample, other.map(|m| m.robot_id));
                    links::reject(&mut self.status, format_args!("{why}"));
                }
            }
        }
    }

    /// Applies the newest fresh command per robot (the others stop), steps the world and
    /// dispatches tasks; returns the tick's fleet events.
    fn step(&mut self) -> Vec<FleetEvent> {
        let n = self.links.len();
        // Real robots stand where their agents last reported them.
        let mut placed = Vec::new();
        for &id in &self.config.live {
            if let Some(state) = self.links[id as usize].report.take() {
                journal::place(&mut self.fleet, id as usize, &state);
                placed.push((id, state));
            }
        }
        let mut commands = vec![Command::STOP; n];
        for (i, link) in self.links.iter().enumerate() {
            let fresh = link.fresh_command(self.config.stale_ticks);
            let zone = self.status.safety.get(i).copied().unwrap_or_default();
            let layer_held = matches!(zone, SafetyZone::Protective | SafetyZone::Yield);
            self.fleet.set_layer_held(i, fresh.is_some() && layer_held);
            // A ROS 2 robot drives on its cmd_vel; the agent's fleet command says it answered.
            let fresh = match (&self.wire.ros, fresh) {
                (Some(ros), Some(_)) => {
                    let heading = self.fleet.world.robots[i].state.heading;
                    Some(ros.command(i, heading).unwrap_or(Command::STOP))
                }
                (_, fresh) => fresh,
            };
            match fresh {
                Some(command) => commands[i] = command,
                // Stale: more than `stale_ticks` observations unanswered, or a safe stop.
                None if link.alive
                    && self.fleet.job(i).is_some()
                    && (link.unanswered() > self.config.stale_ticks
                        || link.command.is_some_and(|c| c.2)) =>
                {
                    self.status.stale_commands += 1;
                    self.status.stale_per_robot[i] += 1;
                }
                None => {}
            }
        }
        let mut input = self
            .config
            .journal
            .is_some()
            .then(|| self.journal_input(&commands, placed));
        let mut events = self.fleet.step(&commands);
        events.extend(self.fleet.dispatch());
        if let (Some(journal), Some(mut input)) = (&self.config.journal, input.take()) {
            let tick = input.tick;
            if (tick + 1).is_multiple_of(journal::FINGERPRINT_EVERY) {
                input.fingerprint = Some(journal::fingerprint(&self.fleet));
            }
            journal.tick(input, &events);
            let ran = tick + 1;
            if ran.is_multiple_of(self.snapshot_every) {
                journal.snapshot(ran, self.fleet.clone());
            }
        }
        self.status.tick += 1;
        self.status.sim_time = self.fleet.world.time;
        events
    }

    /// This tick's inputs for the journal: held flags changed since the last tick, and the
    /// command each moving robot drives on.
    fn journal_input(
        &mut self,
        commands: &[Command],
        placed: Vec<(u32, schemas::RobotState)>,
    ) -> journal::TickInput {
        let mut held = Vec::new();
        for (i, last) in self.journal_held.iter_mut().enumerate() {
            let now = self.fleet.is_held(i);
            if now != *last {
                held.push((i as u32, now));
                *last = now;
            }
        }
        let commands = commands
            .iter()
            .enumerate()
            // Bit for bit: a command of -0.0 is not left out as a stop.
            .filter(|(_, c)| !matches!(c, Command::Velocity(v) if v.x.to_bits() == 0 && v.y.to_bits() == 0))
            .map(|(i, c)| (i as u32, wire::motion(*c)))
            .collect();
        let layer_held = (0..self.fleet.robots())
            .filter(|&i| self.fleet.is_layer_held(i))
            .map(|i| i as u32)
            .collect();
        journal::TickInput {
            tick: self.status.tick,
            held,
            commands,
            layer_held,
            intents: std::mem::take(&mut self.journal_intents),
            fingerprint: None,
            placed,
        }
    }

    /// Sends new assignments to their robots and counts finished tasks.
    async fn publish_tasks(&mut self, events: &[FleetEvent]) {
        for event in events {
            match *event {
                FleetEvent::Assigned { robot, task } => {
                    let site = self.fleet.site();
                    let assignment = TaskAssignment {
                        robot_id: robot as u32,
                        task_id: task.id,
                        pick_station: task.pick as u32,
                        pick: wire::p2(site.stations[task.pick].position),
                        drop_station: task.drop as u32,
                        drop: wire::p2(site.stations[task.drop].position),
                        assigned_at: self.fleet.world.time,
                    };
                    if let Err(e) = self.wire.tasks[robot].put(encode(&assignment)).await {
                        tracing::warn!(robot, "task not sent: {e}");
                    }
                }
                FleetEvent::Done { robot, task } => {
                    self.status.tasks_done += 1;
                    let done = Event::TaskDone {
                        robot: robot as u32,
                        task,
                    };
                    links::emit(&mut self.status, &self.config, done);
                }
                FleetEvent::Picked { .. } => {}
            }
        }
    }

    /// Observations for robots with a live agent, all of this tick's state, published in
    /// `stagger` slices at fixed offsets over the first 90 % of the tick, so that agents
    /// sharing a machine do not all plan in the same instant (real robots' sensors are not in
    /// phase either) and the last slice's commands still arrive before the next tick. Offsets
    /// are absolute (timer rounding never accumulates), and each slice's observations are
    /// built just before it goes out (the world does not change within a tick), which spreads
    /// the perception work over the tick as well.
    async fn publish_observations(
        &mut self,
        tick_started: tokio::time::Instant,
        shutdown: &mut (impl Future<Output = ()> + Unpin),
    ) -> Published {
        let live: Vec<usize> = (0..self.links.len())
            .filter(|&i| self.links[i].alive)
            .collect();
        let window = self.tick_wall.mul_f64(0.9);
        // Slices at least 2 ms apart: the timer wakes up to 1 ms late.
        let max_slices = (window.as_millis() / 2).max(1) as usize;
        let per_slice = live
            .len()
            .div_ceil(self.config.stagger.clamp(1, max_slices))
            .max(1);
        let slices = live.len().div_ceil(per_slice).max(1);
        let offset = window / slices as u32;
        let mut previous: Option<tokio::time::Instant> = None;
        for (k, chunk) in live.chunks(per_slice).enumerate() {
            // A slice that is late after a stall catches up at half the spacing, never back to
            // back: slices sent at once would make their agents plan all at once.
            let due = tick_started + offset * k as u32;
            let at = previous.map_or(due, |p| due.max(p + offset / 2));
            // A shutdown during the tick stops the remaining slices too.
            tokio::select! {
                biased;
                () = &mut *shutdown => return Published::ShutDown,
                () = tokio::time::sleep_until(at) => {}
            }
            previous = Some(tokio::time::Instant::now());
            for &i in chunk {
                let mut obs = observation(
                    &mut self.fleet,
                    i,
                    self.links[i].next_seq,
                    self.wire.map_version,
                );
                obs.real = self.fleet.is_external(i);
                // The robot's own topics go first, so an agent in ROS mode has them when the
                // observation comes.
                if let Some(ros) = &mut self.wire.ros {
                    ros.publish(&obs).await;
                }
                let bytes = encode(&obs);
                self.links[i].sent(obs.seq);
                self.status.observations += 1;
                if let Err(e) = self.wire.observations[i].put(bytes).await {
                    tracing::warn!(robot = i, "observation not sent: {e}");
                }
                if let Some(msg) = traffic_message(&self.fleet, i, self.status.tick)
                    && let Err(e) = self.wire.traffic[i].put(encode(&msg)).await
                {
                    tracing::warn!(robot = i, "traffic constraint not sent: {e}");
                }
            }
        }
        Published::All
    }

    /// Publishes the fleet metrics frame and keeps it in the status.
    async fn publish_metrics(&mut self) {
        let frame = self.metrics_frame();
        if let Err(e) = self.wire.metrics.put(encode(&frame)).await {
            tracing::warn!("metrics not sent: {e}");
        }
    }

    /// Summarises the fleet (once per frame), keeps the summary and its frame in the status,
    /// and returns the frame.
    fn metrics_frame(&mut self) -> FleetMetrics {
        let summary =
            FleetSummary::of(&self.fleet).with_free_flow(self.config.free_flow.get().copied());
        let frame = messages::metrics_frame(&self.fleet, &summary, &self.links, &self.status);
        self.status.summary = Some(summary);
        self.status.metrics = Some(frame.clone());
        frame
    }

    /// Updates the status's derived fields and shows it to the observer.
    fn report_status(&mut self, observer: &mut impl Observer) {
        links::refresh(&mut self.status, &self.links, &self.round_trips.us);
        observer.status(&self.fleet, &self.status);
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
    let n = fleet.robots();
    let dt = fleet.world.dt;
    let wire = Wire::declare(session, &fleet, &config).await?;
    // The journal records held flags as they change, from the fleet's as handed over.
    let journal_held: Vec<bool> = (0..n).map(|i| fleet.is_held(i)).collect();
    // Robots without a live agent are held until one joins.
    for i in 0..n {
        fleet.set_held(i, true);
    }
    for &id in &config.live {
        if id as usize >= n {
            return Err(CoordinatorError::Live {
                robot: id,
                robots: n,
            });
        }
        fleet.set_external(id as usize, true);
    }
    let resume = config.resume.unwrap_or(status::Resume {
        tick: 0,
        tasks_done: 0,
    });
    if config.resume.is_some() {
        tracing::info!(
            tick = resume.tick,
            tasks_done = resume.tasks_done,
            "resuming the run"
        );
    }
    let start_time = fleet.world.time;
    let tick_wall = Duration::from_secs_f64(dt / config.speed);
    let mut c = Coordinator {
        fleet,
        wire,
        links: vec![Link::default(); n],
        status: Status {
            robots: n,
            fans: vec![None; n],
            stale_per_robot: vec![0; n],
            tick: resume.tick,
            tasks_done: resume.tasks_done,
            sim_time: start_time,
            ..Status::default()
        },
        round_trips: RoundTrips::new(config.round_trips.clone()),
        planner_p99: vec![0.0; n],
        tick_wall,
        journal_held,
        journal_intents: Vec::new(),
        snapshot_every: ((journal::SNAPSHOT_EVERY_S / dt).round() as u64).max(1),
        config,
    };
    let mut ticker = tokio::time::interval(tick_wall);
    ticker.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let mut last_status = Instant::now();
    let ticks_per_metrics = (1.0 / dt).round().max(1.0) as u64;
    let end_tick = c.config.seconds.map(|s| (s / dt).round() as u64);
    tokio::pin!(shutdown);

    loop {
        // A shutdown wins over a due tick: once asked to stop, nothing more goes out.
        tokio::select! {
            biased;
            () = &mut shutdown => break,
            _ = ticker.tick() => {}
        }
        let tick_started = tokio::time::Instant::now();
        c.take_arrivals();
        // The end comes after the last observations had a tick to be answered.
        if end_tick.is_some_and(|end| c.status.tick >= end) {
            tokio::time::sleep(tick_wall).await;
            c.take_commands();
            break;
        }
        c.take_reports();
        let events = c.step();
        c.publish_tasks(&events).await;
        if let Published::ShutDown = c.publish_observations(tick_started, &mut shutdown).await {
            break;
        }
        observer.tick(&c.fleet, &c.status, &events);
        if c.status.tick.is_multiple_of(ticks_per_metrics) {
            c.publish_metrics().await;
        }
        if last_status.elapsed() >= Duration::from_secs(1) {
            last_status = Instant::now();
            c.report_status(observer);
        }
    }
    if let Some(journal) = &c.config.journal {
        // The world as the journal's records leave it: held flags changed since the last
        // tick (robots held at a start with no tick after it, say) are in no record yet.
        journal.end(journal::End {
            ticks: c.status.tick,
            fingerprint: journal::fingerprint_with_held(&c.fleet, &c.journal_held),
            tasks_done: c.status.tasks_done,
            lost: 0,
        });
    }
    // Final frame and status.
    let frame = c.metrics_frame();
    let _ = c.wire.metrics.put(encode(&frame)).await;
    c.report_status(observer);
    c.wire.map_server.abort();
    Ok(c.status)
}

#[cfg(test)]
mod tests {
    use super::*;
    use agent::planner::PlannerSpec;
    use world_sim::scenario::Scenario;

    /// A served fleet's efficiency is measured as the studies measure it: against one robot
    /// alone over the run's own length (so that the demo and `study traffic` give a seed the
    /// same figure), and over [`FREE_FLOW_S`] only where the run has no end or is too short
    /// for the robot alone to finish anything.
    #[test]
    fn the_free_flow_runs_as_long_as_the_run_unless_that_finishes_nothing() {
        let scenario = Scenario::builtin("warehouse").expect("built in");
        let planner: PlannerSpec = "pgp+orca".parse().expect("a planner");
        let free = |seconds| free_flow(&scenario, planner, true, None, seconds).expect("a site");

        // The simulated time is summed step by step.
        let ran_for = |free: world_sim::efficiency::FreeFlow, seconds: f64| {
            assert!(
                (free.seconds - seconds).abs() < 0.01,
                "{} s, not {seconds}",
                free.seconds
            );
        };
        let own = free(Some(120.0));
        ran_for(own, 120.0);
        assert!(own.tasks > 0, "one robot alone finishes a task in 120 s");
        let options = world_sim::fleet::FleetOptions {
            share_intents: true,
            policy: None,
            human_impact_window_s: None,
        };
        let study = world_sim::efficiency::free_flow(&scenario, planner, 120.0, options);
        assert_eq!(Ok(own), study, "the study's free flow of the same length");

        let endless = free(None);
        ran_for(endless, FREE_FLOW_S);
        assert!(endless.tasks > own.tasks);
        assert_eq!(free(Some(1.0)), endless, "nothing finished in 1 s");
        assert_eq!(free(Some(f64::NAN)), endless);
    }
}
