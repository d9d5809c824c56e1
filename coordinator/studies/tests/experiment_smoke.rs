//! A small version of the open-space study: the whole pipeline runs, its outputs are complete,
//! and they do not depend on the number of threads.

use studies::Study;
use studies::open_space::StudyPlan;
use studies::runs::runs_csv;
use world_sim::scenario::Scenario;

fn plan() -> StudyPlan {
    StudyPlan {
        scenario: Scenario::builtin("open-space").expect("built-in scenario"),
        algorithms: ["orca", "pgp+orca", "sf", "pgp+sf"]
            .iter()
            .map(|a| a.parse().expect("known planner"))
            .collect(),
        densities: vec![0.1, 0.3],
        first_seed: 1,
        seeds: 3,
    }
}

fn run_with(threads: usize) -> (String, String) {
    let plan = plan();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let Ok(rows) = pool.install(|| plan.execute(&|| {}));
    let summary = plan.summarize(&rows);
    (
        runs_csv(&rows),
        serde_json::to_string_pretty(&summary).expect("serialisable"),
    )
}

#[test]
fn study_smoke_is_complete_and_thread_count_independent() {
    let (csv1, json1) = run_with(1);
    let (csv2, json2) = run_with(2);
    assert_eq!(csv1, csv2, "runs.csv must not depend on --jobs");
    assert_eq!(json1, json2, "summary.json must not depend on --jobs");

    let lines: Vec<&str> = csv1.lines().collect();
    assert_eq!(lines.len(), 1 + 4 * 2 * 3, "header plus one row per run");
    assert!(lines[0].starts_with("algorithm,density,seed,success,time_to_goal_s"));

    let summary: serde_json::Value = serde_json::from_str(&json1).expect("valid JSON");
    let groups = summary["groups"].as_array().expect("groups");
    assert_eq!(groups.len(), 8);
    assert!(groups.iter().all(|g| g["runs"] == 3));
    let comparisons = summary["comparisons"].as_array().expect("comparisons");
    assert_eq!(comparisons.len(), 2 * 7, "two PGP+X pairs × seven metrics");
    for c in comparisons {
        assert_eq!(c["pairs"].as_u64().map(|p| p > 0), Some(true), "{c}");
    }
    // At low density every planner gets through.
    for g in groups.iter().filter(|g| g["density"] == 0.1) {
        assert_eq!(g["success_rate"], 1.0, "{g}");
    }
}
