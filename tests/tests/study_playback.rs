//! `gapfleet study playback` (`experiment replay` and `experiment eth`, its old names, still
//! work) end to end, as a user runs it: a small smoke version on both recorded crowds, every output file, the table's
//! keys, and clear errors for bad input.

use gapfleet_tests::binary;
use std::path::{Path, PathBuf};
use std::process::Command;

fn dataset(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../world-sim/datasets")
        .join(path)
}

/// A folder named `name` (not yet there) in a temporary folder removed when it is dropped.
fn out_dir(name: &str) -> (tempfile::TempDir, PathBuf) {
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let dir = tmp.path().join(name);
    (tmp, dir)
}

#[test]
fn smoke_runs_on_eth_and_zara01_write_the_tables() {
    // The old names still work, as the results' commands have them.
    for (set, kind, command) in [
        ("ETH/seq_eth", "partial", "eth"),
        ("UCY/zara01", "full", "replay"),
    ] {
        let (_tmp, out) = out_dir(kind);
        let status = Command::new(binary("gapfleet"))
            .args(["experiment", command, "--dataset"])
            .arg(dataset(set))
            .args(["--planners", "foigp,foigp-1,igp-diag,igp-lin,dwa,pgp+orca"])
            .args(["--runs", kind, "--limit", "3", "--jobs", "2", "--out"])
            .arg(&out)
            .output()
            .expect("gapfleet runs");
        let stderr = String::from_utf8_lossy(&status.stderr);
        assert!(status.status.success(), "{set}: {stderr}");
        // It says where foIGP's intents come from: seq_eth's destinations.txt fits its tracks,
        // zara01's is in another frame and is set aside for clustered end points.
        let destinations = if set == "ETH/seq_eth" {
            "4 destinations from destinations.txt"
        } else {
            "destinations.txt set aside"
        };
        assert!(stderr.contains(destinations), "{set}: {stderr}");
        let table: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(out.join("table.json")).expect("table.json"),
        )
        .expect("valid JSON");
        assert_eq!(table["runs"], kind);
        let rows = table["rows"].as_array().expect("rows");
        let names: Vec<&str> = rows.iter().filter_map(|r| r["planner"].as_str()).collect();
        assert_eq!(
            names,
            [
                "human", "foigp", "foigp-1", "igp-diag", "igp-lin", "dwa", "pgp+orca"
            ]
        );
        for row in rows {
            for key in [
                "mean_s",
                "pct_s_lt_0_3",
                "pct_s_lt_0_21",
                "mean_path_m",
                "pct_ratio_gt_1_25",
                "max_ratio",
                "mean_replan_s",
                "mean_density",
            ] {
                assert!(row.get(key).is_some(), "{set} {}: no {key}", row["planner"]);
            }
            assert_eq!(row["runs"], 3);
            assert!(row["mean_path_m"].as_f64().is_some_and(|m| m > 0.0));
        }
        assert!(rows[0]["mean_replan_s"].is_null() && rows[0]["max_ratio"].is_null());
        assert!(rows[1]["mean_replan_s"].as_f64().is_some_and(|t| t > 0.0));
        let csv = std::fs::read_to_string(out.join("runs.csv")).expect("runs.csv");
        assert_eq!(csv.lines().count(), 1 + 7 * 3, "{csv}");
        let md = std::fs::read_to_string(out.join("table.md")).expect("table.md");
        assert!(md.contains("| foigp | 3 | 0 |"), "{md}");
        let png = std::fs::read(out.join("safety_vs_path.png")).expect("figure");
        assert!(png.starts_with(b"\x89PNG"));
    }
}

#[test]
fn bad_input_gets_a_clear_error() {
    let run = |args: &[&str]| {
        let out = Command::new(binary("gapfleet"))
            .args(["study", "playback"])
            .args(args)
            .output()
            .expect("gapfleet runs");
        assert!(!out.status.success(), "{args:?} should fail");
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let (_missing_tmp, missing) = out_dir("missing");
    let err = run(&["--dataset", &missing.display().to_string()]);
    assert!(err.contains("obsmat.txt"), "{err}");
    let (_bad_tmp, bad) = out_dir("bad");
    std::fs::create_dir_all(&bad).expect("temp dir");
    std::fs::write(
        bad.join("obsmat.txt"),
        "780 1 8.4 0 3.5 1.6 0 0.1\n786 1 9.1 0\n",
    )
    .expect("write");
    let err = run(&["--dataset", &bad.display().to_string()]);
    assert!(
        err.contains("obsmat.txt:2:") && err.contains("expected 8 columns"),
        "{err}"
    );
    let eth = dataset("ETH/seq_eth").display().to_string();
    let err = run(&["--dataset", &eth, "--planners", "foigp,rrt"]);
    assert!(err.contains("\"rrt\""), "{err}");
    let err = run(&["--dataset", &eth, "--runs", "some"]);
    assert!(err.contains("partial or full"), "{err}");
}

#[test]
fn playback_has_help_under_all_its_names() {
    for command in ["playback", "replay", "eth"] {
        let out = Command::new(binary("gapfleet"))
            .args(["study", command, "--help"])
            .output()
            .expect("gapfleet runs");
        assert!(out.status.success(), "{command}");
        let help = String::from_utf8_lossy(&out.stdout);
        assert!(
            help.contains("--dataset") && help.contains("recorded crowd"),
            "{help}"
        );
    }
    let out = Command::new(binary("gapfleet"))
        .args(["study", "--help"])
        .output()
        .expect("gapfleet runs");
    assert!(String::from_utf8_lossy(&out.stdout).contains("playback"));
}
