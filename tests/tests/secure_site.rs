//! A secured site on real Zenoh sessions on loopback, as `gapfleet site init` writes it:
//! mutual TLS, user/password, and the access-control list enforced by the routing process.
//!
//! 1. The coordinator's own session routes (`coordinator/zenoh.json5`): strangers are refused
//!    (no TLS, no client certificate, a certificate from another site's authority, a wrong
//!    password), and an authenticated robot 5 is held to its own keys: it cannot put on robot
//!    2's command or intent keys or the metrics, hold robot 2's token, read robot 2's
//!    observations, or serve a map; the router never sees any of it, while robot 5's own
//!    messages get through. Observers read everything and cannot put.
//! 2. The same with a real coordinator and agent: a forged command with a future `obs_seq`
//!    on a robot's own key is rejected and counted, one on another robot's key never arrives,
//!    and the real agent's robot drives on.
//! 3. The same list enforced by a real `zenohd` 1.10.2 router between the coordinator and the
//!    agents (tests/run.sh installs it).

use agent::runtime::{AgentConfig, AgentCounters, run_agent};
use coordinator::serve::{CoordinatorConfig, Status, run_coordinator};
use coordinator::site::Identity;
use coordinator::site::{SitePaths, TemporarySite};
use fleet_net::from_file;
use gapfleet_tests::{Zenohd, zenohd};
use schemas::{Channel, CommandMsg, Keys, Motion, P2, SafetyZone, encode};
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use world_sim::fleet::Fleet;
use zenoh::Session;
use zenoh::handlers::{FifoChannelHandler, RingChannel};
use zenoh::sample::Sample;

const SITE: &str = "sec-test";

/// `path`'s config, edited by `edit` (as JSON: the site writes JSON, which is JSON5), failing
/// after 3 s instead of waiting for the router forever.
fn edited(path: &Path, edit: impl FnOnce(&mut serde_json::Value)) -> zenoh::Config {
    let text = std::fs::read_to_string(path).expect("the site's config");
    let mut value: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    value["connect"]["timeout_ms"] = 3000.into();
    edit(&mut value);
    zenoh::Config::from_json5(&value.to_string()).expect("a Zenoh config")
}

/// `path`'s config as it is, failing after 3 s instead of waiting for the router forever.
fn quick(path: &Path) -> zenoh::Config {
    edited(path, |_| {})
}

async fn open(config: zenoh::Config) -> zenoh::Result<Session> {
    zenoh::open(config).await
}

/// Everything a subscriber received so far: keys.
fn drain(sub: &zenoh::pubsub::Subscriber<FifoChannelHandler<Sample>>) -> Vec<String> {
    let mut keys = Vec::new();
    while let Ok(Some(sample)) = sub.try_recv() {
        keys.push(sample.key_expr().as_str().to_owned());
    }
    keys
}

async fn put(session: &Session, key: String) {
    session
        .put(key, vec![0u8; 8])
        .congestion_control(zenoh::qos::CongestionControl::Block)
        .await
        .expect("a put is sent (the router may drop it)");
}

/// Delivery on loopback takes microseconds; this leaves room for a busy machine.
async fn settle() {
    tokio::time::sleep(Duration::from_millis(700)).await;
}

#[test]
fn the_router_refuses_strangers_and_holds_each_identity_to_its_part() {
    let rt = gapfleet_tests::runtime();
    let site = TemporarySite::new(&gapfleet_tests::keys(SITE), 8).expect("a site");
    let other = TemporarySite::new(&gapfleet_tests::keys(SITE), 8).expect("another site");
    let paths = &site.paths;
    let keys = Keys::new(SITE).expect("valid");
    rt.block_on(async {
        let router = open(from_file(&paths.coordinator_config()).expect("parses"))
            .await
            .expect("the coordinator's session routes");
        let endpoint = site_endpoint(paths);

        // 1. Strangers are refused.
        let robot5_config = paths.robot_config(5);
        let plain = edited(&robot5_config, |v| {
            v["transport"]["link"]["protocols"] = serde_json::json!(["tcp"]);
            v["connect"]["endpoints"] = serde_json::json!([endpoint.replacen("tls/", "tcp/", 1)]);
        });
        assert!(open(plain).await.is_err(), "plain TCP is refused");
        let no_certificate = edited(&robot5_config, |v| {
            let tls = v["transport"]["link"]["tls"]
                .as_object_mut()
                .expect("TLS settings");
            tls.remove("connect_private_key");
            tls.remove("connect_certificate");
        });
        assert!(
            open(no_certificate).await.is_err(),
            "TLS without a client certificate is refused"
        );
        let foreign = other.paths.folder(&Identity::Robot(5));
        let foreign_certificate = edited(&robot5_config, |v| {
            let tls = &mut v["transport"]["link"]["tls"];
            tls["connect_private_key"] = foreign.join("key.pem").display().to_string().into();
            tls["connect_certificate"] = foreign.join("cert.pem").display().to_string().into();
        });
        assert!(
            open(foreign_certificate).await.is_err(),
            "a certificate from another site's authority is refused"
        );
        let wrong_password = edited(&robot5_config, |v| {
            v["transport"]["auth"]["usrpwd"]["password"] = "not-the-password".into();
        });
        assert!(
            open(wrong_password).await.is_err(),
            "a wrong password is refused"
        );
        let borrowed_user = edited(&robot5_config, |v| {
            v["transport"]["auth"]["usrpwd"]["user"] = "robot-2".into();
        });
        assert!(
            open(borrowed_user).await.is_err(),
            "robot 2's user name with robot 5's password is refused"
        );

        // 2. Robot 5 is held to its own keys. The router's own session sees what arrives.
        let robot5 = open(quick(&paths.robot_config(5)))
            .await
            .expect("robot 5's own credentials are accepted");
        let heard = router
            .declare_subscriber(format!("{}/**", keys.prefix()))
            .await
            .expect("subscriber");
        let tokens = router
            .liveliness()
            .declare_subscriber(format!("{}/alive/*", keys.prefix()))
            .await
            .expect("liveliness subscriber");
        let own_obs = robot5
            .declare_subscriber(keys.robot(5, Channel::Obs))
            .await
            .expect("its own observations");
        let others_obs = robot5
            .declare_subscriber(keys.robot(2, Channel::Obs))
            .await
            .expect("declared (the router ignores it)");
        let every_obs = robot5
            .declare_subscriber(keys.every_robot(Channel::Obs))
            .await
            .expect("declared (the router filters what it sends)");
        settle().await;
        put(&robot5, keys.robot(5, Channel::Cmd)).await;
        put(&robot5, keys.robot(5, Channel::Intent)).await;
        // (Not on observation keys: its own session would hand those to its own subscribers
        // below, router or not.)
        for key in [
            keys.robot(2, Channel::Cmd),
            keys.robot(2, Channel::Intent),
            keys.robot(2, Channel::Task),
            keys.metrics(),
        ] {
            put(&robot5, key).await;
        }
        let _own_token = robot5
            .liveliness()
            .declare_token(keys.alive(5))
            .await
            .expect("its own token");
        let _stolen_token = robot5
            .liveliness()
            .declare_token(keys.alive(2))
            .await
            .expect("declared (the router ignores it)");
        settle().await;
        put(&router, keys.robot(5, Channel::Obs)).await;
        put(&router, keys.robot(2, Channel::Obs)).await;
        settle().await;
        let mut heard_keys = drain(&heard);
        heard_keys.sort();
        let mut expected = vec![keys.robot(5, Channel::Cmd), keys.robot(5, Channel::Intent)];
        expected.sort();
        // The router's own puts reach its own subscriber too.
        heard_keys.retain(|k| !k.ends_with("/obs"));
        assert_eq!(heard_keys, expected, "only robot 5's own messages arrive");
        let mut token_keys = Vec::new();
        while let Ok(Some(sample)) = tokens.try_recv() {
            token_keys.push(sample.key_expr().as_str().to_owned());
        }
        assert_eq!(token_keys, vec![keys.alive(5)], "only robot 5's own token");
        assert_eq!(drain(&own_obs), vec![keys.robot(5, Channel::Obs)]);
        assert_eq!(
            drain(&others_obs),
            Vec::<String>::new(),
            "robot 2's observations"
        );
        assert_eq!(drain(&every_obs), vec![keys.robot(5, Channel::Obs)]);

        // Robot 5 cannot serve a map: robot 3 gets the coordinator's only.
        let map = router
            .declare_queryable(keys.map())
            .await
            .expect("the coordinator's map");
        let _forged_map = robot5
            .declare_queryable(keys.map())
            .callback(|q| {
                tokio::spawn(async move {
                    let _ = q.reply(q.key_expr().clone(), b"forged".to_vec()).await;
                });
            })
            .await
            .expect("declared (the router ignores it)");
        let serve = tokio::spawn(async move {
            while let Ok(q) = map.recv_async().await {
                let _ = q.reply(q.key_expr().clone(), b"real".to_vec()).await;
            }
        });
        let robot3 = open(quick(&paths.robot_config(3))).await.expect("robot 3");
        settle().await;
        let replies = robot3
            .get(keys.map())
            .timeout(Duration::from_secs(2))
            .await
            .expect("a query");
        let mut answers = Vec::new();
        while let Ok(reply) = replies.recv_async().await {
            if let Ok(sample) = reply.result() {
                answers.push(sample.payload().to_bytes().to_vec());
            }
        }
        assert_eq!(
            answers,
            vec![b"real".to_vec()],
            "only the coordinator's map"
        );
        serve.abort();

        // 3. An observer reads everything and cannot put.
        let observer = open(quick(&paths.observer_config("python")))
            .await
            .expect("the observer's credentials are accepted");
        let watched = observer
            .declare_subscriber(format!("{}/**", keys.prefix()))
            .await
            .expect("an observer may subscribe");
        // Another observer tries to put (a session hands its own puts to its own subscribers).
        let observer2 = open(quick(&paths.observer_config("dashboard")))
            .await
            .expect("the other observer's credentials are accepted");
        settle().await;
        drain(&heard);
        put(&observer2, keys.robot(0, Channel::Cmd)).await;
        put(&observer2, keys.metrics()).await;
        put(&router, keys.robot(6, Channel::Obs)).await;
        put(&router, keys.metrics()).await;
        settle().await;
        let mut seen = drain(&watched);
        seen.sort();
        let mut expected = vec![keys.robot(6, Channel::Obs), keys.metrics()];
        expected.sort();
        assert_eq!(seen, expected, "the observer reads");
        let mut heard_keys = drain(&heard);
        heard_keys.sort();
        assert_eq!(
            heard_keys, expected,
            "only the router's own two puts: the observer's are dropped"
        );

        for s in [robot5, robot3, observer, observer2, router] {
            s.close().await.expect("closes");
        }
    });
}

/// The endpoint the site's clients connect to.
fn site_endpoint(paths: &SitePaths) -> String {
    let text = std::fs::read_to_string(paths.dir.join("site.json")).expect("site.json");
    let site: serde_json::Value = serde_json::from_str(&text).expect("JSON");
    site["endpoint"].as_str().expect("an endpoint").to_owned()
}

/// A command for `robot` answering observation `obs_seq`, driving ahead.
fn forged(robot: u32, obs_seq: u64) -> Vec<u8> {
    encode(&CommandMsg {
        robot_id: robot,
        obs_seq,
        stamp: 0.0,
        motion: Motion::Velocity(P2(1.0, 0.0)),
        safe_stop: false,
        safety: SafetyZone::Clear,
        state: None,
    })
}

/// What the coordinator showed last.
#[derive(Debug, Default, Clone)]
struct Seen {
    status: Option<Status>,
    path_m: Vec<f64>,
}

/// Runs a coordinator with two robots on `coordinator_session` and robot 0's agent with its
/// credentials from `paths`, while robot 1's credentials forge commands for robot 1 (with a
/// far-future `obs_seq`) and for robot 0. Returns what the coordinator saw and how many forged
/// commands for robot 1 were sent.
async fn forge_against_a_fleet(coordinator_session: Session, paths: &SitePaths) -> (Seen, u64) {
    let agent_config = from_file(&paths.robot_config(0)).expect("parses");
    let attacker_config = quick(&paths.robot_config(1));
    let keys = Keys::new(SITE).expect("valid");
    let scenario = gapfleet_tests::warehouse(2, 0);
    let fleet = Fleet::new(&scenario).expect("a warehouse");
    let mut config = CoordinatorConfig::new(gapfleet_tests::keys(SITE));
    config.speed = 4.0;
    // Ten wall seconds at 4×: with six, a slow machine saw the last forgery arrive after the
    // coordinator had stopped (79 of 80 rejected).
    config.seconds = Some(40.0);
    let seen = Arc::new(Mutex::new(Seen::default()));
    let seen_in = seen.clone();
    let coordinator = tokio::spawn(async move {
        let mut observer = move |status: &Status, fleet: &Fleet| {
            let mut s = seen_in.lock().expect("not poisoned");
            s.status = Some(status.clone());
            s.path_m = (0..fleet.robots())
                .map(|i| fleet.metrics(i).path_length_m)
                .collect();
        };
        let status = run_coordinator(
            &coordinator_session,
            fleet,
            config,
            std::future::pending(),
            &mut observer,
        )
        .await
        .expect("the coordinator runs");
        coordinator_session.close().await.expect("closes");
        status
    });
    let agent_session = open(agent_config).await.expect("robot 0's agent");
    let (stop_tx, mut stop_rx) = tokio::sync::watch::channel(false);
    let counters = Arc::new(AgentCounters::default());
    let agent = tokio::spawn(run_agent_until(agent_session, counters, async move {
        let _ = stop_rx.wait_for(|s| *s).await;
    }));
    let attacker = open(attacker_config).await.expect("robot 1's credentials");
    // The coordinator hears commands once it reports (its subscribers are declared by then).
    while seen.lock().expect("not poisoned").status.is_none() {
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let mut forged_for_1 = 0;
    // Four wall seconds of forgeries, well inside the coordinator's ten.
    for k in 0..80u64 {
        for (robot, seq) in [(1, 1u64 << 62), (0, 1u64 << 62), (0, k)] {
            attacker
                .put(keys.robot(robot, Channel::Cmd), forged(robot, seq))
                .congestion_control(zenoh::qos::CongestionControl::Block)
                .await
                .expect("sent");
            forged_for_1 += u64::from(robot == 1);
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let status = coordinator.await.expect("coordinator task");
    let _ = stop_tx.send(true);
    agent.await.expect("agent task");
    attacker.close().await.expect("closes");
    let mut seen = seen.lock().expect("not poisoned").clone();
    seen.status = Some(status);
    (seen, forged_for_1)
}

async fn run_agent_until(
    session: Session,
    counters: Arc<AgentCounters>,
    shutdown: impl std::future::Future<Output = ()>,
) {
    let config = AgentConfig::new(
        0,
        gapfleet_tests::keys(SITE),
        "pgp+orca".parse().expect("a planner"),
    );
    run_agent(&session, config, counters, shutdown)
        .await
        .expect("the agent runs");
    session.close().await.expect("closes");
}

fn check_forgeries_failed(seen: &Seen, forged_for_1: u64) {
    let status = seen.status.as_ref().expect("a final status");
    println!(
        "coordinator: {} commands, {} rejected, {} answered; robot paths {:?} m",
        status.commands, status.rejected, status.answered, seen.path_m
    );
    // Robot 1 has no agent: every forged command on its key arrived, and each was rejected
    // for answering an observation never sent. Those for robot 0 never arrived at all (the
    // router dropped them), so none was counted, and robot 0's real agent drove it.
    assert_eq!(
        status.rejected, forged_for_1,
        "each forgery on robot 1's key is rejected"
    );
    assert!(seen.path_m[0] > 2.0, "robot 0 drove: {:?}", seen.path_m);
    assert!(
        seen.path_m[1] < 1e-9,
        "robot 1 never moved: {:?}",
        seen.path_m
    );
}

#[test]
fn forged_commands_have_no_effect_on_a_secured_fleet() {
    let rt = gapfleet_tests::runtime();
    let site = TemporarySite::new(&gapfleet_tests::keys(SITE), 2).expect("a site");
    let paths = &site.paths;
    let (seen, forged_for_1) = rt.block_on(async {
        let router = open(from_file(&paths.coordinator_config()).expect("parses"))
            .await
            .expect("the coordinator routes");
        forge_against_a_fleet(router, paths).await
    });
    check_forgeries_failed(&seen, forged_for_1);
}

#[test]
fn a_zenohd_router_enforces_the_same_list() {
    let zenohd = zenohd();
    let site = TemporarySite::new(&gapfleet_tests::keys(SITE), 2).expect("a site");
    let paths = &site.paths;
    let _router = Zenohd(
        std::process::Command::new(zenohd)
            .args(["-c", &paths.router_config().display().to_string()])
            .env("RUST_LOG", "error")
            .stdin(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .spawn()
            .expect("zenohd starts"),
    );
    let rt = gapfleet_tests::runtime();
    let (seen, forged_for_1) = rt.block_on(async {
        // The coordinator is a client of zenohd now: it waits for the router to listen.
        let coordinator =
            open(from_file(&paths.coordinator_behind_router_config()).expect("parses"))
                .await
                .expect("the coordinator connects to zenohd");
        // An agent's identity is refused what only the coordinator may do, by zenohd now.
        let keys = Keys::new(SITE).expect("valid");
        let robot1 = open(quick(&paths.robot_config(1))).await.expect("robot 1");
        let heard = coordinator
            .declare_subscriber(keys.every_robot(Channel::Obs))
            .with(RingChannel::new(16))
            .await
            .expect("subscriber");
        settle().await;
        put(&robot1, keys.robot(0, Channel::Obs)).await;
        settle().await;
        assert!(
            heard.try_recv().ok().flatten().is_none(),
            "robot 1 cannot publish observations through zenohd"
        );
        drop(heard);
        robot1.close().await.expect("closes");
        forge_against_a_fleet(coordinator, paths).await
    });
    check_forgeries_failed(&seen, forged_for_1);
}
