//! `gapfleet-agent --ros` drives a ROS 2 robot that no one here wrote the middleware of: a
//! Python robot on ROBOTIS's zenoh-ros2-sdk (pure-Python rmw_zenoh; tests/python/ros2_robot.py),
//! through a real `zenohd`, to three goals in a walled room that two people keep crossing
//! without reacting. Once with the people on its people topic, once with them in the scan only.
//! The robot's scanner sits 0.2 m ahead of its centre, facing backwards, as its /tf_static
//! says; the agent starts after that was said and reads it from the robot's cache. A third run
//! puts odometry in a drifted frame and the map pose on `amcl_pose`.

use gapfleet_tests::{Killed, Zenohd, binary, free_endpoint};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const ROBOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/python/ros2_robot.py");
const GOALS: [(f64, f64); 3] = [(3.0, 0.0), (3.0, 3.0), (0.0, 3.0)];

/// The Python with zenoh-ros2-sdk and rosbags ($GAPFLEET_PYTHON; tests/run.sh installs them).
fn python() -> String {
    let python = std::env::var("GAPFLEET_PYTHON").unwrap_or_else(|_| "python3".to_owned());
    let ok = Command::new(&python)
        .args(["-c", "import zenoh_ros2_sdk, rosbags"])
        .status()
        .is_ok_and(|s| s.success());
    assert!(
        ok,
        "{python} lacks zenoh-ros2-sdk/rosbags: run `bash tests/run.sh` or set GAPFLEET_PYTHON"
    );
    python
}

/// Drives the Python robot through the goals: with its people on the people topic or in the
/// scan only (`no_people`), with odometry in the map frame or, `localized`, in a drifted odom
/// frame with the map pose on `amcl_pose` (the agent given `--pose-topic amcl_pose`).
fn drive(no_people: bool, localized: bool) {
    let python = python();
    let endpoint = free_endpoint();
    let router = endpoint.trim_start_matches("tcp/").to_owned();
    let _zenohd = Zenohd::listening(&endpoint);
    let dir = tempfile::tempdir().expect("a temporary folder");
    let log = dir.path().join("robot.jsonl");
    let mut robot_cmd = Command::new(&python);
    robot_cmd
        .args([
            ROBOT,
            "--namespace",
            "/robot1",
            "--router",
            &router,
            "--seconds",
            "120",
        ])
        .arg("--log")
        .arg(&log)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
    if no_people {
        robot_cmd.arg("--no-people");
    }
    if localized {
        robot_cmd.arg("--localized");
    }
    let _robot = Killed(robot_cmd.spawn().expect("the Python robot starts"));
    // The agent comes after the robot has said where its scanner is, once, on /tf_static: it
    // learns the mounting from the robot's transient-local cache, as a late ROS 2 node does.
    let waiting = Instant::now();
    while std::fs::metadata(&log).map_or(0, |m| m.len()) == 0 {
        assert!(
            waiting.elapsed() < Duration::from_secs(60),
            "the Python robot did not start"
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    let mut agent_cmd = Command::new(binary("gapfleet-agent"));
    agent_cmd
        .args([
            "--ros",
            "--namespace",
            "/robot1",
            "--base",
            "differential",
            "--exit-at-last-goal",
        ])
        .args(["--connect", &endpoint])
        .env("RUST_LOG", "info,zenoh=warn")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    for (x, y) in GOALS {
        agent_cmd.arg("--goal").arg(format!("{x},{y}"));
    }
    if localized {
        agent_cmd.args(["--pose-topic", "amcl_pose"]);
    }
    let mut agent = Killed(agent_cmd.spawn().expect("the agent starts"));
    let started = Instant::now();
    let status = loop {
        if let Some(status) = agent.0.try_wait().expect("agent status") {
            break status;
        }
        assert!(
            started.elapsed() < Duration::from_secs(100),
            "the agent did not reach its goals in 100 s"
        );
        std::thread::sleep(Duration::from_millis(200));
    };
    let mut stderr = String::new();
    if let Some(mut pipe) = agent.0.stderr.take() {
        use std::io::Read;
        let _ = pipe.read_to_string(&mut stderr);
    }
    assert!(status.success(), "agent failed: {stderr}");
    // The scanner, 0.2 m ahead and facing backwards, is placed where /tf_static mounts it,
    // and nowhere else: until that transform comes, the agent holds rather than use the scan.
    let mounts: Vec<_> = stderr
        .lines()
        .filter(|l| l.contains("scanner mounted"))
        .collect();
    println!("{mounts:?}");
    assert!(
        !mounts.is_empty(),
        "the agent never placed the scanner: {stderr}"
    );
    assert!(
        mounts
            .iter()
            .all(|m| m.contains("base_scan at (0.200, 0.000) m, 3.142 rad")),
        "{mounts:?}"
    );
    let summary = stderr.lines().last().unwrap_or_default();
    println!("{summary}");
    assert!(
        summary.contains("3 of 3 goals") && summary.contains(" 0 refused"),
        "{stderr}"
    );
    assert_eq!(
        !summary.contains(" 0 map poses"),
        localized,
        "map poses only from amcl_pose: {summary}"
    );

    let lines: Vec<serde_json::Value> = std::fs::read_to_string(&log)
        .expect("the robot's log")
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect();
    // The independent implementation reads our liveliness tokens as ROS 2 graph entries.
    let graph = lines
        .iter()
        .find_map(|l| l.get("graph"))
        .expect("the robot queried the graph");
    println!("graph as zenoh-ros2-sdk reads it: {graph}");
    let ours = |list: &str, ty: &str| {
        graph[list].as_array().is_some_and(|eps| {
            eps.iter().any(|e| {
                e["node"] == "gapfleet_agent" && e["namespace"] == "/robot1" && e["type"] == ty
            })
        })
    };
    assert!(
        ours("cmd_vel_publishers", "geometry_msgs/msg/Twist"),
        "{graph}"
    );
    assert!(ours("odom_subscribers", "nav_msgs/msg/Odometry"), "{graph}");
    let rows: Vec<serde_json::Value> = lines
        .into_iter()
        .filter(|l| l.get("graph").is_none())
        .collect();
    assert!(rows.len() > 20, "the robot ran: {} steps", rows.len());
    let num = |r: &serde_json::Value, k: &str| r[k].as_f64().expect("a number");
    // The robot itself (ground truth) passed within 0.35 m of every goal, in order.
    let mut next = 0;
    for r in &rows {
        if next < GOALS.len() {
            let (gx, gy) = GOALS[next];
            if (num(r, "x") - gx).hypot(num(r, "y") - gy) < 0.35 {
                next += 1;
            }
        }
    }
    assert_eq!(next, GOALS.len(), "the robot visited {next} goals");
    let contacts: Vec<_> = rows
        .iter()
        .flat_map(|r| r["contacts"].as_array().cloned().unwrap_or_default())
        .collect();
    let min_wall = rows
        .iter()
        .map(|r| num(r, "wall_gap"))
        .fold(f64::INFINITY, f64::min);
    let min_person = rows
        .iter()
        .flat_map(|r| {
            let (x, y) = (num(r, "x"), num(r, "y"));
            r["people"]
                .as_array()
                .cloned()
                .unwrap_or_default()
                .into_iter()
                .map(move |p| {
                    (p[0].as_f64().unwrap_or(f64::NAN) - x)
                        .hypot(p[1].as_f64().unwrap_or(f64::NAN) - y)
                        - 0.6
                })
        })
        .fold(f64::INFINITY, f64::min);
    println!(
        "no_people={no_people}: contacts {}, closest person {min_person:.2} m, closest wall {min_wall:.2} m",
        contacts.len()
    );
    if no_people {
        // The bar for a person the tracker misses: no contact the robot causes (moving
        // toward them at more than 0.05 m/s at the onset, world_sim's rule).
        let caused = contacts
            .iter()
            .filter(|c| c["robot_toward"].as_f64().unwrap_or(0.0) > 0.05)
            .count();
        assert_eq!(caused, 0, "robot-caused contacts: {contacts:?}");
    } else {
        assert!(contacts.is_empty(), "contacts with people: {contacts:?}");
    }
    assert!(min_wall > 0.0, "the robot touched a wall: {min_wall}");
}

#[test]
fn the_agent_drives_a_python_rmw_zenoh_robot_to_three_goals() {
    drive(false, false);
}

#[test]
fn people_seen_only_in_the_scan_are_not_touched_either() {
    drive(true, false);
}

/// Odometry drifted 1.1 m and 0.3 rad from the map, and AMCL's map pose on `amcl_pose`: the
/// goals, given in the map, are still reached where the robot's ground truth says.
#[test]
fn a_robot_localized_on_amcl_pose_reaches_its_goals_in_the_map() {
    drive(false, true);
}

/// `gapfleet demo --ros`: the simulator plays every robot as a ROS 2 robot and every agent
/// drives its robot through those topics. The fleet works, nothing on the ROS side is refused,
/// and no robot drives into anyone.
#[test]
fn a_fleet_of_simulated_ros_robots_works_through_its_topics() {
    let out = Command::new(binary("gapfleet"))
        .args([
            "demo",
            "--ros",
            "--robots",
            "4",
            "--humans",
            "10",
            "--seconds",
            "60",
            "--speed",
            "2",
        ])
        .stdin(Stdio::null())
        .output()
        .expect("gapfleet demo runs");
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{text}");
    let line = |prefix: &str| {
        text.lines()
            .find(|l| l.starts_with(prefix))
            .unwrap_or_else(|| panic!("no `{prefix}` line in:\n{text}"))
            .to_owned()
    };
    let tasks_line = line("tasks done");
    println!("{tasks_line}\n{}", line("contacts (onsets)"));
    let tasks: u64 = tasks_line
        .split_whitespace()
        .nth(2)
        .and_then(|n| n.parse().ok())
        .expect("a task count");
    assert!(tasks >= 2, "{tasks_line}");
    assert!(
        tasks_line.contains("rejected messages 0 (coordinator) 0 (agents)"),
        "{tasks_line}"
    );
    assert!(
        line("contacts (onsets)").contains("with people 0 robot-caused"),
        "{text}"
    );
}
