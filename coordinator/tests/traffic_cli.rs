//! `gapfleet study traffic` on the command line: runs are saved as they end and a study
//! interrupted part-way goes on from what it saved; a site can be left out; no sites at all
//! is a clear error.

use std::path::Path;
use std::process::{Command, Output};

fn traffic(out: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gapfleet"))
        .args(["study", "traffic", "--seeds", "2", "--seconds", "2"])
        .args([
            "--narrow-fleets",
            "2",
            "--hallway-fleets",
            "",
            "--policy",
            "on",
        ])
        .args(["--jobs", "1", "--out"])
        .arg(out)
        .args(extra)
        .output()
        .expect("gapfleet runs")
}

fn rows(csv: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(csv).expect("readable");
    text.lines().map(str::to_owned).collect()
}

#[test]
fn an_interrupted_study_goes_on_from_the_runs_it_saved() {
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let base = tmp.path().join("study");
    let (first, second) = (base.join("first"), base.join("second"));
    let done = traffic(&first, &[]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let stderr = String::from_utf8_lossy(&done.stderr);
    assert!(stderr.contains("runs.partial.csv"), "{stderr}");
    // Finished: the partial file is gone, runs.csv has both seeds (and no hallway runs).
    assert!(!first.join("runs.partial.csv").exists());
    let all = rows(&first.join("runs.csv"));
    assert_eq!(all.len(), 3, "{all:?}");
    assert!(
        all[1..]
            .iter()
            .all(|r| r.starts_with("warehouse-narrow,2,true,"))
    );

    // As if interrupted after seed 1: its row saved, marked so that reusing it shows.
    std::fs::create_dir_all(&second).expect("writable");
    let partial = second.join("runs.partial.csv");
    let seed_1 = all[1].replacen(
        "warehouse-narrow,2,true,1,",
        "warehouse-narrow,2,true,1,999",
        1,
    );
    std::fs::write(&partial, format!("{}\n{seed_1}\n", all[0])).expect("writable");
    let reuse = partial.to_str().expect("UTF-8 path");
    let resumed = traffic(&second, &["--reuse", reuse, "--reuse-policy", "on"]);
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    assert!(!partial.exists());
    let again = rows(&second.join("runs.csv"));
    // Seed 1 taken from the saved row, seed 2 run afresh, the same bits as before.
    assert_eq!(again, [all[0].clone(), seed_1, all[2].clone()]);
}

#[test]
fn no_sites_at_all_is_a_clear_error() {
    let out = Command::new(env!("CARGO_BIN_EXE_gapfleet"))
        .args([
            "study",
            "traffic",
            "--narrow-fleets",
            "",
            "--hallway-fleets",
            "",
        ])
        .output()
        .expect("gapfleet runs");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("no fleet sizes given"), "{stderr}");
    let out = Command::new(env!("CARGO_BIN_EXE_gapfleet"))
        .args(["study", "traffic", "--narrow-fleets", "10,x"])
        .output()
        .expect("gapfleet runs");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("fleet size `x`"), "{stderr}");
}
