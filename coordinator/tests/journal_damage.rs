//! A journal damaged on disk is an input like any other: a real journal (a warehouse run
//! in-process, its inputs written through the coordinator's journal writer, as a live run
//! writes them) with random bytes flipped, cut at random lengths, emptied, replaced by text or
//! written in another format version. Reading it (`gapfleet replay`), replaying it and opening
//! it to go on (`gapfleet coordinator --state`) each give a clear error that names the file,
//! or read and replay it correctly; none panics. A journal whose newest commit is damaged is
//! refused at start-up and goes on with `--recover-state`: from the commit before, or, when
//! the run closed it cleanly (no commit before is kept), from the newest intact snapshot file
//! beside it.

use agent::model::Command;
use agent::planner::PlannerStack;
use agent::runtime::wire;
use agent::safety::Zone;
use coordinator::serve::journal::{
    self, End, Header, Integrity, IntentInput, Journal, JournalError, Recovery, ScenarioSource,
    TickInput, read, replay,
};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use world_sim::fleet::{Fleet, plan_all};

/// A folder named `name` in a temporary folder removed when it is dropped.
fn temp_dir(name: &str) -> (tempfile::TempDir, PathBuf) {
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let dir = tmp.path().join(name);
    std::fs::create_dir_all(&dir).expect("a folder");
    (tmp, dir)
}

fn source() -> ScenarioSource {
    ScenarioSource::builtin("warehouse", Some(3), Some(6), Some(5)).expect("built in")
}

/// Writes a journal of `ticks` ticks into `dir` as the coordinator writes one (inputs every
/// tick, fingerprints every 100, a snapshot every 30 s, the ledger, the end), committed in
/// several batches; returns the final fingerprint.
fn write_journal(dir: &Path, header: &Header, ticks: u64) -> u64 {
    let scenario = header.scenario.scenario().expect("a fleet site");
    let journal = Journal::create(dir, header).expect("a journal");
    let mut fleet = Fleet::new(&scenario).expect("a warehouse");
    fleet.share_intents = header.share_intents;
    fleet.set_traffic_policy(Some(Default::default()));
    let fleet = drive(&journal, &scenario, fleet, 0..ticks);
    journal.finish().expect("written");
    journal::fingerprint(&fleet)
}

/// Runs `fleet` through `ticks` with `pgp+orca` stacks under their layers, journaling each
/// tick through `journal` and ending it there; returns the fleet.
fn drive(
    journal: &Journal,
    scenario: &world_sim::scenario::Scenario,
    mut fleet: Fleet,
    ticks: std::ops::Range<u64>,
) -> Fleet {
    let sink = journal.sink();
    let n = fleet.robots();
    let mut stacks: Vec<PlannerStack> = (0..n)
        .map(|_| PlannerStack::new("pgp+orca".parse().expect("known")))
        .collect();
    let mut guards = world_sim::episode::guards(scenario, n);
    let mut commands = vec![Command::STOP; n];
    let snapshot_every = (journal::SNAPSHOT_EVERY_S / scenario.dt_s).round() as u64;
    for tick in ticks.clone() {
        // Which robots' layers held their commands back, journaled as the coordinator does.
        let mut layer_held = vec![false; n];
        plan_all(
            &mut fleet,
            &mut stacks,
            &mut commands,
            |i, stack, input| match &mut guards[i] {
                Some(g) => {
                    let (plan, guarded) = g.plan(stack, input);
                    layer_held[i] = matches!(guarded.zone, Zone::Protective | Zone::Yield);
                    plan
                }
                None => stack.plan(input),
            },
        );
        for (i, &held) in layer_held.iter().enumerate() {
            fleet.set_layer_held(i, held);
        }
        // Each robot's intent as the coordinator sets it: as it came over the wire.
        let mut intents = Vec::new();
        for i in 0..n {
            if let Some((stamp, trajectory)) = fleet.intent(i) {
                let trajectory = wire::samples_to_wire(trajectory);
                fleet.set_intent(i, stamp, wire::samples_from_wire(&trajectory));
                intents.push(IntentInput {
                    robot: i as u32,
                    stamp,
                    trajectory,
                });
            }
        }
        let mut input = TickInput {
            tick,
            held: Vec::new(),
            commands: commands
                .iter()
                .enumerate()
                .map(|(i, c)| (i as u32, wire::motion(*c)))
                .collect(),
            intents,
            layer_held: (0..n as u32).filter(|&i| layer_held[i as usize]).collect(),
            fingerprint: None,
            placed: Vec::new(),
        };
        let mut events = fleet.step(&commands);
        events.extend(fleet.dispatch());
        if (tick + 1).is_multiple_of(journal::FINGERPRINT_EVERY) {
            input.fingerprint = Some(journal::fingerprint(&fleet));
        }
        sink.tick(input, &events);
        if (tick + 1).is_multiple_of(snapshot_every) {
            sink.snapshot(tick + 1, fleet.clone());
        }
        // Several commits, as a live run makes (the writer commits every 200 ms).
        if tick % 150 == 149 {
            std::thread::sleep(std::time::Duration::from_millis(250));
        }
    }
    sink.end(End {
        ticks: ticks.end,
        fingerprint: journal::fingerprint(&fleet),
        tasks_done: (0..n).map(|i| fleet.tasks_done(i)).sum(),
        lost: 0,
    });
    fleet
}

/// A small deterministic generator (SplitMix64) for the damage.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n.max(1)
    }
}

/// What a damaged journal came to.
#[derive(Debug, Default)]
struct Outcomes {
    /// Read intact and replayed to the recorded end.
    replayed: u32,
    /// Read as its previous commit, and replayed that far.
    recovered: u32,
    /// Refused with an error naming the file.
    refused: u32,
    /// The errors' kinds (their text up to the first parenthesis), each once.
    messages: Vec<String>,
}

/// Reads, replays and opens (to go on) the journal in `dir`, none of which may panic; every
/// error must name the file. `print` is the intact run's final fingerprint.
fn exercise(dir: &Path, header: &Header, print: u64, outcomes: &mut Outcomes) {
    let file = journal::database(dir);
    let named = |e: &JournalError| {
        let text = e.to_string();
        assert!(
            text.contains(&file.display().to_string()) || text.starts_with("journal: "),
            "an error that names neither the file nor the journal: {text}"
        );
    };
    match read(dir) {
        Err(e) => {
            named(&e);
            let text = e.to_string();
            let kind = text
                .split(" (")
                .next()
                .unwrap_or(&text)
                .replace(&file.display().to_string(), "FILE");
            if !outcomes.messages.contains(&kind) {
                outcomes.messages.push(kind);
            }
            outcomes.refused += 1;
        }
        Ok(recorded) => {
            let ticks = recorded.ticks.len();
            match replay(&recorded, |_, _| {}) {
                Ok(replayed) => {
                    if recorded.integrity == Integrity::Intact && recorded.end.is_some() {
                        assert_eq!(replayed.fingerprint, print, "an intact journal replays");
                        outcomes.replayed += 1;
                    } else {
                        assert_eq!(replayed.ticks as usize, ticks);
                        outcomes.recovered += 1;
                    }
                }
                Err(e) => {
                    named(&e);
                    outcomes.refused += 1;
                }
            }
        }
    }
    // The coordinator's start on it: goes on, or refuses with what is wrong.
    match Journal::open(dir, header) {
        Ok((journal, _)) => {
            journal.finish().expect("closed");
        }
        Err(e) => named(&e),
    }
}

#[test]
fn damaged_journals_give_clear_errors_and_never_panic() {
    let header = Header::new("damage-test", source(), true, Some(Default::default()));
    let (_original_tmp, original) = temp_dir("original");
    let print = write_journal(&original, &header, 700);
    let bytes = std::fs::read(journal::database(&original)).expect("the journal");
    let recorded = read(&original).expect("intact");
    assert_eq!(recorded.integrity, Integrity::Intact);
    assert!(!recorded.snapshots.is_empty() && !recorded.tasks.is_empty());

    let (_trial_tmp, trial) = temp_dir("trial");
    // A copy as it was written reads and replays as the original does.
    std::fs::write(journal::database(&trial), &bytes).expect("written");
    let mut intact = Outcomes::default();
    exercise(&trial, &header, print, &mut intact);
    assert_eq!(intact.replayed, 1, "{intact:?}");

    let mut rng = Rng(49);
    let mut outcomes = Outcomes::default();
    let mut panics = Vec::new();
    // 200 journals with 1–50 bytes flipped anywhere, then 60 cut at random lengths.
    for k in 0..260 {
        let mut damaged = bytes.clone();
        let what = if k < 200 {
            let flips = 1 + rng.below(50);
            for _ in 0..flips {
                let at = rng.below(damaged.len() as u64) as usize;
                damaged[at] ^= 1 << rng.below(8);
            }
            format!("{flips} bytes flipped")
        } else {
            let len = rng.below(damaged.len() as u64) as usize;
            damaged.truncate(len);
            format!("cut to {len} bytes")
        };
        let _ = std::fs::remove_dir_all(&trial);
        std::fs::create_dir_all(&trial).expect("a folder");
        std::fs::write(journal::database(&trial), &damaged).expect("written");
        let run = catch_unwind(AssertUnwindSafe(|| {
            exercise(&trial, &header, print, &mut outcomes)
        }));
        if run.is_err() {
            panics.push(format!("trial {k}: {what}"));
        }
    }
    println!("260 damaged journals: {outcomes:?}");
    assert!(panics.is_empty(), "panicked: {panics:?}");
    assert_eq!(
        outcomes.replayed + outcomes.recovered + outcomes.refused,
        260
    );
    // Damage was found: most of the file is the run's data, each page under a checksum.
    assert!(outcomes.refused > 100, "{outcomes:?}");
}

#[test]
fn an_empty_file_a_text_file_and_an_older_format_are_named_as_such() {
    let header = Header::new("damage-test", source(), true, Some(Default::default()));
    let (_tmp, dir) = temp_dir("kinds");
    let file = journal::database(&dir);
    let error = |dir: &Path| read(dir).expect_err("not a journal").to_string();

    std::fs::write(&file, b"").expect("written");
    let e = error(&dir);
    assert!(
        e.contains(&file.display().to_string()) && e.contains("empty"),
        "{e}"
    );
    assert!(Journal::open(&dir, &header).is_err());

    std::fs::write(&file, "tick,robot,command\n0,1,stop\n").expect("written");
    let e = error(&dir);
    assert!(e.contains("not a journal"), "{e}");
    assert!(Journal::open(&dir, &header).is_err());

    std::fs::remove_file(&file).expect("removed");
    let mut older = header.clone();
    older.format = 1;
    write_journal(&dir, &older, 20);
    let e = error(&dir);
    assert!(e.contains("format 1") && e.contains("reads 3"), "{e}");
    let Err(e) = Journal::open(&dir, &header) else {
        panic!("an older journal is not gone on with");
    };
    assert!(e.to_string().contains("format 1"), "{e}");
}

/// A journal of 700 ticks in a new folder `name`, closed cleanly, then damaged in its newest
/// commit: nothing of it can be trusted (the store keeps no earlier commit past a clean
/// close). Returns the temporary folder (removed when dropped), the journal's folder in it,
/// the intact journal as read before the damage, and the damaged bytes.
fn damaged_after_a_clean_close(
    name: &str,
    header: &Header,
) -> (tempfile::TempDir, PathBuf, journal::Recorded, Vec<u8>) {
    let (tmp, dir) = temp_dir(name);
    write_journal(&dir, header, 700);
    let file = journal::database(&dir);
    let before = std::fs::read(&file).expect("the journal");
    // One more commit, as a restart makes (the header again, the end record taken out).
    let (journal, _) = Journal::open(&dir, header).expect("goes on");
    journal.finish().expect("closed");
    let intact = read(&dir).expect("intact");
    let after = std::fs::read(&file).expect("the journal");
    // A byte of a page that commit wrote (past the file's header page).
    let at = (4096..after.len())
        .find(|&i| before.get(i) != Some(&after[i]))
        .expect("the commit wrote a page");
    let mut damaged = after.clone();
    damaged[at] ^= 0x55;
    std::fs::write(&file, &damaged).expect("written");

    let e = read(&dir).expect_err("damaged").to_string();
    assert!(
        e.contains(&file.display().to_string()) && e.contains("damaged on disk"),
        "{e}"
    );
    // Reading never writes the file.
    assert_eq!(std::fs::read(&file).expect("the file"), damaged);
    let Err(e) = Journal::open(&dir, header) else {
        panic!("a damaged journal is not gone on with");
    };
    let e = e.to_string();
    assert!(e.contains(&file.display().to_string()), "{e}");
    (tmp, dir, intact, damaged)
}

/// `replay` and the coordinator's start name the damaged file and what is wrong;
/// `--recover-state` (`journal::recover`) keeps it beside a new journal that begins at the
/// newest intact snapshot file. The run goes on from there exactly where the damaged one was
/// then, and the new journal replays bit for bit from its start.
#[test]
fn a_damaged_journal_goes_on_from_the_newest_intact_snapshot_file() {
    let header = Header::new("damage-test", source(), true, Some(Default::default()));
    let (_tmp, dir, intact, damaged) = damaged_after_a_clean_close("snapshot", &header);
    // Snapshots every 300 ticks: the files of 300 and 600 are beside the journal.
    let newest = journal::snapshot_files::newest_intact(&dir).expect("snapshot files");
    assert_eq!(newest.ticks, 600);
    let at_600 = intact.ticks[599].fingerprint.expect("fingerprinted");

    let recovery = journal::recover(&dir).expect("recovered");
    let Recovery::FromSnapshot {
        kept,
        snapshot,
        ticks,
        what,
    } = recovery
    else {
        panic!("{recovery:?}");
    };
    assert_eq!((ticks, &snapshot), (600, &newest.path));
    assert!(what.contains("damaged on disk"), "{what}");
    assert_eq!(std::fs::read(&kept).expect("kept"), damaged);

    // The coordinator's restart: the run resumes at tick 600 as it stood then.
    let (journal, recorded) = Journal::open(&dir, &header).expect("the new journal");
    let recorded = recorded.expect("it begins at the snapshot");
    assert_eq!((recorded.first_tick(), recorded.ticks_run()), (600, 600));
    assert!(recorded.events[0].event.contains("snapshot of tick 600"));
    let resumed = journal::resume(&recorded).expect("resumes");
    assert_eq!((resumed.from, resumed.ticks), (600, 600));
    assert_eq!(journal::fingerprint(&resumed.fleet), at_600);

    // It goes on for 100 ticks; the new journal replays from its start, checked.
    let scenario = header.scenario.scenario().expect("a fleet site");
    let fleet = drive(&journal, &scenario, resumed.fleet, 600..700);
    journal.finish().expect("written");
    let recorded = read(&dir).expect("the new journal");
    assert_eq!(recorded.integrity, Integrity::Intact);
    assert_eq!((recorded.first_tick(), recorded.ticks.len()), (600, 100));
    let replayed = replay(&recorded, |_, _| {}).expect("replays");
    assert_eq!(
        (replayed.from, replayed.ticks, replayed.checked),
        (600, 700, 1)
    );
    assert_eq!(replayed.fingerprint, journal::fingerprint(&fleet));
    assert_eq!(replayed.tasks_checked, recorded.tasks.len() as u64);
    // The damaged file stays where it was put.
    assert_eq!(std::fs::read(&kept).expect("kept"), damaged);
}

/// When the newest snapshot file is damaged too, the one before it is taken.
#[test]
fn a_damaged_snapshot_file_is_passed_over_for_the_one_before() {
    let header = Header::new("damage-test", source(), true, Some(Default::default()));
    let (_tmp, dir, intact, _) = damaged_after_a_clean_close("snapshot-older", &header);
    let newest = journal::snapshot_files::newest_intact(&dir).expect("snapshot files");
    let mut bytes = std::fs::read(&newest.path).expect("the file");
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0x01;
    std::fs::write(&newest.path, bytes).expect("written");
    let recovery = journal::recover(&dir).expect("recovered");
    assert!(
        matches!(recovery, Recovery::FromSnapshot { ticks: 300, .. }),
        "{recovery:?}"
    );
    let (journal, recorded) = Journal::open(&dir, &header).expect("the new journal");
    let resumed = journal::resume(&recorded.expect("begun")).expect("resumes");
    assert_eq!(resumed.ticks, 300);
    assert_eq!(
        journal::fingerprint(&resumed.fleet),
        intact.ticks[299].fingerprint.expect("fingerprinted")
    );
    journal.finish().expect("closed");
}

/// With no snapshot file beside it either, the damaged journal is kept beside a new one that
/// the run begins anew.
#[test]
fn a_damaged_journal_without_snapshot_files_is_kept_and_a_new_one_begun_beside_it() {
    let header = Header::new("damage-test", source(), true, Some(Default::default()));
    let (_tmp, dir, _, damaged) = damaged_after_a_clean_close("recover", &header);
    std::fs::remove_dir_all(journal::snapshot_files::folder(&dir)).expect("removed");
    let recovery = journal::recover(&dir).expect("recovered");
    let Recovery::Kept { kept, what } = recovery else {
        panic!("{recovery:?}");
    };
    assert!(what.contains("damaged on disk"), "{what}");
    assert_eq!(std::fs::read(&kept).expect("kept"), damaged);
    let (journal, resumed) = Journal::open(&dir, &header).expect("a new journal");
    assert!(resumed.is_none());
    journal.finish().expect("closed");
    assert_eq!(
        read(&dir).expect("the new journal").integrity,
        Integrity::Intact
    );
    assert_eq!(journal::recover(&dir).expect("intact"), Recovery::Intact);
    // The damaged file stays where it was put.
    assert_eq!(std::fs::read(&kept).expect("kept"), damaged);
}

/// A run on a floor plan given by path keeps the map's fingerprint: rebuilt on the same files
/// it is the same scenario; with the map changed since (its thresholds edited), rebuilding is
/// refused, naming the map.
#[test]
fn a_journal_on_a_floor_plan_refuses_a_changed_map() {
    let (_tmp, dir) = temp_dir("site");
    let sample =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../world-sim/maps/aws-small-warehouse");
    for f in ["map.yaml", "map_rotated.png"] {
        std::fs::copy(sample.join(f), dir.join(f)).expect("copied");
    }
    let builtin = world_sim::scenario::BUILTIN
        .iter()
        .find(|(n, _)| *n == "aws-small-warehouse")
        .expect("built in")
        .1;
    let toml = builtin.replace("map = \"aws-small-warehouse\"", "map = \"map.yaml\"");
    let path = dir.join("site.toml");
    std::fs::write(&path, &toml).expect("written");
    let name = path.display().to_string();
    let scenario = world_sim::scenario::Scenario::from_toml(&toml, &name).expect("loads");
    let fingerprint = scenario
        .floor_plan
        .as_ref()
        .and_then(|f| f.plan.as_ref())
        .map(|p| p.fingerprint);
    let source = ScenarioSource {
        name,
        toml,
        robots: Some(3),
        humans: Some(4),
        seed: Some(2),
        no_safety: false,
        map_fingerprint: fingerprint,
    };
    let rebuilt = source.scenario().expect("the same map");
    assert_eq!(rebuilt.fleet_size(), Some((3, 4)));
    let yaml = std::fs::read_to_string(dir.join("map.yaml")).expect("yaml");
    std::fs::write(dir.join("map.yaml"), yaml.replace("0.196", "0.2")).expect("edited");
    let err = source.scenario().expect_err("another map").to_string();
    assert!(
        err.contains("is not the one the run had") && err.contains("map.yaml"),
        "{err}"
    );
}
