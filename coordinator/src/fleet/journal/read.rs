//! A journal read back: header, inputs, events, snapshots, the ledger, the end.

use super::*;

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
