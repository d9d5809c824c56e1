//! The deployment topology in the loop, each part its own process behind a real `zenohd`: the
//! robots' hardware (`gapfleet hardware`, two processes of two robots each), one agent per
//! robot driving it over ROS 2 (`gapfleet-agent --ros --robot-id`), and a coordinator that
//! simulates no robot and no person (`gapfleet coordinator --live all --humans 0`).
//!
//! One hardware process is killed: its two robots are flagged lost and the fleet goes on with
//! the other two. The coordinator is killed and started again on its journal: it resumes and
//! manages the same robots. The journal then replays bit for bit, reports of real robots
//! included.

use gapfleet_tests::{Killed, Zenohd, binary, free_endpoint, wait_until};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Each test runs a whole site of processes: one at a time, so that two do not share the
/// machine's cores.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// A process whose stderr lines are kept with the moment each arrived.
struct Logged {
    child: Killed,
    lines: Arc<Mutex<Vec<(Instant, String)>>>,
}

impl Logged {
    fn spawn(command: &mut Command) -> Self {
        let mut child = command
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("the process starts");
        let lines = Arc::new(Mutex::new(Vec::new()));
        let sink = lines.clone();
        let stderr = child.stderr.take().expect("piped stderr");
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                sink.lock().expect("lines").push((Instant::now(), line));
            }
        });
        Self {
            child: Killed(child),
            lines,
        }
    }

    fn text(&self) -> String {
        let lines = self.lines.lock().expect("lines");
        lines
            .iter()
            .map(|(_, l)| l.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// The first line after `after` for which `pick` gives something.
    fn find<T>(&self, after: Instant, pick: impl Fn(&str) -> Option<T>) -> Option<(Instant, T)> {
        let lines = self.lines.lock().expect("lines");
        lines
            .iter()
            .filter(|(at, _)| *at >= after)
            .find_map(|(at, l)| pick(l).map(|t| (*at, t)))
    }

    /// Waits (at most `limit`) for a line after `after` that `pick` accepts.
    fn wait_for<T>(
        &self,
        what: &str,
        after: Instant,
        limit: Duration,
        pick: impl Fn(&str) -> Option<T>,
    ) -> (Instant, T) {
        wait_until(limit, || self.find(after, &pick))
            .unwrap_or_else(|| panic!("no {what} within {limit:?}; the log:\n{}", self.text()))
    }
}

/// `gapfleet replay` on the journal in `state`: its output, once it has succeeded.
fn replayed(state: &std::path::Path) -> String {
    let replay = Command::new(binary("gapfleet"))
        .arg("replay")
        .arg(state)
        .output()
        .expect("gapfleet replay runs");
    let text = String::from_utf8_lossy(&replay.stdout).to_string()
        + &String::from_utf8_lossy(&replay.stderr);
    println!("{text}");
    assert!(replay.status.success(), "{text}");
    text
}

/// The task count of a coordinator's status line (`t … | tasks   3 | …`).
fn tasks(line: &str) -> Option<u64> {
    let rest = line.split("| tasks").nth(1)?;
    rest.split('|').next()?.trim().parse().ok()
}

/// Whether `line` is the coordinator's warning that robot `id` is lost.
fn lost(line: &str, id: u32) -> bool {
    line.contains("robot lost") && line.ends_with(&format!("robot={id}"))
}

#[test]
fn the_deployment_loop_loses_robots_whose_hardware_dies_and_survives_a_coordinator_restart() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let endpoint = free_endpoint();
    let _zenohd = Zenohd::listening(&endpoint);
    let dir = tempfile::tempdir().expect("a temporary folder");
    let state = dir.path().join("state");
    let site = ["--robots", "4", "--seed", "3"];
    let coordinator = || {
        let mut cmd = Command::new(binary("gapfleet"));
        cmd.arg("coordinator")
            .args(site)
            .args(["--humans", "0", "--live", "all", "--speed", "2"])
            .args(["--connect", &endpoint])
            .arg("--state")
            .arg(&state)
            .env("RUST_LOG", "info,zenoh=warn");
        Logged::spawn(&mut cmd)
    };
    let hardware = |play: &str| {
        let mut cmd = Command::new(binary("gapfleet"));
        cmd.arg("hardware")
            .args(site)
            .args(["--humans", "10", "--speed", "2", "--play", play])
            .args(["--connect", &endpoint]);
        Logged::spawn(&mut cmd)
    };
    let first = coordinator();
    let _hardware_a = hardware("0-1");
    let mut hardware_b = hardware("2-3");
    let _agents: Vec<Killed> = (0..4)
        .map(|i| {
            Killed(
                Command::new(binary("gapfleet-agent"))
                    .args(["--robot-id", &i.to_string(), "--ros", "--namespace"])
                    .arg(format!("/robot{i}"))
                    // The default warehouse's people (people_msgs carries no size).
                    .args(["--person-radius", "0.35"])
                    .args(["--connect", &endpoint])
                    .env("RUST_LOG", "warn")
                    .stdin(Stdio::null())
                    .stdout(Stdio::null())
                    .stderr(Stdio::null())
                    .spawn()
                    .expect("an agent starts"),
            )
        })
        .collect();
    let start = Instant::now();

    // The fleet works with every robot real: tasks get done.
    let (_, done) = first.wait_for("a finished task", start, Duration::from_secs(120), |l| {
        tasks(l).filter(|&n| n >= 1)
    });
    println!("first task(s) done: {done}");
    assert!(
        first.find(start, |l| lost(l, 0).then_some(())).is_none(),
        "a robot was lost while its hardware ran:\n{}",
        first.text()
    );

    // The hardware of robots 2 and 3 dies: both are flagged lost, the other two are not.
    let _ = hardware_b.child.0.kill();
    let killed = Instant::now();
    for id in [2, 3] {
        let (at, ()) = first.wait_for(
            &format!("robot {id} lost"),
            killed,
            Duration::from_secs(10),
            |l| lost(l, id).then_some(()),
        );
        // Printed, not asserted: tests do not judge wall time (results/deployment reports it).
        println!(
            "robot {id} flagged lost {:?} after its hardware died",
            at - killed
        );
    }
    // The fleet goes on without them: more tasks get done.
    let before = first.find(killed, tasks).map_or(done, |(_, n)| n.max(done));
    let (_, after) = first.wait_for(
        "a task done after the loss",
        killed,
        Duration::from_secs(120),
        |l| tasks(l).filter(|&n| n > before),
    );
    println!("tasks went on: {before} -> {after}");
    for id in [0, 1] {
        assert!(
            first.find(start, |l| lost(l, id).then_some(())).is_none(),
            "robot {id} lost though its hardware runs:\n{}",
            first.text()
        );
    }

    // The coordinator dies and starts again on its journal: it resumes the run and manages
    // the same robots (tasks go on; the two without hardware are lost again).
    drop(first);
    let restarted_at = Instant::now();
    let second = coordinator();
    second.wait_for("the resume", restarted_at, Duration::from_secs(60), |l| {
        l.starts_with("resuming at tick").then_some(())
    });
    let (_, resumed) = second.wait_for(
        "a status line",
        restarted_at,
        Duration::from_secs(60),
        tasks,
    );
    let (_, later) = second.wait_for(
        "a task done after the restart",
        restarted_at,
        Duration::from_secs(120),
        |l| tasks(l).filter(|&n| n > resumed),
    );
    println!("after the restart: {resumed} -> {later} tasks");
    for id in [2, 3] {
        second.wait_for(
            &format!("robot {id} lost again"),
            restarted_at,
            Duration::from_secs(30),
            |l| lost(l, id).then_some(()),
        );
    }
    // A clean stop, then the journal replays bit for bit.
    let _ = Command::new("kill")
        .args(["-INT", &second.child.0.id().to_string()])
        .status();
    let mut second = second;
    let status = second.child.0.wait().expect("the coordinator exits");
    assert!(status.success(), "{}", second.text());
    let text = replayed(&state);
    assert!(text.contains("match the recorded run"), "{text}");
}

/// A mixed site: robot 0 is real (its hardware a process of its own, with no people in it),
/// robots 1 and 2 and ten people are simulated by the coordinator. The real robot's agent plans
/// around the simulated bodies its sensors cannot see; the fleet gets work done, the real
/// robot drives and is never lost, and the journal replays with its reports.
#[test]
fn a_mixed_site_runs_simulated_people_and_robots_around_a_real_one() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let endpoint = free_endpoint();
    let _zenohd = Zenohd::listening(&endpoint);
    let dir = tempfile::tempdir().expect("a temporary folder");
    let state = dir.path().join("state");
    let site = ["--robots", "3", "--seed", "4", "--speed", "2"];
    let mut coordinator = Logged::spawn(
        Command::new(binary("gapfleet"))
            .arg("coordinator")
            .args(site)
            .args(["--humans", "10", "--live", "0", "--seconds", "80"])
            .args(["--connect", &endpoint])
            .arg("--state")
            .arg(&state)
            .env("RUST_LOG", "info,zenoh=warn"),
    );
    let hardware = Logged::spawn(
        Command::new(binary("gapfleet"))
            .arg("hardware")
            .args(site)
            .args(["--humans", "0", "--play", "0", "--connect", &endpoint]),
    );
    let _agents: Vec<Killed> = (0..3)
        .map(|i| {
            let mut cmd = Command::new(binary("gapfleet-agent"));
            cmd.args(["--robot-id", &i.to_string(), "--connect", &endpoint])
                .env("RUST_LOG", "warn")
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::null());
            if i == 0 {
                cmd.args(["--ros", "--namespace", "/robot0"]);
            }
            Killed(cmd.spawn().expect("an agent starts"))
        })
        .collect();
    let started = Instant::now();
    let status = loop {
        if let Some(status) = coordinator.child.0.try_wait().expect("status") {
            break status;
        }
        assert!(
            started.elapsed() < Duration::from_secs(150),
            "the coordinator did not finish:\n{}",
            coordinator.text()
        );
        std::thread::sleep(Duration::from_millis(200));
    };
    let log = coordinator.text();
    assert!(status.success(), "{log}");
    let done = log.lines().rev().find_map(tasks).expect("a status line");
    println!("tasks done: {done}");
    assert!(done >= 1, "{log}");
    assert!(
        coordinator
            .find(started, |l| lost(l, 0).then_some(()))
            .is_none(),
        "the real robot was lost:\n{log}"
    );
    // The real robot drove: the hardware's odometer.
    let metres = hardware
        .find(started, |l| {
            let m = l.split(" m |").next()?.rsplit('|').next()?.trim();
            m.parse::<f64>().ok().filter(|&m| m > 5.0)
        })
        .map(|(_, m)| m);
    assert!(
        metres.is_some(),
        "robot 0 did not drive:\n{}",
        hardware.text()
    );
    println!(
        "robot 0 drove {:.0} m on its hardware",
        metres.unwrap_or(0.0)
    );
    let text = replayed(&state);
    assert!(text.contains("real robots [0]: placed from"), "{text}");
    assert!(text.contains("match the recorded run"), "{text}");
}

/// `gapfleet loop`, the documented command, end to end: its own `zenohd`, hardware, one agent
/// per robot and a coordinator of real robots, run to its end; every agent joined and planned,
/// the robots drove, none caused a contact, and the journal replays bit for bit.
#[test]
fn gapfleet_loop_runs_the_deployment_to_its_end_and_its_journal_replays() {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().expect("a temporary folder");
    let (state, logs) = (dir.path().join("state"), dir.path().join("logs"));
    let robots = 3;
    let output = dir.path().join("loop.txt");
    let file = std::fs::File::create(&output).expect("the loop's output file");
    let mut child = Command::new(binary("gapfleet"))
        .arg("loop")
        .args([
            "--robots",
            &robots.to_string(),
            "--humans",
            "10",
            "--seed",
            "2",
        ])
        .args([
            "--seconds",
            "15",
            "--speed",
            "2",
            "--zenohd",
            &gapfleet_tests::zenohd(),
        ])
        .arg("--state")
        .arg(&state)
        .arg("--logs")
        .arg(&logs)
        .stdin(Stdio::null())
        .stdout(file.try_clone().expect("a second handle"))
        .stderr(file)
        .spawn()
        .expect("gapfleet loop starts");
    let status = wait_until(Duration::from_secs(300), || child.try_wait().ok().flatten());
    let Some(status) = status else {
        let _ = child.kill();
        panic!(
            "gapfleet loop did not end within 300 s; its logs are in {}",
            logs.display()
        );
    };
    let out = std::fs::read_to_string(&output).expect("the loop's output");
    println!("{out}");
    assert!(status.success(), "gapfleet loop failed: {out}");
    assert!(
        out.contains("stopped after 15.0 simulated seconds"),
        "the coordinator ran its time: {out}"
    );
    assert!(
        out.contains("robot-caused 0"),
        "no robot caused a contact: {out}"
    );
    for i in 0..robots {
        let log = std::fs::read_to_string(logs.join(format!("agent{i}.log"))).expect("agent log");
        let plans: u64 = log
            .lines()
            .find_map(|l| {
                let rest = l.strip_prefix(&format!("gapfleet-agent {i}: "))?;
                rest.split(' ').next()?.parse().ok()
            })
            .unwrap_or_else(|| panic!("agent {i} printed no exit line: {log}"));
        assert!(plans > 0, "agent {i} planned: {log}");
    }
    let replay = replayed(&state);
    assert!(replay.contains("match the recorded run"), "{replay}");
}
