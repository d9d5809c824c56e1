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
//! - `map/shelves`, `map/walls`, `map/stations`, and `map/keepout` on a site with keep-out
//!   zones (static)
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

mod blueprint;
mod draw;
mod frame;
pub mod heat;
pub mod table;

pub use frame::*;

use blueprint::blueprint;
use draw::{Painter, log_map};
use heat::HeatParams;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{SyncSender, TrySendError, sync_channel};
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

/// Why the dashboard could not start.
#[derive(Debug, thiserror::Error)]
pub enum DashboardError {
    /// Rerun refused a sink or the recording.
    #[error("rerun: {0}")]
    Rerun(String),
    /// The logging thread could not start.
    #[error("dashboard thread: {0}")]
    Thread(#[from] std::io::Error),
    /// The .rrd file's folder could not be made.
    #[error("cannot create {path}: {source}")]
    Folder {
        /// The folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
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
            if let Some(folder) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
                std::fs::create_dir_all(folder).map_err(|source| DashboardError::Folder {
                    path: folder.to_path_buf(),
                    source,
                })?;
            }
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
