//! Snapshots kept beside the journal, one file each (`DIR/snapshots/tick-<ticks>.snap`), so
//! that a run can go on from its newest intact snapshot when the journal itself is damaged
//! past repair: after a clean close, redb keeps no earlier commit to fall back to.
//!
//! A file is self-contained and checked: a magic, its format, the run's [`Header`], the ticks
//! run when the snapshot was taken, the fleet's snapshot, and an FNV-1a checksum over all of
//! it. It is written to a temporary name, synced and renamed, so a crash leaves the old file
//! set or the new one, never half a file under a snapshot's name. The newest
//! [`KEPT_SNAPSHOTS`] are kept.

use super::*;
use std::io::Write;

/// The first bytes of every snapshot file.
const MAGIC: [u8; 8] = *b"gfsnap\r\n";

/// The snapshot files' format.
const FILE_FORMAT: u32 = 1;

/// The folder of snapshot files beside the journal in `dir`.
pub fn folder(dir: &Path) -> PathBuf {
    dir.join("snapshots")
}

/// A snapshot file read back and verified.
#[derive(Debug, Clone)]
pub struct SnapshotFile {
    /// The file.
    pub path: PathBuf,
    /// The run it belongs to.
    pub header: Header,
    /// Ticks run when it was taken.
    pub ticks: u64,
    /// The fleet's snapshot ([`Fleet::snapshot`]).
    pub fleet: Vec<u8>,
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The file's bytes.
fn encode(header: &Header, ticks: u64, fleet: &[u8]) -> Vec<u8> {
    let header = pack(header);
    let mut out = Vec::with_capacity(40 + header.len() + fleet.len());
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&FILE_FORMAT.to_le_bytes());
    out.extend_from_slice(&(header.len() as u64).to_le_bytes());
    out.extend_from_slice(&header);
    out.extend_from_slice(&ticks.to_le_bytes());
    out.extend_from_slice(&(fleet.len() as u64).to_le_bytes());
    out.extend_from_slice(fleet);
    let sum = fnv1a(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    out
}

/// Reads `bytes` back; Err says what is wrong.
fn decode(bytes: &[u8]) -> Result<(Header, u64, Vec<u8>), String> {
    let (body, sum) = bytes
        .split_last_chunk::<8>()
        .ok_or_else(|| format!("{} bytes: too short", bytes.len()))?;
    if fnv1a(body) != u64::from_le_bytes(*sum) {
        return Err("its checksum does not verify".to_owned());
    }
    let mut rest = body;
    let mut take = |n: usize| -> Result<&[u8], String> {
        if rest.len() < n {
            return Err("cut short".to_owned());
        }
        let (head, tail) = rest.split_at(n);
        rest = tail;
        Ok(head)
    };
    let u64_at = |b: &[u8]| u64::from_le_bytes(b.try_into().unwrap_or([0; 8]));
    if take(MAGIC.len())? != MAGIC {
        return Err("not a snapshot file".to_owned());
    }
    let format = u32::from_le_bytes(take(4)?.try_into().unwrap_or([0; 4]));
    if format != FILE_FORMAT {
        return Err(format!(
            "format {format} (this gapfleet reads {FILE_FORMAT})"
        ));
    }
    let header_len = usize::try_from(u64_at(take(8)?)).map_err(|e| e.to_string())?;
    let header: Header = unpack(take(header_len)?).map_err(|e| e.to_string())?;
    let ticks = u64_at(take(8)?);
    let fleet_len = usize::try_from(u64_at(take(8)?)).map_err(|e| e.to_string())?;
    let fleet = take(fleet_len)?.to_vec();
    if !rest.is_empty() {
        return Err(format!("{} bytes past its end", rest.len()));
    }
    Ok((header, ticks, fleet))
}

/// Writes the snapshot of `ticks` ticks into `dir`'s folder (created if missing), durably, then
/// removes all but the newest [`KEPT_SNAPSHOTS`].
pub(super) fn write(dir: &Path, header: &Header, ticks: u64, fleet: &[u8]) -> std::io::Result<()> {
    let folder = folder(dir);
    std::fs::create_dir_all(&folder)?;
    let path = folder.join(format!("tick-{ticks:012}.snap"));
    let partial = path.with_extension("snap.partial");
    {
        let mut file = std::fs::File::create(&partial)?;
        file.write_all(&encode(header, ticks, fleet))?;
        file.sync_all()?;
    }
    std::fs::rename(&partial, &path)?;
    std::fs::File::open(&folder)?.sync_all()?;
    let mut files = names(&folder);
    while files.len() > KEPT_SNAPSHOTS {
        std::fs::remove_file(files.remove(0))?;
    }
    Ok(())
}

/// The snapshot files in `folder`, oldest first (by name: the tick is zero-padded).
fn names(folder: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).collect())
        .unwrap_or_default();
    files.retain(|f| f.extension().is_some_and(|e| e == "snap"));
    files.sort();
    files
}

/// The newest snapshot file in `dir`'s folder that verifies; those that do not are logged and
/// passed over.
pub fn newest_intact(dir: &Path) -> Option<SnapshotFile> {
    names(&folder(dir)).into_iter().rev().find_map(|path| {
        let read = std::fs::read(&path).map_err(|e| e.to_string());
        match read.and_then(|bytes| decode(&bytes)) {
            Ok((header, ticks, fleet)) => Some(SnapshotFile {
                path,
                header,
                ticks,
                fleet,
            }),
            Err(what) => {
                tracing::warn!(file = %path.display(), "snapshot file not used: {what}");
                None
            }
        }
    })
}

/// Removes the snapshot files in `dir`'s folder: a new journal begins, and those of a journal
/// no longer there must not be taken for its own.
pub(super) fn clear(dir: &Path) -> std::io::Result<()> {
    for file in names(&folder(dir)) {
        std::fs::remove_file(file)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> Header {
        let source =
            ScenarioSource::builtin("warehouse", Some(2), Some(3), Some(1)).expect("built in");
        Header::new("site", source, true, Some(Default::default()))
    }

    #[test]
    fn a_file_reads_back_and_any_flipped_byte_or_cut_is_refused() {
        let bytes = encode(&header(), 300, &[1, 2, 3, 4, 5]);
        let (h, ticks, fleet) = decode(&bytes).expect("reads back");
        assert_eq!((h, ticks, fleet), (header(), 300, vec![1, 2, 3, 4, 5]));
        for at in 0..bytes.len() {
            let mut damaged = bytes.clone();
            damaged[at] ^= 0x10;
            assert!(decode(&damaged).is_err(), "a flip at byte {at} went unseen");
        }
        for len in 0..bytes.len() {
            assert!(decode(&bytes[..len]).is_err(), "cut at {len} went unseen");
        }
    }

    #[test]
    fn the_newest_intact_file_is_found_and_only_the_newest_are_kept() {
        let dir = tempfile::tempdir().expect("a folder");
        for ticks in [300, 600, 900, 1200, 1500] {
            write(dir.path(), &header(), ticks, &ticks.to_le_bytes()).expect("written");
        }
        assert_eq!(names(&folder(dir.path())).len(), KEPT_SNAPSHOTS);
        assert_eq!(newest_intact(dir.path()).expect("one").ticks, 1500);
        // The newest damaged: the one before it is taken.
        let newest = folder(dir.path()).join("tick-000000001500.snap");
        let mut bytes = std::fs::read(&newest).expect("read");
        bytes[20] ^= 1;
        std::fs::write(&newest, bytes).expect("written");
        assert_eq!(newest_intact(dir.path()).expect("one").ticks, 1200);
        clear(dir.path()).expect("cleared");
        assert!(newest_intact(dir.path()).is_none());
    }
}
