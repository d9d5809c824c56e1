//! A small version of the anticipatory Social Force experiment: the whole pipeline runs, its
//! outputs are complete, they do not depend on the number of threads, and its rows are the
//! committed ones.

use agent::asfm::AsfmParams;
use studies::Study;
use studies::anticipatory::{AnticipatoryStudy, Method, run, summarize, write_outputs};
use studies::csv_fields::to_csv;

fn study() -> AnticipatoryStudy {
    AnticipatoryStudy {
        params: AsfmParams::default(),
        a_o: vec![20.0, 0.0],
        runs: 2,
    }
}

#[test]
fn anticipatory_smoke_is_complete_committed_and_thread_count_independent() {
    let run_with = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("thread pool");
        pool.install(|| {
            let Ok(rows) = study().execute(&|| {});
            rows
        })
    };
    let rows = run_with(2);
    let csv = to_csv(rows.clone());
    assert_eq!(
        csv,
        to_csv(run_with(1)),
        "runs.csv must not depend on --jobs"
    );
    assert_eq!(
        csv.lines().count(),
        1 + 2 * 3 * 2,
        "header plus one row per run"
    );
    // Every row is in the committed results/anticipatory/runs.csv (same header).
    let path = format!(
        "{}/../../results/anticipatory/runs.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let committed = std::fs::read_to_string(&path).expect("the committed experiment");
    let mut lines = csv.lines();
    assert_eq!(lines.next(), committed.lines().next(), "runs.csv columns");
    for line in lines {
        assert!(
            committed.lines().any(|l| l == line),
            "not committed: {line}"
        );
    }

    let study = study();
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let out = tmp.path().join("out");
    let cells = write_outputs(&out, &study, &rows).expect("outputs written");
    assert_eq!(cells, summarize(&study, &rows));
    assert_eq!(cells.len(), 2 * 3);
    for file in [
        "runs.csv",
        "summary.json",
        "estimate.csv",
        "estimate.png",
        "min_distance_ao20.png",
        "movement_time_ao0.png",
    ] {
        let len = std::fs::metadata(out.join(file))
            .map(|m| m.len())
            .unwrap_or(0);
        assert!(len > 0, "{file} written");
    }
}

#[test]
fn assuming_an_obstacle_avoids_when_it_does_not_breaks_d_min() {
    // The paper's Fig. 6(a): against A_o = 0, a fixed Â_o = 20 passes closer than d_min; the
    // correct Â_o = 0 and the estimate keep it.
    let p = AsfmParams::default();
    for seed in 1..=3 {
        let wrong = run(0.0, Method::Fixed(20.0), seed, &p).0;
        let right = run(0.0, Method::Fixed(0.0), seed, &p).0;
        let estimated = run(0.0, Method::Estimated, seed, &p).0;
        assert!(wrong.min_distance_m < p.d_min, "{wrong:?}");
        assert!(right.min_distance_m > p.d_min, "{right:?}");
        assert!(estimated.min_distance_m > p.d_min, "{estimated:?}");
        assert!(estimated.final_estimate.abs() < 2.0, "{estimated:?}");
    }
}

#[test]
fn the_estimates_check_runs_on_a_recording_and_in_the_simulator() {
    use studies::estimates::{
        EstimatesStudy, RecordedCrowd, SimCrowd, mixed_auc, mixed_closest_auc, summarize,
    };
    use world_sim::dataset::Recording;
    use world_sim::playback::{PlaybackOptions, map_of, median_speed};
    let dir = format!(
        "{}/../../world-sim/datasets/ETH/seq_eth",
        env!("CARGO_MANIFEST_DIR")
    );
    let recording = Recording::load(std::path::Path::new(&dir)).expect("seq_eth");
    let map = map_of(&recording).expect("its map");
    let mut options = PlaybackOptions::default();
    options.robot.max_speed = median_speed(&recording);
    let base = world_sim::scenario::Scenario::builtin("open-space").expect("built in");
    let study = EstimatesStudy {
        recorded: vec![RecordedCrowd {
            recording,
            map,
            options,
        }],
        limit: Some(2),
        base: base.clone(),
        crowds: vec![(SimCrowd::Reacting, 0.1)],
        seeds: 1..=1,
        params: AsfmParams::default(),
    };
    let Ok(rows) = study.execute(&|| {});
    let mut rows: Vec<_> = rows.into_iter().flatten().collect();
    // The paper's planner keeps too far from people for 3 s near it; `asfm-crowd` passes.
    let mixed = EstimatesStudy {
        recorded: Vec::new(),
        crowds: vec![(SimCrowd::Mixed(0.5), 0.3)],
        seeds: 1..=2,
        params: AsfmParams::crowd(),
        ..study
    };
    let Ok(mixed) = mixed.execute(&|| {});
    let mixed: Vec<_> = mixed.into_iter().flatten().collect();
    for auc in [mixed_auc(&mixed), mixed_closest_auc(&mixed)] {
        assert!(
            auc.is_some_and(|a| (0.0..=1.0).contains(&a)),
            "both kinds near the robot for 3 s: {mixed:?}"
        );
    }
    // Each person's closest approach is a gap between surfaces, within the sensor's range.
    assert!(mixed.iter().all(|r| r.closest_m < 12.0), "{mixed:?}");
    rows.extend(mixed);
    let summary = summarize(&rows);
    let sources: Vec<&str> = summary.iter().map(|s| s.source.as_str()).collect();
    assert_eq!(sources[..2], ["seq_eth", "sim-reacting"]);
    assert!(sources.contains(&"sim-mixed-reacting") && sources.contains(&"sim-mixed-ignoring"));
    assert!(summary.iter().all(|s| s.people > 0), "{summary:?}");
    // Estimates are posterior means over the samples in [−40, 40].
    assert!(rows.iter().all(|r| r.estimate.abs() <= 40.0), "{rows:?}");
}

#[test]
fn the_auc_is_the_chance_a_reacting_person_scores_above_an_ignoring_one() {
    use studies::estimates::auc;
    assert_eq!(auc(&[3.0, 4.0], &[1.0, 2.0]), Some(1.0));
    assert_eq!(auc(&[1.0, 2.0], &[3.0, 4.0]), Some(0.0));
    // 3 beats 1 and 2, ties 3 (half), 1 ties 1 (half) and loses to 2 and 3: (2.5 + 0.5) / 6.
    assert_eq!(auc(&[3.0, 1.0], &[1.0, 2.0, 3.0]), Some(0.5));
    assert_eq!(auc(&[], &[1.0]), None);
}
