//! Helpers for the end-to-end tests: finding the built binaries, agent processes that are
//! killed when dropped, and a router session the tests own.

use std::path::PathBuf;
use std::process::{Child, Command, Stdio};

/// A binary of the workspace, built by `cargo test --workspace` next to the test executables.
pub fn binary(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("the test knows its own path");
    // target/<profile>/deps/<test> → target/<profile>/<name>
    let dir = exe
        .parent()
        .and_then(|deps| deps.parent())
        .expect("test executables live in target/<profile>/deps");
    let path = dir.join(name);
    assert!(
        path.exists(),
        "{} is missing: run `cargo test --workspace` (it builds every binary) or `cargo build -p agent -p coordinator`",
        path.display()
    );
    path
}

/// A `gapfleet-agent` process; killed (SIGKILL) when dropped unless it already exited.
#[derive(Debug)]
pub struct AgentProcess {
    /// The robot it drives.
    pub robot_id: u32,
    child: Child,
}

impl AgentProcess {
    /// Starts an agent for `robot_id` connecting to `endpoint`.
    pub fn spawn(robot_id: u32, endpoint: &str, site: &str, planner: &str) -> Self {
        Self::spawn_with(robot_id, endpoint, site, planner, &[])
    }

    /// The same with `extra` arguments.
    pub fn spawn_with(
        robot_id: u32,
        endpoint: &str,
        site: &str,
        planner: &str,
        extra: &[&str],
    ) -> Self {
        let child = Command::new(binary("gapfleet-agent"))
            .args(["--robot-id", &robot_id.to_string()])
            .args(["--planner", planner, "--site", site, "--connect", endpoint])
            .args(extra)
            // GAPFLEET_TEST_AGENT_LOG=info shows the agents' logs when a test misbehaves.
            .env(
                "RUST_LOG",
                std::env::var("GAPFLEET_TEST_AGENT_LOG").unwrap_or_else(|_| "off".to_owned()),
            )
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("gapfleet-agent starts");
        Self { robot_id, child }
    }

    /// Process id.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Sends a signal (`KILL`, `TERM`, `INT`) with the system's `kill`.
    pub fn signal(&self, name: &str) {
        let ok = Command::new("kill")
            .args([format!("-{name}"), self.pid().to_string()])
            .status()
            .is_ok_and(|s| s.success());
        assert!(ok, "kill -{name} {}", self.pid());
    }

    /// Whether it is still running.
    pub fn running(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }

    /// Waits for it to exit and returns whether it exited successfully.
    pub fn wait_success(&mut self) -> bool {
        self.child.wait().is_ok_and(|s| s.success())
    }
}

impl Drop for AgentProcess {
    fn drop(&mut self) {
        if self.running() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// A free loopback TCP endpoint, `tcp/127.0.0.1:<port>`.
pub fn free_endpoint() -> String {
    let port = fleet_net::free_loopback_port().expect("a free loopback port");
    format!("tcp/127.0.0.1:{port}")
}

/// The tests' Tokio runtime: two worker threads, as on the machines this runs on.
pub fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("a Tokio runtime")
}

/// A loopback router session listening at `endpoint` (as the coordinator's, or a zenohd).
pub fn router(rt: &tokio::runtime::Runtime, endpoint: &str) -> zenoh::Session {
    let config = fleet_net::loopback(fleet_net::Role::Router, &[endpoint.to_owned()], &[])
        .expect("a router config");
    rt.block_on(async { zenoh::open(config).await })
        .expect("a router session")
}

/// The built-in `warehouse` with `robots` robots and `humans` people.
pub fn warehouse(robots: usize, humans: usize) -> world_sim::scenario::Scenario {
    let mut scenario = world_sim::scenario::Scenario::builtin("warehouse").expect("built in");
    let w = scenario.warehouse.as_mut().expect("a warehouse");
    w.robots = robots;
    w.humans = humans;
    scenario
}

/// Asks `ready` every 10 ms until it gives `Some`, for at most `timeout`; None if it never
/// did. Every test waits for a condition this way or with [`recv_until`].
pub fn wait_until<T>(
    timeout: std::time::Duration,
    mut ready: impl FnMut() -> Option<T>,
) -> Option<T> {
    let deadline = std::time::Instant::now() + timeout;
    loop {
        if let Some(value) = ready() {
            return Some(value);
        }
        if std::time::Instant::now() >= deadline {
            return None;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
}

/// Receives from `rx` until an item satisfies `wanted`, for at most `timeout`: that item, or
/// None (the time ran out, or every sender went). Items that do not satisfy it are shown to
/// `wanted` and dropped.
pub fn recv_until<T>(
    rx: &std::sync::mpsc::Receiver<T>,
    timeout: std::time::Duration,
    mut wanted: impl FnMut(&T) -> bool,
) -> Option<T> {
    let deadline = std::time::Instant::now() + timeout;
    while let Some(left) = deadline.checked_duration_since(std::time::Instant::now()) {
        match rx.recv_timeout(left) {
            Ok(item) if wanted(&item) => return Some(item),
            Ok(_) => {}
            Err(_) => return None,
        }
    }
    None
}

/// The keys of the test site `site` (a valid name).
pub fn keys(site: &str) -> schemas::Keys {
    schemas::Keys::new(site).expect("a valid site name")
}

/// `zenohd` from $GAPFLEET_ZENOHD or PATH (tests/run.sh installs 1.10.2).
pub fn zenohd() -> String {
    let zenohd = std::env::var("GAPFLEET_ZENOHD").unwrap_or_else(|_| "zenohd".to_owned());
    let version = std::process::Command::new(&zenohd)
        .arg("--version")
        .output()
        .unwrap_or_else(|e| {
            panic!("{zenohd}: {e}; run `bash tests/run.sh` (it installs zenohd 1.10.2) or set GAPFLEET_ZENOHD")
        });
    let text = String::from_utf8_lossy(&version.stdout);
    assert!(text.contains("1.10.2"), "{zenohd} is not 1.10.2: {text}");
    zenohd
}

/// A `zenohd` process, killed when dropped.
#[derive(Debug)]
pub struct Zenohd(pub std::process::Child);

impl Zenohd {
    /// The pinned `zenohd` ([`zenohd`]) listening on `endpoint`, without scouting, quiet.
    pub fn listening(endpoint: &str) -> Self {
        Self(
            Command::new(zenohd())
                .args(["-l", endpoint, "--no-multicast-scouting"])
                .env("RUST_LOG", "error")
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("zenohd starts"),
        )
    }
}

impl Drop for Zenohd {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Any child process, killed when dropped.
#[derive(Debug)]
pub struct Killed(pub Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}
