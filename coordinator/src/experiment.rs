//! The PGP paper's open-space study (Sec. IV): every algorithm × density × seed, run
//! in-process and in parallel, with identical seeds across algorithms; results written as
//! `runs.csv` (one row per run) and `summary.json` (means per group, and paired Wilcoxon
//! signed-rank comparisons of each PGP+X against X). The output depends only on the inputs,
//! not on the number of threads.

use crate::stats::{mean, wilcoxon_signed_rank};
use agent::planner::PlannerSpec;
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;
use world_sim::episode::run_open_space;
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
#[derive(Debug, Clone)]
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
                let metrics = run_open_space(&scenario, algorithm)[0];
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

/// `runs.csv`: a header and one line per run.
pub fn runs_csv(rows: &[RunRow]) -> String {
    let mut out = String::from(
        "algorithm,density,seed,success,time_to_goal_s,path_length_m,collision_rate,svr,social_force,\
         min_human_distance_m,intimate_time_s,personal_time_s,still_time_s,force_on_people\n",
    );
    for r in rows {
        let m = &r.metrics;
        let f = |x: f64| {
            if x.is_finite() {
                format!("{x}")
            } else {
                String::new()
            }
        };
        out.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            r.algorithm,
            r.density,
            r.seed,
            m.success,
            f(m.time_to_goal_s),
            f(m.path_length_m),
            f(m.collision_rate),
            f(m.svr),
            f(m.social_force),
            f(m.min_human_distance_m),
            f(m.intimate_time_s),
            f(m.personal_time_s),
            f(m.still_time_s),
            f(m.force_on_people),
        ));
    }
    out
}

/// Means of one (algorithm, density) group.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Group {
    /// Planner name.
    pub algorithm: String,
    /// People per m².
    pub density: f64,
    /// Number of runs.
    pub runs: usize,
    /// Share of runs that reached the goal.
    pub success_rate: f64,
    /// Mean time to goal over successful runs (s).
    pub time_to_goal_s: Option<f64>,
    /// Mean path length over successful runs (m).
    pub path_length_m: Option<f64>,
    /// Mean collision rate while moving.
    pub collision_rate: Option<f64>,
    /// Mean space-violation rate while moving.
    pub svr: Option<f64>,
    /// Mean average social force on the robot.
    pub social_force: Option<f64>,
}

/// PGP+X against X on one metric, pooled over densities, paired by (density, seed).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Comparison {
    /// E.g. `pgp+dwa`.
    pub with_pgp: String,
    /// E.g. `dwa`.
    pub baseline: String,
    /// Metric name as in `runs.csv`.
    pub metric: String,
    /// Number of pairs.
    pub pairs: usize,
    /// Mean with PGP.
    pub mean_with: Option<f64>,
    /// Mean without PGP.
    pub mean_without: Option<f64>,
    /// Two-sided Wilcoxon signed-rank p-value (`None`: all differences zero).
    pub wilcoxon_p: Option<f64>,
}

/// `summary.json`'s content.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Summary {
    /// Per (algorithm, density).
    pub groups: Vec<Group>,
    /// PGP+X vs X per metric.
    pub comparisons: Vec<Comparison>,
}

/// A compared metric: its name, how to read it, and whether only successful runs count.
type MetricColumn = (&'static str, fn(&RobotMetrics) -> f64, bool);

/// Metrics compared between PGP+X and X; time and path only over pairs where both succeeded.
const COMPARED: [MetricColumn; 5] = [
    ("time_to_goal_s", |m| m.time_to_goal_s, true),
    ("path_length_m", |m| m.path_length_m, true),
    ("collision_rate", |m| m.collision_rate, false),
    ("svr", |m| m.svr, false),
    ("social_force", |m| m.social_force, false),
];

/// Group means and the paired comparisons.
pub fn summarize(plan: &StudyPlan, rows: &[RunRow]) -> Summary {
    let mut groups = Vec::new();
    for &a in &plan.algorithms {
        for &d in &plan.densities {
            let g: Vec<&RobotMetrics> = rows
                .iter()
                .filter(|r| r.algorithm == a && r.density == d)
                .map(|r| &r.metrics)
                .collect();
            let ok = || g.iter().filter(|m| m.success);
            groups.push(Group {
                algorithm: a.to_string(),
                density: d,
                runs: g.len(),
                success_rate: ok().count() as f64 / g.len().max(1) as f64,
                time_to_goal_s: mean(ok().map(|m| m.time_to_goal_s)),
                path_length_m: mean(ok().map(|m| m.path_length_m)),
                collision_rate: mean(g.iter().map(|m| m.collision_rate)),
                svr: mean(g.iter().map(|m| m.svr)),
                social_force: mean(g.iter().map(|m| m.social_force)),
            });
        }
    }
    let mut comparisons = Vec::new();
    for &with in plan.algorithms.iter().filter(|a| a.pgp) {
        let baseline = PlannerSpec {
            pgp: false,
            local: with.local,
        };
        if !plan.algorithms.contains(&baseline) {
            continue;
        }
        for (metric, get, successes_only) in COMPARED {
            let mut pairs = Vec::new();
            for r in rows.iter().filter(|r| r.algorithm == with) {
                let Some(b) = rows.iter().find(|b| {
                    b.algorithm == baseline && b.density == r.density && b.seed == r.seed
                }) else {
                    continue;
                };
                if successes_only && !(r.metrics.success && b.metrics.success) {
                    continue;
                }
                pairs.push((get(&r.metrics), get(&b.metrics)));
            }
            let diffs: Vec<f64> = pairs.iter().map(|(w, wo)| w - wo).collect();
            comparisons.push(Comparison {
                with_pgp: with.to_string(),
                baseline: baseline.to_string(),
                metric: metric.to_string(),
                pairs: pairs.len(),
                mean_with: mean(pairs.iter().map(|p| p.0)),
                mean_without: mean(pairs.iter().map(|p| p.1)),
                wilcoxon_p: wilcoxon_signed_rank(&diffs),
            });
        }
    }
    Summary {
        groups,
        comparisons,
    }
}

/// Writes `runs.csv` and `summary.json` into `out`.
pub fn write_outputs(out: &Path, plan: &StudyPlan, rows: &[RunRow]) -> std::io::Result<Summary> {
    std::fs::create_dir_all(out)?;
    std::fs::write(out.join("runs.csv"), runs_csv(rows))?;
    let summary = summarize(plan, rows);
    let json = serde_json::to_string_pretty(&summary).map_err(std::io::Error::other)?;
    std::fs::write(out.join("summary.json"), json + "\n")?;
    Ok(summary)
}
