//! `gapfleet study intent-sharing`: the same warehouse seeds with the robots sharing their
//! intents and without, in-process; robot–robot near misses and contacts, tasks, and the
//! social metrics, compared per seed with the Wilcoxon signed-rank test.

use super::runner::Study;
use super::stats::{mean, wilcoxon_signed_rank};
use agent::planner::PlannerSpec;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use world_sim::fleet::{FleetReport, NotAWarehouse, run_fleet};
use world_sim::scenario::Scenario;

/// What to run.
#[derive(Debug, Clone)]
pub struct IntentSharingStudy {
    /// The warehouse (robot and people counts applied; the seed is replaced per run).
    pub scenario: Scenario,
    /// Planner stack of every robot.
    pub planner: PlannerSpec,
    /// Seeds 1..=seeds, each with sharing on and off.
    pub seeds: u64,
    /// Simulated seconds per run.
    pub seconds: f64,
}

/// A compared metric: its name and how to read it from a run.
type Metric = (&'static str, fn(&SharingRun) -> f64);

/// One run: a seed with sharing on or off, and what the fleet did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SharingRun {
    /// Scenario seed.
    pub seed: u64,
    /// Whether observations carried the other robots' intents.
    pub sharing: bool,
    /// Tasks completed by the fleet.
    pub tasks: u64,
    /// Robot-steps with another robot closer than the near-miss gap, summed over robots.
    pub robot_near_miss_steps: u64,
    /// Robot-steps overlapping another robot, summed over robots.
    pub robot_contact_steps: u64,
    /// Mean over robots of the collision rate while moving.
    pub collision_rate: f64,
    /// Mean over robots of the space-violation rate while moving.
    pub svr: f64,
    /// Contacts with people the robots caused (onsets, `world_sim::metrics::contact_cause`).
    #[serde(default)]
    pub robot_caused_contacts: u64,
    /// Contacts people caused: walking into a robot stopped or moving away (onsets).
    #[serde(default)]
    pub person_caused_contacts: u64,
    /// Robot–robot contacts (onsets, each pair once per robot).
    #[serde(default)]
    pub robot_robot_contacts: u64,
    /// Robot–wall contacts (onsets).
    #[serde(default)]
    pub wall_contacts: u64,
    /// Commands the safety layer's protective field slowed or stopped (0 without the layer).
    #[serde(default)]
    pub protective_commands: u64,
}

impl SharingRun {
    fn new(seed: u64, sharing: bool, report: &FleetReport) -> Self {
        let fleet = &report.summary;
        Self {
            seed,
            sharing,
            tasks: fleet.tasks,
            robot_near_miss_steps: fleet.near_miss_steps,
            robot_contact_steps: fleet.robot_contact_steps,
            collision_rate: fleet.collision_rate,
            svr: fleet.svr,
            robot_caused_contacts: fleet.robot_caused_contacts,
            person_caused_contacts: fleet.person_caused_contacts,
            robot_robot_contacts: fleet.robot_robot_contacts,
            wall_contacts: fleet.wall_contacts,
            protective_commands: report.protective.iter().sum(),
        }
    }

    /// The compared metrics, by name.
    const METRICS: [Metric; 7] = [
        ("tasks", |r| r.tasks as f64),
        ("robot_near_miss_steps", |r| r.robot_near_miss_steps as f64),
        ("robot_contact_steps", |r| r.robot_contact_steps as f64),
        ("collision_rate", |r| r.collision_rate),
        ("svr", |r| r.svr),
        ("robot_caused_contacts", |r| r.robot_caused_contacts as f64),
        ("person_caused_contacts", |r| {
            r.person_caused_contacts as f64
        }),
    ];
}

/// Every seed with sharing on and off, in (seed, on, off) order.
impl Study for IntentSharingStudy {
    type Key = (u64, bool);
    type Row = SharingRun;
    type Error = NotAWarehouse;

    fn keys(&self) -> Vec<Self::Key> {
        (1..=self.seeds)
            .flat_map(|s| [(s, true), (s, false)])
            .collect()
    }

    fn run(&self, &(seed, sharing): &Self::Key) -> Result<SharingRun, NotAWarehouse> {
        let mut scenario = self.scenario.clone();
        scenario.seed = seed;
        let report = run_fleet(&scenario, self.planner, self.seconds, sharing)?;
        Ok(SharingRun::new(seed, sharing, &report))
    }
}

/// The means per run with sharing on and off, and the paired comparison per metric, as text.
pub fn report(runs: &[SharingRun]) -> String {
    let mut out = String::new();
    let of = |sharing: bool| runs.iter().filter(move |r| r.sharing == sharing);
    let _ = writeln!(
        out,
        "sharing  tasks  robot_near_miss_steps  robot_contact_steps  collision%   SVR  \
         robot-caused  person-caused  protective"
    );
    for sharing in [true, false] {
        let m = |get: fn(&SharingRun) -> f64| mean(of(sharing).map(get)).unwrap_or(0.0);
        let _ = writeln!(
            out,
            "{:7}  {:5.1}  {:21.1}  {:19.1}  {:10.3}  {:.3}  {:12.2}  {:13.2}  {:10.1}",
            if sharing { "on" } else { "off" },
            m(SharingRun::METRICS[0].1),
            m(SharingRun::METRICS[1].1),
            m(SharingRun::METRICS[2].1),
            m(SharingRun::METRICS[3].1) * 100.0,
            m(SharingRun::METRICS[4].1),
            m(SharingRun::METRICS[5].1),
            m(SharingRun::METRICS[6].1),
            m(|r| r.protective_commands as f64),
        );
    }
    // Paired by seed: the seeds are the same world with sharing switched, so the per-seed
    // differences carry the effect and the Wilcoxon signed-rank test asks whether it is zero.
    let _ = writeln!(
        out,
        "paired by seed (on - off): metric, mean difference, seeds higher with sharing, \
         two-sided Wilcoxon signed-rank p (normal approximation)"
    );
    for (name, get) in SharingRun::METRICS {
        let diffs: Vec<f64> = of(true)
            .filter_map(|on| {
                let off = of(false).find(|off| off.seed == on.seed)?;
                Some(get(on) - get(off))
            })
            .collect();
        let higher = diffs.iter().filter(|d| **d > 0.0).count();
        let p = wilcoxon_signed_rank(&diffs)
            .map_or_else(|| "n/a (no seed differs)".to_owned(), |p| format!("{p:.3}"));
        let _ = writeln!(
            out,
            "  {name:22} {:+12.4}  {higher:3} of {}  p = {p}",
            mean(diffs.iter().copied()).unwrap_or(0.0),
            diffs.len()
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(seed: u64, sharing: bool, tasks: u64) -> SharingRun {
        SharingRun {
            seed,
            sharing,
            tasks,
            robot_near_miss_steps: 10 * seed,
            robot_contact_steps: 0,
            collision_rate: 0.01,
            svr: 0.2,
            robot_caused_contacts: 0,
            person_caused_contacts: seed,
            robot_robot_contacts: 0,
            wall_contacts: 0,
            protective_commands: 3,
        }
    }

    #[test]
    fn report_pairs_runs_by_seed() {
        let runs = [
            run(1, true, 5),
            run(1, false, 3),
            run(2, true, 4),
            run(2, false, 4),
        ];
        let text = report(&runs);
        let words = |prefix: &str| -> Vec<String> {
            let line = text
                .lines()
                .find(|l| l.trim_start().starts_with(prefix))
                .unwrap_or_else(|| panic!("no {prefix} line in {text}"));
            line.split_whitespace().map(str::to_owned).collect()
        };
        // Tasks: on 4.5, off 3.5 per run; seed 1 higher with sharing, seed 2 tied.
        assert_eq!(words("on ")[1], "4.5");
        assert_eq!(words("off ")[1], "3.5");
        assert_eq!(words("tasks ")[1..5], ["+1.0000", "1", "of", "2"]);
        // Near misses grow with the seed alike on and off: no seed differs.
        let near = words("robot_near_miss_steps ");
        assert_eq!(near[1..5], ["+0.0000", "0", "of", "2"]);
        assert_eq!(near[7], "n/a");
    }
}
