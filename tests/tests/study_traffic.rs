//! `gapfleet study traffic` on the command line: runs are saved as they end, and a study
//! killed part-way goes on from what it saved (`--resume`) to the same bits; runs of an
//! earlier `runs.csv` can be reused; a site can be left out; no sites at all is a clear error.

use std::path::Path;
use std::process::{Command, Output};

/// Two seeds of 2 s.
const SHORT: [&str; 4] = ["--seeds", "2", "--seconds", "2"];

/// `study traffic` of a 2-robot narrow warehouse with the policy on, one thread, into `out`;
/// `extra` gives the seeds and seconds, and more.
fn traffic_command(out: &Path, extra: &[&str]) -> Command {
    let mut command = Command::new(gapfleet_tests::binary("gapfleet"));
    command
        .args(["study", "traffic"])
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
        .args(extra);
    command
}

/// [`traffic_command`] run to its end.
fn traffic(out: &Path, extra: &[&str]) -> Output {
    traffic_command(out, extra).output().expect("gapfleet runs")
}

fn rows(csv: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(csv).expect("readable");
    text.lines().map(str::to_owned).collect()
}

#[test]
fn an_interrupted_study_goes_on_from_the_runs_it_saved() {
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let (whole, cut) = (tmp.path().join("whole"), tmp.path().join("cut"));
    let longer = ["--seeds", "3", "--seconds", "20"];
    let done = traffic(&whole, &longer);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    // Finished: the checkpoint is gone, runs.csv has every seed (and no hallway runs).
    assert!(!whole.join("checkpoint.bin").exists());
    let all = rows(&whole.join("runs.csv"));
    assert_eq!(all.len(), 4, "{all:?}");
    assert!(
        all[1..]
            .iter()
            .all(|r| r.starts_with("warehouse-narrow,2,true,"))
    );

    // Killed once the first run is saved (the header is 24 bytes, a record more).
    let mut child = traffic_command(&cut, &longer)
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("gapfleet starts");
    let checkpoint = cut.join("checkpoint.bin");
    let saved = gapfleet_tests::wait_until(std::time::Duration::from_secs(120), || {
        std::fs::metadata(&checkpoint)
            .is_ok_and(|m| m.len() > 28)
            .then_some(())
    });
    child.kill().expect("killed");
    child.wait().expect("reaped");
    assert!(saved.is_some(), "no run saved within 120 s");
    assert!(!cut.join("runs.csv").exists(), "killed before the end");

    // Without --resume it refuses to start over the saved runs.
    let refused = traffic(&cut, &longer);
    assert!(!refused.status.success());
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(stderr.contains("pass --resume"), "{stderr}");

    let resumed = traffic(&cut, &[&longer[..], &["--resume"]].concat());
    let stderr = String::from_utf8_lossy(&resumed.stderr);
    assert!(resumed.status.success(), "{stderr}");
    assert!(!stderr.contains("(0 resumed)"), "{stderr}");
    assert!(!checkpoint.exists());
    assert_eq!(
        rows(&cut.join("runs.csv")),
        all,
        "the same bits as uninterrupted"
    );
}

#[test]
fn runs_of_an_earlier_runs_csv_are_reused() {
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let (first, second) = (tmp.path().join("first"), tmp.path().join("second"));
    let done = traffic(&first, &SHORT);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let all = rows(&first.join("runs.csv"));
    assert_eq!(all.len(), 3, "{all:?}");
    // Seed 1's row, marked so that reusing it shows.
    std::fs::create_dir_all(&second).expect("writable");
    let earlier = second.join("earlier.csv");
    let seed_1 = all[1].replacen(
        "warehouse-narrow,2,true,1,",
        "warehouse-narrow,2,true,1,999",
        1,
    );
    std::fs::write(&earlier, format!("{}\n{seed_1}\n", all[0])).expect("writable");
    let reuse = earlier.to_str().expect("UTF-8 path");
    let reused = traffic(
        &second,
        &[&SHORT[..], &["--reuse", reuse, "--reuse-policy", "on"]].concat(),
    );
    assert!(
        reused.status.success(),
        "{}",
        String::from_utf8_lossy(&reused.stderr)
    );
    let again = rows(&second.join("runs.csv"));
    // Seed 1 taken from the earlier row, seed 2 run afresh, the same bits as before.
    assert_eq!(again, [all[0].clone(), seed_1, all[2].clone()]);
}

#[test]
fn no_sites_at_all_is_a_clear_error() {
    let out = Command::new(gapfleet_tests::binary("gapfleet"))
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
    let out = Command::new(gapfleet_tests::binary("gapfleet"))
        .args(["study", "traffic", "--narrow-fleets", "10,x"])
        .output()
        .expect("gapfleet runs");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("fleet size `x`"), "{stderr}");
}
