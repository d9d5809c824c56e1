//! `gapfleet bench world`: the wall model is chosen on the command line and reported, with the
//! set-up time that the field's table adds.

mod common;

use common::gapfleet_json;
use std::process::Command;

fn bench_world(walls: &str) -> serde_json::Value {
    gapfleet_json(&[
        "bench",
        "world",
        "--scenario",
        "warehouse",
        "--humans",
        "40",
        "--steps",
        "20",
        "--walls",
        walls,
        "--json",
    ])
}

#[test]
fn bench_world_reports_the_wall_model_it_ran() {
    for walls in ["points", "field"] {
        let report = bench_world(walls);
        assert_eq!(report["walls"], walls);
        assert_eq!(report["humans"], 40);
        assert_eq!(report["steps"], 20);
        for key in ["median_us_per_step", "steps_per_s", "set_up_s"] {
            let value = report[key].as_f64().unwrap_or(f64::NAN);
            assert!(value.is_finite() && value > 0.0, "{key} = {value}");
        }
    }
    let bad = Command::new(env!("CARGO_BIN_EXE_gapfleet"))
        .args(["bench", "world", "--walls", "grid"])
        .output()
        .expect("gapfleet runs");
    assert!(!bad.status.success());
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(
        stderr.contains("--walls") && stderr.contains("field"),
        "{stderr}"
    );
}
