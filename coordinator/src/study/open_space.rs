//! The PGP paper's open-space study (Sec. IV): every algorithm × density × seed, run
//! in-process and in parallel, with identical seeds across algorithms; results written as
//! `runs.csv` (one row per run) and `summary.json` (means per group, and paired Wilcoxon
//! signed-rank comparisons of each PGP+X against X). The output depends only on the inputs,
//! not on the number of threads.

use super::StudyError;
use super::csv_fields::{display, shortest};
use super::summary::{Summary, summarize};
use agent::planner::PlannerSpec;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;
use world_sim::episode::run_episode;
use world_sim::metrics::RobotMetrics;
use world_sim::scenario::Scenario;

/// What to run.
#[derive(Debug, Clone)]
pub struct StudyPlan {
    /// The base scenario (its density and seed are replaced per run).
    pub scenario: Scenario,
    /// Algorithms, in report order.
    pub algorithms: Vec<PlannerSpec>,
    /// People per m².
    pub densities: Vec<f64>,
    /// Seeds 1..=seeds for every (algorithm, density).
    pub seeds: u64,
}

/// One run's outcome.
#[derive(Debug, Clone, PartialEq)]
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

impl StudyPlan {
    /// Every (algorithm, density, seed) in report order.
    pub fn runs(&self) -> Vec<(PlannerSpec, f64, u64)> {
        let mut out = Vec::new();
        for &a in &self.algorithms {
            for &d in &self.densities {
                for seed in 1..=self.seeds {
                    out.push((a, d, seed));
                }
            }
        }
        out
    }

    /// Runs everything on the current rayon pool; `progress` is called after each run.
    pub fn execute(&self, progress: &(dyn Fn() + Sync)) -> Vec<RunRow> {
        self.runs()
            .into_par_iter()
            .map(|(algorithm, density, seed)| {
                let mut scenario = self.scenario.clone();
                if let Some(open) = scenario.open_space.as_mut() {
                    open.density = density;
                }
                scenario.seed = seed;
                let metrics = run_episode(&scenario, algorithm)[0];
                progress();
                RunRow {
                    algorithm,
                    density,
                    seed,
                    metrics,
                }
            })
            .collect()
    }
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
                force_on_people: r.force_on_people,
                human_delay_s: r.human_delay_s,
                human_extra_path_m: r.human_extra_path_m,
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

/// Writes `runs.csv`, `summary.json` and the two figures into `out`.
pub fn write_outputs(out: &Path, plan: &StudyPlan, rows: &[RunRow]) -> Result<Summary, StudyError> {
    std::fs::create_dir_all(out).map_err(StudyError::io(out))?;
    let path = out.join("runs.csv");
    std::fs::write(&path, runs_csv(rows)).map_err(StudyError::io(&path))?;
    write_summary(out, plan, rows)
}

/// Writes `summary.json` and the two figures into `out`.
pub fn write_summary(out: &Path, plan: &StudyPlan, rows: &[RunRow]) -> Result<Summary, StudyError> {
    let summary = summarize(plan, rows);
    super::write_json(&out.join("summary.json"), &summary)?;
    super::plots::write_figures(&summary, out)?;
    Ok(summary)
}
