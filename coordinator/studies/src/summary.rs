//! The open-space study's `summary.json`: means per (algorithm, density) group, and paired
//! Wilcoxon signed-rank comparisons of each PGP+X against X.

use super::runs::RunRow;
use super::stats::{mean, wilcoxon_signed_rank};
use agent::planner::PlannerSpec;
use serde::Serialize;
use world_sim::metrics::RobotMetrics;

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
    /// Contacts with people the robot caused, summed over the runs
    /// (`world_sim::metrics::contact_cause`).
    pub robot_caused_contacts: u64,
    /// Contacts people caused (walking into a robot stopped or moving away), summed.
    pub person_caused_contacts: u64,
    /// Contacts with other robots, summed.
    pub robot_robot_contacts: u64,
    /// Contacts with walls and shelves, summed.
    pub wall_contacts: u64,
    /// Every contact, summed (`world_sim::metrics::RobotMetrics::total_contacts`).
    pub total_contacts: u64,
    /// Mean delay the robot caused people (s).
    pub human_delay_s: Option<f64>,
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
    /// For metrics of successful runs only (time, path): over *every* successful run rather
    /// than the pairs where both succeeded, how many PGP+X runs succeeded and their mean.
    /// The paired mean compares like with like; this one shows what the runs each planner
    /// alone finishes look like (PGP+X finishes runs that X fails, often slowly).
    pub successes_with: Option<(usize, f64)>,
    /// The same for X.
    pub successes_without: Option<(usize, f64)>,
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
pub fn summarize(algorithms: &[PlannerSpec], densities: &[f64], rows: &[RunRow]) -> Summary {
    let mut groups = Vec::new();
    for &a in algorithms {
        for &d in densities {
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
                robot_caused_contacts: g.iter().map(|m| m.robot_caused_contacts).sum(),
                person_caused_contacts: g.iter().map(|m| m.person_caused_contacts).sum(),
                robot_robot_contacts: g.iter().map(|m| m.robot_robot_contacts).sum(),
                wall_contacts: g.iter().map(|m| m.wall_contacts).sum(),
                total_contacts: g.iter().map(|m| m.total_contacts()).sum(),
                human_delay_s: mean(g.iter().map(|m| m.human_delay_s)),
            });
        }
    }
    let mut comparisons = Vec::new();
    for &with in algorithms.iter().filter(|a| a.pgp) {
        let baseline = PlannerSpec {
            pgp: false,
            local: with.local,
        };
        if !algorithms.contains(&baseline) {
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
            let successes = |a: PlannerSpec| {
                let ok: Vec<f64> = rows
                    .iter()
                    .filter(|r| r.algorithm == a && r.metrics.success)
                    .map(|r| get(&r.metrics))
                    .collect();
                mean(ok.iter().copied()).map(|m| (ok.len(), m))
            };
            comparisons.push(Comparison {
                with_pgp: with.to_string(),
                baseline: baseline.to_string(),
                metric: metric.to_string(),
                pairs: pairs.len(),
                mean_with: mean(pairs.iter().map(|p| p.0)),
                mean_without: mean(pairs.iter().map(|p| p.1)),
                wilcoxon_p: wilcoxon_signed_rank(&diffs),
                successes_with: successes_only.then(|| successes(with)).flatten(),
                successes_without: successes_only.then(|| successes(baseline)).flatten(),
            });
        }
    }
    Summary {
        groups,
        comparisons,
    }
}
