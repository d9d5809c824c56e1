//! The fleet as separate processes: the coordinator on a router session (as `gapfleet
//! coordinator` runs it for small fleets) and ten `gapfleet-agent` processes connecting to it,
//! all on loopback with multicast scouting off. One run walks through the life of a fleet:
//!
//! 1. all ten agents join and robots complete tasks;
//! 2. one agent is killed (SIGKILL): the coordinator notices within 1 s, its robot stops and
//!    is flagged, the others keep completing tasks;
//! 3. the agent is restarted: it rejoins and its robot gets work again;
//! 4. garbage on an agent's observation key: the agent counts it and keeps planning;
//! 5. one agent gets SIGTERM: it exits cleanly and the coordinator classes it as a leave;
//! 6. the coordinator stops: every agent still running sends a safe stop within 0.5 s;
//! 7. SIGTERM: every agent exits cleanly.

use coordinator::serve::{CoordinatorConfig, Event, Status, run_coordinator};
use fleet_net::{Role, loopback};
use gapfleet_tests::{AgentProcess, free_endpoint};
use schemas::{AgentInfo, Channel, CommandMsg, Keys, decode};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use world_sim::fleet::Fleet;
use world_sim::scenario::Scenario;

const ROBOTS: u32 = 10;
/// The agent that leaves cleanly in step 5.
const LEAVER: u32 = 7;
const SITE: &str = "proc-test";

/// What the coordinator showed at one wall second.
#[derive(Debug, Clone)]
struct Snapshot {
    status: Status,
    speeds: Vec<f64>,
    held: Vec<bool>,
    busy: Vec<bool>,
}

#[test]
fn ten_agent_processes_survive_kills_restarts_garbage_and_a_coordinator_stop() {
    let rt = gapfleet_tests::runtime();
    let endpoint = free_endpoint();
    let keys = Keys::new(SITE).expect("valid site");

    // The router (as zenohd would be) and the test's eyes on the fleet.
    let router = rt
        .block_on(async {
            zenoh::open(
                loopback(Role::Router, std::slice::from_ref(&endpoint), &[]).expect("config"),
            )
            .await
        })
        .expect("router session");
    let info_sub = rt
        .block_on(async {
            // A ring keeps the newest heartbeats; an undrained FIFO would stall the router.
            router
                .declare_subscriber(keys.robot(5, Channel::Info))
                .with(zenoh::handlers::RingChannel::new(4))
                .await
        })
        .expect("info subscriber");

    // The coordinator, 4x real time.
    let mut scenario = Scenario::builtin("warehouse").expect("valid");
    let w = scenario.warehouse.as_mut().expect("warehouse");
    w.robots = ROBOTS as usize;
    w.humans = 20;
    let fleet = Fleet::new(&scenario).expect("warehouse");
    let (event_tx, events) = mpsc::channel();
    let (snap_tx, snaps) = mpsc::channel::<Snapshot>();
    let (stop_tx, stop_rx) = tokio::sync::oneshot::channel::<()>();
    let mut config = CoordinatorConfig::new(gapfleet_tests::keys(SITE));
    config.speed = 4.0;
    config.events = Some(event_tx);
    // The coordinator runs on the router's session; stopping it (step 5) ends the coordinator
    // while the router, like a zenohd would, stays up to carry the agents' safe stops.
    let session = router.clone();
    let coordinator = rt.spawn(async move {
        run_coordinator(
            &session,
            fleet,
            config,
            async {
                let _ = stop_rx.await;
            },
            &mut |status: &Status, fleet: &Fleet| {
                let _ = snap_tx.send(Snapshot {
                    status: status.clone(),
                    speeds: fleet
                        .world
                        .robots
                        .iter()
                        .map(|r| r.state.velocity.norm())
                        .collect(),
                    held: (0..fleet.robots()).map(|i| fleet.is_held(i)).collect(),
                    busy: (0..fleet.robots())
                        .map(|i| fleet.job(i).is_some())
                        .collect(),
                });
            },
        )
        .await
        .expect("coordinator runs")
    });

    // 1. Ten agent processes join and complete tasks.
    let mut agents: Vec<AgentProcess> = (0..ROBOTS)
        .map(|id| AgentProcess::spawn(id, &endpoint, SITE, "pgp+orca"))
        .collect();
    let mut joined = std::collections::BTreeSet::new();
    gapfleet_tests::recv_until(&events, Duration::from_secs(30), |(_, e)| {
        if let Event::Joined(id) = e {
            joined.insert(*id);
        }
        joined.len() == ROBOTS as usize
    })
    .unwrap_or_else(|| panic!("only {joined:?} joined"));
    let mut done = 0;
    gapfleet_tests::recv_until(&events, Duration::from_secs(90), |(_, e)| {
        done += u32::from(matches!(e, Event::TaskDone { .. }));
        done >= 3
    })
    .unwrap_or_else(|| {
        let snap = newest(&snaps);
        panic!(
            "robots completed {done} tasks; coordinator: {}; agent 5: {:?}",
            coordinator::serve::demo::status_line(&snap.status),
            latest_info(&info_sub)
        )
    });

    // 2. Kill agent 3: noticed within 1 s, robot stops and is flagged, others carry on.
    let killed_at = Instant::now();
    agents[3].signal("KILL");
    let (noticed_at, event) =
        gapfleet_tests::recv_until(&events, Duration::from_secs(5), |(_, e)| {
            matches!(e, Event::Crashed(3) | Event::Left(3))
        })
        .expect("the coordinator notices the killed agent");
    let delay = noticed_at.duration_since(killed_at);
    println!("killed agent 3 noticed after {delay:?} as {event:?}");
    assert_eq!(event, Event::Crashed(3), "no safe stop came first: a crash");
    assert!(delay <= Duration::from_secs(1), "noticed after {delay:?}");
    std::thread::sleep(Duration::from_millis(1500));
    let snap = newest(&snaps);
    assert!(snap.held[3], "robot 3 is held");
    assert!(snap.status.flagged.contains(&3), "robot 3 is flagged");
    assert!(
        snap.speeds[3] < 1e-6,
        "robot 3 stopped (speed {})",
        snap.speeds[3]
    );
    let others = gapfleet_tests::recv_until(
        &events,
        Duration::from_secs(90),
        |(_, e)| matches!(e, Event::TaskDone { robot, .. } if *robot != 3),
    );
    assert!(
        others.is_some(),
        "the rest of the fleet keeps completing tasks"
    );

    // 3. Restart agent 3: it rejoins and its robot works again.
    agents[3] = AgentProcess::spawn(3, &endpoint, SITE, "pgp+orca");
    gapfleet_tests::recv_until(&events, Duration::from_secs(30), |(_, e)| {
        *e == Event::Joined(3)
    })
    .expect("agent 3 rejoins");
    std::thread::sleep(Duration::from_millis(1500));
    let snap = newest(&snaps);
    assert!(!snap.held[3] && !snap.status.flagged.contains(&3));
    assert!(snap.busy[3], "robot 3 has a task again");

    // 4. Garbage on agent 5's observation key: counted, and it keeps planning.
    let plans_before = latest_info(&info_sub).map_or(0, |i| i.plans);
    for k in 0..50u8 {
        let garbage: Vec<u8> = if k % 2 == 0 {
            vec![0xc1; 7]
        } else {
            b"\x81\xa1v\x01".to_vec()
        };
        // Blocking, not zenoh's default of dropping on a full queue: all 50 must arrive for
        // the count below to be exact, on a machine the fleet keeps busy.
        rt.block_on(async {
            router
                .put(keys.robot(5, Channel::Obs), garbage)
                .congestion_control(zenoh::qos::CongestionControl::Block)
                .await
        })
        .expect("put");
    }
    let mut seen = None;
    let info = gapfleet_tests::wait_until(Duration::from_secs(5), || {
        let info = latest_info(&info_sub)?;
        if info.rejected >= 50 && info.plans > plans_before {
            return Some(info);
        }
        seen = Some(info);
        None
    })
    .unwrap_or_else(|| {
        panic!("agent 5's newest report after 5 s: {seen:?} (planned {plans_before} before)")
    });
    println!("agent 5 after garbage: {info:?}");
    assert!(agents[5].running(), "agent 5 survived the garbage");

    // 5. SIGTERM agent 7 while the coordinator runs: it safe-stops, withdraws its token and
    //    exits, and the coordinator classes that as a clean leave, not a crash.
    agents[LEAVER as usize].signal("TERM");
    let (_, event) = gapfleet_tests::recv_until(&events, Duration::from_secs(5), |(_, e)| {
        matches!(e, Event::Crashed(LEAVER) | Event::Left(LEAVER))
    })
    .expect("the coordinator notices agent 7 leaving");
    assert_eq!(event, Event::Left(LEAVER), "a clean exit is a leave");
    assert!(
        agents[LEAVER as usize].wait_success(),
        "agent 7 exits cleanly on SIGTERM"
    );

    // 6. Stop the coordinator: every agent still running safe-stops within 0.5 s.
    let cmd_sub = rt
        .block_on(async {
            router
                .declare_subscriber(keys.every_robot(Channel::Cmd))
                .with(zenoh::handlers::RingChannel::new(4096))
                .await
        })
        .expect("command subscriber");
    let stopped_at = Instant::now();
    stop_tx.send(()).expect("coordinator still running");
    let status = rt.block_on(coordinator).expect("coordinator task");
    let mut safe = std::collections::BTreeMap::new();
    let running = ROBOTS as usize - 1;
    while safe.len() < running && stopped_at.elapsed() < Duration::from_secs(3) {
        if let Ok(Some(sample)) = cmd_sub.try_recv() {
            if let Ok(cmd) = decode::<CommandMsg>(&sample.payload().to_bytes())
                && cmd.safe_stop
                && cmd.robot_id != LEAVER
            {
                safe.entry(cmd.robot_id).or_insert(stopped_at.elapsed());
            }
        } else {
            std::thread::sleep(Duration::from_millis(2));
        }
    }
    println!("safe stops after the coordinator stopped: {safe:?}");
    assert_eq!(safe.len(), running, "every agent safe-stops: {safe:?}");
    for (robot, after) in &safe {
        assert!(
            *after <= Duration::from_millis(500),
            "agent {robot} safe-stopped after {after:?}"
        );
    }
    println!(
        "coordinator: {} ticks, {} tasks, round trip p50 {:.2} ms p99 {:.2} ms, {} stale-command ticks",
        status.tick,
        status.tasks_done,
        status.round_trip_ms.0,
        status.round_trip_ms.1,
        status.stale_commands
    );

    // 7. SIGTERM: clean exits.
    agents.remove(LEAVER as usize);
    for a in &agents {
        a.signal("TERM");
    }
    for a in &mut agents {
        let id = a.robot_id;
        assert!(a.wait_success(), "agent {id} exits cleanly on SIGTERM");
    }
    rt.block_on(async { router.close().await })
        .expect("router closes");
}

/// The newest snapshot: what is queued, else the next one.
fn newest(snaps: &mpsc::Receiver<Snapshot>) -> Snapshot {
    let mut last = None;
    while let Ok(s) = snaps.try_recv() {
        last = Some(s);
    }
    last.or_else(|| snaps.recv_timeout(Duration::from_secs(3)).ok())
        .expect("the coordinator reports every wall second")
}

/// The newest heartbeat of agent 5 received so far.
fn latest_info(
    sub: &zenoh::pubsub::Subscriber<zenoh::handlers::RingChannelHandler<zenoh::sample::Sample>>,
) -> Option<AgentInfo> {
    let mut latest = None;
    while let Ok(Some(sample)) = sub.try_recv() {
        if let Ok(info) = decode::<AgentInfo>(&sample.payload().to_bytes()) {
            latest = Some(info);
        }
    }
    latest
}
