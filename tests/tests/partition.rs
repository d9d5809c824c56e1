//! A network partition between one agent and the router, on loopback: the agent's session goes
//! through a TCP proxy that the test pauses (nothing is forwarded, nothing is lost: the bytes
//! wait, as on a dead Wi-Fi link) and later lets through again. Zenoh's lease is 3 s
//! (`fleet_net::LEASE_MS`).
//!
//! - the agent safe-stops within 0.5 s (its observations stopped);
//! - the coordinator stops the robot once more than 3 observations newer than the one its
//!   newest command answers have gone out: 4 or 5 ticks after the last tick before the cut
//!   (5 when the answer to that tick's observation came back before the cut, 4 when it was on
//!   its way), held in ticks, not in wall time;
//! - the robot is flagged (crashed) once the lease has run out;
//! - when the link heals, the agent reconnects by itself and the robot drives again, and
//!   nothing is counted twice.

use agent::runtime::{AgentConfig, AgentCounters, run_agent};
use coordinator::serve::{CoordinatorConfig, Event, Observer, Status, run_coordinator};
use fleet_net::{Role, loopback};
use gapfleet_tests::free_endpoint;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use world_sim::fleet::{Fleet, FleetEvent};

const SITE: &str = "partition-test";

/// Forwards `from` to `to` while `open`; while not, reads nothing (the bytes wait).
async fn pump(
    mut from: tokio::net::tcp::OwnedReadHalf,
    mut to: tokio::net::tcp::OwnedWriteHalf,
    open: Arc<AtomicBool>,
) {
    let mut buf = vec![0u8; 64 * 1024];
    loop {
        while !open.load(Ordering::Relaxed) {
            tokio::time::sleep(Duration::from_millis(5)).await;
        }
        match from.read(&mut buf).await {
            Ok(0) | Err(_) => break,
            Ok(n) => {
                // Bytes read while the cut came wait for the link too.
                while !open.load(Ordering::Relaxed) {
                    tokio::time::sleep(Duration::from_millis(5)).await;
                }
                if to.write_all(&buf[..n]).await.is_err() {
                    break;
                }
            }
        }
    }
    let _ = to.shutdown().await;
}

/// A TCP proxy on a free loopback port to `upstream` (host:port); returns its endpoint.
async fn proxy(upstream: String, open: Arc<AtomicBool>) -> String {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0")
        .await
        .expect("a port");
    let endpoint = format!("tcp/{}", listener.local_addr().expect("an address"));
    tokio::spawn(async move {
        while let Ok((down, _)) = listener.accept().await {
            let Ok(up) = tokio::net::TcpStream::connect(&upstream).await else {
                continue;
            };
            let (down_r, down_w) = down.into_split();
            let (up_r, up_w) = up.into_split();
            tokio::spawn(pump(down_r, up_w, open.clone()));
            tokio::spawn(pump(up_r, down_w, open.clone()));
        }
    });
    endpoint
}

/// What the coordinator did at one tick, for robot 0.
struct TickSeen {
    at: Instant,
    /// The coordinator's tick count after it.
    tick: u64,
    stale: u64,
    speed: f64,
    events: Vec<Event>,
}

struct Watch {
    tx: mpsc::Sender<TickSeen>,
    seen_events: u64,
}

impl Observer for Watch {
    fn tick(&mut self, fleet: &Fleet, status: &Status, _: &[FleetEvent]) {
        let events = status.events_since(self.seen_events).to_vec();
        self.seen_events = status.events_total();
        let _ = self.tx.send(TickSeen {
            at: Instant::now(),
            tick: status.tick,
            stale: status.stale_per_robot.first().copied().unwrap_or(0),
            speed: fleet.world.robots[0].state.velocity.norm(),
            events,
        });
    }
}

#[test]
fn a_partitioned_agent_stops_is_flagged_and_comes_back() {
    let rt = gapfleet_tests::runtime();
    let endpoint = free_endpoint();
    let open = Arc::new(AtomicBool::new(true));
    let (router, via_proxy) = rt.block_on(async {
        let router = zenoh::open(
            loopback(Role::Router, std::slice::from_ref(&endpoint), &[]).expect("config"),
        )
        .await
        .expect("router");
        let via = proxy(endpoint.trim_start_matches("tcp/").to_owned(), open.clone()).await;
        (router, via)
    });

    let scenario = gapfleet_tests::warehouse(2, 0);
    let fleet = Fleet::new(&scenario).expect("a warehouse");
    let mut config = CoordinatorConfig::new(gapfleet_tests::keys(SITE));
    config.seconds = Some(25.0);
    let (tx, ticks) = mpsc::channel();
    let session = router.clone();
    let coordinator = rt.spawn(async move {
        let mut watch = Watch { tx, seen_events: 0 };
        run_coordinator(&session, fleet, config, std::future::pending(), &mut watch)
            .await
            .expect("the coordinator runs")
    });
    // Robot 0's agent goes through the proxy, robot 1's straight to the router.
    let counters = Arc::new(AgentCounters::default());
    let (stop_tx, stop_rx) = tokio::sync::watch::channel(false);
    let mut agents = Vec::new();
    for (id, at) in [(0u32, via_proxy.clone()), (1, endpoint.clone())] {
        let c = if id == 0 {
            counters.clone()
        } else {
            Arc::new(AgentCounters::default())
        };
        let mut stop = stop_rx.clone();
        agents.push(rt.spawn(async move {
            let session = zenoh::open(loopback(Role::Client, &[], &[at]).expect("config"))
                .await
                .expect("an agent session");
            let config = AgentConfig::new(
                id,
                gapfleet_tests::keys(SITE),
                "pgp+orca".parse().expect("a planner"),
            );
            run_agent(&session, config, c, async move {
                let _ = stop.wait_for(|s| *s).await;
            })
            .await
            .expect("the agent runs");
            let _ = session.close().await;
        }));
    }

    // Robot 0 drives.
    let mut all: Vec<TickSeen> = Vec::new();
    let wait = |all: &mut Vec<TickSeen>, timeout: Duration, done: &dyn Fn(&TickSeen) -> bool| {
        let deadline = Instant::now() + timeout;
        while let Some(left) = deadline.checked_duration_since(Instant::now()) {
            match ticks.recv_timeout(left) {
                Ok(t) => {
                    let hit = done(&t);
                    all.push(t);
                    if hit {
                        return all.last().map(|t| t.at);
                    }
                }
                Err(_) => break,
            }
        }
        None
    };
    wait(&mut all, Duration::from_secs(20), &|t| t.speed > 0.2)
        .expect("robot 0 drives before the partition");

    // The partition.
    let cut = Instant::now();
    let safe_stops = counters.safe_stops.load(Ordering::Relaxed);
    let stale_before = all.last().map_or(0, |t| t.stale);
    open.store(false, Ordering::Relaxed);
    let mut agent_stopped = None;
    while cut.elapsed() < Duration::from_secs(2) && agent_stopped.is_none() {
        if counters.safe_stops.load(Ordering::Relaxed) > safe_stops {
            agent_stopped = Some(cut.elapsed());
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    let agent_stopped = agent_stopped.expect("the agent safe-stops");
    let held = wait(&mut all, Duration::from_secs(2), &|t| {
        t.stale > stale_before
    })
    .expect("the coordinator stops robot 0")
    .duration_since(cut);
    // In ticks: from the last tick before the cut to the one that stopped the robot.
    let last_before = all
        .iter()
        .filter(|t| t.at <= cut)
        .map(|t| t.tick)
        .max()
        .expect("ticks before the cut");
    let stopped_at = all
        .iter()
        .find(|t| t.stale > stale_before)
        .expect("the stopping tick")
        .tick;
    let held_ticks = stopped_at - last_before;
    let flagged = wait(&mut all, Duration::from_secs(10), &|t| {
        t.events.contains(&Event::Crashed(0))
    })
    .expect("robot 0 is flagged")
    .duration_since(cut);
    println!(
        "partition: agent safe-stopped after {agent_stopped:?}, coordinator stopped the robot \
         after {held:?} ({held_ticks} ticks), flagged after {flagged:?}"
    );
    assert!(
        agent_stopped <= Duration::from_millis(500),
        "safe-stopped after {agent_stopped:?}"
    );
    // The rule (`CoordinatorConfig::stale_ticks` = 3): a robot drives on its newest command
    // while at most 3 newer observations have gone out unanswered. With the last answered
    // observation sent at tick c, it drives through tick c + 4 and stops at c + 5. The cut
    // falls after tick T with c = T (the answer to T came back first) or c = T − 1 (it was on
    // its way): 5 or 4 ticks.
    assert!(
        (4..=5).contains(&held_ticks),
        "stopped {held_ticks} ticks after the cut"
    );
    assert!(
        (Duration::from_millis(2500)..=Duration::from_millis(8000)).contains(&flagged),
        "flagged after the 3 s lease: {flagged:?}"
    );

    // The link heals: the agent comes back by itself and robot 0 drives again.
    std::thread::sleep(Duration::from_secs(1));
    let healed = Instant::now();
    open.store(true, Ordering::Relaxed);
    let back = wait(&mut all, Duration::from_secs(15), &|t| {
        t.events.contains(&Event::Joined(0))
    })
    .expect("robot 0's agent rejoins")
    .duration_since(healed);
    let drives = wait(&mut all, Duration::from_secs(10), &|t| t.speed > 0.2)
        .expect("robot 0 drives again")
        .duration_since(healed);
    println!("healed: rejoined after {back:?}, driving after {drives:?}");

    let status = rt.block_on(coordinator).expect("coordinator task");
    let _ = stop_tx.send(true);
    for a in agents {
        rt.block_on(a).expect("agent task");
    }
    while let Ok(t) = ticks.try_recv() {
        all.push(t);
    }
    let events: Vec<&Event> = all.iter().flat_map(|t| &t.events).collect();
    let count = |e: &Event| events.iter().filter(|x| **x == e).count();
    assert_eq!(count(&Event::Joined(0)), 2, "{events:?}");
    assert_eq!(count(&Event::Crashed(0)), 1, "{events:?}");
    assert_eq!(
        count(&Event::Joined(1)),
        1,
        "robot 1 never left: {events:?}"
    );
    let mut done: Vec<u64> = events
        .iter()
        .filter_map(|e| match e {
            Event::TaskDone { task, .. } => Some(*task),
            _ => None,
        })
        .collect();
    let n = done.len();
    done.sort_unstable();
    done.dedup();
    assert_eq!(done.len(), n, "a task counted twice: {events:?}");
    assert_eq!(status.tasks_done, n as u64);
}
