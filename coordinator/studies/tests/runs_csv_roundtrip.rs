//! `runs.csv` reads back into the same rows, so summaries and figures can be rebuilt from it.

use studies::Study;
use studies::open_space::StudyPlan;
use studies::runs::{parse_runs_csv, runs_csv, runs_csv_header};
use world_sim::scenario::Scenario;

#[test]
fn runs_csv_round_trips_and_rebuilds_the_same_summary() {
    let plan = StudyPlan {
        scenario: Scenario::builtin("open-space").expect("built-in"),
        algorithms: vec![
            "orca".parse().expect("known"),
            "pgp+orca".parse().expect("known"),
        ],
        densities: vec![0.2],
        first_seed: 1,
        seeds: 2,
    };
    let Ok(rows) = plan.execute(&|| {});
    let csv = runs_csv(&rows);
    let back = parse_runs_csv(&csv).expect("our own output parses");
    assert_eq!(runs_csv(&back.rows), csv);
    assert_eq!(
        (back.algorithms, back.densities),
        (plan.algorithms.clone(), plan.densities.clone())
    );
    assert_eq!(plan.summarize(&back.rows), plan.summarize(&rows));
}

#[test]
fn malformed_runs_csv_names_the_line() {
    let header = runs_csv_header();
    assert_eq!(runs_csv(&[]), format!("{header}\n"));
    // A row with too few fields, and one whose number is not a number.
    let short = format!("{header}\ndwa,0.1,1,true\n");
    let err = parse_runs_csv(&short).unwrap_err().to_string();
    assert!(err.contains("line 2"), "{err}");
    let fields = header.split(',').count();
    let mut row = vec!["1"; fields];
    row[0] = "dwa";
    row[3] = "true";
    row[4] = "fast";
    let bad_number = format!("{header}\n{}\n{}\n", row.join(","), row.join(","));
    let err = parse_runs_csv(&bad_number).unwrap_err().to_string();
    assert!(err.contains("line 2") && err.contains("float"), "{err}");
    // Not this study's file at all.
    let err = parse_runs_csv("hello\n").unwrap_err().to_string();
    assert!(err.contains("line 1"), "{err}");
}
