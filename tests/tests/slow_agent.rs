//! Neither a slow agent nor a stalled listener holds up the fleet. The coordinator on a router
//! session (as `gapfleet coordinator` runs it), three `gapfleet-agent` processes in real time,
//! one of them taking 300 ms per plan (three ticks), and a `gapfleet/**` subscriber on its own
//! session whose queue is never drained:
//!
//! - the slow agent plans on the newest observation each time, never on a backlog: its commands
//!   answer observations at most 4 ticks old, all run long;
//! - the other robots never lack a fresh command (their stale-command counts stay 0) and every
//!   observation sent to them is answered.

use coordinator::serve::{CoordinatorConfig, Status, run_coordinator};
use fleet_net::{Role, loopback};
use gapfleet_tests::{AgentProcess, free_endpoint};
use schemas::{Channel, CommandMsg, Keys, Observation, decode};
use std::sync::mpsc;
use std::time::Instant;
use world_sim::fleet::Fleet;

const SITE: &str = "slow-test";
const SLOW: u32 = 1;

#[test]
fn a_slow_agent_and_an_undrained_subscriber_do_not_hold_up_the_fleet() {
    let rt = gapfleet_tests::runtime();
    let endpoint = free_endpoint();
    let keys = Keys::new(SITE).expect("valid");
    let router = gapfleet_tests::router(&rt, &endpoint);
    // The slow robot's observations and commands, in arrival order.
    let (seen_tx, seen) = mpsc::channel::<(bool, u64)>();
    let obs_tx = seen_tx.clone();
    let _obs = rt
        .block_on(async {
            router
                .declare_subscriber(keys.robot(SLOW, Channel::Obs))
                .callback(move |s| {
                    if let Ok(o) = decode::<Observation>(&s.payload().to_bytes()) {
                        let _ = obs_tx.send((true, o.seq));
                    }
                })
                .await
        })
        .expect("subscriber");
    let _cmds = rt
        .block_on(async {
            router
                .declare_subscriber(keys.robot(SLOW, Channel::Cmd))
                .callback(move |s| {
                    if let Ok(c) = decode::<CommandMsg>(&s.payload().to_bytes())
                        && !c.safe_stop
                    {
                        let _ = seen_tx.send((false, c.obs_seq));
                    }
                })
                .await
        })
        .expect("subscriber");
    // A listener that never drains its small queue, on a session of its own.
    let stalled = rt
        .block_on(async {
            zenoh::open(
                loopback(Role::Client, &[], std::slice::from_ref(&endpoint)).expect("config"),
            )
            .await
        })
        .expect("a client");
    let _never_drained = rt
        .block_on(async {
            stalled
                .declare_subscriber("gapfleet/**")
                .with(zenoh::handlers::FifoChannel::new(8))
                .await
        })
        .expect("subscriber");

    let scenario = gapfleet_tests::warehouse(3, 10);
    let fleet = Fleet::new(&scenario).expect("a warehouse");
    let mut config = CoordinatorConfig::new(gapfleet_tests::keys(SITE));
    config.seconds = Some(15.0);
    let (status_tx, statuses) = mpsc::channel::<Status>();
    let session = router.clone();
    let coordinator = rt.spawn(async move {
        run_coordinator(
            &session,
            fleet,
            config,
            std::future::pending(),
            &mut move |status: &Status, _: &Fleet| {
                let _ = status_tx.send(status.clone());
            },
        )
        .await
        .expect("the coordinator runs")
    });
    let _agents: Vec<AgentProcess> = (0..3)
        .map(|id| {
            let extra: &[&str] = if id == SLOW {
                &["--fault-plan-delay-ms", "300"]
            } else {
                &[]
            };
            AgentProcess::spawn_with(id, &endpoint, SITE, "pgp+orca", extra)
        })
        .collect();
    let started = Instant::now();
    let status = rt.block_on(coordinator).expect("coordinator task");
    while statuses.try_recv().is_ok() {}

    // How far behind the newest observation each of the slow agent's commands was.
    let (mut newest, mut lags) = (None::<u64>, Vec::new());
    while let Ok((is_obs, seq)) = seen.try_recv() {
        if is_obs {
            newest = Some(newest.map_or(seq, |n| n.max(seq)));
        } else if let Some(n) = newest {
            lags.push(n.saturating_sub(seq));
        }
    }
    let worst = lags.iter().copied().max().unwrap_or(u64::MAX);
    println!(
        "{:.1} s: slow agent's {} commands answer observations at most {worst} ticks old; \
         stale-command ticks per robot {:?}; {} observations, {} answered",
        started.elapsed().as_secs_f64(),
        lags.len(),
        status.stale_per_robot,
        status.observations,
        status.answered
    );
    assert!(
        lags.len() >= 20,
        "the slow agent planned: {} commands",
        lags.len()
    );
    assert!(
        worst <= 4,
        "the slow agent worked through a backlog: {worst} ticks behind"
    );
    for robot in [0, 2] {
        assert_eq!(
            status.stale_per_robot[robot], 0,
            "robot {robot} lacked a fresh command: {:?}",
            status.stale_per_robot
        );
    }
    assert!(
        status.stale_per_robot[SLOW as usize] > 0,
        "300 ms plans are 3 ticks late"
    );
    drop(stalled);
}
