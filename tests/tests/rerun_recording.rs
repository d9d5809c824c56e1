//! A short demo records its dashboard to an .rrd file; the official `rerun` CLI (rerun-sdk
//! 0.36.3 from PyPI, installed by tests/run.sh) verifies the file and lists what it holds.

use gapfleet_tests::binary;
use std::process::Command;

/// The `rerun` CLI: $GAPFLEET_RERUN (tests/run.sh sets it) or `rerun` on PATH.
fn rerun_cli() -> String {
    std::env::var("GAPFLEET_RERUN").unwrap_or_else(|_| "rerun".to_owned())
}

/// Runs `gapfleet demo` with `args` and `--rrd rrd`; returns its stdout. Panics on failure.
fn record_demo(args: &[&str], rrd: &std::path::Path) -> String {
    let out = Command::new(binary("gapfleet"))
        .arg("demo")
        .args(args)
        .arg("--rrd")
        .arg(rrd)
        .output()
        .expect("gapfleet demo runs");
    assert!(
        out.status.success(),
        "demo failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// `rerun rrd print <verbosity> rrd`: what the recording holds. Panics on failure.
fn rrd_print(verbosity: &str, rrd: &std::path::Path) -> String {
    let cli = rerun_cli();
    let print = Command::new(&cli)
        .args(["rrd", "print", verbosity])
        .arg(rrd)
        .env("RERUN_ANALYTICS", "0")
        .output()
        .unwrap_or_else(|e| panic!("{cli} runs (bash tests/run.sh installs it): {e}"));
    assert!(
        print.status.success(),
        "{}",
        String::from_utf8_lossy(&print.stderr)
    );
    String::from_utf8_lossy(&print.stdout).into_owned()
}

#[test]
fn demo_rrd_passes_rerun_verify_and_holds_the_dashboard() {
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let dir = tmp.path().join("recordings");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let rrd = dir.join("demo.rrd");
    let stdout = record_demo(
        &[
            "--robots",
            "3",
            "--humans",
            "12",
            "--seconds",
            // Two 10 s windows of the human-impact measurement: its series starts after the
            // first, and frames may be dropped (by design) when the logger lags.
            "20",
            "--speed",
            "4",
        ],
        &rrd,
    );
    assert!(stdout.contains("dashboard: "), "{stdout}");
    // The summary leads with the fleet's efficiency against one robot alone.
    assert!(stdout.contains("fleet efficiency "), "{stdout}");
    assert!(
        !stdout.contains("fleet efficiency: not defined"),
        "{stdout}"
    );

    let cli = rerun_cli();
    let verify = Command::new(&cli)
        .args(["rrd", "verify"])
        .arg(&rrd)
        .env("RERUN_ANALYTICS", "0")
        .output()
        .unwrap_or_else(|e| panic!("{cli} runs (bash tests/run.sh installs it): {e}"));
    assert!(
        verify.status.success(),
        "rerun rrd verify failed:\n{}\n{}",
        String::from_utf8_lossy(&verify.stdout),
        String::from_utf8_lossy(&verify.stderr)
    );

    let listing = rrd_print("-vv", &rrd);
    for entity in [
        "/map/shelves",
        "/map/stations",
        "/world/humans",
        "/world/robots",
        "/world/intents",
        "/events",
        "/metrics/svr/fleet",
        "/metrics/collision_rate/fleet",
        "/metrics/tasks_per_minute/fleet",
        "/metrics/efficiency_pct/fleet",
        "/metrics/gridlocks/fleet",
        "/metrics/stuck_s_planner/fleet",
        "/metrics/svr/robot/0",
        "/metrics/min_human_distance/robot/2",
        "/metrics/human_delay_s_per_min/fleet",
        "/metrics/human_extra_path_m_per_min/fleet",
        "/metrics/human_delay_s_per_min/robot/0",
        "/world/safety/protective",
        "/world/safety/warning",
        "/metrics/robot_caused_contacts/fleet",
        "/metrics/person_caused_contacts/fleet",
        "/metrics/protective_robots/fleet",
        "/metrics/stuck_robots/fleet",
        "/metrics/live_agents/fleet",
        // The y-flip, the heatmaps under the map, the robot table, fading event markers.
        "/map",
        "/map/heat/window/near_people",
        "/map/heat/window/contacts",
        "/map/heat/window/stuck",
        "/map/heat/run/near_people",
        "/map/heat/run/contacts",
        "/map/heat/run/stuck",
        "/map/heat/run/people_delay",
        "/fleet/robots",
        "/world/events",
    ] {
        assert!(
            listing.contains(entity),
            "{entity} missing from the recording"
        );
    }
    let values = rrd_print("-vvv", &rrd);
    assert!(
        values.contains("3 robots, ") && values.contains("| robot | planner | state"),
        "no robot table in the recording"
    );
    assert!(
        values.contains("Transform3D:scale"),
        "no y-flip or heatmap placement"
    );
    for timeline in ["tick", "sim_time"] {
        assert!(listing.contains(timeline), "timeline {timeline} missing");
    }
}

/// The real `rerun` executable's path (the wrapper below must not find itself).
fn real_rerun() -> std::path::PathBuf {
    let cli = rerun_cli();
    if cli.contains('/') {
        return cli.into();
    }
    std::env::var_os("PATH")
        .and_then(|paths| {
            std::env::split_paths(&paths)
                .map(|d| d.join(&cli))
                .find(|p| p.is_file())
        })
        .expect("the rerun CLI is installed (bash tests/run.sh installs it)")
}

/// `--spawn` starts a `rerun` viewer process itself (the Rerun SDK's spawn: `rerun` from
/// PATH, on port 9876) and streams to it. A headless machine has no window to show, so the
/// `rerun` found on PATH here is a wrapper that runs the real viewer with `--save FILE`
/// (gRPC server, no window, everything received written to FILE); the file then holds the
/// dashboard.
#[test]
fn spawn_starts_a_viewer_process_and_streams_to_it() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let dir = tmp.path().join("recordings");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let saved = dir.join("spawned.rrd");
    let wrapper = dir.join("rerun");
    std::fs::write(
        &wrapper,
        format!(
            "#!/bin/sh\nexec '{}' \"$@\" --save '{}'\n",
            real_rerun().display(),
            saved.display()
        ),
    )
    .expect("write the wrapper");
    std::fs::set_permissions(&wrapper, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    let path = format!(
        "{}:{}",
        dir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    // The spawned viewer inherits the demo's output streams and outlives it (as a viewer
    // should), so the demo writes to a file rather than to pipes this test would wait on.
    let log = dir.join("demo.log");
    let status = Command::new(binary("gapfleet"))
        .args(["demo", "--robots", "2", "--humans", "8", "--seconds", "5"])
        .args(["--speed", "5", "--spawn"])
        .env("PATH", &path)
        .env("RERUN_ANALYTICS", "0")
        .stdin(std::process::Stdio::null())
        .stdout(std::fs::File::create(&log).expect("log file"))
        .stderr(std::fs::File::create(dir.join("demo.err")).expect("log file"))
        .status()
        .expect("gapfleet demo runs");
    // Stop the spawned viewer. It ignores Ctrl-C while it serves and saves, so it gets
    // SIGTERM, and SIGKILL if it is still there after 5 s: a viewer left behind would hold
    // port 9876, and the next run's demo would stream to it instead of spawning its own.
    let viewer = saved.display().to_string();
    let _ = Command::new("pkill")
        .args(["-TERM", "-f", &viewer])
        .status();
    let running = || {
        Command::new("pgrep")
            .args(["-f", &viewer])
            .stdout(std::process::Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    };
    gapfleet_tests::wait_until(std::time::Duration::from_secs(5), || {
        (!running()).then_some(())
    });
    if running() {
        let _ = Command::new("pkill")
            .args(["-KILL", "-f", &viewer])
            .status();
    }
    assert!(
        status.success(),
        "demo --spawn failed: {}",
        std::fs::read_to_string(dir.join("demo.err")).unwrap_or_default()
    );
    let print = Command::new(real_rerun())
        .args(["rrd", "print"])
        .arg(&saved)
        .env("RERUN_ANALYTICS", "0")
        .output()
        .expect("rerun rrd print runs");
    let listing = String::from_utf8_lossy(&print.stdout);
    for entity in ["/map/shelves", "/world/robots", "/metrics/svr/fleet"] {
        assert!(
            listing.contains(entity),
            "{entity} missing from what the spawned viewer received:\n{}",
            String::from_utf8_lossy(&print.stderr)
        );
    }
}

/// In the narrow warehouse the dashboard draws the traffic policy: the one-way segments with
/// their reservations (a label with the direction and who is inside), who waits on whom,
/// stuck robots, the goals the policy set, its grants in the event log, and the traffic
/// series. `rerun rrd print -vvv` lists the logged values.
#[test]
fn narrow_warehouse_rrd_shows_reserved_segments_and_grants() {
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let dir = tmp.path().join("recordings");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let rrd = dir.join("narrow.rrd");
    record_demo(
        &[
            "--scenario",
            "warehouse-narrow",
            "--robots",
            "10",
            "--humans",
            "20",
            "--seconds",
            "30",
            "--speed",
            "4",
        ],
        &rrd,
    );
    let listing = rrd_print("-vvv", &rrd);
    for entity in [
        "/world/traffic/segments",
        "/world/traffic/directions",
        "/world/traffic/waits",
        "/world/traffic/stuck",
        "/world/traffic/goals",
        "/metrics/stuck_robots/fleet",
        "/metrics/deadlocks/fleet",
        "/metrics/waiting_robots/fleet",
    ] {
        assert!(
            listing.contains(entity),
            "{entity} missing from the recording"
        );
    }
    assert!(
        listing.contains("granted to robot"),
        "no segment grant in the event log"
    );
    let reserved = listing
        .lines()
        .any(|l| l.contains("seg ") && (l.contains("→ in: ") || l.contains("← in: ")));
    assert!(reserved, "no segment drawn as reserved with robots inside");
}
