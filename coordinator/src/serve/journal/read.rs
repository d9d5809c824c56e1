//! A journal read back: header, inputs, events, snapshots, the ledger, the end.

use super::*;

/// A journal read back.
#[derive(Debug, Clone)]
pub struct Recorded {
    /// What the run was.
    pub header: Header,
    /// Where it begins, when it was begun at a snapshot file ([`recover`]): the ticks run then,
    /// and the fleet's snapshot. None for a journal that begins at tick 0.
    pub start: Option<(u64, Vec<u8>)>,
    /// Its inputs, tick by tick from where it begins, as far as they were committed.
    pub ticks: Vec<TickInput>,
    /// Its event log.
    pub events: Vec<EventRecord>,
    /// How it ended (None: it did not end cleanly, e.g. the coordinator was killed).
    pub end: Option<End>,
    /// The snapshots kept, oldest first: ticks run when taken, and the bytes.
    pub snapshots: Vec<(u64, Vec<u8>)>,
    /// The task ledger, by id.
    pub tasks: Vec<TaskRecord>,
    /// What the check of the file found.
    pub integrity: Integrity,
}

impl Recorded {
    /// The tick its first record is for: 0, or the ticks run at its start snapshot.
    pub fn first_tick(&self) -> u64 {
        self.start.as_ref().map_or(0, |(at, _)| *at)
    }

    /// Ticks the run had run at its last committed record.
    pub fn ticks_run(&self) -> u64 {
        self.first_tick() + self.ticks.len() as u64
    }
}

/// What the check of a journal's file found, when it could be read at all.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Integrity {
    /// Every page of its newest commit verified.
    Intact,
    /// Its newest commit did not verify (bytes changed on disk since it was written); the
    /// commit before it did, and the journal reads as it stood then: the ticks after it are
    /// lost.
    Recovered,
}

/// The first bytes of every redb file.
const REDB_MAGIC: [u8; 9] = [b'r', b'e', b'd', b'b', 0x1A, 0x0A, 0xA9, 0x0D, 0x0A];

/// Reads the journal in `dir`, checked: every page's checksum is verified on a copy of the
/// file (the file itself is never written by a read), so a damaged journal is an error that
/// names the file and what is wrong, never a panic. A journal whose newest commit is damaged
/// but whose previous one is intact reads as that one, [`Integrity::Recovered`].
pub fn read(dir: &Path) -> Result<Recorded, JournalError> {
    let path = database(dir);
    let (db, integrity, _copy) = open_checked(&path)?;
    let mut recorded = read_db(&db, &path)?;
    recorded.integrity = integrity;
    Ok(recorded)
}

/// `path` checked and opened from a copy, with what the check found; the copy lives as long
/// as the returned temporary file.
pub(super) fn open_checked(
    path: &Path,
) -> Result<(redb::Database, Integrity, tempfile::TempPath), JournalError> {
    let damaged = |what: String| JournalError::Damaged {
        path: path.to_path_buf(),
        what,
    };
    let io = |source| JournalError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut file = match std::fs::File::open(path) {
        Ok(file) => file,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(JournalError::State(format!(
                "{}: no such journal",
                path.display()
            )));
        }
        Err(e) => return Err(io(e)),
    };
    let len = file.metadata().map_err(io)?.len();
    if len == 0 {
        return Err(damaged("an empty file (0 bytes), not a journal".to_owned()));
    }
    let mut magic = [0u8; REDB_MAGIC.len()];
    use std::io::Read;
    if file.read_exact(&mut magic).is_err() || magic != REDB_MAGIC {
        return Err(damaged(format!(
            "not a journal: a {len}-byte file that is not a redb database"
        )));
    }
    drop(file);
    let copy = tempfile::NamedTempFile::new()
        .map_err(|source| JournalError::Io {
            path: std::env::temp_dir(),
            source,
        })?
        .into_temp_path();
    std::fs::copy(path, &copy).map_err(io)?;
    // The store's checked open: every page's checksum verified, a damaged newest commit
    // rolled back to the one before (the repair reports progress 0.3 exactly then), and
    // damage it cannot repair reported as an error rather than a panic.
    let fell_back = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let flag = Arc::clone(&fell_back);
    let db = redb::Builder::new()
        .set_check_integrity_on_open(true)
        .set_repair_callback(move |session| {
            if (0.25..0.35).contains(&session.progress()) {
                flag.store(true, Ordering::Relaxed);
            }
        })
        .open(&copy)
        .map_err(|e| match e {
            redb::DatabaseError::Storage(redb::StorageError::Corrupted(why)) => damaged(format!(
                "damaged on disk: what it holds does not verify against its checksums ({why})"
            )),
            e => damaged(format!("unreadable: {e}")),
        })?;
    let integrity = if fell_back.load(Ordering::Relaxed) {
        Integrity::Recovered
    } else {
        Integrity::Intact
    };
    Ok((db, integrity, copy))
}

pub(super) fn read_db(db: &redb::Database, path: &Path) -> Result<Recorded, JournalError> {
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
    let start = match txn.open_table(START) {
        Ok(table) => table
            .first()
            .map_err(db_err(&path, "read start"))?
            .map(|(at, bytes)| (at.value(), bytes.value().to_vec())),
        Err(redb::TableError::TableDoesNotExist(_)) => None,
        Err(e) => return Err(db_err(&path, "open start")(e)),
    };
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
        start,
        ticks,
        events,
        end,
        snapshots,
        tasks,
        integrity: Integrity::Intact,
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
