//! The open-space study's runs: one typed row per run, and `runs.csv`, written and read back
//! through the `csv` crate (so that summaries and figures can be rebuilt without re-running).

use super::csv_fields::{display, shortest};
use agent::planner::PlannerSpec;
use serde::{Deserialize, Serialize};
use world_sim::metrics::RobotMetrics;

/// One run's outcome.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRow {
    /// Planner.
    pub algorithm: PlannerSpec,
    /// People per m².
    pub density: f64,
    /// Scenario seed.
    pub seed: u64,
    /// The robot's metrics.
    pub metrics: RobotMetrics,
}

/// One line of `runs.csv`: a run's planner, density and seed, and the robot's metrics.
/// Numbers are written as Rust prints them (the shortest text that reads back to the same
/// bits); a metric that does not exist for the run (NaN: no time to goal without success) is
/// an empty field.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct RunRecord {
    #[serde(with = "display")]
    algorithm: PlannerSpec,
    #[serde(with = "shortest")]
    density: f64,
    seed: u64,
    success: bool,
    #[serde(with = "shortest")]
    time_to_goal_s: f64,
    #[serde(with = "shortest")]
    path_length_m: f64,
    #[serde(with = "shortest")]
    collision_rate: f64,
    #[serde(with = "shortest")]
    svr: f64,
    #[serde(with = "shortest")]
    social_force: f64,
    #[serde(with = "shortest")]
    min_human_distance_m: f64,
    #[serde(with = "shortest")]
    intimate_time_s: f64,
    #[serde(with = "shortest")]
    personal_time_s: f64,
    #[serde(with = "shortest")]
    still_time_s: f64,
    #[serde(with = "shortest")]
    force_on_people: f64,
    #[serde(with = "shortest")]
    human_delay_s: f64,
    #[serde(with = "shortest")]
    human_extra_path_m: f64,
    robot_caused_contacts: u64,
    person_caused_contacts: u64,
    wall_contacts: u64,
}

impl From<&RunRow> for RunRecord {
    fn from(r: &RunRow) -> Self {
        let m = &r.metrics;
        Self {
            algorithm: r.algorithm,
            density: r.density,
            seed: r.seed,
            success: m.success,
            time_to_goal_s: m.time_to_goal_s,
            path_length_m: m.path_length_m,
            collision_rate: m.collision_rate,
            svr: m.svr,
            social_force: m.social_force,
            min_human_distance_m: m.min_human_distance_m,
            intimate_time_s: m.intimate_time_s,
            personal_time_s: m.personal_time_s,
            still_time_s: m.still_time_s,
            force_on_people: m.force_on_people,
            human_delay_s: m.human_delay_s,
            human_extra_path_m: m.human_extra_path_m,
            robot_caused_contacts: m.robot_caused_contacts,
            person_caused_contacts: m.person_caused_contacts,
            wall_contacts: m.wall_contacts,
        }
    }
}

impl From<RunRecord> for RunRow {
    fn from(r: RunRecord) -> Self {
        Self {
            algorithm: r.algorithm,
            density: r.density,
            seed: r.seed,
            metrics: RobotMetrics {
                success: r.success,
                time_to_goal_s: r.time_to_goal_s,
                path_length_m: r.path_length_m,
                collision_rate: r.collision_rate,
                svr: r.svr,
                social_force: r.social_force,
                min_human_distance_m: r.min_human_distance_m,
                intimate_time_s: r.intimate_time_s,
                personal_time_s: r.personal_time_s,
                still_time_s: r.still_time_s,
                // Robot–robot counts: the open-space study has one robot.
                robot_near_misses: 0,
                robot_contacts: 0,
                robot_robot_contacts: 0,
                force_on_people: r.force_on_people,
                human_delay_s: r.human_delay_s,
                human_extra_path_m: r.human_extra_path_m,
                robot_caused_contacts: r.robot_caused_contacts,
                person_caused_contacts: r.person_caused_contacts,
                wall_contacts: r.wall_contacts,
                // Not in the open-space study's runs.csv.
                personal_space_entries: 0,
                human_path_changes: 0,
            },
        }
    }
}

/// `runs.csv`: a header and one line per run.
pub fn runs_csv(rows: &[RunRow]) -> String {
    if rows.is_empty() {
        return runs_csv_header() + "\n";
    }
    super::csv_fields::to_csv(rows.iter().map(RunRecord::from))
}

/// `runs.csv`'s header line.
pub fn runs_csv_header() -> String {
    super::csv_fields::header(&RunRecord::from(&RunRow {
        algorithm: PlannerSpec::STUDY[0],
        density: 0.0,
        seed: 0,
        metrics: RobotMetrics::default(),
    }))
}

/// Why a `runs.csv` could not be read back.
#[derive(Debug, thiserror::Error)]
pub enum CsvError {
    /// The first line is not this study's header.
    #[error("runs.csv line 1: not a gapfleet open-space runs.csv header (expected {expected:?})")]
    Header {
        /// The header [`runs_csv`] writes.
        expected: String,
    },
    /// A line does not hold a run.
    #[error("runs.csv line {line}: {source}")]
    Row {
        /// Line number, from 1.
        line: u64,
        /// What the CSV reader found.
        source: csv::Error,
    },
}

impl CsvError {
    fn row(source: csv::Error) -> Self {
        Self::Row {
            line: source.position().map_or(1, |p| p.line()),
            source,
        }
    }
}

/// A `runs.csv` read back.
#[derive(Debug, Clone)]
pub struct ParsedRuns {
    /// The rows, in file order.
    pub rows: Vec<RunRow>,
    /// The algorithms, in order of first appearance.
    pub algorithms: Vec<PlannerSpec>,
    /// The densities, in order of first appearance.
    pub densities: Vec<f64>,
}

/// Reads `runs.csv` back (the inverse of [`runs_csv`]), so that summaries and figures can be
/// rebuilt without re-running.
pub fn parse_runs_csv(text: &str) -> Result<ParsedRuns, CsvError> {
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let expected = runs_csv_header();
    let found = reader.headers().map_err(CsvError::row)?;
    if found.iter().ne(expected.split(',')) {
        return Err(CsvError::Header { expected });
    }
    let (mut rows, mut algorithms, mut densities) = (Vec::new(), Vec::new(), Vec::new());
    for record in reader.deserialize::<RunRecord>() {
        let row = RunRow::from(record.map_err(CsvError::row)?);
        if !algorithms.contains(&row.algorithm) {
            algorithms.push(row.algorithm);
        }
        if !densities.contains(&row.density) {
            densities.push(row.density);
        }
        rows.push(row);
    }
    Ok(ParsedRuns {
        rows,
        algorithms,
        densities,
    })
}
