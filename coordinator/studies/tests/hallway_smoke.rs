//! A small version of the hallway study: the whole pipeline runs, its outputs are complete,
//! and they do not depend on the number of threads.

use studies::Study;
use studies::csv_fields::to_csv;
use studies::hallway::{HallwayStudy, median_time, summarize, write_outputs};
use world_sim::scenario::Scenario;

fn study() -> HallwayStudy {
    let mut scenario = Scenario::builtin("hallway").expect("built-in scenario");
    scenario.robot.max_speed = 3.0;
    scenario.robot.body_occlusion = true;
    HallwayStudy {
        scenario,
        planners: ["pnp", "orca"]
            .iter()
            .map(|p| p.parse().expect("known planner"))
            .collect(),
        lengths: vec![12.0],
        width_m: 4.0,
        speeds: vec![0.5, 1.5],
        first_seed: 1,
        seeds: 2,
    }
}

fn run_with(threads: usize) -> String {
    let study = study();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    let Ok(rows) = pool.install(|| study.execute(&|| {}));
    to_csv(rows)
}

#[test]
fn hallway_smoke_is_complete_and_thread_count_independent() {
    let (one, two) = (run_with(1), run_with(2));
    assert_eq!(one, two, "runs.csv must not depend on --jobs");
    let lines: Vec<&str> = one.lines().collect();
    assert_eq!(lines.len(), 1 + 2 * 2 * 2, "header plus one row per run");
    assert!(lines[0].starts_with("planner,length_m,human_speed,seed,reached,time_to_goal_s"));
    assert!(lines[1].starts_with("pnp,12.0,0.5,1,"), "{}", lines[1]);

    let study = study();
    let Ok(rows) = study.execute(&|| {});
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let out = tmp.path().join("out");
    let summary = write_outputs(&out, &study, &rows).expect("outputs written");
    assert_eq!(summary, summarize(&study, &rows));
    assert_eq!(summary.cells.len(), 2 * 2);
    assert!(summary.cells.iter().all(|c| c.runs == 2));
    // One row per (planner, length) over both speeds.
    assert_eq!(summary.lengths.len(), 2);
    assert!(summary.lengths.iter().all(|l| l.runs == 4));
    for file in [
        "runs.csv",
        "summary.json",
        "time_vs_length.png",
        "social.png",
    ] {
        let len = std::fs::metadata(out.join(file))
            .map(|m| m.len())
            .unwrap_or(0);
        assert!(len > 0, "{file} written");
    }
    // Without a 50 m hallway there is no speed figure.
    assert!(!out.join("time_vs_human_speed_50m.png").exists());
    // Every run drove somewhere: the robot moves off its start in a 12 m hallway.
    assert!(rows.iter().all(|r| r.path_m > 1.0), "{rows:?}");
}

#[test]
fn laned_smoke_sweeps_c3_and_summarises_the_average_speed() {
    use studies::laned::{LanedStudy, five_numbers, summarize};
    let mut scenario = Scenario::builtin("hallway").expect("built-in scenario");
    let hall = scenario.hallway.as_mut().expect("a hallway");
    hall.length_m = 12.0;
    hall.width_m = 3.6;
    hall.lanes = Some(3);
    hall.humans = 6;
    scenario.robot.max_speed = 3.0;
    scenario.robot.body_occlusion = true;
    scenario.robot.safety = false;
    let study = LanedStudy {
        scenario,
        ratios: vec![0.001, 1.0],
        seeds: 2,
    };
    // c3 = 1/(c1·ratio) with c1 = 1.
    assert_eq!(study.params(0.001).c3, 1000.0);
    let Ok(rows) = study.execute(&|| {});
    assert_eq!(rows.len(), 4);
    assert!(
        rows.iter()
            .all(|r| r.average_speed > 0.0 && r.average_speed <= 3.0),
        "{rows:?}"
    );
    let cells = summarize(&study, &rows);
    assert_eq!(cells.len(), 2);
    assert!(cells.iter().all(|c| c.runs == 2));
    // Quartiles by linear interpolation.
    assert_eq!(
        five_numbers(&[4.0, 1.0, 3.0, 2.0, 5.0]),
        [1.0, 2.0, 3.0, 4.0, 5.0]
    );
    assert_eq!(five_numbers(&[1.0, 2.0]), [1.0, 1.25, 1.5, 1.75, 2.0]);
}

#[test]
fn a_run_that_never_arrives_counts_as_slower_than_every_arrival() {
    assert_eq!(median_time(&[Some(3.0), None, Some(1.0)]), Some(3.0));
    assert_eq!(
        median_time(&[Some(3.0), Some(1.0), Some(2.0), None]),
        Some(2.5)
    );
    // Half or more never arrive: no median time.
    assert_eq!(median_time(&[Some(3.0), None]), None);
    assert_eq!(median_time(&[]), None);
}
