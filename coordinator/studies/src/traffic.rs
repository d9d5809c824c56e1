//! `gapfleet study traffic`: fleets of several sizes in the narrow-aisle warehouse, the
//! fleet hallway and (optionally) the default warehouse, with the traffic policy
//! (`world_sim::traffic_policy`) off and on and the safety layer on (or off, or both), the
//! same seeds every way; deadlocks, stuck robot-seconds, tasks per minute, contacts of every
//! cause and their total, closeness, people's delay and what the safety layer changed, per
//! run, and throughput against fleet size.

use crate::runner::Study;
use agent::planner::PlannerSpec;
use serde::{Deserialize, Serialize};
use world_sim::efficiency::{FreeFlow, free_flow};
use world_sim::fleet::{FleetOptions, FleetReport, NotAWarehouse, run_fleet_with};
use world_sim::scenario::Scenario;
use world_sim::traffic_policy::PolicyParams;

mod summary;

pub use summary::{Cell, contacts_table, stuck_table, summarize, table, write_outputs};

/// People's delay is measured in windows of this length (s), as in the open-space study.
const IMPACT_WINDOW_S: f64 = 5.0;

/// One site of the study and the fleet sizes it runs.
#[derive(Debug, Clone)]
pub struct Site {
    /// The scenario (its robot count is replaced per run, its seed per run).
    pub scenario: Scenario,
    /// Fleet sizes.
    pub fleets: Vec<usize>,
}

/// What to run.
#[derive(Debug, Clone)]
pub struct TrafficStudy {
    /// The sites.
    pub sites: Vec<Site>,
    /// Planner stack of every robot.
    pub planner: PlannerSpec,
    /// The first seed.
    pub first_seed: u64,
    /// Seeds per (site, fleet size, policy): `first_seed..first_seed + seeds`.
    pub seeds: u64,
    /// The policy settings to run: off (`false`), on (`true`) or both, in this order.
    pub policies: Vec<bool>,
    /// The safety layer settings to run: off, on or both, in this order.
    pub layers: Vec<bool>,
    /// Simulated seconds per run.
    pub seconds: f64,
    /// The traffic policy's parameters, where it is on.
    pub policy_params: PolicyParams,
}

/// One run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrafficRun {
    /// Scenario name.
    pub scenario: String,
    /// Robots.
    pub robots: usize,
    /// Whether the traffic policy was on.
    pub policy: bool,
    /// Whether the robots ran the safety layer (true in runs.csv files older than this
    /// column: the layer was on by default).
    #[serde(default = "layer_on")]
    pub safety: bool,
    /// Seed.
    pub seed: u64,
    /// Tasks completed by the fleet.
    pub tasks: u64,
    /// Tasks per simulated minute.
    pub tasks_per_min: f64,
    /// Deadlocks that began (`world_sim::traffic`).
    pub deadlocks: u64,
    /// Robot-seconds deadlocked.
    pub deadlocked_robot_s: f64,
    /// Times a robot became stuck.
    pub stuck_onsets: u64,
    /// Robot-seconds stuck.
    pub stuck_robot_s: f64,
    /// Most robots stuck at once.
    pub max_stuck: usize,
    /// Contacts with people the robots caused (onsets).
    pub robot_caused_contacts: u64,
    /// Contacts people caused, walking into robots (onsets).
    pub person_caused_contacts: u64,
    /// Robot–robot contacts (onsets).
    pub robot_robot_contacts: u64,
    /// Contacts with walls and shelves (onsets; 0 in runs.csv files older than this column,
    /// as are the ones below down to `yielded`).
    #[serde(default)]
    pub wall_contacts: u64,
    /// Every contact: robot-caused, person-caused, robot–robot and wall contacts.
    #[serde(default)]
    pub total_contacts: u64,
    /// The smallest centre distance between any robot and any person (m).
    #[serde(default)]
    pub min_human_distance_m: f64,
    /// Robot-seconds with a person in a robot's intimate zone (0.45 m between bodies).
    #[serde(default)]
    pub intimate_robot_s: f64,
    /// Commands the safety layer checked.
    #[serde(default)]
    pub layer_checked: u64,
    /// Commands its warning field slowed.
    #[serde(default)]
    pub layer_warned: u64,
    /// Commands its protective field slowed further or stopped.
    #[serde(default)]
    pub layer_protective: u64,
    /// Commands its yield replaced with a way out.
    #[serde(default)]
    pub yielded: u64,
    /// How far it moved the commands it changed, summed (m/s).
    #[serde(default)]
    pub layer_change_sum: f64,
    /// Person-seconds of delay the robots caused, against a crowd that ignores them.
    pub human_delay_s: f64,
    /// Segments granted (0 with the policy off).
    pub grants: u64,
    /// Waits for a segment.
    pub waits: u64,
    /// Retreats ordered.
    pub retreats: u64,
    /// Stations granted (0 with the policy off).
    pub station_grants: u64,
    /// Times a robot began to wait in line for a station.
    pub queued: u64,
    /// Times a robot pushed off its route got a new one.
    pub reroutes: u64,
    /// Robots the policy sent round a blocked segment (0 in runs.csv files older than this
    /// column).
    #[serde(default)]
    pub detours: u64,
    /// Two-way knots in corridors untangled by one direction giving way (0 in runs.csv files
    /// older than this column).
    #[serde(default)]
    pub give_ways: u64,
    /// Stuck robot-seconds in aisles (`world_sim::stuck`; 0 in runs.csv files older than
    /// this column, as are the next six).
    #[serde(default)]
    pub stuck_aisle_s: f64,
    /// ... in cross-aisles.
    #[serde(default)]
    pub stuck_cross_aisle_s: f64,
    /// ... near stations.
    #[serde(default)]
    pub stuck_station_s: f64,
    /// ... in corridors.
    #[serde(default)]
    pub stuck_corridor_s: f64,
    /// ... with a person next to the robot.
    #[serde(default)]
    pub stuck_next_to_person_s: f64,
    /// ... with another robot and no person next to it.
    #[serde(default)]
    pub stuck_next_to_robot_s: f64,
    /// ... with nobody next to it.
    #[serde(default)]
    pub stuck_alone_s: f64,
    /// Tasks one robot alone did on the site with the same seed, planner, layer and policy, no
    /// people (`world_sim::efficiency`; 0 in runs.csv files older than this column, as are
    /// the ones below).
    #[serde(default)]
    pub free_flow_tasks: u64,
    /// Fleet efficiency: tasks per robot over the free flow's tasks; 0 when the free flow did
    /// no task.
    #[serde(default)]
    pub efficiency: f64,
    /// Gridlocks that began: robots stuck together for a minute, cycle or not.
    #[serde(default)]
    pub gridlocks: u64,
    /// Robot-seconds gridlocked.
    #[serde(default)]
    pub gridlocked_robot_s: f64,
    /// Stuck robot-seconds held by the traffic policy (`world_sim::stuck::Hold`).
    #[serde(default)]
    pub stuck_by_policy_s: f64,
    /// ... with a person or group in the way.
    #[serde(default)]
    pub stuck_by_person_s: f64,
    /// ... with a robot in the way.
    #[serde(default)]
    pub stuck_by_robot_s: f64,
    /// ... held by the safety layer, nobody in the way.
    #[serde(default)]
    pub stuck_by_layer_s: f64,
    /// ... with nothing visible holding the robot.
    #[serde(default)]
    pub stuck_by_planner_s: f64,
    /// Share of person-minutes in which a person moved less than 1 m: people stalled, in a
    /// jam or short of a goal (`FleetReport::people_stalled_share`).
    #[serde(default)]
    pub people_stalled_share: f64,
    /// Times a segment's robots were turned round from people in their way
    /// (`world_sim::traffic_policy::PolicyParams::people_turn_after_s`; 0 in runs.csv files
    /// older than this column).
    #[serde(default)]
    pub people_turns: u64,
}

fn layer_on() -> bool {
    true
}

impl TrafficRun {
    fn new(scenario: &str, seed: u64, safety: bool, report: &FleetReport, free: &FreeFlow) -> Self {
        let fleet = report.summary.clone().with_free_flow(Some(*free));
        let policy = report.policy.unwrap_or_default();
        Self {
            scenario: scenario.to_owned(),
            robots: fleet.robots,
            policy: report.policy.is_some(),
            safety,
            seed,
            tasks: fleet.tasks,
            tasks_per_min: fleet.tasks_per_min(),
            deadlocks: fleet.traffic.deadlocks,
            deadlocked_robot_s: fleet.traffic.deadlocked_robot_s,
            stuck_onsets: fleet.traffic.stuck_onsets,
            stuck_robot_s: fleet.traffic.stuck_robot_s,
            max_stuck: fleet.traffic.max_stuck,
            robot_caused_contacts: fleet.robot_caused_contacts,
            person_caused_contacts: fleet.person_caused_contacts,
            robot_robot_contacts: fleet.robot_robot_contacts,
            wall_contacts: fleet.wall_contacts,
            total_contacts: fleet.total_contacts,
            min_human_distance_m: fleet.min_human_distance_m,
            intimate_robot_s: fleet.intimate_robot_s,
            layer_checked: report.checked.iter().sum(),
            layer_warned: report.warned.iter().sum(),
            layer_protective: report.protective.iter().sum(),
            yielded: report.yielded.iter().sum(),
            layer_change_sum: report.change_sum,
            human_delay_s: fleet.human_delay_s,
            grants: policy.grants,
            waits: policy.waits,
            retreats: policy.retreats,
            station_grants: policy.station_grants,
            queued: policy.queued,
            reroutes: report.reroutes,
            detours: policy.detours,
            give_ways: policy.give_ways,
            stuck_aisle_s: report.stuck_where.aisle_s,
            stuck_cross_aisle_s: report.stuck_where.cross_aisle_s,
            stuck_station_s: report.stuck_where.station_s,
            stuck_corridor_s: report.stuck_where.corridor_s,
            stuck_next_to_person_s: report.stuck_where.person_s,
            stuck_next_to_robot_s: report.stuck_where.robot_s,
            stuck_alone_s: report.stuck_where.nobody_s,
            free_flow_tasks: free.tasks,
            efficiency: fleet.efficiency().unwrap_or(0.0),
            gridlocks: fleet.traffic.gridlocks,
            gridlocked_robot_s: fleet.traffic.gridlocked_robot_s,
            stuck_by_policy_s: fleet.stuck_causes.policy_s,
            stuck_by_person_s: fleet.stuck_causes.person_s,
            stuck_by_robot_s: fleet.stuck_causes.robot_s,
            stuck_by_layer_s: fleet.stuck_causes.layer_s,
            stuck_by_planner_s: fleet.stuck_causes.planner_s,
            people_stalled_share: report.people_stalled_share,
            people_turns: policy.people_turns,
        }
    }
}

impl TrafficStudy {
    /// Every run, in (site, fleet, seed, policy, layer) order.
    pub fn runs(&self) -> Vec<(usize, usize, u64, bool, bool)> {
        let mut out = Vec::new();
        for (s, site) in self.sites.iter().enumerate() {
            for &robots in &site.fleets {
                for seed in self.first_seed..self.first_seed + self.seeds {
                    for &on in &self.policies {
                        out.extend(
                            self.layers
                                .iter()
                                .map(|&layer| (s, robots, seed, on, layer)),
                        );
                    }
                }
            }
        }
        out
    }
}

impl Study for TrafficStudy {
    type Key = (usize, usize, u64, bool, bool);
    type Row = TrafficRun;
    type Error = NotAWarehouse;

    fn keys(&self) -> Vec<Self::Key> {
        self.runs()
    }

    fn run(
        &self,
        &(s, robots, seed, policy, safety): &Self::Key,
    ) -> Result<TrafficRun, NotAWarehouse> {
        let mut scenario = self.sites[s].scenario.clone();
        scenario.seed = seed;
        scenario.robot.safety = safety;
        scenario.set_fleet_size(Some(robots), None);
        let options = FleetOptions {
            share_intents: true,
            policy: policy.then_some(self.policy_params),
            human_impact_window_s: Some(IMPACT_WINDOW_S),
        };
        let report = run_fleet_with(&scenario, self.planner, self.seconds, options)?;
        let free = free_flow(&scenario, self.planner, self.seconds, options)?;
        Ok(TrafficRun::new(
            &scenario.name,
            seed,
            safety,
            &report,
            &free,
        ))
    }
}

/// A traffic study whose runs found in `earlier` (same site, fleet size, seed, policy and
/// layer setting) are taken from there instead of run again: for settings whose code has not
/// changed since (the runs are deterministic, so they would come out the same bits). The
/// other rows of `earlier` are ignored.
#[derive(Debug, Clone, Copy)]
pub struct Reusing<'a> {
    /// The study.
    pub study: &'a TrafficStudy,
    /// Runs of an earlier `runs.csv`.
    pub earlier: &'a [TrafficRun],
}

impl Study for Reusing<'_> {
    type Key = (usize, usize, u64, bool, bool);
    type Row = TrafficRun;
    type Error = NotAWarehouse;

    fn keys(&self) -> Vec<Self::Key> {
        self.study.runs()
    }

    fn run(&self, key: &Self::Key) -> Result<TrafficRun, NotAWarehouse> {
        let &(s, robots, seed, policy, safety) = key;
        let name = self.study.sites[s].scenario.name.as_str();
        let found = self.earlier.iter().find(|r| {
            (r.scenario.as_str(), r.robots, r.seed, r.policy, r.safety)
                == (name, robots, seed, policy, safety)
        });
        match found {
            Some(run) => Ok(run.clone()),
            None => self.study.run(key),
        }
    }
}

/// Reads a `runs.csv` this study wrote back.
pub fn parse_runs(text: &str) -> Result<Vec<TrafficRun>, csv::Error> {
    csv::Reader::from_reader(text.as_bytes())
        .deserialize()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A floor plan's site is drawn: the plot is written and shows its floor, not a blank
    /// page (a PNG of tens of kilobytes).
    #[test]
    fn a_floor_plan_site_is_drawn() {
        let dir = tempfile::tempdir().expect("temp dir");
        let scenario = Scenario::builtin("aws-small-warehouse").expect("valid");
        let path = dir.path().join("site.png");
        crate::plots::write_site(&path, &scenario).expect("drawn");
        let bytes = std::fs::read(&path).expect("written");
        assert!(
            bytes.starts_with(b"\x89PNG") && bytes.len() > 50_000,
            "{}",
            bytes.len()
        );
    }

    /// One short seed (seed 3, 90 s) of each site, both ways: every run is there, the summary counts them,
    /// runs.csv reads back, and earlier runs are reused.
    #[test]
    fn a_smoke_study_runs_both_sites_both_ways() {
        let narrow = Scenario::builtin("warehouse-narrow").expect("valid");
        let hallway = Scenario::builtin("hallway-fleet").expect("valid");
        let study = TrafficStudy {
            sites: vec![
                Site {
                    scenario: narrow,
                    fleets: vec![4],
                },
                Site {
                    scenario: hallway,
                    fleets: vec![4],
                },
            ],
            planner: "pgp+orca".parse().expect("known"),
            first_seed: 3,
            seeds: 1,
            policies: vec![false, true],
            layers: vec![true],
            seconds: 90.0,
            policy_params: PolicyParams::default(),
        };
        let runs = study.execute(&|| {}).expect("fleet sites");
        // One robot alone does a task in the narrow warehouse in 90 s.
        assert!(
            runs.iter()
                .any(|r| r.scenario == "warehouse-narrow" && r.free_flow_tasks > 0),
            "{runs:?}"
        );
        assert_eq!(runs.len(), 4);
        assert!(runs.iter().all(|r| r.seed == 3));
        assert!(
            runs.iter()
                .filter(|r| r.policy)
                .all(|r| r.grants + r.waits > 0 || r.scenario == "hallway-fleet")
        );
        assert!(runs.iter().filter(|r| !r.policy).all(|r| r.grants == 0));
        // Stuck time is split by place and by company, each split adding up to it.
        for r in &runs {
            let places =
                r.stuck_aisle_s + r.stuck_cross_aisle_s + r.stuck_station_s + r.stuck_corridor_s;
            let company = r.stuck_next_to_person_s + r.stuck_next_to_robot_s + r.stuck_alone_s;
            assert!((places - r.stuck_robot_s).abs() < 1e-6, "{r:?}");
            assert!((company - r.stuck_robot_s).abs() < 1e-6, "{r:?}");
        }
        // ... and by what held the robot, adding up to it too; every run has its free flow.
        for r in &runs {
            let held = r.stuck_by_policy_s
                + r.stuck_by_person_s
                + r.stuck_by_robot_s
                + r.stuck_by_layer_s
                + r.stuck_by_planner_s;
            assert!((held - r.stuck_robot_s).abs() < 1e-6, "{r:?}");
            if r.free_flow_tasks > 0 {
                let e = r.tasks as f64 / r.robots as f64 / r.free_flow_tasks as f64;
                assert!((r.efficiency - e).abs() < 1e-9, "{r:?}");
            }
        }
        let cells = summarize(&study, &runs);
        assert_eq!(cells.len(), 4);
        assert!(cells.iter().all(|c| c.runs == 1));
        let tmp = tempfile::tempdir().expect("a temporary folder");
        let dir = tmp.path().join("study");
        write_outputs(&dir, &study, &runs).expect("written");
        for f in ["runs.csv", "summary.json", "summary.md", "throughput.png"] {
            assert!(dir.join(f).is_file(), "{f}");
        }
        let csv = std::fs::read_to_string(dir.join("runs.csv")).expect("read");
        assert_eq!(csv.lines().count(), 5, "{csv}");
        assert_eq!(parse_runs(&csv).expect("its own runs.csv"), runs);
        // Runs found in an earlier runs.csv are taken from it, the rest are run.
        let mut earlier = runs[0].clone();
        earlier.tasks = 999;
        let again = Reusing {
            study: &study,
            earlier: std::slice::from_ref(&earlier),
        }
        .execute(&|| {})
        .expect("fleet sites");
        assert_eq!(again[0], earlier);
        assert_eq!(again[1..], runs[1..]);
    }
}
