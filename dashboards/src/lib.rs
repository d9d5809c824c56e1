//! gapfleet's Rerun dashboards: the warehouse, people, robots, their intents, events and the
//! fleet's social metrics, to any mix of sinks (an .rrd file, the web viewer served from the
//! binary, a running `rerun` viewer, a spawned one).
//!
//! Callers hand over plain-data [`Frame`]s; one logging thread, fed by a bounded channel, turns
//! them into Rerun archetypes. When the sinks cannot keep up, frames are dropped and counted:
//! the simulation never waits for drawing.
//!
//! Entities (timelines `tick` and `sim_time`), drawn y up as in the world frame (a static
//! y-flip on `map` and `world`: Rerun's 2D views put y down):
//! - `map/shelves`, `map/walls`, `map/stations` (static)
//! - `map/heat/window/<kind>` and `map/heat/run/<kind>` (heatmaps under the map, once per
//!   simulated second: where robots came within 1 m of people, contacts, stuck robots, where
//!   people lost time to robots; see
//!   [`heat`])
//! - `world/humans` (points coloured by group), `world/robots` (points labelled with the id),
//!   `world/robots/heading` (arrows), `world/intents` (planned paths), `world/subgoals`,
//!   `world/fan/<robot>` (PGP candidates coloured by survival, when the planner shares them),
//!   `world/events` (markers for the last [`EVENT_FADE_S`], fading)
//! - `world/traffic/segments` (one-way aisle segments: grey free, green reserved along +x,
//!   violet along −x, labelled with holders and waiting robots), `world/traffic/directions`
//!   (arrows), `world/traffic/waits` (who waits on whom: amber, red in a cycle),
//!   `world/traffic/stuck` (rings round stuck robots), `world/traffic/goals` (where robots are
//!   told to hold, queue or retreat), when the fleet runs a traffic policy or monitor
//! - `events` (text log), `fleet/robots` (the robot table, Markdown, see [`table`])
//! - `metrics/<name>/fleet` and `metrics/<name>/robot/<id>` (scalars): the KPI plots show the
//!   fleet's series; the per-robot ones are in the "per robot" tab

pub mod heat;
pub mod table;

use heat::{Heat, HeatParams};
use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::thread::JoinHandle;

/// A point in the world frame (metres).
pub type P = [f32; 2];

/// Where recordings go. Several at once are fine.
#[derive(Debug, Clone, Default)]
pub struct Sinks {
    /// Save to this .rrd file.
    pub rrd: Option<PathBuf>,
    /// Serve the web viewer from this process (the URL is in [`Dashboard::web_url`]).
    pub web: bool,
    /// Stream to a running viewer, e.g. `rerun+http://127.0.0.1:9876/proxy`.
    pub connect: Option<String>,
    /// Spawn a native `rerun` viewer (needs `rerun` on PATH) and stream to it.
    pub spawn: bool,
}

impl Sinks {
    /// Whether any sink is asked for.
    pub fn any(&self) -> bool {
        self.rrd.is_some() || self.web || self.connect.is_some() || self.spawn
    }
}

/// The static site.
#[derive(Debug, Clone, Default)]
pub struct MapFrame {
    /// Closed polygons (shelves).
    pub shelves: Vec<Vec<P>>,
    /// Wall segments.
    pub walls: Vec<[P; 2]>,
    /// Stations with labels.
    pub stations: Vec<(P, String)>,
}

/// One robot as drawn.
#[derive(Debug, Clone)]
pub struct RobotView {
    /// Robot id.
    pub id: u32,
    /// Position.
    pub position: P,
    /// Heading (rad).
    pub heading: f32,
    /// Body radius (m).
    pub radius: f32,
    /// Label suffix, e.g. the planner name.
    pub planner: String,
    /// Agent alive.
    pub alive: bool,
}

/// Which of a robot's safety fields acted on its newest command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FieldState {
    /// Neither (or no layer).
    #[default]
    Clear,
    /// The warning field slowed it.
    Warning,
    /// The protective field slowed it further or stopped it.
    Protective,
}

/// A robot's protective and warning fields as outlines on the floor.
#[derive(Debug, Clone)]
pub struct FieldView {
    /// Robot id.
    pub robot: u32,
    /// The protective field's outline (closed).
    pub protective: Vec<P>,
    /// The warning field's outline (closed).
    pub warning: Vec<P>,
    /// Which field acted on the robot's newest command.
    pub state: FieldState,
}

/// A robot's announced intent.
#[derive(Debug, Clone)]
pub struct IntentView {
    /// Robot id.
    pub robot: u32,
    /// Planned path.
    pub path: Vec<P>,
    /// Subgoal.
    pub subgoal: P,
}

/// A PGP candidate fan.
#[derive(Debug, Clone)]
pub struct FanView {
    /// Robot id.
    pub robot: u32,
    /// Each candidate's path and final survival probability.
    pub candidates: Vec<(Vec<P>, f32)>,
}

/// Something that happened.
#[derive(Debug, Clone)]
pub struct EventView {
    /// Text for the log.
    pub text: String,
    /// Where to put a marker, if it happened somewhere.
    pub position: Option<P>,
    /// Whether it is bad news (collision, crash).
    pub warning: bool,
}

/// A one-way aisle segment and its reservation.
#[derive(Debug, Clone)]
pub struct SegmentView {
    /// Segment index.
    pub id: u32,
    /// Lower-left corner.
    pub min: P,
    /// Upper-right corner.
    pub max: P,
    /// The direction it is reserved in (+1 along x, −1 against), `None` when free.
    pub direction: Option<i8>,
    /// Robots holding it.
    pub holders: Vec<u32>,
    /// Robots waiting for it.
    pub waiting: Vec<u32>,
}

/// A robot's goal as the traffic policy set it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrafficGoal {
    /// Waiting short of a segment.
    Hold,
    /// Waiting in line for a station.
    Queue,
    /// Backing off out of a wait-for cycle.
    Retreat,
}

/// The fleet's traffic: reservations, who waits on whom, stuck robots.
#[derive(Debug, Clone, Default)]
pub struct TrafficView {
    /// One-way segments (empty where aisles are wide).
    pub segments: Vec<SegmentView>,
    /// Wait-for edges: from the waiting robot's position to the one it waits on, and whether
    /// the edge is part of a cycle.
    pub waits: Vec<(P, P, bool)>,
    /// Stuck robots: id, position, radius.
    pub stuck: Vec<(u32, P, f32)>,
    /// Goals the policy set: robot, point, kind.
    pub goals: Vec<(u32, P, TrafficGoal)>,
}

/// What a heatmap marks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeatKind {
    /// A robot within 1 m of a person (weight: seconds).
    NearPeople = 0,
    /// A contact between a robot and a person began (weight: 1).
    Contact = 1,
    /// A robot stood stuck (weight: seconds).
    Stuck = 2,
    /// People lost time to robots (weight: person-seconds of delay).
    PeopleDelay = 3,
}

impl HeatKind {
    /// Every kind, in index order.
    pub const ALL: [HeatKind; 4] = [
        HeatKind::NearPeople,
        HeatKind::Contact,
        HeatKind::Stuck,
        HeatKind::PeopleDelay,
    ];

    /// The entity name.
    pub fn name(self) -> &'static str {
        match self {
            HeatKind::NearPeople => "near_people",
            HeatKind::Contact => "contacts",
            HeatKind::Stuck => "stuck",
            HeatKind::PeopleDelay => "people_delay",
        }
    }

    fn colour(self) -> [u8; 3] {
        match self {
            HeatKind::NearPeople => [240, 150, 0],
            HeatKind::Contact => [220, 20, 20],
            HeatKind::Stuck => [140, 40, 200],
            HeatKind::PeopleDelay => [30, 110, 230],
        }
    }
}

/// One heatmap event: something of `kind` at `at`, weighing `weight`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatEvent {
    /// What.
    pub kind: HeatKind,
    /// Where (world frame, m).
    pub at: P,
    /// How much (seconds for durations, 1 for onsets).
    pub weight: f32,
}

/// One robot's row in the robot table.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotRow {
    /// Robot id.
    pub id: u32,
    /// Planner stack.
    pub planner: String,
    /// "idle", "to pick", "to drop", "held", "crashed", "left", "stuck", ...
    pub state: String,
    /// Crashed, gone, stuck, or touched a person: listed first, in bold.
    pub trouble: bool,
    /// Tasks done.
    pub tasks_done: u64,
    /// Contacts with people so far (robot- and person-caused onsets).
    pub contacts: u64,
    /// Social space violation rate so far.
    pub svr: f64,
    /// Distance to the nearest person now, centre to centre (m), if anyone is in range.
    pub closest_person_m: Option<f32>,
    /// Its share of the delay robots caused people in the latest window, if measured.
    pub delay_share: Option<f32>,
}

/// Event markers stay on the map this long (s), fading out.
pub const EVENT_FADE_S: f64 = 10.0;

/// One frame of the world.
#[derive(Debug, Clone, Default)]
pub struct Frame {
    /// Simulation tick.
    pub tick: u64,
    /// Simulation time (s).
    pub sim_time: f64,
    /// People's positions.
    pub humans: Vec<P>,
    /// Each person's group.
    pub human_groups: Vec<u32>,
    /// People's body radius (m).
    pub human_radius: f32,
    /// Robots.
    pub robots: Vec<RobotView>,
    /// Intents.
    pub intents: Vec<IntentView>,
    /// Candidate fans (empty unless a planner shares them).
    pub fans: Vec<FanView>,
    /// Safety fields of the robots that run the layer.
    pub fields: Vec<FieldView>,
    /// Events since the last frame.
    pub events: Vec<EventView>,
    /// Traffic, when the fleet runs a policy or a monitor.
    pub traffic: Option<TrafficView>,
    /// Fleet-wide series: name → value.
    pub fleet_metrics: Vec<(&'static str, f64)>,
    /// Per-robot series: robot → (name → value).
    pub robot_metrics: Vec<(u32, Vec<(&'static str, f64)>)>,
    /// The robot table's rows (empty: no table this frame).
    pub robot_rows: Vec<RobotRow>,
    /// Heatmap events since the last frame.
    pub heat: Vec<HeatEvent>,
}

/// Why the dashboard could not start.
#[derive(Debug, thiserror::Error)]
pub enum DashboardError {
    /// Rerun refused a sink or the recording.
    #[error("rerun: {0}")]
    Rerun(String),
    /// The logging thread could not start.
    #[error("dashboard thread: {0}")]
    Thread(#[from] std::io::Error),
}

fn rerr(e: impl std::fmt::Display) -> DashboardError {
    DashboardError::Rerun(e.to_string())
}

/// A running dashboard: send frames, then [`finish`](Dashboard::finish).
#[derive(Debug)]
pub struct Dashboard {
    tx: Option<SyncSender<Frame>>,
    dropped: Arc<AtomicU64>,
    logged: Arc<AtomicU64>,
    thread: Option<JoinHandle<()>>,
    web_url: Option<String>,
}

/// Frames queued before new ones are dropped.
pub const QUEUE_FRAMES: usize = 64;

/// Counts after the dashboard finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DashboardStats {
    /// Frames logged.
    pub logged: u64,
    /// Frames dropped because the logging thread was behind.
    pub dropped: u64,
}

impl Dashboard {
    /// Opens the sinks, logs the static map and the blueprint, and starts the logging thread.
    pub fn start(app: &'static str, sinks: &Sinks, map: MapFrame) -> Result<Self, DashboardError> {
        let mut sink_list: Vec<Box<dyn rerun::sink::LogSink>> = Vec::new();
        let mut web_url = None;
        let mut web_server = None;
        if let Some(path) = &sinks.rrd {
            sink_list.push(Box::new(rerun::sink::FileSink::new(path).map_err(rerr)?));
        }
        if let Some(url) = &sinks.connect {
            let uri: rerun::external::re_uri::ProxyUri = url.parse().map_err(rerr)?;
            sink_list.push(Box::new(rerun::sink::GrpcSink::new(uri)));
        }
        if sinks.spawn {
            rerun::spawn(&rerun::SpawnOptions::default()).map_err(rerr)?;
            let uri: rerun::external::re_uri::ProxyUri = format!(
                "rerun+http://127.0.0.1:{}/proxy",
                rerun::DEFAULT_SERVER_PORT
            )
            .parse()
            .map_err(rerr)?;
            sink_list.push(Box::new(rerun::sink::GrpcSink::new(uri)));
        }
        if sinks.web {
            let grpc_port = free_port()?;
            let server = rerun::grpc_server::GrpcServerSink::new(
                "127.0.0.1",
                grpc_port,
                rerun::ServerOptions::default(),
            )
            .map_err(rerr)?;
            let grpc_url = format!("rerun+http://127.0.0.1:{grpc_port}/proxy");
            let web = rerun::web_viewer::WebViewerConfig {
                bind_ip: "127.0.0.1".to_owned(),
                connect_to: vec![grpc_url],
                open_browser: false,
                ..Default::default()
            }
            .host_web_viewer()
            .map_err(rerr)?;
            web_url = Some(format!(
                "{}?url=rerun%2Bhttp%3A%2F%2F127.0.0.1%3A{grpc_port}%2Fproxy",
                web.server_url()
            ));
            web_server = Some(web);
            sink_list.push(Box::new(server));
        }
        let rec = rerun::RecordingStreamBuilder::new(app)
            .set_sinks(sink_list)
            .map_err(rerr)?;
        blueprint()
            .send(
                &rec,
                rerun::blueprint::BlueprintActivation {
                    make_active: true,
                    make_default: true,
                },
            )
            .map_err(rerr)?;
        log_map(&rec, &map).map_err(rerr)?;
        let mut painter = Painter::new(&map, HeatParams::default());

        let (tx, rx) = sync_channel::<Frame>(QUEUE_FRAMES);
        let dropped = Arc::new(AtomicU64::new(0));
        let logged = Arc::new(AtomicU64::new(0));
        let (dropped_in, logged_in) = (dropped.clone(), logged.clone());
        let thread = std::thread::Builder::new()
            .name("dashboard".to_owned())
            .spawn(move || {
                let _web = web_server;
                painter.run(&rec, &rx, &dropped_in, &logged_in);
                if let Err(e) = rec.flush_blocking() {
                    tracing::warn!("dashboard flush: {e}");
                }
            })?;
        Ok(Self {
            tx: Some(tx),
            dropped,
            logged,
            thread: Some(thread),
            web_url,
        })
    }

    /// Queues a frame, or drops and counts it if the logging thread is behind. Never blocks.
    pub fn send(&self, frame: Frame) {
        if let Some(tx) = &self.tx {
            match tx.try_send(frame) {
                Ok(()) => {}
                Err(TrySendError::Full(_)) | Err(TrySendError::Disconnected(_)) => {
                    self.dropped.fetch_add(1, Ordering::Relaxed);
                }
            }
        }
    }

    /// Frames dropped so far.
    pub fn dropped(&self) -> u64 {
        self.dropped.load(Ordering::Relaxed)
    }

    /// The served web viewer's URL, with `--web`.
    pub fn web_url(&self) -> Option<&str> {
        self.web_url.as_deref()
    }

    /// Logs what is queued, flushes every sink and stops the thread.
    pub fn finish(mut self) -> DashboardStats {
        self.stop()
    }

    fn stop(&mut self) -> DashboardStats {
        self.tx = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
        DashboardStats {
            logged: self.logged.load(Ordering::Relaxed),
            dropped: self.dropped.load(Ordering::Relaxed),
        }
    }
}

impl Drop for Dashboard {
    fn drop(&mut self) {
        self.stop();
    }
}

fn free_port() -> std::io::Result<u16> {
    Ok(std::net::TcpListener::bind("127.0.0.1:0")?
        .local_addr()?
        .port())
}

/// The layout. Left: the floor (tabs: the last minute's heatmaps, the whole run's, PGP fans)
/// over the robot table. Right: the fleet KPIs, one plot each with the fleet's series only,
/// over tabs for the event log, per-robot plots and the other fleet plots.
fn blueprint() -> rerun::blueprint::Blueprint {
    use rerun::blueprint::components::PanelState;
    use rerun::blueprint::{
        Blueprint, BlueprintPanel, Grid, Horizontal, SelectionPanel, Spatial2DView, Tabs,
        TextDocumentView, TextLogView, TimePanel, TimeSeriesView, Vertical,
    };
    let fleet_plot = |name: &str, metrics: &[&str]| {
        TimeSeriesView::new(name)
            .with_contents(metrics.iter().map(|m| format!("/metrics/{m}/fleet")))
            .into()
    };
    let robot_plot = |name: &str, metric: &str| {
        TimeSeriesView::new(name)
            .with_contents([format!("/metrics/{metric}/robot/**")])
            .into()
    };
    let floor = |name: &str, contents: &[&str]| {
        Spatial2DView::new(name)
            .with_contents(contents.iter().map(|c| (*c).to_owned()))
            .into()
    };
    let heat_kinds = |span: &str| {
        HeatKind::ALL
            .iter()
            .map(move |k| format!("/map/heat/{span}/{}", k.name()))
            .collect::<Vec<_>>()
    };
    let mut last_minute = vec!["/map/**", "/world/**", "-/map/heat/**", "-/world/fan/**"]
        .into_iter()
        .map(str::to_owned)
        .collect::<Vec<_>>();
    last_minute.extend(heat_kinds("window"));
    let mut whole_run = vec!["/map/**", "/world/**", "-/map/heat/**", "-/world/fan/**"]
        .into_iter()
        .map(str::to_owned)
        .collect::<Vec<_>>();
    whole_run.extend(heat_kinds("run"));
    let floor_tabs = Tabs::new([
        Spatial2DView::new("floor: heat of the last minute")
            .with_contents(last_minute)
            .into(),
        Spatial2DView::new("floor: heat of the whole run")
            .with_contents(whole_run)
            .into(),
        floor(
            "floor: PGP fans",
            &["/map/**", "/world/**", "-/map/heat/**"],
        ),
    ]);
    let kpis = Grid::new([
        fleet_plot("tasks / min", &["tasks_per_minute"]),
        fleet_plot(
            "contacts with people: robot-caused, person-caused",
            &["robot_caused_contacts", "person_caused_contacts"],
        ),
        fleet_plot("space violations (SVR)", &["svr"]),
        fleet_plot(
            "people's delay (person-s / min)",
            &["human_delay_s_per_min"],
        ),
        fleet_plot("stuck robots", &["stuck_robots"]),
        fleet_plot("live agents", &["live_agents"]),
    ]);
    let per_robot = Grid::new([
        robot_plot("SVR per robot", "svr"),
        robot_plot("min human distance per robot (m)", "min_human_distance"),
        robot_plot("people's delay per robot", "human_delay_s_per_min"),
        robot_plot("social force per robot", "social_force"),
    ])
    .with_name("per robot");
    let more = Grid::new([
        fleet_plot("collision rate", &["collision_rate"]),
        fleet_plot("min human distance (m)", &["min_human_distance"]),
        fleet_plot("social force", &["social_force"]),
        fleet_plot(
            "traffic: deadlocks, waiting robots",
            &["deadlocks", "waiting_robots"],
        ),
        fleet_plot(
            "protective stops, extra path (m / min)",
            &["protective_robots", "human_extra_path_m_per_min"],
        ),
        fleet_plot(
            "planner p99 (µs), stale commands, dropped frames",
            &["planner_p99_us", "stale_commands", "dropped_frames"],
        ),
    ])
    .with_name("more fleet plots");
    Blueprint::new(
        Horizontal::new([
            Vertical::new([
                floor_tabs.into(),
                TextDocumentView::new("robots")
                    .with_contents(["/fleet/robots"])
                    .into(),
            ])
            .with_row_shares([0.62, 0.38])
            .into(),
            Vertical::new([
                kpis.into(),
                Tabs::new([
                    TextLogView::new("events").with_contents(["/events"]).into(),
                    per_robot.into(),
                    more.into(),
                ])
                .into(),
            ])
            .with_row_shares([0.6, 0.4])
            .into(),
        ])
        .with_column_shares([0.55, 0.45]),
    )
    // The side panels folded away: the floor, KPIs and table get the screen.
    .with_blueprint_panel(BlueprintPanel::new().with_state(PanelState::Collapsed))
    .with_selection_panel(SelectionPanel::new().with_state(PanelState::Collapsed))
    .with_time_panel(TimePanel::new().with_state(PanelState::Collapsed))
}

fn log_map(rec: &rerun::RecordingStream, map: &MapFrame) -> rerun::RecordingStreamResult<()> {
    // y up, as in the world frame: Rerun's 2D views put y down.
    for root in ["map", "world"] {
        rec.log_static(root, &rerun::Transform3D::from_scale([1.0, -1.0, 1.0]))?;
    }
    let shelves: Vec<Vec<P>> = map
        .shelves
        .iter()
        .map(|poly| {
            let mut closed = poly.clone();
            if let Some(&first) = poly.first() {
                closed.push(first);
            }
            closed
        })
        .collect();
    rec.log_static(
        "map/shelves",
        &rerun::LineStrips2D::new(shelves).with_colors([rerun::Color::from_rgb(140, 110, 70)]),
    )?;
    rec.log_static(
        "map/walls",
        &rerun::LineStrips2D::new(map.walls.iter().map(|w| w.to_vec()))
            .with_colors([rerun::Color::from_rgb(90, 90, 90)]),
    )?;
    rec.log_static(
        "map/stations",
        &rerun::Points2D::new(map.stations.iter().map(|s| s.0))
            .with_labels(map.stations.iter().map(|s| s.1.clone()))
            .with_radii([0.25])
            .with_colors([rerun::Color::from_rgb(60, 160, 220)]),
    )?;
    Ok(())
}

const GROUP_COLOURS: [(u8, u8, u8); 10] = [
    (230, 159, 0),
    (86, 180, 233),
    (0, 158, 115),
    (240, 228, 66),
    (204, 121, 167),
    (213, 94, 0),
    (0, 114, 178),
    (170, 170, 170),
    (120, 200, 120),
    (200, 120, 200),
];

/// Red (survival 0) to green (survival 1).
fn survival_colour(p: f32) -> rerun::Color {
    let p = p.clamp(0.0, 1.0);
    rerun::Color::from_rgb((255.0 * (1.0 - p)) as u8, (200.0 * p) as u8, 40)
}

/// An event marker on the map: when, where, label, bad news.
type Mark = (f64, P, String, bool);

/// The logging thread's state across frames: the heatmaps and the markers still fading.
#[derive(Debug)]
struct Painter {
    heat: Heat,
    marks: VecDeque<Mark>,
    /// The simulated second the heatmaps and the table were last drawn in.
    drawn_second: Option<i64>,
}

impl Painter {
    fn new(map: &MapFrame, params: HeatParams) -> Self {
        Self {
            heat: Heat::new(map, params),
            marks: VecDeque::new(),
            drawn_second: None,
        }
    }

    fn run(
        &mut self,
        rec: &rerun::RecordingStream,
        rx: &Receiver<Frame>,
        dropped: &AtomicU64,
        logged: &AtomicU64,
    ) {
        while let Ok(frame) = rx.recv() {
            if let Err(e) = self.log(rec, &frame, dropped.load(Ordering::Relaxed)) {
                tracing::warn!("dashboard: {e}");
            }
            logged.fetch_add(1, Ordering::Relaxed);
        }
    }

    fn log(
        &mut self,
        rec: &rerun::RecordingStream,
        f: &Frame,
        dropped: u64,
    ) -> rerun::RecordingStreamResult<()> {
        log_frame(rec, f, dropped)?;
        self.heat.add(f.sim_time, &f.heat);
        self.log_marks(rec, f)?;
        // Heatmaps and the table once per simulated second (and on the first frame).
        let second = f.sim_time.floor() as i64;
        if self.drawn_second != Some(second) {
            self.drawn_second = Some(second);
            self.log_heat(rec)?;
            if !f.robot_rows.is_empty() {
                rec.log(
                    "fleet/robots",
                    &rerun::TextDocument::new(table::markdown(&f.robot_rows))
                        .with_media_type(rerun::MediaType::markdown()),
                )?;
            }
        }
        Ok(())
    }

    /// Markers for the events of the last [`EVENT_FADE_S`], more transparent the older.
    fn log_marks(
        &mut self,
        rec: &rerun::RecordingStream,
        f: &Frame,
    ) -> rerun::RecordingStreamResult<()> {
        let fresh = f.events.iter().filter_map(|e| {
            // Bad news is labelled, with the text up to its first colon ("robot 3 stuck: no
            // progress ..."); the rest (agents joining, tasks done) only marked, so that labels
            // stay legible with many robots.
            let label = if e.warning {
                e.text.split(':').next().unwrap_or_default().to_owned()
            } else {
                String::new()
            };
            Some((f.sim_time, e.position?, label, e.warning))
        });
        let before = self.marks.len();
        self.marks.extend(fresh);
        let mut changed = self.marks.len() != before;
        while self
            .marks
            .front()
            .is_some_and(|m| f.sim_time - m.0 >= EVENT_FADE_S)
        {
            self.marks.pop_front();
            changed = true;
        }
        // Redrawn every tenth of the fade while any are up (not every tick), and when one
        // comes or goes.
        let tick_fade = f.tick.is_multiple_of(10) && !self.marks.is_empty();
        if !changed && !tick_fade {
            return Ok(());
        }
        let alpha = |m: &Mark| {
            let left = 1.0 - (f.sim_time - m.0) / EVENT_FADE_S;
            (40.0 + 215.0 * left.clamp(0.0, 1.0)) as u8
        };
        rec.log(
            "world/events",
            &rerun::Points2D::new(self.marks.iter().map(|m| m.1))
                .with_radii([0.35])
                .with_labels(self.marks.iter().map(|m| m.2.clone()))
                .with_colors(self.marks.iter().map(|m| {
                    let (r, g, b) = if m.3 { (255, 40, 40) } else { (40, 200, 40) };
                    rerun::Color::from_unmultiplied_rgba(r, g, b, alpha(m))
                })),
        )
    }

    /// Every heatmap as an image under the map, in the map's frame.
    fn log_heat(&self, rec: &rerun::RecordingStream) -> rerun::RecordingStreamResult<()> {
        let grid = self.heat.grid;
        for kind in HeatKind::ALL {
            let layer = &self.heat.layers[kind as usize];
            for (span, values) in [("window", &layer.window), ("run", &layer.run)] {
                let path = format!("map/heat/{span}/{}", kind.name());
                rec.log(
                    path.as_str(),
                    &rerun::Transform3D::from_translation_scale(
                        [grid.origin[0], grid.origin[1], 0.0],
                        rerun::Scale3D::uniform(grid.cell_m),
                    ),
                )?;
                rec.log(
                    path.as_str(),
                    &rerun::Image::from_rgba32(self.heat.image(values, kind.colour()), grid.size)
                        .with_draw_order(-20.0),
                )?;
            }
        }
        Ok(())
    }
}

/// The fields: outlines always, in the colour of the field that acted (amber warning, red
/// protective), grey otherwise.
fn log_fields(
    rec: &rerun::RecordingStream,
    fields: &[FieldView],
) -> rerun::RecordingStreamResult<()> {
    let grey = rerun::Color::from_rgb(170, 170, 170);
    let colour = |acting: bool, on: rerun::Color| if acting { on } else { grey };
    rec.log(
        "world/safety/protective",
        &rerun::LineStrips2D::new(fields.iter().map(|f| f.protective.clone()))
            .with_colors(fields.iter().map(|f| {
                colour(
                    f.state == FieldState::Protective,
                    rerun::Color::from_rgb(230, 30, 30),
                )
            }))
            .with_labels(fields.iter().map(|f| match f.state {
                FieldState::Protective => format!("{} protective", f.robot),
                _ => String::new(),
            })),
    )?;
    rec.log(
        "world/safety/warning",
        &rerun::LineStrips2D::new(fields.iter().map(|f| f.warning.clone())).with_colors(
            fields.iter().map(|f| {
                colour(
                    f.state == FieldState::Warning,
                    rerun::Color::from_rgb(240, 170, 0),
                )
            }),
        ),
    )?;
    Ok(())
}

/// A closed circle of `radius` round `centre`.
fn ring(centre: P, radius: f32) -> Vec<P> {
    const SIDES: usize = 20;
    (0..=SIDES)
        .map(|k| {
            let a = std::f32::consts::TAU * k as f32 / SIDES as f32;
            [centre[0] + radius * a.cos(), centre[1] + radius * a.sin()]
        })
        .collect()
}

/// Segments coloured by their reservation, arrows along reserved ones, wait-for edges, rings
/// round stuck robots and the goals the policy set.
fn log_traffic(rec: &rerun::RecordingStream, t: &TrafficView) -> rerun::RecordingStreamResult<()> {
    let segment_colour = |d: Option<i8>| match d {
        None => rerun::Color::from_unmultiplied_rgba(160, 160, 160, 90),
        Some(d) if d > 0 => rerun::Color::from_unmultiplied_rgba(40, 170, 80, 150),
        Some(_) => rerun::Color::from_unmultiplied_rgba(150, 70, 200, 150),
    };
    let ids = |v: &[u32]| v.iter().map(u32::to_string).collect::<Vec<_>>().join(",");
    if !t.segments.is_empty() {
        rec.log(
            "world/traffic/segments",
            &rerun::Boxes2D::from_mins_and_sizes(
                t.segments.iter().map(|s| s.min),
                t.segments
                    .iter()
                    .map(|s| [s.max[0] - s.min[0], s.max[1] - s.min[1]]),
            )
            .with_colors(t.segments.iter().map(|s| segment_colour(s.direction)))
            .with_labels(t.segments.iter().map(|s| {
                let arrow = match s.direction {
                    None => "free",
                    Some(d) if d > 0 => "→",
                    Some(_) => "←",
                };
                let mut label = format!("seg {} {arrow}", s.id);
                if !s.holders.is_empty() {
                    label += &format!(" in: {}", ids(&s.holders));
                }
                if !s.waiting.is_empty() {
                    label += &format!(" waiting: {}", ids(&s.waiting));
                }
                label
            })),
        )?;
        let reserved: Vec<&SegmentView> = t
            .segments
            .iter()
            .filter(|s| s.direction.is_some())
            .collect();
        rec.log(
            "world/traffic/directions",
            &rerun::Arrows2D::from_vectors(reserved.iter().map(|s| {
                let d = f32::from(s.direction.unwrap_or(1));
                [d * 0.4 * (s.max[0] - s.min[0]), 0.0]
            }))
            .with_origins(reserved.iter().map(|s| {
                let d = f32::from(s.direction.unwrap_or(1));
                let mid = [(s.min[0] + s.max[0]) / 2.0, (s.min[1] + s.max[1]) / 2.0];
                [mid[0] - d * 0.2 * (s.max[0] - s.min[0]), mid[1]]
            }))
            .with_colors(reserved.iter().map(|s| segment_colour(s.direction))),
        )?;
    }
    rec.log(
        "world/traffic/waits",
        &rerun::Arrows2D::from_vectors(
            t.waits
                .iter()
                .map(|(a, b, _)| [0.85 * (b[0] - a[0]), 0.85 * (b[1] - a[1])]),
        )
        .with_origins(t.waits.iter().map(|w| w.0))
        .with_colors(t.waits.iter().map(|w| {
            if w.2 {
                rerun::Color::from_rgb(230, 30, 30)
            } else {
                rerun::Color::from_rgb(240, 170, 0)
            }
        })),
    )?;
    rec.log(
        "world/traffic/stuck",
        &rerun::LineStrips2D::new(t.stuck.iter().map(|s| ring(s.1, s.2 + 0.2)))
            .with_colors([rerun::Color::from_rgb(230, 30, 30)])
            .with_labels(t.stuck.iter().map(|s| format!("{} stuck", s.0))),
    )?;
    rec.log(
        "world/traffic/goals",
        &rerun::Points2D::new(t.goals.iter().map(|g| g.1))
            .with_radii([0.1])
            .with_labels(t.goals.iter().map(|g| {
                let kind = match g.2 {
                    TrafficGoal::Hold => "hold",
                    TrafficGoal::Queue => "queue",
                    TrafficGoal::Retreat => "retreat",
                };
                format!("{} {kind}", g.0)
            }))
            .with_colors(t.goals.iter().map(|g| match g.2 {
                TrafficGoal::Hold | TrafficGoal::Queue => rerun::Color::from_rgb(240, 170, 0),
                TrafficGoal::Retreat => rerun::Color::from_rgb(230, 30, 30),
            })),
    )?;
    Ok(())
}

fn log_frame(
    rec: &rerun::RecordingStream,
    f: &Frame,
    dropped: u64,
) -> rerun::RecordingStreamResult<()> {
    rec.set_time_sequence("tick", f.tick as i64);
    rec.set_duration_secs("sim_time", f.sim_time);
    rec.log(
        "world/humans",
        &rerun::Points2D::new(f.humans.iter().copied())
            .with_radii([f.human_radius])
            .with_colors(f.human_groups.iter().map(|&g| {
                let (r, gr, b) = GROUP_COLOURS[g as usize % GROUP_COLOURS.len()];
                rerun::Color::from_rgb(r, gr, b)
            })),
    )?;
    rec.log(
        "world/robots",
        &rerun::Points2D::new(f.robots.iter().map(|r| r.position))
            .with_radii(f.robots.iter().map(|r| r.radius))
            .with_labels(f.robots.iter().map(|r| r.id.to_string()))
            .with_colors(f.robots.iter().map(|r| {
                if r.alive {
                    rerun::Color::from_rgb(30, 30, 220)
                } else {
                    rerun::Color::from_rgb(220, 30, 30)
                }
            })),
    )?;
    rec.log(
        "world/robots/heading",
        &rerun::Arrows2D::from_vectors(
            f.robots
                .iter()
                .map(|r| [0.6 * r.heading.cos(), 0.6 * r.heading.sin()]),
        )
        .with_origins(f.robots.iter().map(|r| r.position)),
    )?;
    rec.log(
        "world/intents",
        &rerun::LineStrips2D::new(f.intents.iter().map(|i| i.path.clone()))
            .with_colors([rerun::Color::from_rgb(80, 80, 255)]),
    )?;
    rec.log(
        "world/subgoals",
        &rerun::Points2D::new(f.intents.iter().map(|i| i.subgoal))
            .with_radii([0.12])
            .with_colors([rerun::Color::from_rgb(255, 0, 255)]),
    )?;
    if !f.fields.is_empty() {
        log_fields(rec, &f.fields)?;
    }
    if let Some(traffic) = &f.traffic {
        log_traffic(rec, traffic)?;
    }
    for fan in &f.fans {
        rec.log(
            format!("world/fan/{}", fan.robot),
            &rerun::LineStrips2D::new(fan.candidates.iter().map(|c| c.0.clone()))
                .with_colors(fan.candidates.iter().map(|c| survival_colour(c.1))),
        )?;
    }
    if !f.events.is_empty() {
        for e in &f.events {
            let level = if e.warning { "WARN" } else { "INFO" };
            rec.log(
                "events",
                &rerun::TextLog::new(e.text.clone()).with_level(level),
            )?;
        }
    }
    for (name, value) in &f.fleet_metrics {
        rec.log(
            format!("metrics/{name}/fleet"),
            &rerun::Scalars::single(*value),
        )?;
    }
    rec.log(
        "metrics/dropped_frames/fleet",
        &rerun::Scalars::single(dropped as f64),
    )?;
    for (robot, series) in &f.robot_metrics {
        for (name, value) in series {
            rec.log(
                format!("metrics/{name}/robot/{robot}"),
                &rerun::Scalars::single(*value),
            )?;
        }
    }
    Ok(())
}
