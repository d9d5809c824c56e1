//! The PGP paper's open-space study (Sec. IV): every algorithm × density × seed, run
//! in-process and in parallel, with identical seeds across algorithms; results written as
//! `runs.csv` (one row per run) and `summary.json` (means per group, and paired Wilcoxon
//! signed-rank comparisons of each PGP+X against X). The output depends only on the inputs,
//! not on the number of threads.

use super::output::{StudyError, write_json};
use super::runner::Study;
use super::runs::{RunRow, runs_csv};
use super::summary::{Summary, summarize};
use agent::planner::PlannerSpec;
use std::path::Path;
use world_sim::episode::run_episode;
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
    /// The first seed: every (algorithm, density) runs seeds `first_seed` to
    /// `first_seed + seeds - 1` (1 for the tuning seeds, 101 for held-out ones).
    pub first_seed: u64,
    /// How many seeds per (algorithm, density).
    pub seeds: u64,
}

impl StudyPlan {
    /// Every (algorithm, density, seed) in report order.
    pub fn runs(&self) -> Vec<(PlannerSpec, f64, u64)> {
        let mut out = Vec::new();
        for &a in &self.algorithms {
            for &d in &self.densities {
                for seed in self.first_seed..self.first_seed + self.seeds {
                    out.push((a, d, seed));
                }
            }
        }
        out
    }

    /// Group means and the paired comparisons of `rows`, run by this plan.
    pub fn summarize(&self, rows: &[RunRow]) -> Summary {
        summarize(&self.algorithms, &self.densities, rows)
    }
}

impl Study for StudyPlan {
    type Key = (PlannerSpec, f64, u64);
    type Row = RunRow;
    type Error = std::convert::Infallible;

    fn keys(&self) -> Vec<Self::Key> {
        self.runs()
    }

    fn run(&self, &(algorithm, density, seed): &Self::Key) -> Result<RunRow, Self::Error> {
        let mut scenario = self.scenario.clone();
        if let Some(open) = scenario.open_space.as_mut() {
            open.density = density;
        }
        scenario.seed = seed;
        let metrics = run_episode(&scenario, algorithm)[0];
        Ok(RunRow {
            algorithm,
            density,
            seed,
            metrics,
        })
    }
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
    let summary = plan.summarize(rows);
    write_json(&out.join("summary.json"), &summary)?;
    super::plots::write_figures(&summary, out)?;
    Ok(summary)
}
