//! `gapfleet demo`: a whole fleet in one process. The coordinator's Zenoh session is a router
//! on a loopback port; every agent has its own session (a peer connected to it, multicast
//! scouting off), its own planner stack and its own tokio task, exactly as a separate
//! `gapfleet-agent` process would.

use super::dashboard::{DashboardObserver, HUMAN_IMPACT_WINDOW_S};
use super::{
    CoordinatorConfig, CoordinatorError, RoundTrip, Status, declare_presence, run_coordinator,
};
use agent::planner::PlannerSpec;
use agent::runtime::{AgentConfig, AgentCounters, AgentError, run_agent};
use fleet_net::{ConfigError, Role, free_loopback_port, open_loopback};
use std::future::Future;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use world_sim::fleet::{Fleet, FleetSummary};
use world_sim::scenario::Scenario;
use world_sim::traffic_policy::{PolicyParams, PolicyTotals, TrafficPolicy};

/// What to run.
#[derive(Debug, Clone)]
pub struct DemoOptions {
    /// The warehouse scenario (robots and people counts already applied).
    pub scenario: Scenario,
    /// Planner stack of every agent.
    pub planner: PlannerSpec,
    /// Simulated seconds.
    pub seconds: f64,
    /// Simulated seconds per wall second.
    pub speed: f64,
    /// The site's keys.
    pub keys: schemas::Keys,
    /// Where the coordinator listens (default: a free loopback port; plain TCP only).
    pub listen: Option<String>,
    /// How the sessions connect.
    pub transport: Transport,
    /// Where the coordinator's journal goes (`--state DIR`), when kept.
    pub journal: Option<super::journal::JournalSink>,
    /// Whether observations carry other robots' intents.
    pub share_intents: bool,
    /// The traffic policy (`world_sim::traffic_policy`) that constrains the robots' goals;
    /// `None`: off.
    pub traffic_policy: Option<PolicyParams>,
    /// Rerun sinks (none: no dashboard).
    pub sinks: dashboards::Sinks,
    /// Receives every timed round trip (benchmarks).
    pub round_trips: Option<std::sync::mpsc::Sender<RoundTrip>>,
    /// Every robot a ROS 2 robot over rmw_zenoh (`super::ros_robots`), every agent in ROS mode
    /// driving it through its topics.
    pub ros: bool,
}

/// How the demo's sessions connect.
#[derive(Debug, Clone, Default)]
pub enum Transport {
    /// Plain TCP on loopback, no authentication.
    #[default]
    Tcp,
    /// A secured site written by [`crate::site::init`] for the demo's site name and at least
    /// its robots: the coordinator routes with the site's `coordinator/zenoh.json5` (mutual
    /// TLS, user/password, the access-control list), each agent connects with its robot's.
    Secured(crate::site::SitePaths),
}

/// What a demo run produced.
#[derive(Debug)]
pub struct DemoReport {
    /// The coordinator's final status.
    pub status: Status,
    /// Each agent's counters.
    pub agents: Vec<Arc<AgentCounters>>,
    /// The fleet at the end (metrics per robot).
    pub fleet_metrics: Vec<world_sim::metrics::RobotMetrics>,
    /// Tasks per robot.
    pub tasks_done: Vec<u64>,
    /// Dashboard frames logged and dropped, when a dashboard ran.
    pub dashboard: Option<dashboards::DashboardStats>,
    /// What the traffic policy did, when on.
    pub policy: Option<PolicyTotals>,
    /// The fleet-wide figures at the end, against the site's free flow.
    pub summary: FleetSummary,
}

/// Why a demo could not run.
#[derive(Debug, thiserror::Error)]
pub enum DemoError {
    /// The scenario has no warehouse.
    #[error(transparent)]
    NotAWarehouse(#[from] world_sim::fleet::NotAWarehouse),
    /// The dashboard could not start.
    #[error(transparent)]
    Dashboard(#[from] dashboards::DashboardError),
    /// No free loopback port.
    #[error("no free loopback port: {0}")]
    Port(#[from] std::io::Error),
    /// A Zenoh session could not be opened.
    #[error(transparent)]
    Session(#[from] ConfigError),
    /// The coordinator failed.
    #[error(transparent)]
    Coordinator(#[from] CoordinatorError),
    /// An agent failed.
    #[error(transparent)]
    Agent(#[from] AgentError),
    /// The free-flow run's thread panicked.
    #[error("the free-flow run (one robot alone, for the efficiency) failed: {0}")]
    FreeFlow(String),
    /// An agent's task panicked or was cancelled.
    #[error("agent task: {0}")]
    AgentTask(#[from] tokio::task::JoinError),
    /// The coordinator's session did not close cleanly.
    #[error("closing the coordinator session: {0}")]
    Close(zenoh::Error),
}

/// Runs the demo; `on_status` sees the coordinator's status and the fleet about once per wall
/// second;
/// `on_web_url` gets the served web viewer's address (with `--web`) before the fleet starts.
pub async fn run_demo(
    options: DemoOptions,
    shutdown: impl Future<Output = ()>,
    mut on_status: impl FnMut(&Status, &Fleet),
    on_web_url: impl FnOnce(&str),
) -> Result<DemoReport, DemoError> {
    let mut fleet = Fleet::new(&options.scenario)?;
    fleet.share_intents = options.share_intents;
    fleet.set_traffic_policy(options.traffic_policy);
    let dashboard = if options.sinks.any() {
        fleet.measure_human_impact(HUMAN_IMPACT_WINDOW_S);
        let d = DashboardObserver::start(&fleet, &options.sinks, &options.planner.to_string())?;
        if let Some(url) = d.web_url() {
            on_web_url(url);
        }
        Some(d)
    } else {
        None
    };
    let (router, endpoint) = match &options.transport {
        Transport::Tcp => {
            let endpoint = match &options.listen {
                Some(e) => e.clone(),
                None => format!("tcp/127.0.0.1:{}", free_loopback_port()?),
            };
            (open_loopback(Role::Router, &endpoint).await?, endpoint)
        }
        Transport::Secured(site) => {
            let path = site.coordinator_config();
            (open_file(&path).await?, path.display().to_string())
        }
    };
    tracing::info!("coordinator listening: {endpoint}");

    let (stop_tx, stop_rx) = tokio::sync::watch::channel(false);
    let mut agents = Vec::new();
    let mut counters = Vec::new();
    for id in 0..fleet.robots() as u32 {
        let session = match &options.transport {
            Transport::Tcp => open_loopback(Role::Client, &endpoint).await?,
            Transport::Secured(site) => open_file(&site.robot_config(id)).await?,
        };
        let c = Arc::new(AgentCounters::default());
        counters.push(c.clone());
        let mut agent_config = AgentConfig::new(id, options.keys.clone(), options.planner);
        // Fans only travel when someone draws them.
        agent_config.share_fan = options.sinks.any();
        let robot = &options.scenario.robot;
        agent_config.safety = robot
            .safety
            .then(|| robot.safety_limits(options.scenario.dt_s));
        if options.ros {
            agent_config.ros = Some(agent::runtime::ros::RosConfig {
                namespace: super::ros_robots::namespace(id as usize),
                robot_radius: robot.radius_m,
                // people_msgs carries no size; the site's people model does.
                person_radius: options.scenario.humans.radius_m,
                ..Default::default()
            });
        }
        let mut stop = stop_rx.clone();
        agents.push(tokio::spawn(async move {
            let shutdown = async move {
                let _ = stop.wait_for(|s| *s).await;
            };
            let result = run_agent(&session, agent_config, c, shutdown).await;
            let _ = session.close().await;
            result
        }));
    }

    let mut config = CoordinatorConfig::new(options.keys.clone());
    config.safety_layer = options.scenario.robot.safety_layer;
    // One robot alone on the site, run beside the fleet (as `gapfleet coordinator` does) so
    // that the fleet does not wait for it: the efficiency shows once it is in, and the summary
    // waits for it at the end.
    let mut free_flow = {
        let (scenario, planner) = (options.scenario.clone(), options.planner);
        let (share, policy) = (options.share_intents, options.traffic_policy);
        let (slot, seconds) = (config.free_flow.clone(), options.seconds);
        tokio::task::spawn_blocking(move || {
            let free = super::free_flow(&scenario, planner, share, policy, Some(seconds))?;
            let _ = slot.set(free);
            Ok::<_, DemoError>(free)
        })
    };
    let free_slot = config.free_flow.clone();
    // A dashboard shows the efficiency from its first frame: with one, the fleet waits for it.
    let waited = if options.sinks.any() {
        Some((&mut free_flow).await)
    } else {
        None
    };
    config.seconds = Some(options.seconds);
    config.speed = options.speed;
    config.round_trips = options.round_trips;
    config.journal = options.journal;
    config.ros = options.ros.then(super::ros_robots::RosSimConfig::default);
    // The demo holds the coordinator's token itself and drops it after its agents have shut
    // down: the end of a demo is planned, not a lost coordinator.
    config.announce_presence = false;
    let presence = declare_presence(&router, &options.keys).await?;
    let mut final_fleet = None;
    let status_line = |status: &Status, fleet: &Fleet| {
        on_status(status, fleet);
        final_fleet = Some((
            (0..fleet.robots()).map(|i| fleet.metrics(i)).collect(),
            (0..fleet.robots()).map(|i| fleet.tasks_done(i)).collect(),
            fleet.traffic_policy().map(TrafficPolicy::totals),
            status.summary.clone().unwrap_or_else(|| {
                FleetSummary::of(fleet).with_free_flow(free_slot.get().copied())
            }),
        ));
    };
    let mut observers = (status_line, dashboard);
    let status = run_coordinator(&router, fleet, config, shutdown, &mut observers).await?;
    let dashboard = observers.1.map(DashboardObserver::finish);
    // The last tick's observations may still be on their way (at high speed a tick is shorter
    // than a hop): let them land before the agents go, so that none counts as lost.
    tokio::time::sleep(std::time::Duration::from_millis(200)).await;
    let _ = stop_tx.send(true);
    for agent in agents {
        agent.await??;
    }
    drop(presence);
    router.close().await.map_err(DemoError::Close)?;
    // The coordinator reports its status at the end of every run, so this is never empty.
    let (fleet_metrics, tasks_done, policy, summary) = final_fleet.unwrap_or_default();
    let free = match waited {
        Some(done) => done,
        None => free_flow.await,
    }
    .map_err(|e| DemoError::FreeFlow(e.to_string()))??;
    let summary = summary.with_free_flow(Some(free));
    Ok(DemoReport {
        status,
        agents: counters,
        fleet_metrics,
        tasks_done,
        dashboard,
        policy,
        summary,
    })
}

/// Opens a session with the config file at `path`.
async fn open_file(path: &std::path::Path) -> Result<zenoh::Session, ConfigError> {
    let config = fleet_net::from_file(path)?;
    zenoh::open(config).await.map_err(|source| ConfigError {
        setting: format!("session with {}", path.display()),
        source,
    })
}

/// One line of live status.
pub fn status_line(s: &Status) -> String {
    let m = s.metrics.as_ref();
    format!(
        "t {:6.1} s | agents {}/{} | tasks {:3} | efficiency {} | stuck {} | deadlocks {} gridlocks {} | SVR {:.3} | collisions {:.2}% | rtt p50 {:.2} ms p99 {:.2} ms | stale {}",
        s.sim_time,
        s.alive,
        s.robots,
        s.tasks_done,
        m.and_then(|m| m.efficiency)
            .map_or_else(|| "-".to_owned(), |e| format!("{:3.0}%", 100.0 * e)),
        m.map_or(0, |m| m.stuck_robots),
        m.map_or(0, |m| m.deadlocks),
        m.map_or(0, |m| m.gridlocks),
        m.map_or(0.0, |m| m.svr),
        m.map_or(0.0, |m| m.collision_rate * 100.0),
        s.round_trip_ms.0,
        s.round_trip_ms.1,
        s.stale_commands,
    )
}

/// The final summary, as printed by `gapfleet demo`.
pub fn summary(report: &DemoReport, planner: PlannerSpec) -> String {
    let s = &report.status;
    // One counter summed over the agents.
    let sum = |counter: fn(&AgentCounters) -> &AtomicU64| -> u64 {
        report
            .agents
            .iter()
            .map(|c| counter(c).load(Ordering::Relaxed))
            .sum()
    };
    let plans = sum(|c| &c.plans);
    // In ROS mode the robots' own topics count too.
    let rejected = sum(|c| &c.rejected) + sum(|c| &c.ros.rejected);
    let warned = sum(|c| &c.warned);
    let protective = sum(|c| &c.protective);
    let yielded = sum(|c| &c.yielded);
    let mut out = String::new();
    out.push_str(&format!(
        "\n{} robots ({planner}), {} people, {:.0} simulated seconds\n",
        s.robots,
        s.metrics.as_ref().map_or(0, |m| m.humans),
        s.sim_time
    ));
    let fleet = &report.summary;
    out.push_str(&match (fleet.efficiency(), fleet.free_flow) {
        (Some(e), Some(free)) => format!(
            "fleet efficiency {:.0}%: {:.2} tasks per robot-minute, against {:.2} per minute \
             for one robot alone on the site ({} tasks in {:.0} s, no people)\n",
            100.0 * e,
            fleet.tasks_per_robot_min(),
            free.tasks_per_min(),
            free.tasks,
            free.seconds
        ),
        (_, Some(free)) => format!(
            "fleet efficiency: not defined (one robot alone did {} tasks in {:.0} s)\n",
            free.tasks, free.seconds
        ),
        (_, None) => "fleet efficiency: not defined (free flow not measured)\n".to_owned(),
    });
    out.push_str(&format!(
        "tasks done {} | plans {plans} | observation->command round trip p50 {:.2} ms, p99 {:.2} ms | stale-command ticks {} | rejected messages {} (coordinator) {rejected} (agents)\n",
        s.tasks_done, s.round_trip_ms.0, s.round_trip_ms.1, s.stale_commands, s.rejected
    ));
    out.push_str(&format!(
        "safety layer: {warned} commands slowed in the warning field, {protective} slowed further or stopped in the protective field, {yielded} replaced by a way out (yield)\n"
    ));
    out.push_str(
        "robot  tasks  path_m  collision%   SVR   min_human_m  social_force  near_miss_steps  \
         contacts: robot-caused  person-caused  robot-robot  walls  total\n",
    );
    for (i, m) in report.fleet_metrics.iter().enumerate() {
        out.push_str(&format!(
            "{i:5}  {:5}  {:6.1}  {:10.2}  {:.3}  {:11.2}  {:12.3}  {:15}  {:22}  {:13}  {:11}  {:5}  {:5}\n",
            report.tasks_done.get(i).copied().unwrap_or(0),
            m.path_length_m,
            m.collision_rate * 100.0,
            m.svr,
            m.min_human_distance_m,
            m.social_force,
            m.robot_near_misses,
            m.robot_caused_contacts,
            m.person_caused_contacts,
            m.robot_robot_contacts,
            m.wall_contacts,
            m.total_contacts(),
        ));
    }
    out.push_str(&format!(
        "contacts (onsets): with people {} robot-caused, {} person-caused; robot-robot {} \
         (each robot counts its own); walls and shelves {}; total {}\n",
        fleet.robot_caused_contacts,
        fleet.person_caused_contacts,
        fleet.robot_robot_contacts,
        fleet.wall_contacts,
        fleet.total_contacts,
    ));
    let t = &fleet.traffic;
    out.push_str(&format!(
        "traffic: {} deadlocks ({:.0} robot-s deadlocked), {} gridlocks ({:.0} robot-s); {} \
         times a robot got stuck, {:.0} robot-s stuck, at most {} at once\n",
        t.deadlocks,
        t.deadlocked_robot_s,
        t.gridlocks,
        t.gridlocked_robot_s,
        t.stuck_onsets,
        t.stuck_robot_s,
        t.max_stuck
    ));
    let c = &fleet.stuck_causes;
    out.push_str(&format!(
        "stuck robot-s by what held them: traffic policy {:.0}, a person in the way {:.0}, a \
         robot in the way {:.0}, the safety layer {:.0}, nothing visible (planner) {:.0}\n",
        c.policy_s, c.person_s, c.robot_s, c.layer_s, c.planner_s
    ));
    out.push_str(&match &report.policy {
        Some(p) => format!(
            "traffic policy: {} one-way aisle segments granted, {} waits for one, {} stations \
             granted, {} waits in a station's line, {} retreats, {} two-way knots given way in, \
             {} robots sent round a blocked segment, {} robots found against a segment's \
             direction, {} segments' robots turned round from people in their way\n",
            p.grants,
            p.waits,
            p.station_grants,
            p.queued,
            p.retreats,
            p.give_ways,
            p.detours,
            p.intrusions,
            p.people_turns
        ),
        None => "traffic policy: off\n".to_owned(),
    });
    if let Some(d) = &report.dashboard {
        out.push_str(&format!(
            "dashboard: {} frames logged, {} dropped\n",
            d.logged, d.dropped
        ));
    }
    out.push_str(&format!(
        "fleet: collision rate {:.2}%  SVR {:.3}  robot near-miss steps {}\n",
        fleet.collision_rate * 100.0,
        fleet.svr,
        fleet.near_miss_steps
    ));
    out
}
