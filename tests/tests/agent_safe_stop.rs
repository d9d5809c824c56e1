//! The agent's two ways to stop its robot when the coordinator is gone, each on its own, with
//! one in-process agent on a real Zenoh client session and a router on loopback:
//!
//! 1. the coordinator's liveliness token disappears: a safe stop at once, long before the
//!    observation timeout (set to 30 s here, so only the token can explain the stop);
//! 2. observations stop while no coordinator token was ever seen: a safe stop once the
//!    observation timeout has passed, never before.

use agent::runtime::{AgentConfig, AgentCounters, run_agent};
use fleet_net::{Role, open_loopback};
use gapfleet_tests::free_endpoint;
use schemas::{Channel, CommandMsg, Keys, Observation, P2, decode, encode};
use std::sync::Arc;
use std::time::Duration;
use tokio::time::Instant;

const ROBOT: u32 = 3;

fn observation(seq: u64) -> Observation {
    Observation {
        robot_id: ROBOT,
        seq,
        sim_time: seq as f64 * 0.1,
        dt: 0.1,
        map_version: 1,
        p: P2(1.0, 1.0),
        heading: 0.0,
        vel: P2(0.0, 0.0),
        yaw_rate: 0.0,
        radius: 0.3,
        // Idle: the agent answers with a plain stop and needs no map.
        goal: None,
        task: None,
        neighbours: Vec::new(),
        visibility: None,
        real: false,
    }
}

/// When the first safe stop arrived: after the cut (the token dropped, or observations no
/// longer sent), and after the last observation was sent.
struct SafeStop {
    after_cut: Duration,
    after_last_observation: Duration,
}

/// Runs an agent with `obs_timeout` against a router; `coordinator_token` says whether the
/// router holds the coordinator's token while observations flow.
async fn first_safe_stop(site: &str, obs_timeout: Duration, coordinator_token: bool) -> SafeStop {
    let endpoint = free_endpoint();
    let keys = Keys::new(site).expect("valid site");
    let router = open_loopback(Role::Router, &endpoint)
        .await
        .expect("router");
    let token = if coordinator_token {
        Some(
            router
                .liveliness()
                .declare_token(keys.coordinator())
                .await
                .expect("coordinator token"),
        )
    } else {
        None
    };
    let commands = router
        .declare_subscriber(keys.robot(ROBOT, Channel::Cmd))
        .await
        .expect("command subscriber");
    let obs_pub = router
        .declare_publisher(keys.robot(ROBOT, Channel::Obs))
        .await
        .expect("observation publisher");

    let agent_session = open_loopback(Role::Client, &endpoint)
        .await
        .expect("agent session");
    let mut config = AgentConfig::new(
        ROBOT,
        gapfleet_tests::keys(site),
        "pgp+orca".parse().expect("planner"),
    );
    config.obs_timeout = obs_timeout;
    let counters = Arc::new(AgentCounters::default());
    let (stop_tx, stop_rx) = tokio::sync::oneshot::channel::<()>();
    let agent = tokio::spawn({
        let counters = counters.clone();
        async move {
            run_agent(&agent_session, config, counters, async {
                let _ = stop_rx.await;
            })
            .await
        }
    });

    // Observations at 10 Hz until the agent has answered some (it is then driving).
    let mut seq = 0;
    let mut answered = 0;
    let mut last_sent = Instant::now();
    while answered < 5 {
        seq += 1;
        assert!(seq < 200, "the agent never answered its observations");
        last_sent = Instant::now();
        obs_pub.put(encode(&observation(seq))).await.expect("put");
        tokio::time::sleep(Duration::from_millis(100)).await;
        while let Ok(Some(sample)) = commands.try_recv() {
            let cmd = decode::<CommandMsg>(&sample.payload().to_bytes()).expect("command");
            assert!(!cmd.safe_stop, "no safe stop while observations flow");
            answered += 1;
        }
    }

    // The cut: the coordinator's token goes (case 1), or observations simply stop (case 2).
    let cut = Instant::now();
    drop(token);
    let after = loop {
        let sample = tokio::time::timeout(Duration::from_secs(60), commands.recv_async())
            .await
            .expect("a safe stop within 60 s")
            .expect("command");
        let cmd = decode::<CommandMsg>(&sample.payload().to_bytes()).expect("command");
        if cmd.safe_stop {
            // The newest observation planned on: the last one sent, or the one before if the
            // stop overtook it.
            assert!(
                cmd.obs_seq + 1 >= seq && cmd.obs_seq <= seq,
                "stop for observation {}",
                cmd.obs_seq
            );
            break SafeStop {
                after_cut: cut.elapsed(),
                after_last_observation: last_sent.elapsed(),
            };
        }
    };
    stop_tx.send(()).expect("agent still running");
    agent.await.expect("agent task").expect("agent ran");
    assert_eq!(
        counters.rejected.load(std::sync::atomic::Ordering::Relaxed),
        0
    );
    after
}

#[test]
fn agent_stops_its_robot_when_the_coordinator_token_goes_or_observations_stop() {
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("runtime");

    // 1. The token goes: the stop comes long before the 30 s observation timeout.
    let timeout = Duration::from_secs(30);
    let stop = rt.block_on(first_safe_stop("stop-token", timeout, true));
    println!(
        "safe stop {:?} after the coordinator token went",
        stop.after_cut
    );
    assert!(
        stop.after_last_observation < timeout,
        "the token's disappearance stopped the robot, not the timeout ({:?})",
        stop.after_last_observation
    );

    // 2. No token ever seen: observations stop, and the stop waits for the timeout.
    let timeout = Duration::from_millis(300);
    let stop = rt.block_on(first_safe_stop("stop-timeout", timeout, false));
    println!(
        "safe stop {:?} after the last observation was sent (timeout {timeout:?})",
        stop.after_last_observation
    );
    // The agent received the last observation after it was sent and re-armed its timer then;
    // a timer never fires early.
    assert!(
        stop.after_last_observation >= timeout,
        "no safe stop before the timeout ({:?})",
        stop.after_last_observation
    );
}
