//! The committed study results are what the code computes now: a smoke version of the
//! open-space study reproduces its cells of `results/open-space/runs.csv` (the papers'
//! protocol: no safety layer) and of `results/open-space-safety/runs.csv` (the layer under
//! every planner) byte for byte, as do `asfm-crowd`'s and `pgp+asfm-crowd`'s, and small versions of the laned, hallway and traffic studies
//! reproduce rows of `results/laned/runs.csv`, `results/hallway/runs.csv` (and of
//! `pnp-side` and `pnp-side-brake` under the layer in `results/hallway-layer-heldout`) and
//! `results/traffic/runs.csv`. A change that moves any
//! bit of any planner, of the layer or of the crowd fails here; if the change is meant to,
//! re-run the study and commit its results (each study's REPORT.md has the command).

use studies::Study;
use studies::csv_fields::to_csv;
use studies::open_space::StudyPlan;
use studies::runs::runs_csv;
use world_sim::scenario::Scenario;

#[test]
fn open_space_smoke_rows_are_the_committed_rows() {
    smoke_rows_are_committed("open-space", false, &PLANNERS, &[0.1, 0.5, 1.0]);
}

#[test]
fn open_space_smoke_rows_under_the_safety_layer_are_the_committed_rows() {
    smoke_rows_are_committed("open-space-safety", true, &PLANNERS, &[0.1, 0.5, 1.0]);
}

/// `asfm-crowd` in the crowds it was made for (`results/open-space/asfm-crowd`).
#[test]
fn asfm_crowd_smoke_rows_are_the_committed_rows() {
    smoke_rows_are_committed(
        "open-space/asfm-crowd/seeds-1-100",
        true,
        &["asfm-crowd"],
        &[0.2, 0.5],
    );
}

/// `pgp+asfm-crowd`, PGP's subgoals in front of it (`results/open-space/pgp+asfm-crowd`).
#[test]
fn pgp_asfm_crowd_smoke_rows_are_the_committed_rows() {
    smoke_rows_are_committed(
        "open-space/pgp+asfm-crowd/seeds-1-100",
        true,
        &["pgp+asfm-crowd"],
        &[0.3, 0.6],
    );
}

fn smoke_rows_are_committed(dir: &str, safety: bool, planners: &[&str], densities: &[f64]) {
    let path = format!(
        "{}/../../results/{dir}/runs.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let committed = std::fs::read_to_string(&path).expect("the committed study");
    let mut scenario = Scenario::builtin("open-space").expect("built-in");
    scenario.robot.safety = safety;
    as_committed(&mut scenario);
    let plan = StudyPlan {
        scenario,
        algorithms: planners.iter().map(|a| a.parse().expect("known")).collect(),
        densities: densities.to_vec(),
        first_seed: 1,
        seeds: 2,
    };
    let Ok(rows) = plan.execute(&|| {});
    let ours = runs_csv(&rows);
    let mut lines = ours.lines();
    let header = lines.next().expect("a header");
    assert_eq!(Some(header), committed.lines().next(), "runs.csv columns");
    let mut compared = 0;
    for line in lines {
        // The committed row of the same (algorithm, density, seed).
        let cell: Vec<&str> = line.splitn(4, ',').take(3).collect();
        let key = cell.join(",") + ",";
        let theirs = committed
            .lines()
            .find(|l| l.starts_with(&key))
            .unwrap_or_else(|| panic!("no committed row for {key}"));
        assert_eq!(line, theirs, "run {key}");
        compared += 1;
    }
    assert_eq!(compared, planners.len() * densities.len() * 2);
}

const PLANNERS: [&str; 6] = ["dwa", "orca", "sf", "pgp+dwa", "pgp+orca", "pgp+sf"];

/// The laned study (`results/laned`): two seeds at two ratios, re-run as the command runs them,
/// are the committed rows.
#[test]
fn laned_smoke_rows_are_the_committed_rows() {
    use studies::laned::{LanedStudy, laned_hallway};
    let study = LanedStudy {
        scenario: laned_hallway(50.0, 3, 1.0, 3.0, false).expect("valid"),
        ratios: vec![0.0001, 0.01],
        seeds: 2,
    };
    let Ok(rows) = study.execute(&|| {});
    rows_are_committed("laned", &to_csv(rows), 4);
}

/// The hallway study (`results/hallway`): pnp and orca in the 25 m hallway at two human
/// speeds, two seeds, re-run as the command runs them, are the committed rows.
#[test]
fn hallway_smoke_rows_are_the_committed_rows() {
    let rows = hallway_rows(false, &["pnp", "orca"], 1, 2);
    rows_are_committed("hallway", &rows, 2 * 2 * 2);
}

/// `pnp-side` in the hallway under the layer (`results/hallway-layer-heldout/pnp-side`): its
/// first held-out seed at 25 m with people at 1 and 2.5 m/s.
#[test]
fn pnp_side_hallway_rows_are_the_committed_rows() {
    let rows = hallway_rows(true, &["pnp-side"], 101, 1);
    rows_are_committed("hallway-layer-heldout/pnp-side", &rows, 2);
}

/// `pnp-side-brake` in the hallway under the layer
/// (`results/hallway-layer-heldout/pnp-side-brake`): the same seed, lengths and speeds.
#[test]
fn pnp_side_brake_hallway_rows_are_the_committed_rows() {
    let rows = hallway_rows(true, &["pnp-side-brake"], 101, 1);
    rows_are_committed("hallway-layer-heldout/pnp-side-brake", &rows, 2);
}

/// The hallway study's runs.csv for `planners` in the 25 m hallway with people at 1 and
/// 2.5 m/s, `seeds` seeds from `first_seed`, the layer on or off.
fn hallway_rows(safety: bool, planners: &[&str], first_seed: u64, seeds: u64) -> String {
    use studies::hallway::{HallwayStudy, hallway_scenario};
    let mut scenario = hallway_scenario(3.0, safety).expect("valid");
    as_committed(&mut scenario);
    let study = HallwayStudy {
        scenario,
        planners: planners.iter().map(|p| p.parse().expect("known")).collect(),
        lengths: vec![25.0],
        width_m: 4.0,
        speeds: vec![1.0, 2.5],
        first_seed,
        seeds,
    };
    let Ok(rows) = study.execute(&|| {});
    to_csv(rows)
}

/// The fleet traffic study (`results/traffic`): seed 1 of the 10-robot fleets in both sites,
/// policy off and on, 300 s each as the command runs them, are the committed rows.
#[test]
fn traffic_rows_are_the_committed_rows() {
    use studies::traffic::{Site, TrafficStudy};
    let site = |name: &str| {
        let mut scenario = Scenario::builtin(name).expect("built-in");
        as_committed(&mut scenario);
        Site {
            scenario,
            fleets: vec![10],
        }
    };
    let study = TrafficStudy {
        sites: vec![site("warehouse-narrow"), site("hallway-fleet")],
        planner: "pgp+orca".parse().expect("known"),
        first_seed: 1,
        seeds: 1,
        policies: vec![false, true],
        layers: vec![true],
        seconds: 300.0,
        // Committed before robots turned round from people in their way (results/people-turn)
        // and left an aisle they were alone in by either end (results/way-out).
        policy_params: world_sim::traffic_policy::PolicyParams {
            people_turn_after_s: 0.0,
            alone_exit_clear_m: 0.0,
            ..Default::default()
        },
    };
    let runs = study.execute(&|| {}).expect("fleet sites");
    rows_are_committed("traffic", &to_csv(&runs), 4);
}

/// These studies were committed while the safety layer let people stop dead from walking
/// speed (`SafetyParams::people_stop_dead`, on until results/halting) and swerve at a_h
/// everywhere (`person_accel_away`, 2 m/s² away from a warehouse's stations since
/// results/swerve-allowance), and while robots reached every corner on a narrow aisle
/// closely (`cut_clear_corners`, since results/corner-cut), and while the hallway fleet warned
/// a second ahead (`warning_time`, 0.5 s since results/warning-time): their runs reproduce
/// with all four as they were.
fn as_committed(scenario: &mut Scenario) {
    let layer = &mut scenario.robot.safety_layer;
    layer.people_stop_dead = true;
    layer.person_accel_away = layer.person_accel;
    layer.warning_time = 1.0;
    if let Some(warehouse) = &mut scenario.warehouse {
        warehouse.cut_clear_corners = false;
    }
}

/// Every row of `ours` (a runs.csv with its header) is a line of `results/<dir>/runs.csv`,
/// under the same header, and there are `rows` of them.
fn rows_are_committed(dir: &str, ours: &str, rows: usize) {
    let path = format!(
        "{}/../../results/{dir}/runs.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let committed = std::fs::read_to_string(&path).expect("the committed study");
    let mut lines = ours.lines();
    assert_eq!(lines.next(), committed.lines().next(), "runs.csv columns");
    let mut compared = 0;
    for line in lines {
        assert!(
            committed.lines().any(|l| l == line),
            "not committed: {line}"
        );
        compared += 1;
    }
    assert_eq!(compared, rows);
}
