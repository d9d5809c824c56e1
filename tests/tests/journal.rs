//! A live run's journal (`--state DIR`) replays bit for bit: a demo over Zenoh (a coordinator
//! and its agents, each with its own session, planning on whatever observations arrived when)
//! writes its inputs; `journal::replay` re-runs them in-process and meets every recorded
//! fingerprint, the snapshot the coordinator took at 30 s (byte for byte: every robot, person,
//! random stream, metrics accumulator, intent and the traffic policy's state) and the final
//! fingerprint; a restart's `journal::resume` restores that snapshot and re-runs only the 100
//! ticks after it, to the same end state. The run's traffic policy is not the default one: the
//! journal's header carries its parameters to the replay. A journal with one command or one
//! intent changed leaves the recorded run, and the replay says at which tick.

use coordinator::serve::demo::{DemoOptions, Transport, run_demo};
use coordinator::serve::journal::{Header, Journal, ScenarioSource, read, replay, resume};

#[test]
fn a_recorded_demo_replays_bit_for_bit() {
    let source =
        ScenarioSource::builtin("warehouse", Some(4), Some(20), Some(3)).expect("built in");
    let scenario = source.scenario().expect("a fleet site");
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let dir = tmp.path().join("demo");
    let policy = world_sim::traffic_policy::PolicyParams::default()
        .with_overrides("people_route_weight_m=3,retreat_after_s=6")
        .expect("known parameters");
    let journal = Journal::create(
        &dir,
        &Header::new("journal-test", source, true, Some(policy)),
    )
    .expect("a journal");
    let options = DemoOptions {
        scenario,
        planner: "pgp+orca".parse().expect("a planner"),
        seconds: 40.0,
        speed: 4.0,
        keys: gapfleet_tests::keys("journal-test"),
        listen: None,
        transport: Transport::Tcp,
        journal: Some(journal.sink()),
        share_intents: true,
        traffic_policy: Some(policy),
        sinks: dashboards::Sinks::default(),
        round_trips: None,
        ros: false,
    };
    let rt = gapfleet_tests::runtime();
    let report = rt
        .block_on(run_demo(options, std::future::pending(), |_, _| {}, |_| {}))
        .expect("the demo runs");
    let written = journal.finish().expect("the journal is written");
    let recorded = read(&dir).expect("the journal reads back");
    assert_eq!(recorded.header.policy(), Some(policy));
    let end = recorded.end.clone().expect("a clean end");
    println!(
        "demo: {} ticks, {} tasks, {} events; journal: {written} ticks",
        report.status.tick,
        report.status.tasks_done,
        recorded.events.len()
    );
    assert_eq!(written, report.status.tick);
    assert_eq!(end.ticks, report.status.tick);
    assert_eq!(end.lost, 0);
    assert!(
        recorded
            .events
            .iter()
            .filter(|e| e.event.starts_with("Joined"))
            .count()
            == 4,
        "every agent's join is in the event log"
    );
    // The robots moved: there is something to replay.
    assert!(recorded.ticks.iter().any(|t| !t.commands.is_empty()));

    let replayed = replay(&recorded, |_, _| {}).expect("the replay meets every fingerprint");
    assert_eq!(replayed.fingerprint, end.fingerprint);
    assert_eq!(replayed.ticks, end.ticks);
    assert_eq!(replayed.tasks_done, end.tasks_done);
    assert_eq!(replayed.tasks_done, report.status.tasks_done);
    assert!(replayed.checked >= end.ticks / 100);
    // The live fleet's snapshot at 30 s is the replayed fleet's then, byte for byte.
    let taken: Vec<u64> = recorded.snapshots.iter().map(|(at, _)| *at).collect();
    println!(
        "snapshots at ticks {taken:?} ({} bytes); {} intents journaled",
        recorded
            .snapshots
            .iter()
            .map(|(_, b)| b.len())
            .sum::<usize>(),
        recorded
            .ticks
            .iter()
            .map(|t| t.intents.len())
            .sum::<usize>()
    );
    assert_eq!(taken, [300]);
    // The task ledger: ids 0, 1, … in order of assignment, each line rebuilt by the replay.
    println!("ledger: {:?}", recorded.tasks);
    assert!(recorded.tasks.len() >= 4, "every robot got a task");
    for (k, line) in recorded.tasks.iter().enumerate() {
        assert_eq!(line.task, k as u64);
    }
    let done_in_ledger = recorded
        .tasks
        .iter()
        .filter(|t| t.done_tick.is_some())
        .count();
    assert_eq!(done_in_ledger as u64, end.tasks_done);
    assert_eq!(replayed.tasks_checked, recorded.tasks.len() as u64);
    assert_eq!(replayed.snapshots_checked, 1);
    assert!(recorded.ticks.iter().any(|t| !t.intents.is_empty()));
    // A restart resumes from it: 100 ticks re-run, not 400, to the same end.
    let resumed = resume(&recorded).expect("resumes from the snapshot");
    assert_eq!(resumed.from, 300);
    assert_eq!(resumed.ticks, end.ticks);
    assert_eq!(resumed.fingerprint, end.fingerprint);
    assert_eq!(resumed.tasks_done, end.tasks_done);
    assert!(
        resumed.fleet.snapshot() == replayed.fleet.snapshot(),
        "the resumed fleet ends in the replayed fleet's state"
    );
    for (i, m) in report.fleet_metrics.iter().enumerate() {
        let r = replayed.fleet.metrics(i);
        assert_eq!(
            r.path_length_m.to_bits(),
            m.path_length_m.to_bits(),
            "robot {i}'s path"
        );
        assert_eq!(r.svr.to_bits(), m.svr.to_bits(), "robot {i}'s SVR");
    }

    // One command changed: the replay leaves the run and says where.
    let mut tampered = recorded.clone();
    let k = tampered
        .ticks
        .iter()
        .position(|t| !t.commands.is_empty())
        .expect("a moving tick");
    tampered.ticks[k].commands[0].1 = schemas::Motion::Velocity(schemas::P2(0.7, 0.0));
    let err = replay(&tampered, |_, _| {}).expect_err("a changed command shows");
    println!("tampered at tick {k}: {err}");
    assert!(
        err.to_string().contains("left the recorded run") || err.to_string().contains("ended on")
    );

    // The last intent before the snapshot changed (it is still in the fleet's table then):
    // the snapshot check shows it.
    let mut tampered = recorded.clone();
    let (k, j) = tampered
        .ticks
        .iter()
        .take(300)
        .enumerate()
        .rev()
        .find_map(|(k, t)| {
            t.intents
                .iter()
                .rposition(|i| i.trajectory.len() > 1)
                .map(|j| (k, j))
        })
        .expect("an intent before the snapshot");
    tampered.ticks[k].intents[j].trajectory[1].p.0 += 0.01;
    let err = replay(&tampered, |_, _| {}).expect_err("a changed intent shows");
    println!("intent tampered at tick {k}: {err}");
    assert!(err.to_string().contains("snapshot taken then"), "{err}");
}
