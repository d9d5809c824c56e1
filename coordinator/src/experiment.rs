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

/// `runs.csv`: a header and one line per run.
pub fn runs_csv(rows: &[RunRow]) -> String {
    let mut out = String::from(
        "algorithm,density,seed,success,time_to_goal_s,path_length_m,collision_rate,svr,social_force,\
         min_human_distance_m,intimate_time_s,personal_time_s,still_time_s,force_on_people,\
         human_delay_s,human_extra_path_m\n",
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
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
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
            f(m.human_delay_s),
            f(m.human_extra_path_m),
        ));
    }
    out
}

/// Why a `runs.csv` could not be read back.
#[derive(Debug, thiserror::Error)]
#[error("runs.csv line {line}: {message}")]
pub struct CsvError {
    line: usize,
    message: String,
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
    let mut lines = text.lines().enumerate();
    let header = lines.next().map(|(_, h)| h).unwrap_or_default();
    if !header.starts_with("algorithm,density,seed,success,") {
        return Err(CsvError {
            line: 1,
            message: "not a gapfleet runs.csv header".into(),
        });
    }
    let (mut rows, mut algorithms, mut densities) = (Vec::new(), Vec::new(), Vec::new());
    for (i, line) in lines {
        let err = |message: String| CsvError {
            line: i + 1,
            message,
        };
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 16 {
            return Err(err(format!("expected 16 fields, got {}", f.len())));
        }
        let num = |k: usize| -> Result<f64, CsvError> {
            if f[k].is_empty() {
                Ok(f64::NAN)
            } else {
                f[k].parse()
                    .map_err(|e| err(format!("field {}: {e}", k + 1)))
            }
        };
        let algorithm: PlannerSpec = f[0].parse().map_err(|e| err(format!("{e}")))?;
        let density = num(1)?;
        let seed = f[2].parse().map_err(|e| err(format!("seed: {e}")))?;
        let metrics = RobotMetrics {
            success: f[3] == "true",
            time_to_goal_s: num(4)?,
            path_length_m: num(5)?,
            collision_rate: num(6)?,
            svr: num(7)?,
            social_force: num(8)?,
            min_human_distance_m: num(9)?,
            intimate_time_s: num(10)?,
            personal_time_s: num(11)?,
            still_time_s: num(12)?,
            robot_near_misses: 0,
            robot_contacts: 0,
            force_on_people: num(13)?,
            human_delay_s: num(14)?,
            human_extra_path_m: num(15)?,
        };
        if !algorithms.contains(&algorithm) {
            algorithms.push(algorithm);
        }
        if !densities.contains(&density) {
            densities.push(density);
        }
        rows.push(RunRow {
            algorithm,
            density,
            seed,
            metrics,
        });
    }
    Ok(ParsedRuns {
        rows,
        algorithms,
        densities,
    })
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
    /// Mean smallest centre distance to a person (m).
    pub min_human_distance_m: Option<f64>,
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
const COMPARED: [MetricColumn; 7] = [
    ("time_to_goal_s", |m| m.time_to_goal_s, true),
    ("path_length_m", |m| m.path_length_m, true),
    ("collision_rate", |m| m.collision_rate, false),
    ("svr", |m| m.svr, false),
    ("social_force", |m| m.social_force, false),
    ("human_delay_s", |m| m.human_delay_s, false),
    ("human_extra_path_m", |m| m.human_extra_path_m, false),
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
                min_human_distance_m: mean(g.iter().map(|m| m.min_human_distance_m)),
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

/// Writes `runs.csv`, `summary.json` and the two figures into `out`.
pub fn write_outputs(out: &Path, plan: &StudyPlan, rows: &[RunRow]) -> std::io::Result<Summary> {
    std::fs::create_dir_all(out)?;
    std::fs::write(out.join("runs.csv"), runs_csv(rows))?;
    write_summary(out, plan, rows)
}

/// Writes `summary.json` and the two figures into `out`.
pub fn write_summary(out: &Path, plan: &StudyPlan, rows: &[RunRow]) -> std::io::Result<Summary> {
    let summary = summarize(plan, rows);
    let json = serde_json::to_string_pretty(&summary).map_err(std::io::Error::other)?;
    std::fs::write(out.join("summary.json"), json + "\n")?;
    crate::plots::write_figures(&summary, out).map_err(std::io::Error::other)?;
    Ok(summary)
}
