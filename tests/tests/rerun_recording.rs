//! A short demo records its dashboard to an .rrd file; the official `rerun` CLI (rerun-sdk
//! 0.36.3 from PyPI, installed by tests/run.sh) verifies the file and lists what it holds.

use gapfleet_tests::binary;
use std::process::Command;

/// The `rerun` CLI: $GAPFLEET_RERUN (tests/run.sh sets it) or `rerun` on PATH.
fn rerun_cli() -> String {
    std::env::var("GAPFLEET_RERUN").unwrap_or_else(|_| "rerun".to_owned())
}

#[test]
fn demo_rrd_passes_rerun_verify_and_holds_the_dashboard() {
    let dir = std::env::temp_dir().join(format!("gapfleet-rrd-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let rrd = dir.join("demo.rrd");
    let out = Command::new(binary("gapfleet"))
        .args([
            "demo",
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
        ])
        .arg("--rrd")
        .arg(&rrd)
        .output()
        .expect("gapfleet demo runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "demo failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("dashboard: "), "{stdout}");

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

    let print = Command::new(&cli)
        .args(["rrd", "print", "-vv"])
        .arg(&rrd)
        .env("RERUN_ANALYTICS", "0")
        .output()
        .expect("rerun rrd print runs");
    let listing = String::from_utf8_lossy(&print.stdout);
    assert!(
        print.status.success(),
        "{}",
        String::from_utf8_lossy(&print.stderr)
    );
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
        "/metrics/svr/robot/0",
        "/metrics/min_human_distance/robot/2",
        "/metrics/human_delay_s_per_min/fleet",
        "/metrics/human_extra_path_m_per_min/fleet",
    ] {
        assert!(
            listing.contains(entity),
            "{entity} missing from the recording"
        );
    }
    for timeline in ["tick", "sim_time"] {
        assert!(listing.contains(timeline), "timeline {timeline} missing");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
