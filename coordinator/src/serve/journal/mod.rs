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
//! passes, byte for byte. Each snapshot is also written to a checked file beside the journal
//! ([`snapshot_files`]): when the journal is damaged past repair, [`recover`] begins a new one
//! at the newest intact snapshot file, and that journal replays from there.
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
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::time::Duration;
use world_sim::fleet::{Fleet, FleetEvent};

mod ledger;
mod read;
mod records;
mod replay;
pub mod snapshot_files;

use ledger::task_of;
pub use ledger::{TaskRecord, ledger_step};
use read::read_db;
pub use read::{Integrity, Recorded, read};
pub use records::{End, EventRecord, Header, IntentInput, ScenarioSource, TickInput};
pub use replay::{Replayed, fingerprint, fingerprint_with_held, place, replay, resume};

const META: TableDefinition<&str, &[u8]> = TableDefinition::new("meta");
const TICKS: TableDefinition<u64, &[u8]> = TableDefinition::new("ticks");
const EVENTS: TableDefinition<u64, &[u8]> = TableDefinition::new("events");
/// The task ledger, by task id.
const TASKS: TableDefinition<u64, &[u8]> = TableDefinition::new("tasks");
/// Snapshots by the number of ticks run when they were taken.
const SNAPSHOTS: TableDefinition<u64, &[u8]> = TableDefinition::new("snapshots");
/// Where a journal begun from a snapshot file begins: one row, the ticks run then → the fleet's
/// snapshot. Absent in a journal that begins at tick 0.
const START: TableDefinition<u64, &[u8]> = TableDefinition::new("start");

/// The journal's format (2: intents among the inputs, snapshots; 3: the layer's holds among
/// the inputs, snapshots of format 2).
const FORMAT: u32 = 3;

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

#[derive(Debug)]
enum Record {
    /// A tick's inputs and the task steps it made, for the ledger: one record, so that one
    /// commit holds both (a crash between them would leave a tick whose steps a restart
    /// re-makes but the ledger never sees).
    Tick(TickInput, Vec<FleetEvent>),
    Event(EventRecord),
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
    /// The file is not a journal, or is one that was damaged on disk.
    #[error("journal {path}: {what}")]
    Damaged {
        /// The database file.
        path: PathBuf,
        /// What is wrong with it.
        what: String,
    },
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

/// What [`recover`] did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Recovery {
    /// The journal was intact (or missing): nothing to do.
    Intact,
    /// The damaged file was kept at `kept`, and the journal is now its newest intact commit,
    /// with `ticks` ticks: a run resumes from it.
    Restored {
        /// Where the damaged file is now.
        kept: PathBuf,
        /// Ticks in the restored journal.
        ticks: u64,
    },
    /// The damaged file was kept at `kept`, and a new journal begins at the newest intact
    /// snapshot file beside it, `snapshot`, taken after `ticks` ticks: a run resumes from it,
    /// and the new journal replays from there.
    FromSnapshot {
        /// Where the damaged file is now.
        kept: PathBuf,
        /// The snapshot file.
        snapshot: PathBuf,
        /// Ticks run when it was taken.
        ticks: u64,
        /// What was wrong with the journal.
        what: String,
    },
    /// Nothing of it was intact, nor any snapshot file: the damaged file was kept at `kept`,
    /// and a run on the folder begins a new journal.
    Kept {
        /// Where the damaged file is now.
        kept: PathBuf,
        /// What was wrong with it.
        what: String,
    },
}

/// Makes a damaged journal in `dir` one a run can go on from: the damaged file is kept beside
/// it (`state.redb.damaged`, or `.damaged-2`, …) and replaced by whichever is further on of its
/// newest intact commit and a new journal beginning at the newest intact snapshot file (the
/// commit when they tie: it keeps the run from tick 0), or by nothing when neither exists (the
/// next run begins a new journal). An intact journal is left as it is.
pub fn recover(dir: &Path) -> Result<Recovery, JournalError> {
    let path = database(dir);
    if !path.exists() {
        return Ok(Recovery::Intact);
    }
    let checked = read::open_checked(&path);
    let kept = (1..)
        .map(|n| match n {
            1 => dir.join("state.redb.damaged"),
            n => dir.join(format!("state.redb.damaged-{n}")),
        })
        .find(|p| !p.exists())
        .expect("a free name");
    let io = |source| JournalError::Io {
        path: path.clone(),
        source,
    };
    let snapshot = snapshot_files::newest_intact(dir);
    let from_snapshot = |kept: PathBuf, what: String, file: snapshot_files::SnapshotFile| {
        // The snapshot must restore in its run's scenario before anything is changed.
        let scenario = file.header.scenario.scenario()?;
        let fleet = Fleet::restore(&scenario, &file.fleet).map_err(|e| {
            JournalError::Record(format!(
                "snapshot file {}: {e}. Nothing was changed",
                file.path.display()
            ))
        })?;
        std::fs::rename(&path, &kept).map_err(io)?;
        begin_at_snapshot(&path, &file, fleet.world.time, &kept)?;
        Ok(Recovery::FromSnapshot {
            kept,
            snapshot: file.path,
            ticks: file.ticks,
            what,
        })
    };
    match checked {
        Ok((_, Integrity::Intact, _)) => Ok(Recovery::Intact),
        Ok((db, Integrity::Recovered, copy)) => {
            let recorded = read_db(&db, &path)?;
            let ticks = recorded.ticks_run();
            drop(db);
            match snapshot {
                Some(file) if file.ticks > ticks && file.header.same_run(&recorded.header) => {
                    let what = format!(
                        "its newest commit does not verify; the one before does, with {ticks} ticks"
                    );
                    from_snapshot(kept, what, file)
                }
                _ => {
                    std::fs::rename(&path, &kept).map_err(io)?;
                    std::fs::copy(&copy, &path).map_err(io)?;
                    Ok(Recovery::Restored { kept, ticks })
                }
            }
        }
        Err(JournalError::Damaged { what, .. }) => match snapshot {
            Some(file) => from_snapshot(kept, what, file),
            None => {
                std::fs::rename(&path, &kept).map_err(io)?;
                Ok(Recovery::Kept { kept, what })
            }
        },
        Err(e) => Err(e),
    }
}

/// Writes a new journal at `path` that begins at the snapshot `file`, taken at simulated time
/// `sim_time` (its run's header, the snapshot as where it starts, and an event saying so).
fn begin_at_snapshot(
    path: &Path,
    file: &snapshot_files::SnapshotFile,
    sim_time: f64,
    kept: &Path,
) -> Result<(), JournalError> {
    let db = redb::Database::create(path).map_err(db_err(path, "create"))?;
    let txn = db.begin_write().map_err(db_err(path, "begin"))?;
    {
        let mut meta = txn.open_table(META).map_err(db_err(path, "open meta"))?;
        meta.insert("header", pack(&file.header).as_slice())
            .map_err(db_err(path, "write header"))?;
        let mut start = txn.open_table(START).map_err(db_err(path, "open start"))?;
        start
            .insert(file.ticks, file.fleet.as_slice())
            .map_err(db_err(path, "write start"))?;
        let mut events = txn
            .open_table(EVENTS)
            .map_err(db_err(path, "open events"))?;
        let event = EventRecord {
            tick: file.ticks,
            sim_time,
            event: format!(
                "journal begun at the snapshot of tick {} ({}); the damaged journal is kept at {}",
                file.ticks,
                file.path.display(),
                kept.display()
            ),
        };
        events
            .insert(0, pack(&event).as_slice())
            .map_err(db_err(path, "write event"))?;
    }
    txn.commit().map_err(db_err(path, "commit"))?;
    Ok(())
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
                if fleet_net::log_rejection(n) {
                    tracing::warn!(lost = n, "journal behind: record dropped");
                }
            }
        }
    }

    /// Records one tick's inputs and the task steps (assigned, picked, done) it made, for the
    /// ledger.
    pub fn tick(&self, input: TickInput, events: &[FleetEvent]) {
        self.send(Record::Tick(input, events.to_vec()));
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
        // An existing journal is checked first (on a copy): a damaged one is refused, with
        // the way to go on ([`recover`]).
        let recorded = if path.exists() {
            let recorded = read(dir).map_err(|e| match e {
                JournalError::Damaged { path, what } => JournalError::Damaged {
                    path,
                    what: format!(
                        "{what}. Nothing was changed. {}",
                        match snapshot_files::newest_intact(dir) {
                            Some(file) => format!(
                                "To keep it beside a new journal that begins at the newest \
                                 intact snapshot file ({}, {} ticks), start again with \
                                 --recover-state",
                                file.path.display(),
                                file.ticks
                            ),
                            None => "To keep it beside a new journal, start again with \
                                     --recover-state"
                                .to_owned(),
                        }
                    ),
                },
                e => e,
            })?;
            if recorded.integrity != Integrity::Intact {
                return Err(JournalError::Damaged {
                    path,
                    what: format!(
                        "damaged on disk: its newest commit does not verify (the one before \
                         does, with {} ticks). Nothing was changed. To go on from that one, \
                         keeping the damaged file beside it, start again with --recover-state",
                        recorded.ticks_run()
                    ),
                });
            }
            Some(recorded)
        } else {
            None
        };
        if recorded.is_none() {
            // A new journal: snapshot files of one no longer here are not its own.
            snapshot_files::clear(dir).map_err(|source| JournalError::Io {
                path: snapshot_files::folder(dir),
                source,
            })?;
        }
        let db = redb::Database::create(&path).map_err(db_err(&path, "create"))?;
        let recorded = if let Some(recorded) = recorded {
            if !recorded.header.same_run(header) {
                return Err(JournalError::State(format!(
                    "{} holds a run of site {:?}, scenario {} ({:?} robots, {:?} people, seed \
                     {:?}, real robots {:?}, traffic policy {}); this one differs: give a new \
                     folder",
                    path.display(),
                    recorded.header.site,
                    recorded.header.scenario.name,
                    recorded.header.scenario.robots,
                    recorded.header.scenario.humans,
                    recorded.header.scenario.seed,
                    recorded.header.live,
                    recorded.header.policy_text(),
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
        let (dir_, header_) = (dir.to_path_buf(), header.clone());
        let writer = std::thread::Builder::new()
            .name("journal".to_owned())
            .spawn(move || write_loop(&db, &path, (&dir_, &header_), &rx, first_event))
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
    (dir, header): (&Path, &Header),
    rx: &Receiver<Record>,
    first_event: u64,
) -> Result<u64, JournalError> {
    let mut ticks = 0;
    let mut failed_files = 0u64;
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
                    Record::Tick(input, steps) => {
                        // Fields by position: ticks are most of the journal (their intents
                        // above all), and their shape is fixed by the format.
                        let bytes = rmp_serde::to_vec(&input).unwrap_or_default();
                        tick_table
                            .insert(input.tick, bytes.as_slice())
                            .map_err(db_err(path, "write tick"))?;
                        ticks += 1;
                        for event in &steps {
                            let id = task_of(event);
                            let line = match tasks.get(id).map_err(db_err(path, "read task"))? {
                                Some(bytes) => Some(unpack::<TaskRecord>(bytes.value())?),
                                None => None,
                            };
                            if let Some(line) = ledger_step(line, input.tick, event) {
                                tasks
                                    .insert(id, pack(&line).as_slice())
                                    .map_err(db_err(path, "write task"))?;
                            }
                        }
                    }
                    Record::Event(event) => {
                        event_table
                            .insert(events, pack(&event).as_slice())
                            .map_err(db_err(path, "write event"))?;
                        events += 1;
                    }
                    Record::Snapshot(at, fleet) => {
                        let bytes = fleet.snapshot();
                        snapshots
                            .insert(at, bytes.as_slice())
                            .map_err(db_err(path, "write snapshot"))?;
                        // The copy beside the journal; the journal itself loses nothing
                        // if it fails.
                        if let Err(e) = snapshot_files::write(dir, header, at, &bytes) {
                            failed_files += 1;
                            if fleet_net::log_rejection(failed_files) {
                                tracing::warn!(
                                    failed = failed_files,
                                    "snapshot file of tick {at} not written: {e}"
                                );
                            }
                        }
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
