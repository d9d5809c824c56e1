//! The coordinator's journal (`--state DIR`): everything needed to re-run a live run bit for
//! bit, in a redb database, `DIR/state.redb`.
//!
//! The simulator is deterministic: given the scenario, a run is decided by which command each
//! robot drove on at each tick, which robots were held (no agent, or agent gone) and the
//! intents agents shared (the traffic monitor reads them, and the traffic policy reads the
//! monitor). Those are the only inputs the journal keeps, one record per tick, with a
//! fingerprint of the world every 100 ticks and at the end (event sourcing, as databases keep
//! a write-ahead log). The event log (joins, leaves, crashes, tasks done) is kept beside them
//! for people to read.
//!
//! Every [`SNAPSHOT_EVERY_S`] simulated seconds the coordinator also hands the writer a copy
//! of the fleet, which it stores as a snapshot ([`Fleet::snapshot`]; the newest
//! [`KEPT_SNAPSHOTS`] are kept): a restart restores the newest and replays only the ticks
//! after it ([`resume`]); `gapfleet replay` re-runs from tick 0 and checks every snapshot it
//! passes, byte for byte.
//!
//! The task ledger keeps a line per task, by its id (unique on the site: ids count on from
//! the snapshot across restarts): the robot, the stations, and the ticks it was assigned,
//! picked and done. A replay from tick 0 rebuilds it from the fleet's events and checks it.
//!
//! Writes leave the tick through a bounded queue to a thread of their own, which commits every
//! 200 ms: the tick never waits for the disk. What a crash can lose is what was not yet
//! committed: at most the last 200 ms of inputs, plus the queue if the disk fell behind. If
//! the queue ever fills, records are dropped and counted, and the journal says so: a replay of
//! it then stops where the gap begins.
//!
//! redb rather than SQLite: pure Rust (no C to build beside zenoh and rerun), one file,
//! crash-safe ACID transactions, and the data is plain key → bytes, which needs no SQL.

use agent::runtime::wire;
use redb::{ReadableDatabase, ReadableTable, ReadableTableMetadata, TableDefinition};
use schemas::{Motion, Sample};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::time::Duration;
use world_sim::fleet::{Fleet, FleetEvent};
use world_sim::scenario::Scenario;

const META: TableDefinition<&str, &[u8]> = TableDefinition::new("meta");
const TICKS: TableDefinition<u64, &[u8]> = TableDefinition::new("ticks");
const EVENTS: TableDefinition<u64, &[u8]> = TableDefinition::new("events");
/// The task ledger, by task id.
const TASKS: TableDefinition<u64, &[u8]> = TableDefinition::new("tasks");
/// Snapshots by the number of ticks run when they were taken.
const SNAPSHOTS: TableDefinition<u64, &[u8]> = TableDefinition::new("snapshots");

/// The journal's format (2: intents among the inputs, snapshots).
const FORMAT: u32 = 2;

/// The coordinator snapshots the fleet this often (simulated s).
pub const SNAPSHOT_EVERY_S: f64 = 30.0;

/// Snapshots kept; older ones are deleted as new ones are written.
pub const KEPT_SNAPSHOTS: usize = 4;

/// Records queued before new ones are dropped (and counted).
const QUEUE: usize = 8192;

/// The writer commits this often.
const COMMIT_EVERY: Duration = Duration::from_millis(200);

/// A fingerprint of the world goes into the journal every this many ticks.
pub const FINGERPRINT_EVERY: u64 = 100;

/// Where a run's scenario came from, enough to build it again.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScenarioSource {
    /// Its name (a built-in's, or the file's path) for messages.
    pub name: String,
    /// Its TOML text.
    pub toml: String,
    /// Robots, when overridden.
    pub robots: Option<usize>,
    /// People, when overridden.
    pub humans: Option<usize>,
    /// Seed, when overridden.
    pub seed: Option<u64>,
    /// Whether the safety layer was turned off.
    pub no_safety: bool,
}

impl ScenarioSource {
    /// The scenario as a fleet site, with the overrides applied and validated (the one place
    /// both the command line and a journal build it).
    pub fn scenario(&self) -> Result<Scenario, JournalError> {
        let bad = |e: String| JournalError::Scenario(format!("{}: {e}", self.name));
        let mut s = Scenario::from_toml(&self.toml, &self.name).map_err(|e| bad(e.to_string()))?;
        if !s.set_fleet_size(self.robots, self.humans) {
            return Err(bad(
                "not a fleet site (it needs a [warehouse] table, or a [hallway] with robots = N)"
                    .to_owned(),
            ));
        }
        if let Some(seed) = self.seed {
            s.seed = seed;
        }
        if self.no_safety {
            s.robot.safety = false;
        }
        s.validate(&self.name).map_err(|e| bad(e.to_string()))?;
        Ok(s)
    }
}

/// What a run is: written once, first.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// The journal's format.
    pub format: u32,
    /// Site name.
    pub site: String,
    /// The scenario.
    pub scenario: ScenarioSource,
    /// Whether observations carried other robots' intents (no effect on the world; kept for
    /// the record).
    pub share_intents: bool,
    /// Whether the traffic policy ran.
    pub traffic_policy: bool,
}

impl Header {
    /// A run of `scenario` on `site`.
    pub fn new(
        site: &str,
        scenario: ScenarioSource,
        share_intents: bool,
        traffic_policy: bool,
    ) -> Self {
        Self {
            format: FORMAT,
            site: site.to_owned(),
            scenario,
            share_intents,
            traffic_policy,
        }
    }
}

/// One tick's inputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TickInput {
    /// The tick (0 = the first step).
    pub tick: u64,
    /// Robots whose held flag changed before this tick's step, with the new flag.
    pub held: Vec<(u32, bool)>,
    /// The command each moving robot drove on (robots not listed stood still).
    pub commands: Vec<(u32, Motion)>,
    /// Intents taken from agents since the previous tick's step, in the order they were set.
    pub intents: Vec<IntentInput>,
    /// The world's fingerprint after this tick's step, every [`FINGERPRINT_EVERY`] ticks.
    pub fingerprint: Option<u64>,
}

/// An intent as the coordinator set it in the fleet.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IntentInput {
    /// The robot.
    pub robot: u32,
    /// The intent's stamp (s).
    pub stamp: f64,
    /// Its trajectory, as it came over the wire.
    pub trajectory: Vec<Sample>,
}

impl IntentInput {
    /// Sets the intent in `fleet` as the coordinator did.
    fn apply(&self, fleet: &mut Fleet) -> Result<(), JournalError> {
        let n = fleet.robots();
        if self.robot as usize >= n {
            return Err(JournalError::Record(format!("robot {} of {n}", self.robot)));
        }
        let samples = wire::samples_from_wire(&self.trajectory);
        fleet.set_intent(self.robot as usize, self.stamp, samples);
        Ok(())
    }
}

/// A task's line in the ledger.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TaskRecord {
    /// The task's id, unique on the site.
    pub task: u64,
    /// The robot it was given to.
    pub robot: u32,
    /// The station to pick at.
    pub pick_station: u32,
    /// The dock to drop at.
    pub drop_station: u32,
    /// The tick it was assigned at.
    pub assigned_tick: u64,
    /// The tick the robot reached the pick station, if it has.
    pub picked_tick: Option<u64>,
    /// The tick the robot dropped the load (the task done), if it has.
    pub done_tick: Option<u64>,
}

/// The task a fleet event is about.
fn task_of(event: &FleetEvent) -> u64 {
    match *event {
        FleetEvent::Assigned { task, .. } => task.id,
        FleetEvent::Picked { task, .. } | FleetEvent::Done { task, .. } => task,
    }
}

/// A task's ledger line after `event` at `tick`, from its line so far (`None` for a task
/// not yet in the ledger; a stage of a task never assigned gives `None`).
pub fn ledger_step(line: Option<TaskRecord>, tick: u64, event: &FleetEvent) -> Option<TaskRecord> {
    match *event {
        FleetEvent::Assigned { robot, task } => Some(TaskRecord {
            task: task.id,
            robot: robot as u32,
            pick_station: task.pick as u32,
            drop_station: task.drop as u32,
            assigned_tick: tick,
            picked_tick: None,
            done_tick: None,
        }),
        FleetEvent::Picked { .. } => line.map(|l| TaskRecord {
            picked_tick: Some(tick),
            ..l
        }),
        FleetEvent::Done { .. } => line.map(|l| TaskRecord {
            done_tick: Some(tick),
            ..l
        }),
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct End {
    /// Ticks run.
    pub ticks: u64,
    /// The world's fingerprint at the end.
    pub fingerprint: u64,
    /// Tasks done.
    pub tasks_done: u64,
    /// Records the queue dropped (0 for a journal that replays to the end).
    pub lost: u64,
}

/// A line of the event log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventRecord {
    /// The tick it happened at.
    pub tick: u64,
    /// Simulated time (s).
    pub sim_time: f64,
    /// What happened, as the coordinator logs it.
    pub event: String,
}

#[derive(Debug)]
enum Record {
    Tick(TickInput),
    Event(EventRecord),
    /// A task's step at a tick, for the ledger.
    Task(u64, FleetEvent),
    /// The fleet after this many ticks, encoded by the writer.
    Snapshot(u64, Box<Fleet>),
    End(End),
}

/// Why the journal failed.
#[derive(Debug, thiserror::Error)]
pub enum JournalError {
    /// The database refused.
    #[error("journal {path}: {what}: {message}")]
    Database {
        /// The database file.
        path: PathBuf,
        /// What was being done.
        what: &'static str,
        /// redb's message.
        message: String,
    },
    /// The folder holds a journal already (restarting on it is not built yet), or none, or
    /// the replay left the recorded run.
    #[error("journal: {0}")]
    State(String),
    /// A record would not decode.
    #[error("journal: bad record: {0}")]
    Record(String),
    /// The scenario cannot be built (as given, or again from a journal).
    #[error("scenario {0}")]
    Scenario(String),
    /// The folder could not be made.
    #[error("journal {path}: {source}")]
    Io {
        /// The folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

fn db_err<'a, E: std::fmt::Display>(
    path: &'a Path,
    what: &'static str,
) -> impl Fn(E) -> JournalError + 'a {
    move |e| JournalError::Database {
        path: path.to_path_buf(),
        what,
        message: e.to_string(),
    }
}

fn pack<T: Serialize>(value: &T) -> Vec<u8> {
    // Plain structs of numbers, strings and lists always encode.
    rmp_serde::to_vec_named(value).unwrap_or_default()
}

fn unpack<'a, T: Deserialize<'a>>(bytes: &'a [u8]) -> Result<T, JournalError> {
    rmp_serde::from_slice(bytes).map_err(|e| JournalError::Record(e.to_string()))
}

/// The database file in `dir`.
pub fn database(dir: &Path) -> PathBuf {
    dir.join("state.redb")
}

/// The coordinator's end of the journal: cheap to clone, never blocks.
#[derive(Debug, Clone)]
pub struct JournalSink {
    tx: SyncSender<Record>,
    lost: Arc<AtomicU64>,
}

impl JournalSink {
    fn send(&self, record: Record) {
        match self.tx.try_send(record) {
            Ok(()) => {}
            Err(TrySendError::Full(_)) | Err(TrySendError::Disconnected(_)) => {
                let n = self.lost.fetch_add(1, Ordering::Relaxed) + 1;
                if agent::runtime::log_rejection(n) {
                    tracing::warn!(lost = n, "journal behind: record dropped");
                }
            }
        }
    }

    /// Records one tick's inputs.
    pub fn tick(&self, input: TickInput) {
        self.send(Record::Tick(input));
    }

    /// Records a task's step (assigned, picked, done) at `tick` in the ledger.
    pub fn task(&self, tick: u64, event: FleetEvent) {
        self.send(Record::Task(tick, event));
    }

    /// Records the fleet after `ticks` ticks (a copy: the writer encodes it).
    pub fn snapshot(&self, ticks: u64, fleet: Fleet) {
        self.send(Record::Snapshot(ticks, Box::new(fleet)));
    }

    /// Records an event.
    pub fn event(&self, record: EventRecord) {
        self.send(Record::Event(record));
    }

    /// Records the end of the run.
    pub fn end(&self, mut end: End) {
        end.lost = self.lost.load(Ordering::Relaxed);
        self.send(Record::End(end));
    }

    /// Records dropped so far.
    pub fn lost(&self) -> u64 {
        self.lost.load(Ordering::Relaxed)
    }
}

/// A journal being written: hand [`Journal::sink`] to the coordinator, [`Journal::finish`]
/// after it returns.
#[derive(Debug)]
pub struct Journal {
    sink: JournalSink,
    writer: Option<std::thread::JoinHandle<Result<u64, JournalError>>>,
}

impl Journal {
    /// Starts a new journal in `dir` (created if missing), or continues the one there: then
    /// also returns what it holds, after checking that it is a run of the same site and
    /// scenario. A continued journal loses its end record (the run goes on).
    pub fn open(dir: &Path, header: &Header) -> Result<(Self, Option<Recorded>), JournalError> {
        std::fs::create_dir_all(dir).map_err(|source| JournalError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        let path = database(dir);
        let existed = path.exists();
        let db = redb::Database::create(&path).map_err(db_err(&path, "create"))?;
        let recorded = if existed {
            let recorded = read_db(&db, &path)?;
            if recorded.header != *header {
                return Err(JournalError::State(format!(
                    "{} holds a run of site {:?}, scenario {} ({:?} robots, {:?} people, seed \
                     {:?}); this one differs: give a new folder",
                    path.display(),
                    recorded.header.site,
                    recorded.header.scenario.name,
                    recorded.header.scenario.robots,
                    recorded.header.scenario.humans,
                    recorded.header.scenario.seed,
                )));
            }
            Some(recorded)
        } else {
            None
        };
        let txn = db.begin_write().map_err(db_err(&path, "begin"))?;
        {
            let mut meta = txn.open_table(META).map_err(db_err(&path, "open meta"))?;
            meta.insert("header", pack(header).as_slice())
                .map_err(db_err(&path, "write header"))?;
            meta.remove("end").map_err(db_err(&path, "remove end"))?;
        }
        txn.commit().map_err(db_err(&path, "commit"))?;
        let first_event = recorded.as_ref().map_or(0, |r| r.events.len() as u64);
        let (tx, rx) = sync_channel(QUEUE);
        let writer = std::thread::Builder::new()
            .name("journal".to_owned())
            .spawn(move || write_loop(&db, &path, &rx, first_event))
            .map_err(|source| JournalError::Io {
                path: dir.to_path_buf(),
                source,
            })?;
        let journal = Self {
            sink: JournalSink {
                tx,
                lost: Arc::new(AtomicU64::new(0)),
            },
            writer: Some(writer),
        };
        Ok((journal, recorded))
    }

    /// Starts a new journal in `dir` (created if missing), which must not hold one already.
    pub fn create(dir: &Path, header: &Header) -> Result<Self, JournalError> {
        let path = database(dir);
        if path.exists() {
            return Err(JournalError::State(format!(
                "{} holds a run already: give a new folder",
                path.display()
            )));
        }
        Ok(Self::open(dir, header)?.0)
    }

    /// The coordinator's end.
    pub fn sink(&self) -> JournalSink {
        self.sink.clone()
    }

    /// Waits for every queued record to be committed; returns how many ticks were written.
    pub fn finish(mut self) -> Result<u64, JournalError> {
        let writer = self.writer.take();
        // The writer ends when every sender is gone.
        drop(self);
        match writer.map(|w| w.join()) {
            Some(Ok(result)) => result,
            Some(Err(_)) => Err(JournalError::State("writer thread panicked".to_owned())),
            None => Ok(0),
        }
    }
}

fn write_loop(
    db: &redb::Database,
    path: &Path,
    rx: &Receiver<Record>,
    first_event: u64,
) -> Result<u64, JournalError> {
    let mut ticks = 0;
    let mut events = first_event;
    while let Ok(first) = rx.recv() {
        let mut batch = vec![first];
        let deadline = std::time::Instant::now() + COMMIT_EVERY;
        while let Some(left) = deadline.checked_duration_since(std::time::Instant::now()) {
            match rx.recv_timeout(left) {
                Ok(record) => batch.push(record),
                Err(_) => break,
            }
        }
        let txn = db.begin_write().map_err(db_err(path, "begin"))?;
        {
            let mut tick_table = txn.open_table(TICKS).map_err(db_err(path, "open ticks"))?;
            let mut event_table = txn
                .open_table(EVENTS)
                .map_err(db_err(path, "open events"))?;
            let mut meta = txn.open_table(META).map_err(db_err(path, "open meta"))?;
            let mut snapshots = txn
                .open_table(SNAPSHOTS)
                .map_err(db_err(path, "open snapshots"))?;
            let mut tasks = txn.open_table(TASKS).map_err(db_err(path, "open tasks"))?;
            for record in batch {
                match record {
                    Record::Tick(input) => {
                        // Fields by position: ticks are most of the journal (their intents
                        // above all), and their shape is fixed by the format.
                        let bytes = rmp_serde::to_vec(&input).unwrap_or_default();
                        tick_table
                            .insert(input.tick, bytes.as_slice())
                            .map_err(db_err(path, "write tick"))?;
                        ticks += 1;
                    }
                    Record::Event(event) => {
                        event_table
                            .insert(events, pack(&event).as_slice())
                            .map_err(db_err(path, "write event"))?;
                        events += 1;
                    }
                    Record::Task(tick, event) => {
                        let id = task_of(&event);
                        let line = match tasks.get(id).map_err(db_err(path, "read task"))? {
                            Some(bytes) => Some(unpack::<TaskRecord>(bytes.value())?),
                            None => None,
                        };
                        if let Some(line) = ledger_step(line, tick, &event) {
                            tasks
                                .insert(id, pack(&line).as_slice())
                                .map_err(db_err(path, "write task"))?;
                        }
                    }
                    Record::Snapshot(at, fleet) => {
                        snapshots
                            .insert(at, fleet.snapshot().as_slice())
                            .map_err(db_err(path, "write snapshot"))?;
                        while snapshots.len().map_err(db_err(path, "count snapshots"))?
                            > KEPT_SNAPSHOTS as u64
                        {
                            snapshots
                                .pop_first()
                                .map_err(db_err(path, "drop snapshot"))?;
                        }
                    }
                    Record::End(end) => {
                        meta.insert("end", pack(&end).as_slice())
                            .map_err(db_err(path, "write end"))?;
                    }
                }
            }
        }
        txn.commit().map_err(db_err(path, "commit"))?;
    }
    Ok(ticks)
}

/// A journal read back.
#[derive(Debug, Clone)]
pub struct Recorded {
    /// What the run was.
    pub header: Header,
    /// Its inputs, tick by tick, as far as they were committed.
    pub ticks: Vec<TickInput>,
    /// Its event log.
    pub events: Vec<EventRecord>,
    /// How it ended (None: it did not end cleanly, e.g. the coordinator was killed).
    pub end: Option<End>,
    /// The snapshots kept, oldest first: ticks run when taken, and the bytes.
    pub snapshots: Vec<(u64, Vec<u8>)>,
    /// The task ledger, by id.
    pub tasks: Vec<TaskRecord>,
}

/// Reads the journal in `dir`.
pub fn read(dir: &Path) -> Result<Recorded, JournalError> {
    let path = database(dir);
    if !path.exists() {
        return Err(JournalError::State(format!(
            "{}: no such journal",
            path.display()
        )));
    }
    let db = redb::Database::open(&path).map_err(db_err(&path, "open"))?;
    read_db(&db, &path)
}

fn read_db(db: &redb::Database, path: &Path) -> Result<Recorded, JournalError> {
    let path = path.to_path_buf();
    let txn = db.begin_read().map_err(db_err(&path, "begin"))?;
    let meta = txn.open_table(META).map_err(db_err(&path, "open meta"))?;
    let header: Header = match meta.get("header").map_err(db_err(&path, "read header"))? {
        Some(bytes) => unpack(bytes.value())?,
        None => {
            return Err(JournalError::State(format!(
                "{}: no header",
                path.display()
            )));
        }
    };
    if header.format != FORMAT {
        return Err(JournalError::State(format!(
            "{}: format {} (this gapfleet reads {FORMAT})",
            path.display(),
            header.format
        )));
    }
    let end = match meta.get("end").map_err(db_err(&path, "read end"))? {
        Some(bytes) => Some(unpack(bytes.value())?),
        None => None,
    };
    let ticks = rows(&txn, TICKS, &path)?;
    let events = rows(&txn, EVENTS, &path)?;
    let tasks = rows(&txn, TASKS, &path)?;
    let snapshots = match txn.open_table(SNAPSHOTS) {
        Ok(table) => table
            .iter()
            .map_err(db_err(&path, "read snapshots"))?
            .map(|row| {
                let (at, bytes) = row.map_err(db_err(&path, "read snapshot"))?;
                Ok((at.value(), bytes.value().to_vec()))
            })
            .collect::<Result<_, JournalError>>()?,
        Err(redb::TableError::TableDoesNotExist(_)) => Vec::new(),
        Err(e) => return Err(db_err(&path, "open snapshots")(e)),
    };
    Ok(Recorded {
        header,
        ticks,
        events,
        end,
        snapshots,
        tasks,
    })
}

/// Every row of `table`, decoded, in key order (none if the table was never written).
fn rows<T: serde::de::DeserializeOwned>(
    txn: &redb::ReadTransaction,
    table: TableDefinition<u64, &[u8]>,
    path: &Path,
) -> Result<Vec<T>, JournalError> {
    let table = match txn.open_table(table) {
        Ok(table) => table,
        Err(redb::TableError::TableDoesNotExist(_)) => return Ok(Vec::new()),
        Err(e) => return Err(db_err(path, "open table")(e)),
    };
    let mut out = Vec::new();
    for row in table.iter().map_err(db_err(path, "read rows"))? {
        let (_, bytes) = row.map_err(db_err(path, "read row"))?;
        out.push(unpack(bytes.value())?);
    }
    Ok(out)
}

/// A fingerprint of the world: FNV-1a over the bits of the simulated time, every robot's
/// pose, velocity, held flag, tasks done and path length, and every person's position and
/// velocity.
pub fn fingerprint(fleet: &Fleet) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325_u64;
    let mut eat = |x: u64| {
        for b in x.to_le_bytes() {
            h = (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    eat(fleet.world.time.to_bits());
    for (i, r) in fleet.world.robots.iter().enumerate() {
        let s = &r.state;
        for x in [
            s.position.x,
            s.position.y,
            s.velocity.x,
            s.velocity.y,
            s.heading,
        ] {
            eat(x.to_bits());
        }
        eat(u64::from(fleet.is_held(i)));
        eat(fleet.tasks_done(i));
        eat(fleet.metrics(i).path_length_m.to_bits());
    }
    let crowd = &fleet.world.humans.crowd;
    for i in 0..crowd.len() {
        for x in [
            crowd.positions[i].x,
            crowd.positions[i].y,
            crowd.velocities[i].x,
            crowd.velocities[i].y,
        ] {
            eat(x.to_bits());
        }
    }
    h
}

/// Tasks done by the whole fleet.
fn tasks_done(fleet: &Fleet) -> u64 {
    (0..fleet.robots()).map(|i| fleet.tasks_done(i)).sum()
}

/// What a replay found.
#[derive(Debug)]
pub struct Replayed {
    /// The tick it started from: 0, or the restored snapshot's.
    pub from: u64,
    /// Ticks re-run.
    pub ticks: u64,
    /// The world's fingerprint after them.
    pub fingerprint: u64,
    /// Fingerprints checked on the way (every [`FINGERPRINT_EVERY`] ticks), all equal.
    pub checked: u64,
    /// Snapshots passed on the way and found equal to the replayed fleet, byte for byte.
    pub snapshots_checked: u64,
    /// Ledger lines found equal to the replay's (a replay from tick 0 checks them all).
    pub tasks_checked: u64,
    /// Tasks done.
    pub tasks_done: u64,
    /// The fleet at the end.
    pub fleet: Fleet,
}

/// Re-runs a recorded run in-process from tick 0: builds its scenario, applies each tick's
/// held flags, intents and commands, steps and dispatches as the coordinator did. A
/// fingerprint or snapshot that differs from the recorded one is an error naming the tick.
pub fn replay(
    recorded: &Recorded,
    on_tick: impl FnMut(&Fleet, &[FleetEvent]),
) -> Result<Replayed, JournalError> {
    let fleet = new_fleet(recorded)?;
    run_inputs(fleet, 0, recorded, true, on_tick)
}

/// The run's state at the end of its journal, for a restart: the newest snapshot restored,
/// then the ticks after it re-run (all of them if there is no snapshot, or none restores).
pub fn resume(recorded: &Recorded) -> Result<Replayed, JournalError> {
    let scenario = recorded.header.scenario.scenario()?;
    let ticks = recorded.ticks.len() as u64;
    for (at, bytes) in recorded.snapshots.iter().rev() {
        if *at > ticks {
            tracing::warn!(at, ticks, "snapshot past the journal's ticks: not used");
            continue;
        }
        match Fleet::restore(&scenario, bytes) {
            Ok(fleet) => return run_inputs(fleet, *at, recorded, false, |_, _| {}),
            Err(e) => tracing::warn!(at, "snapshot not used: {e}"),
        }
    }
    replay(recorded, |_, _| {})
}

/// A new fleet as the run began.
fn new_fleet(recorded: &Recorded) -> Result<Fleet, JournalError> {
    let scenario = recorded.header.scenario.scenario()?;
    let mut fleet = Fleet::new(&scenario).map_err(|e| JournalError::Scenario(e.to_string()))?;
    fleet.share_intents = recorded.header.share_intents;
    if recorded.header.traffic_policy {
        fleet.set_traffic_policy(Some(world_sim::traffic_policy::PolicyParams::default()));
    }
    Ok(fleet)
}

/// `fleet` after `from` ticks, on through the rest of the journal.
fn run_inputs(
    mut fleet: Fleet,
    from: u64,
    recorded: &Recorded,
    check_snapshots: bool,
    mut on_tick: impl FnMut(&Fleet, &[FleetEvent]),
) -> Result<Replayed, JournalError> {
    // Held flags start as a new fleet's (none held) or the snapshot's; the first tick's record
    // holds the coordinator's holding every robot without an agent.
    let n = fleet.robots();
    let scenario = recorded.header.scenario.scenario()?;
    let mut snapshots = recorded.snapshots.iter().peekable();
    let (mut checked, mut snapshots_checked) = (0, 0);
    let mut commands = vec![agent::model::Command::STOP; n];
    // The ledger as the replay makes it (from tick 0 only: a snapshot's tasks began before it).
    let mut ledger = std::collections::BTreeMap::<u64, TaskRecord>::new();
    for (k, input) in recorded.ticks.iter().enumerate().skip(from as usize) {
        if input.tick != k as u64 {
            return Err(JournalError::State(format!(
                "tick {} is missing (the record after it is tick {})",
                k, input.tick
            )));
        }
        for &(robot, held) in &input.held {
            if robot as usize >= n {
                return Err(JournalError::Record(format!("robot {robot} of {n}")));
            }
            fleet.set_held(robot as usize, held);
        }
        for intent in &input.intents {
            intent.apply(&mut fleet)?;
        }
        commands.fill(agent::model::Command::STOP);
        for &(robot, motion) in &input.commands {
            let slot = commands
                .get_mut(robot as usize)
                .ok_or_else(|| JournalError::Record(format!("robot {robot} of {n}")))?;
            *slot = wire::command(motion);
        }
        let mut events = fleet.step(&commands);
        events.extend(fleet.dispatch());
        on_tick(&fleet, &events);
        for event in &events {
            let id = task_of(event);
            if let Some(line) = ledger_step(ledger.remove(&id), input.tick, event) {
                ledger.insert(id, line);
            }
        }
        if let Some(recorded_print) = input.fingerprint {
            let now = fingerprint(&fleet);
            if now != recorded_print {
                return Err(JournalError::State(format!(
                    "the replay left the recorded run at tick {}: fingerprint {now:016x}, recorded {recorded_print:016x}",
                    input.tick
                )));
            }
            checked += 1;
        }
        let ran = k as u64 + 1;
        while snapshots.next_if(|(at, _)| *at < ran).is_some() {}
        if check_snapshots && let Some((_, bytes)) = snapshots.next_if(|(at, _)| *at == ran) {
            same_as_snapshot(&fleet, &scenario, bytes, ran)?;
            snapshots_checked += 1;
        }
    }
    let print = fingerprint(&fleet);
    if let Some(end) = &recorded.end
        && end.ticks == recorded.ticks.len() as u64
        && end.fingerprint != print
    {
        return Err(JournalError::State(format!(
            "the replay ended on fingerprint {print:016x}, the run on {:016x}",
            end.fingerprint
        )));
    }
    let mut tasks_checked = 0;
    if from == 0 {
        for line in &recorded.tasks {
            let replayed = ledger.get(&line.task);
            if replayed != Some(line) {
                return Err(JournalError::State(format!(
                    "the ledger's task {} is {line:?}; the replay made it {replayed:?}",
                    line.task
                )));
            }
            tasks_checked += 1;
        }
    }
    Ok(Replayed {
        from,
        ticks: recorded.ticks.len() as u64,
        fingerprint: print,
        checked,
        snapshots_checked,
        tasks_checked,
        tasks_done: tasks_done(&fleet),
        fleet,
    })
}

/// Whether `fleet`, `ran` ticks into the replay, is the snapshot taken then, byte for byte.
/// The human-impact measurement a dashboard attaches is left out of both: it measures the
/// run (a shadow crowd) without changing it, and a replay attaches none.
fn same_as_snapshot(
    fleet: &Fleet,
    scenario: &world_sim::scenario::Scenario,
    bytes: &[u8],
    ran: u64,
) -> Result<(), JournalError> {
    let mut stored = Fleet::restore(scenario, bytes)
        .map_err(|e| JournalError::Record(format!("snapshot at tick {ran}: {e}")))?;
    stored.stop_measuring_human_impact();
    let mut replayed = fleet.clone();
    replayed.stop_measuring_human_impact();
    let (a, b) = (stored.snapshot(), replayed.snapshot());
    if a != b {
        let at = a.iter().zip(&b).position(|(x, y)| x != y);
        return Err(JournalError::State(format!(
            "the replay left the recorded run by tick {ran}: its state differs from the \
             snapshot taken then ({} and {} bytes, first difference at byte {})",
            b.len(),
            a.len(),
            at.map_or("(the end of the shorter)".to_owned(), |i| i.to_string())
        )));
    }
    Ok(())
}
