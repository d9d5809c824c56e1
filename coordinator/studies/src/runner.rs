//! One runner for every study: a [`Study`] is a list of independent runs, each a pure
//! function of its key; the [`Runner`] plays them on a thread pool with a progress bar, saves
//! each run to a checkpoint in the output folder as it ends, and on `--resume` takes the runs
//! an interrupted study had finished from there instead of running them again.
//!
//! **Same bits.** Rows come back in the order of [`Study::keys`], whatever the thread count and
//! whichever runs were resumed. A checkpoint holds the rows as MessagePack, which keeps every
//! float's bits (NaN and infinities included), so a resumed study writes the outputs an
//! uninterrupted one would.
//!
//! **The checkpoint** (`checkpoint.bin` in the output folder) starts with [`MAGIC`], the
//! study's fingerprint and its run count; then one record per finished run, in the order runs
//! ended: the record's length (u32, little-endian) and the MessagePack of (run index, row). The
//! fingerprint hashes the crate version and the study's settings (its `Debug` text), so a
//! checkpoint of other settings is refused rather than mixed in; a rebuilt binary with the same
//! version and settings is not told apart, so resume with the build that started the study. A
//! record cut short (the process killed while writing it) is dropped. The file is removed once
//! the study's outputs are written ([`Runner::finish`]).

use rayon::prelude::*;
use serde::Serialize;
use serde::de::DeserializeOwned;
use std::fmt;
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

/// A study as the runner sees it.
pub trait Study: Sync + fmt::Debug {
    /// What names one run (its cell and seed).
    type Key: Send + Sync;
    /// One run's outcome.
    type Row: Serialize + DeserializeOwned + Send;
    /// Why a run could not be made (a study's settings it finds wrong only when it runs them).
    type Error: std::error::Error + Send + Sync + 'static;

    /// Every run, in the order of the study's outputs.
    fn keys(&self) -> Vec<Self::Key>;

    /// One run. Depends on `key` and the study's settings only, never on the thread or the
    /// order runs are made in.
    fn run(&self, key: &Self::Key) -> Result<Self::Row, Self::Error>;

    /// Every run on the current rayon pool, without a checkpoint; `progress` is called after
    /// each. Rows in the order of [`Study::keys`].
    fn execute(&self, progress: &(dyn Fn() + Sync)) -> Result<Vec<Self::Row>, Self::Error> {
        self.keys()
            .par_iter()
            .map(|key| {
                let row = self.run(key);
                progress();
                row
            })
            .collect()
    }
}

/// The first bytes of a checkpoint: the format and its version.
pub const MAGIC: &[u8; 8] = b"GFSTUDY1";

/// The checkpoint's name in the output folder.
pub const CHECKPOINT: &str = "checkpoint.bin";

/// The largest record a checkpoint may hold (bytes): far above any study's row, so that a
/// damaged length is caught before it is allocated.
const MAX_RECORD: u32 = 64 << 20;

/// Why a study could not be run.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The output folder or the checkpoint could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// Where.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The output folder holds runs of an interrupted study, and `--resume` was not given.
    #[error(
        "{path} holds {runs} finished runs of an interrupted study: pass --resume to go on \
         with them, or remove the file to start again"
    )]
    Unfinished {
        /// The checkpoint.
        path: PathBuf,
        /// The runs it holds.
        runs: usize,
    },
    /// The checkpoint is of other settings (or another version).
    #[error(
        "{path} is the checkpoint of a study with other settings or another gapfleet version: \
         remove it, or choose another output folder"
    )]
    Foreign {
        /// The checkpoint.
        path: PathBuf,
    },
    /// The checkpoint is not one, or a whole record in it does not decode.
    #[error("{path} is damaged: {why}")]
    Damaged {
        /// The checkpoint.
        path: PathBuf,
        /// What was wrong.
        why: String,
    },
    /// The thread pool could not be built.
    #[error("building the thread pool: {0}")]
    Pool(#[from] rayon::ThreadPoolBuildError),
    /// A run failed.
    #[error(transparent)]
    Study(Box<dyn std::error::Error + Send + Sync>),
}

/// How to run a study: threads, where the checkpoint goes, and whether to resume.
#[derive(Debug, Clone)]
pub struct Runner {
    threads: usize,
    checkpoint: Option<PathBuf>,
    resume: bool,
    progress_bar: bool,
}

/// What a study's runs came to.
#[derive(Debug)]
pub struct Finished<R> {
    /// One row per run, in the order of [`Study::keys`].
    pub rows: Vec<R>,
    /// Threads used.
    pub threads: usize,
    /// Runs taken from the checkpoint.
    pub resumed: usize,
    /// Wall time of this invocation.
    pub elapsed: Duration,
}

impl Runner {
    /// A runner on `threads` threads (all cores when `None`) whose checkpoint is
    /// [`CHECKPOINT`] in the output folder `out`.
    pub fn new(threads: Option<usize>, out: impl Into<PathBuf>, resume: bool) -> Self {
        let threads =
            threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
        Self {
            threads: threads.max(1),
            checkpoint: Some(out.into().join(CHECKPOINT)),
            resume,
            progress_bar: true,
        }
    }

    /// The checkpoint at `path` instead (a study whose output is one file), or none at all.
    pub fn checkpoint_at(mut self, path: Option<PathBuf>) -> Self {
        self.checkpoint = path;
        self
    }

    /// Without the progress bar on stderr (tests).
    pub fn quiet(mut self) -> Self {
        self.progress_bar = false;
        self
    }

    /// The checkpoint's path, if the runs are saved.
    pub fn checkpoint(&self) -> Option<&Path> {
        self.checkpoint.as_deref()
    }

    /// Plays every run of `study` not already in the checkpoint, saving each as it ends.
    pub fn run<S: Study>(&self, study: &S) -> Result<Finished<S::Row>, RunError> {
        let started = Instant::now();
        let keys = study.keys();
        let mut done: Vec<Option<S::Row>> = (0..keys.len()).map(|_| None).collect();
        let mut resumed = 0;
        let file = match &self.checkpoint {
            Some(path) => {
                Some(self.open_checkpoint::<S>(path, study, keys.len(), &mut done, &mut resumed)?)
            }
            None => None,
        };
        let writer = file.map(|f| Mutex::new(BufWriter::new(f)));
        let save_error: Mutex<Option<std::io::Error>> = Mutex::new(None);
        let save = |index: usize, row: &S::Row| {
            let Some(writer) = &writer else {
                return;
            };
            let record = rmp_serde::to_vec(&(index as u64, row));
            let saved = match record {
                Ok(bytes) => {
                    let mut w = writer.lock().unwrap_or_else(PoisonError::into_inner);
                    w.write_all(&(bytes.len() as u32).to_le_bytes())
                        .and_then(|()| w.write_all(&bytes))
                        .and_then(|()| w.flush())
                }
                Err(e) => Err(std::io::Error::other(e)),
            };
            if let Err(e) = saved {
                save_error
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .get_or_insert(e);
            }
        };

        let bar = self.progress_bar.then(|| {
            let bar = indicatif::ProgressBar::new(keys.len() as u64).with_style(
                indicatif::ProgressStyle::with_template(
                    "{elapsed_precise} [{bar:40}] {pos}/{len} runs, eta {eta}",
                )
                .expect("a valid progress template")
                .progress_chars("=> "),
            );
            bar.set_position(resumed as u64);
            bar.reset_eta();
            bar
        });
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads)
            .build()?;
        let todo: Vec<usize> = (0..keys.len()).filter(|&i| done[i].is_none()).collect();
        let made: Result<Vec<(usize, S::Row)>, S::Error> = pool.install(|| {
            todo.par_iter()
                .map(|&i| {
                    let row = study.run(&keys[i])?;
                    save(i, &row);
                    if let Some(bar) = &bar {
                        bar.inc(1);
                    }
                    Ok((i, row))
                })
                .collect()
        });
        if let Some(bar) = &bar {
            bar.finish();
        }
        let made = made.map_err(|e| RunError::Study(Box::new(e)))?;
        if let (Some(e), Some(path)) = (
            save_error
                .into_inner()
                .unwrap_or_else(PoisonError::into_inner),
            &self.checkpoint,
        ) {
            eprintln!("warning: saving runs to {} failed: {e}", path.display());
        }
        for (i, row) in made {
            done[i] = Some(row);
        }
        let rows = done
            .into_iter()
            .map(|r| r.expect("every run made or resumed"))
            .collect();
        Ok(Finished {
            rows,
            threads: self.threads,
            resumed,
            elapsed: started.elapsed(),
        })
    }

    /// Removes the checkpoint: call once the study's outputs are written.
    pub fn finish(&self) -> Result<(), RunError> {
        let Some(path) = &self.checkpoint else {
            return Ok(());
        };
        match std::fs::remove_file(path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(RunError::Io {
                path: path.clone(),
                source: e,
            }),
            _ => Ok(()),
        }
    }

    /// The checkpoint at `path` opened for appending: a new one, or (with `resume`) the one
    /// there, whose rows go into `done`.
    fn open_checkpoint<S: Study>(
        &self,
        path: &Path,
        study: &S,
        runs: usize,
        done: &mut [Option<S::Row>],
        resumed: &mut usize,
    ) -> Result<File, RunError> {
        let fingerprint = fingerprint(study);
        if path.exists() {
            let (rows, valid) = read_checkpoint::<S::Row>(path, fingerprint, runs)?;
            if !self.resume {
                return Err(RunError::Unfinished {
                    path: path.to_owned(),
                    runs: rows.len(),
                });
            }
            for (index, row) in rows {
                if done[index].replace(row).is_none() {
                    *resumed += 1;
                }
            }
            // Drop a record cut short, then append.
            let mut file = OpenOptions::new()
                .write(true)
                .open(path)
                .map_err(io(path))?;
            file.set_len(valid).map_err(io(path))?;
            file.seek(SeekFrom::End(0)).map_err(io(path))?;
            Ok(file)
        } else {
            if let Some(folder) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
                std::fs::create_dir_all(folder).map_err(io(folder))?;
            }
            let mut file = File::create(path).map_err(io(path))?;
            let mut header = Vec::with_capacity(24);
            header.extend_from_slice(MAGIC);
            header.extend_from_slice(&fingerprint.to_le_bytes());
            header.extend_from_slice(&(runs as u64).to_le_bytes());
            file.write_all(&header).map_err(io(path))?;
            Ok(file)
        }
    }
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> RunError + '_ {
    move |source| RunError::Io {
        path: path.to_owned(),
        source,
    }
}

/// FNV-1a over the crate version and the study's settings.
fn fingerprint(study: &impl fmt::Debug) -> u64 {
    let text = format!("{} {study:?}", env!("CARGO_PKG_VERSION"));
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The rows a checkpoint holds, with their run indices, and the length of its whole records.
fn read_checkpoint<R: DeserializeOwned>(
    path: &Path,
    fingerprint: u64,
    runs: usize,
) -> Result<(Vec<(usize, R)>, u64), RunError> {
    let mut bytes = Vec::new();
    File::open(path)
        .and_then(|mut f| f.read_to_end(&mut bytes))
        .map_err(io(path))?;
    let damaged = |why: String| RunError::Damaged {
        path: path.to_owned(),
        why,
    };
    if bytes.len() < 24 || &bytes[..8] != MAGIC {
        return Err(damaged("not a gapfleet study checkpoint".into()));
    }
    let word = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"));
    if word(8) != fingerprint || word(16) != runs as u64 {
        return Err(RunError::Foreign {
            path: path.to_owned(),
        });
    }
    let mut at = 24;
    let mut rows = Vec::new();
    while bytes.len() - at >= 4 {
        let len = u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
        if len > MAX_RECORD {
            return Err(damaged(format!("a record at byte {at} claims {len} bytes")));
        }
        let end = at + 4 + len as usize;
        if end > bytes.len() {
            break;
        }
        let (index, row): (u64, R) = rmp_serde::from_slice(&bytes[at + 4..end])
            .map_err(|e| damaged(format!("the record at byte {at}: {e}")))?;
        let index = usize::try_from(index)
            .ok()
            .filter(|&i| i < runs)
            .ok_or_else(|| {
                damaged(format!(
                    "the record at byte {at} names run {index} of {runs}"
                ))
            })?;
        rows.push((index, row));
        at = end;
    }
    Ok((rows, at as u64))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// Squares, with a NaN among them; counts the runs it makes. Its settings (what the
    /// fingerprint sees) are `n` and `setting`; the failure it injects is not one.
    struct Squares {
        n: u64,
        setting: u64,
        made: AtomicUsize,
        fail_at: Option<u64>,
    }

    impl fmt::Debug for Squares {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "Squares {{ n: {}, setting: {} }}", self.n, self.setting)
        }
    }

    #[derive(Debug, thiserror::Error)]
    #[error("run {0} failed")]
    struct Failed(u64);

    impl Study for Squares {
        type Key = u64;
        type Row = (u64, f64);
        type Error = Failed;
        fn keys(&self) -> Vec<u64> {
            (0..self.n).collect()
        }
        fn run(&self, &k: &u64) -> Result<(u64, f64), Failed> {
            if self.fail_at == Some(k) {
                return Err(Failed(k));
            }
            self.made.fetch_add(1, Ordering::Relaxed);
            let x = if k == 3 {
                f64::NAN
            } else {
                (k * k) as f64 + 0.1
            };
            Ok((k, x))
        }
    }

    fn squares(n: u64, fail_at: Option<u64>) -> Squares {
        Squares {
            n,
            setting: 7,
            made: AtomicUsize::new(0),
            fail_at,
        }
    }

    fn bits(rows: &[(u64, f64)]) -> Vec<(u64, u64)> {
        rows.iter().map(|&(k, x)| (k, x.to_bits())).collect()
    }

    #[test]
    fn rows_come_in_key_order_and_the_checkpoint_goes_once_outputs_are_written() {
        let dir = tempfile::tempdir().expect("temp dir");
        let runner = Runner::new(Some(3), dir.path(), false).quiet();
        let done = runner.run(&squares(20, None)).expect("runs");
        assert_eq!(
            done.rows.iter().map(|r| r.0).collect::<Vec<_>>(),
            (0..20).collect::<Vec<_>>()
        );
        assert!(done.rows[3].1.is_nan());
        assert_eq!(done.resumed, 0);
        assert!(runner.checkpoint().expect("saved").exists());
        runner.finish().expect("removed");
        assert!(!runner.checkpoint().expect("saved").exists());
    }

    #[test]
    fn an_interrupted_study_resumes_with_the_same_bits_and_runs_only_what_is_left() {
        let dir = tempfile::tempdir().expect("temp dir");
        let whole = Runner::new(Some(2), dir.path().join("whole"), false).quiet();
        let expected = whole.run(&squares(30, None)).expect("runs").rows;

        // A first attempt fails at run 17; what it finished is saved.
        let out = dir.path().join("cut");
        let first = Runner::new(Some(1), &out, false).quiet();
        let err = first.run(&squares(30, Some(17))).expect_err("run 17 fails");
        assert!(err.to_string().contains("run 17 failed"), "{err}");
        // A record cut short, as if killed while writing it.
        let path = first.checkpoint().expect("saved");
        let mut f = OpenOptions::new().append(true).open(path).expect("open");
        f.write_all(&[40, 0, 0, 0, 1, 2]).expect("write");
        drop(f);

        // Without --resume: refused, nothing lost.
        let again = squares(30, None);
        let refused = first.run(&again).expect_err("needs --resume");
        assert!(matches!(refused, RunError::Unfinished { .. }), "{refused}");
        assert_eq!(again.made.load(Ordering::Relaxed), 0);

        let resumed = Runner::new(Some(2), &out, true).quiet();
        let study = squares(30, None);
        let done = resumed.run(&study).expect("resumes");
        assert!(done.resumed > 0, "something was saved before the failure");
        assert_eq!(done.resumed + study.made.load(Ordering::Relaxed), 30);
        assert_eq!(bits(&done.rows), bits(&expected));

        // Resuming a finished checkpoint makes nothing again.
        let study = squares(30, None);
        let done = resumed.run(&study).expect("resumes");
        assert_eq!((done.resumed, study.made.load(Ordering::Relaxed)), (30, 0));
        assert_eq!(bits(&done.rows), bits(&expected));
    }

    #[test]
    fn a_checkpoint_of_other_settings_or_a_damaged_one_is_refused() {
        let dir = tempfile::tempdir().expect("temp dir");
        let runner = Runner::new(Some(1), dir.path(), true).quiet();
        runner.run(&squares(5, None)).expect("runs");
        let mut other = squares(5, None);
        other.setting = 8;
        let err = runner.run(&other).expect_err("other settings");
        assert!(matches!(err, RunError::Foreign { .. }), "{err}");
        let err = runner.run(&squares(6, None)).expect_err("other run count");
        assert!(matches!(err, RunError::Foreign { .. }), "{err}");

        std::fs::write(
            runner.checkpoint().expect("saved"),
            b"not a checkpoint at all",
        )
        .expect("write");
        let err = runner.run(&squares(5, None)).expect_err("damaged");
        assert!(matches!(err, RunError::Damaged { .. }), "{err}");

        // A whole record that does not decode, and one naming a run out of range.
        let mut bytes = MAGIC.to_vec();
        bytes.extend_from_slice(&fingerprint(&squares(5, None)).to_le_bytes());
        bytes.extend_from_slice(&5u64.to_le_bytes());
        let mut bad = bytes.clone();
        bad.extend_from_slice(&[2, 0, 0, 0, 0xc1, 0xc1]);
        std::fs::write(runner.checkpoint().expect("saved"), &bad).expect("write");
        let err = runner.run(&squares(5, None)).expect_err("undecodable");
        assert!(matches!(err, RunError::Damaged { .. }), "{err}");
        let record = rmp_serde::to_vec(&(9u64, (9u64, 1.0f64))).expect("encodes");
        bytes.extend_from_slice(&(record.len() as u32).to_le_bytes());
        bytes.extend_from_slice(&record);
        std::fs::write(runner.checkpoint().expect("saved"), &bytes).expect("write");
        let err = runner.run(&squares(5, None)).expect_err("out of range");
        assert!(err.to_string().contains("run 9 of 5"), "{err}");
    }
}
