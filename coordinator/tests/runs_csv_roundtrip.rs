//! `runs.csv` reads back into the same rows, so summaries and figures can be rebuilt from it.

use coordinator::experiment::{StudyPlan, parse_runs_csv, runs_csv, summarize};
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
        seeds: 2,
    };
    let rows = plan.execute(&|| {});
    let csv = runs_csv(&rows);
    let back = parse_runs_csv(&csv).expect("our own output parses");
    assert_eq!(runs_csv(&back.rows), csv);
    assert_eq!(
        (back.algorithms, back.densities),
        (plan.algorithms.clone(), plan.densities.clone())
    );
    assert_eq!(summarize(&plan, &back.rows), summarize(&plan, &rows));
}

#[test]
fn malformed_runs_csv_names_the_line() {
    let err = parse_runs_csv("algorithm,density,seed,success,x\ndwa,0.1,1,true\n")
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 2"), "{err}");
    let err = parse_runs_csv("hello\n").unwrap_err().to_string();
    assert!(err.contains("line 1"), "{err}");
}
