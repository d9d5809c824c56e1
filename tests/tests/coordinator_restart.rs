//! The coordinator killed mid-run and restarted on its journal, with real processes: a `zenohd`
//! 1.10.2 router (tests/run.sh installs it), `gapfleet coordinator --state DIR` as its client,
//! three `gapfleet-agent` processes, and the test's own session watching the commands.
//!
//! 1. SIGKILL the coordinator, 36 simulated s in: every agent safe-stops within 0.5 s (its
//!    token is gone).
//! 2. Restart it with the same `--state`: it restores the snapshot of 30 s (tick 300), replays
//!    the journal's ticks after it, goes on from the tick where the journal ends, and every
//!    agent rejoins within 2 s.
//! 3. The whole run, before and after the crash, replays bit for bit (`gapfleet replay`: every
//!    fingerprint, and the snapshots of 30 and 60 s byte for byte), and no task is done twice.
//! 4. A coordinator on another scenario: the same agents fetch its map (another version).

use gapfleet_tests::{AgentProcess, binary, free_endpoint};
use schemas::{AgentInfo, Channel, CommandMsg, Keys, decode};
use std::io::BufRead;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

const SITE: &str = "restart-test";
const ROBOTS: u32 = 3;

/// A child process, killed when dropped.
struct Proc(Child);

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts the coordinator behind `router` with `args`; its stderr lines arrive on the channel.
fn coordinator(router: &str, args: &[&str]) -> (Proc, mpsc::Receiver<String>) {
    let robots = ROBOTS.to_string();
    let mut child = Command::new(binary("gapfleet"))
        .args(["coordinator", "--site", SITE, "--robots", robots.as_str()])
        .args(["--humans", "10", "--speed", "4"])
        .args(["--mode", "client", "--connect", router])
        .args(args)
        .env("RUST_LOG", "warn")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("gapfleet coordinator starts");
    let stderr = child.stderr.take().expect("piped");
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in std::io::BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
        {
            let _ = tx.send(line);
        }
    });
    (Proc(child), rx)
}

/// Waits for a line with `what`; returns it.
fn wait_line(rx: &mpsc::Receiver<String>, what: &str, timeout: Duration) -> String {
    gapfleet_tests::recv_until(rx, timeout, |line| line.contains(what))
        .unwrap_or_else(|| panic!("no line with {what:?} within {timeout:?}"))
}

#[test]
fn a_killed_coordinator_restarts_where_its_journal_ends() {
    let zenohd = std::env::var("GAPFLEET_ZENOHD").unwrap_or_else(|_| "zenohd".to_owned());
    let endpoint = free_endpoint();
    let _router = Proc(
        Command::new(&zenohd)
            .args(["--listen", &endpoint, "--no-multicast-scouting"])
            .env("RUST_LOG", "error")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("{zenohd}: {e}; tests/run.sh installs zenohd 1.10.2")),
    );
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let state = tmp.path().join("state");
    let keys = Keys::new(SITE).expect("valid");
    let rt = gapfleet_tests::runtime();
    // The test's eyes: a client of the router, watching every command.
    let watcher = rt
        .block_on(async {
            zenoh::open(
                fleet_net::loopback(
                    fleet_net::Role::Client,
                    &[],
                    std::slice::from_ref(&endpoint),
                )
                .expect("config"),
            )
            .await
        })
        .expect("a session");
    let commands = rt
        .block_on(async {
            watcher
                .declare_subscriber(keys.every_robot(Channel::Cmd))
                .with(zenoh::handlers::RingChannel::new(4096))
                .await
        })
        .expect("a subscriber");

    // The run: 80 simulated seconds at 4x.
    let state_arg = state.display().to_string();
    let run = ["--seconds", "80", "--state", state_arg.as_str()];
    let (first, lines) = coordinator(&endpoint, &run);
    let _agents: Vec<AgentProcess> = (0..ROBOTS)
        .map(|id| AgentProcess::spawn(id, &endpoint, SITE, "pgp+orca"))
        .collect();
    wait_line(
        &lines,
        &format!("agents {ROBOTS}/{ROBOTS}"),
        Duration::from_secs(30),
    );
    // Past the first snapshot (30 simulated s, 7.5 s here) before the kill.
    std::thread::sleep(Duration::from_secs(9));

    let infos = rt
        .block_on(async {
            watcher
                .declare_subscriber(keys.every_robot(Channel::Info))
                .with(zenoh::handlers::RingChannel::new(64))
                .await
        })
        .expect("a subscriber");
    // The map each agent holds, from its heartbeats (once a second).
    let maps_held = |wanted: &dyn Fn(u32) -> bool| -> Vec<u32> {
        let mut held = vec![0u32; ROBOTS as usize];
        gapfleet_tests::wait_until(Duration::from_secs(15), || {
            while let Ok(Some(sample)) = infos.try_recv() {
                if let Ok(info) = decode::<AgentInfo>(&sample.payload().to_bytes()) {
                    held[info.robot_id as usize] = info.map_version;
                }
            }
            held.iter().all(|&v| wanted(v)).then_some(())
        });
        held
    };
    let first_maps = maps_held(&|v| v != 0);
    let first_map = first_maps[0];
    assert!(
        first_maps.iter().all(|&v| v == first_map && v != 0),
        "every agent holds the coordinator's map: {first_maps:?}"
    );

    // 1. SIGKILL: every agent safe-stops within 0.5 s.
    while let Ok(Some(_)) = commands.try_recv() {}
    let killed_at = Instant::now();
    drop(first);
    let mut safe = std::collections::BTreeMap::new();
    while safe.len() < ROBOTS as usize && killed_at.elapsed() < Duration::from_secs(3) {
        match commands.try_recv() {
            Ok(Some(sample)) => {
                if let Ok(cmd) = decode::<CommandMsg>(&sample.payload().to_bytes())
                    && cmd.safe_stop
                {
                    safe.entry(cmd.robot_id).or_insert(killed_at.elapsed());
                }
            }
            _ => std::thread::sleep(Duration::from_millis(2)),
        }
    }
    println!("safe stops after the kill: {safe:?}");
    assert_eq!(
        safe.len(),
        ROBOTS as usize,
        "every agent safe-stops: {safe:?}"
    );
    for (robot, after) in &safe {
        assert!(
            *after <= Duration::from_millis(500),
            "agent {robot} after {after:?}"
        );
    }

    // 2. Restart on the same journal: it resumes, and every agent is back within 2 s.
    let restarted_at = Instant::now();
    let (second, lines) = coordinator(&endpoint, &run);
    let resumed = wait_line(&lines, "resuming at tick", Duration::from_secs(10));
    println!("{resumed}");
    let number_after = |words: &str| -> u64 {
        resumed
            .split(words)
            .nth(1)
            .and_then(|rest| rest.split(|c: char| !c.is_ascii_digit()).next())
            .and_then(|t| t.parse().ok())
            .unwrap_or_else(|| panic!("{words:?} N in {resumed:?}"))
    };
    let ticks = number_after("resuming at tick ");
    assert!(ticks > 300, "the journal held the run so far: {resumed}");
    // From the snapshot of tick 300, not from tick 0.
    assert_eq!(number_after("snapshot of tick "), 300, "{resumed}");
    let mut joined = 0;
    while joined < ROBOTS {
        let line = wait_line(&lines, "event: Joined", Duration::from_secs(10));
        joined += 1;
        println!("{line} after {:?}", restarted_at.elapsed());
    }
    let back = restarted_at.elapsed();
    println!("every agent rejoined {back:?} after the restart");
    assert!(back <= Duration::from_secs(2), "rejoined after {back:?}");
    let end = wait_line(&lines, "stopped after", Duration::from_secs(60));
    println!("{end}");
    let mut second = second;
    assert!(
        second.0.wait().is_ok_and(|s| s.success()),
        "the coordinator ends cleanly"
    );

    // 3. The whole run replays bit for bit, and no task was done twice.
    let out = Command::new(binary("gapfleet"))
        .arg("replay")
        .arg(&state)
        .arg("--events")
        .arg("--tasks")
        .output()
        .expect("gapfleet replay runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    println!("{stdout}");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("800 ticks recorded, ended cleanly after 800 ticks"),
        "{stdout}"
    );
    assert!(stdout.contains("match the recorded run"), "{stdout}");
    // The snapshots at 30 s (before the kill) and 60 s (after it) are the replay's state then.
    assert!(stdout.contains(" and 2 snapshots on the way"), "{stdout}");
    let mut done: Vec<&str> = stdout
        .lines()
        .filter_map(|l| l.split("task: ").nth(1))
        .collect();
    let all = done.len();
    done.sort_unstable();
    done.dedup();
    assert_eq!(done.len(), all, "a task done twice: {stdout}");
    // The ledger, across the crash: ids 0, 1, … with no gap or repeat, two tasks done.
    let ledger: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("ledger task "))
        .collect();
    for (k, line) in ledger.iter().enumerate() {
        assert!(
            line.starts_with(&format!("ledger task {k}: ")),
            "task ids count on: {stdout}"
        );
    }
    assert!(ledger.len() >= ROBOTS as usize, "{stdout}");
    assert_eq!(
        ledger.iter().filter(|l| !l.ends_with("done at -")).count(),
        2,
        "{stdout}"
    );

    // 4. Another scenario, another map: the same agents fetch it.
    let (_third, lines) = coordinator(
        &endpoint,
        &["--scenario", "warehouse-narrow", "--seconds", "60"],
    );
    wait_line(
        &lines,
        &format!("agents {ROBOTS}/{ROBOTS}"),
        Duration::from_secs(30),
    );
    while let Ok(Some(_)) = infos.try_recv() {}
    let new_maps = maps_held(&|v| v != 0 && v != first_map);
    println!("maps held: {first_map:08x} before, {new_maps:08x?} after the scenario changed");
    assert!(
        new_maps
            .iter()
            .all(|&v| v != 0 && v != first_map && v == new_maps[0]),
        "every agent fetched the new map: {new_maps:08x?} (the old one was {first_map:08x})"
    );
}
