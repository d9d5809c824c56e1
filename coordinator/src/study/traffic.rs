//! `gapfleet study traffic`: fleets of several sizes in the narrow-aisle warehouse, the
//! fleet hallway and (optionally) the default warehouse, with the traffic policy
//! (`world_sim::traffic_policy`) off and on and the safety layer on (or off, or both), the
//! same seeds every way; deadlocks, stuck robot-seconds, tasks per minute, contacts of every
//! cause and their total, closeness, people's delay and what the safety layer changed, per
//! run, and throughput against fleet size.

use super::csv_fields::to_csv;
use super::output::{StudyError, write_json};
use super::plots::{Series, write_lines};
use super::stats::mean;
use agent::planner::PlannerSpec;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;
use world_sim::efficiency::{FreeFlow, efficiency, free_flow};
use world_sim::fleet::{FleetOptions, FleetReport, NotAWarehouse, run_fleet_with};
use world_sim::scenario::Scenario;
use world_sim::stuck::{StuckBreakdown, StuckCauses};
use world_sim::traffic_policy::PolicyParams;

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
}

fn layer_on() -> bool {
    true
}

impl TrafficRun {
    fn new(scenario: &str, seed: u64, safety: bool, report: &FleetReport, free: &FreeFlow) -> Self {
        let sum = |f: fn(&world_sim::metrics::RobotMetrics) -> u64| -> u64 {
            report.robots.iter().map(f).sum()
        };
        let policy = report.policy.unwrap_or_default();
        Self {
            scenario: scenario.to_owned(),
            robots: report.robots.len(),
            policy: report.policy.is_some(),
            safety,
            seed,
            tasks: report.total_tasks(),
            tasks_per_min: report.total_tasks() as f64 * 60.0 / report.seconds,
            deadlocks: report.traffic.deadlocks,
            deadlocked_robot_s: report.traffic.deadlocked_robot_s,
            stuck_onsets: report.traffic.stuck_onsets,
            stuck_robot_s: report.traffic.stuck_robot_s,
            max_stuck: report.traffic.max_stuck,
            robot_caused_contacts: sum(|m| m.robot_caused_contacts),
            person_caused_contacts: sum(|m| m.person_caused_contacts),
            robot_robot_contacts: sum(|m| m.robot_robot_contacts),
            wall_contacts: sum(|m| m.wall_contacts),
            total_contacts: sum(world_sim::metrics::RobotMetrics::total_contacts),
            min_human_distance_m: report
                .robots
                .iter()
                .map(|m| m.min_human_distance_m)
                .fold(f64::INFINITY, f64::min),
            intimate_robot_s: report.robots.iter().map(|m| m.intimate_time_s).sum(),
            layer_checked: report.checked.iter().sum(),
            layer_warned: report.warned.iter().sum(),
            layer_protective: report.protective.iter().sum(),
            yielded: report.yielded.iter().sum(),
            layer_change_sum: report.change_sum,
            human_delay_s: report.robots.iter().map(|m| m.human_delay_s).sum(),
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
            efficiency: efficiency(
                report.total_tasks(),
                report.robots.len(),
                report.seconds,
                free,
            )
            .unwrap_or(0.0),
            gridlocks: report.traffic.gridlocks,
            gridlocked_robot_s: report.traffic.gridlocked_robot_s,
            stuck_by_policy_s: report.stuck_causes.policy_s,
            stuck_by_person_s: report.stuck_causes.person_s,
            stuck_by_robot_s: report.stuck_causes.robot_s,
            stuck_by_layer_s: report.stuck_causes.layer_s,
            stuck_by_planner_s: report.stuck_causes.planner_s,
            people_stalled_share: report.people_stalled_share,
        }
    }
}

/// One (site, fleet size, policy) cell of the summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cell {
    /// Scenario name.
    pub scenario: String,
    /// Robots.
    pub robots: usize,
    /// Policy on.
    pub policy: bool,
    /// Safety layer on.
    pub safety: bool,
    /// Runs.
    pub runs: usize,
    /// Runs with at least one deadlock.
    pub runs_with_deadlock: usize,
    /// Deadlocks in all runs.
    pub deadlocks: u64,
    /// Mean tasks per minute.
    pub tasks_per_min: f64,
    /// Mean tasks per minute per robot.
    pub tasks_per_min_per_robot: f64,
    /// Mean stuck robot-seconds per run.
    pub stuck_robot_s: f64,
    /// Mean share of robot-time stuck.
    pub stuck_share: f64,
    /// Mean robot-caused contacts per run.
    pub robot_caused_contacts: f64,
    /// Mean person-caused contacts per run.
    pub person_caused_contacts: f64,
    /// Mean robot–robot contacts per run.
    pub robot_robot_contacts: f64,
    /// Mean wall and shelf contacts per run.
    pub wall_contacts: f64,
    /// Mean contacts of every cause per run.
    pub total_contacts: f64,
    /// Contacts of every cause per robot-hour.
    pub total_per_robot_hour: f64,
    /// Mean of the runs' smallest robot–person centre distance (m).
    pub min_human_distance_m: f64,
    /// Mean robot-seconds with a person in the intimate zone per run.
    pub intimate_robot_s: f64,
    /// Share of checked commands the safety layer changed.
    pub layer_changed_share: f64,
    /// Share of checked commands its yield replaced.
    pub yielded_share: f64,
    /// Mean change of a changed command (m/s).
    pub layer_mean_change: f64,
    /// Mean person-seconds of delay per run.
    pub human_delay_s: f64,
    /// Mean retreats per run.
    pub retreats: f64,
    /// Mean detours round blocked segments per run.
    pub detours: f64,
    /// Mean two-way knots untangled by giving way per run.
    pub give_ways: f64,
    /// Mean stuck robot-seconds per run by place and company.
    pub stuck_where: StuckBreakdown,
    /// Mean fleet efficiency over the runs whose free flow did a task (0 when none did).
    pub efficiency: f64,
    /// Mean tasks of the free flow (one robot alone) per run.
    pub free_flow_tasks: f64,
    /// Runs with at least one gridlock.
    pub runs_with_gridlock: usize,
    /// Gridlocks in all runs.
    pub gridlocks: u64,
    /// Mean gridlocked robot-seconds per run.
    pub gridlocked_robot_s: f64,
    /// Mean stuck robot-seconds per run by what held the robot.
    pub stuck_causes: StuckCauses,
    /// Person-caused contacts per robot-hour.
    pub person_caused_per_robot_hour: f64,
    /// Mean share of person-minutes with a person stalled (moved less than 1 m).
    pub people_stalled_share: f64,
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

    /// Runs everything on the current rayon pool; `progress` is called after each run.
    pub fn execute(&self, progress: &(dyn Fn() + Sync)) -> Result<Vec<TrafficRun>, NotAWarehouse> {
        self.execute_reusing(&[], &|_| progress())
    }

    /// Like [`TrafficStudy::execute`], but a run found in `earlier` (same site, fleet size,
    /// seed and policy setting) is taken from there instead of run again: for settings whose
    /// code has not changed since (the runs are deterministic, so they would come out the
    /// same bits). Ignores the other rows of `earlier`. `finished` gets each run as it ends
    /// (reused ones too), e.g. to save it at once.
    pub fn execute_reusing(
        &self,
        earlier: &[TrafficRun],
        finished: &(dyn Fn(&TrafficRun) + Sync),
    ) -> Result<Vec<TrafficRun>, NotAWarehouse> {
        self.runs()
            .par_iter()
            .map(|&(s, robots, seed, policy, safety)| {
                let site = &self.sites[s];
                let found = earlier.iter().find(|r| {
                    (r.scenario.as_str(), r.robots, r.seed, r.policy, r.safety)
                        == (site.scenario.name.as_str(), robots, seed, policy, safety)
                });
                if let Some(run) = found {
                    finished(run);
                    return Ok(run.clone());
                }
                let mut scenario = site.scenario.clone();
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
                let run = TrafficRun::new(&scenario.name, seed, safety, &report, &free);
                finished(&run);
                Ok(run)
            })
            .collect()
    }
}

/// Reads a `runs.csv` this study wrote back.
pub fn parse_runs(text: &str) -> Result<Vec<TrafficRun>, csv::Error> {
    csv::Reader::from_reader(text.as_bytes())
        .deserialize()
        .collect()
}

/// The cells, in the study's order.
pub fn summarize(study: &TrafficStudy, runs: &[TrafficRun]) -> Vec<Cell> {
    let mut cells = Vec::new();
    for site in &study.sites {
        for &robots in &site.fleets {
            for (&policy, &safety) in study
                .policies
                .iter()
                .flat_map(|p| study.layers.iter().map(move |l| (p, l)))
            {
                let mine: Vec<&TrafficRun> = runs
                    .iter()
                    .filter(|r| {
                        r.scenario == site.scenario.name
                            && r.robots == robots
                            && r.policy == policy
                            && r.safety == safety
                    })
                    .collect();
                let m = |f: fn(&TrafficRun) -> f64| mean(mine.iter().map(|r| f(r))).unwrap_or(0.0);
                let total = |f: fn(&TrafficRun) -> u64| mine.iter().map(|r| f(r)).sum::<u64>();
                let checked = total(|r| r.layer_checked);
                let changed = total(|r| r.layer_warned)
                    + total(|r| r.layer_protective)
                    + total(|r| r.yielded);
                let share = |n: u64| {
                    if checked > 0 {
                        n as f64 / checked as f64
                    } else {
                        0.0
                    }
                };
                let robot_hours = robots as f64 * study.seconds / 3600.0;
                cells.push(Cell {
                    scenario: site.scenario.name.clone(),
                    robots,
                    policy,
                    safety,
                    runs: mine.len(),
                    runs_with_deadlock: mine.iter().filter(|r| r.deadlocks > 0).count(),
                    deadlocks: mine.iter().map(|r| r.deadlocks).sum(),
                    tasks_per_min: m(|r| r.tasks_per_min),
                    tasks_per_min_per_robot: m(|r| r.tasks_per_min) / robots as f64,
                    stuck_robot_s: m(|r| r.stuck_robot_s),
                    stuck_share: m(|r| r.stuck_robot_s) / (robots as f64 * study.seconds),
                    robot_caused_contacts: m(|r| r.robot_caused_contacts as f64),
                    person_caused_contacts: m(|r| r.person_caused_contacts as f64),
                    robot_robot_contacts: m(|r| r.robot_robot_contacts as f64),
                    wall_contacts: m(|r| r.wall_contacts as f64),
                    total_contacts: m(|r| r.total_contacts as f64),
                    total_per_robot_hour: m(|r| r.total_contacts as f64) / robot_hours,
                    min_human_distance_m: m(|r| r.min_human_distance_m),
                    intimate_robot_s: m(|r| r.intimate_robot_s),
                    layer_changed_share: share(changed),
                    yielded_share: share(total(|r| r.yielded)),
                    layer_mean_change: if changed > 0 {
                        mine.iter().map(|r| r.layer_change_sum).sum::<f64>() / changed as f64
                    } else {
                        0.0
                    },
                    human_delay_s: m(|r| r.human_delay_s),
                    retreats: m(|r| r.retreats as f64),
                    detours: m(|r| r.detours as f64),
                    give_ways: m(|r| r.give_ways as f64),
                    stuck_where: StuckBreakdown {
                        aisle_s: m(|r| r.stuck_aisle_s),
                        cross_aisle_s: m(|r| r.stuck_cross_aisle_s),
                        station_s: m(|r| r.stuck_station_s),
                        corridor_s: m(|r| r.stuck_corridor_s),
                        person_s: m(|r| r.stuck_next_to_person_s),
                        robot_s: m(|r| r.stuck_next_to_robot_s),
                        nobody_s: m(|r| r.stuck_alone_s),
                    },
                    efficiency: mean(
                        mine.iter()
                            .filter(|r| r.free_flow_tasks > 0)
                            .map(|r| r.efficiency),
                    )
                    .unwrap_or(0.0),
                    free_flow_tasks: m(|r| r.free_flow_tasks as f64),
                    runs_with_gridlock: mine.iter().filter(|r| r.gridlocks > 0).count(),
                    gridlocks: mine.iter().map(|r| r.gridlocks).sum(),
                    gridlocked_robot_s: m(|r| r.gridlocked_robot_s),
                    stuck_causes: StuckCauses {
                        policy_s: m(|r| r.stuck_by_policy_s),
                        person_s: m(|r| r.stuck_by_person_s),
                        robot_s: m(|r| r.stuck_by_robot_s),
                        layer_s: m(|r| r.stuck_by_layer_s),
                        planner_s: m(|r| r.stuck_by_planner_s),
                    },
                    person_caused_per_robot_hour: m(|r| r.person_caused_contacts as f64)
                        / robot_hours,
                    people_stalled_share: m(|r| r.people_stalled_share),
                });
            }
        }
    }
    cells
}

/// The summary as a Markdown table.
pub fn table(cells: &[Cell]) -> String {
    let mut out = String::from(
        "| site | robots | policy | layer | runs | efficiency | tasks/min | per robot | alone (tasks) | runs with a deadlock | deadlocks | runs with a gridlock | gridlocks | stuck robot-s | stuck share | people's delay (person-s) | people stalled | retreats | detours | give-ways |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for c in cells {
        out.push_str(&format!(
            "{} | {} | {:.0}% | {:.2} | {:.3} | {:.1} | {} | {} | {} | {} | {:.0} | {:.0}% | {:.1} | {:.0}% | {:.1} | {:.1} | {:.1} |\n",
            row_head(c),
            c.runs,
            100.0 * c.efficiency,
            c.tasks_per_min,
            c.tasks_per_min_per_robot,
            c.free_flow_tasks,
            c.runs_with_deadlock,
            c.deadlocks,
            c.runs_with_gridlock,
            c.gridlocks,
            c.stuck_robot_s,
            100.0 * c.stuck_share,
            c.human_delay_s,
            100.0 * c.people_stalled_share,
            c.retreats,
            c.detours,
            c.give_ways,
        ));
    }
    out
}

/// Contacts of every cause, closeness and what the safety layer changed, per cell, as a
/// Markdown table (means per run, except where a column says otherwise).
pub fn contacts_table(cells: &[Cell]) -> String {
    let mut out = String::from(
        "| site | robots | policy | layer | tasks/min | robot-caused | person-caused | robot–robot | walls | total | person-caused per robot-hour | total per robot-hour | closest (m) | intimate robot-s | people's delay (person-s) | commands changed | yields | mean change (m/s) |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for c in cells {
        out.push_str(&format!(
            "{} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1} | {:.1} | {:.2} | {:.1} | {:.1} | {:.1}% | {:.1}% | {:.2} |\n",
            row_head(c),
            c.tasks_per_min,
            c.robot_caused_contacts,
            c.person_caused_contacts,
            c.robot_robot_contacts,
            c.wall_contacts,
            c.total_contacts,
            c.person_caused_per_robot_hour,
            c.total_per_robot_hour,
            c.min_human_distance_m,
            c.intimate_robot_s,
            c.human_delay_s,
            100.0 * c.layer_changed_share,
            100.0 * c.yielded_share,
            c.layer_mean_change,
        ));
    }
    out
}

/// A table row's first four cells: site, robots, policy, layer.
fn row_head(c: &Cell) -> String {
    let on = |b: bool| if b { "on" } else { "off" };
    format!(
        "| {} | {} | {} | {}",
        c.scenario,
        c.robots,
        on(c.policy),
        on(c.safety)
    )
}

/// Where the stuck robot-seconds went, per cell, as a Markdown table: shares by place, by who
/// stood next to the stuck robot and by what held it (`world_sim::stuck`).
pub fn stuck_table(cells: &[Cell]) -> String {
    let mut out = String::from(
        "| site | robots | policy | layer | stuck robot-s | in aisles | in cross-aisles | near stations | in corridors | next to a person | next to a robot only | nobody next to it | held by: policy | a person in the way | a robot in the way | the layer | nothing visible |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for c in cells {
        let (w, h) = (&c.stuck_where, &c.stuck_causes);
        let share = |x: f64| {
            if c.stuck_robot_s > 0.0 {
                format!("{:.0}%", 100.0 * x / c.stuck_robot_s)
            } else {
                "–".to_owned()
            }
        };
        out.push_str(&format!(
            "{} | {:.0} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
            row_head(c),
            c.stuck_robot_s,
            share(w.aisle_s),
            share(w.cross_aisle_s),
            share(w.station_s),
            share(w.corridor_s),
            share(w.person_s),
            share(w.robot_s),
            share(w.nobody_s),
            share(h.policy_s),
            share(h.person_s),
            share(h.robot_s),
            share(h.layer_s),
            share(h.planner_s),
        ));
    }
    out
}

/// Writes `runs.csv`, `summary.json`, `summary.md` and `throughput.png` into `out`, and
/// `site-NAME.png` for each site from a floor plan ([`super::plots::write_site`]).
pub fn write_outputs(
    out: &Path,
    study: &TrafficStudy,
    runs: &[TrafficRun],
) -> Result<Vec<Cell>, StudyError> {
    std::fs::create_dir_all(out).map_err(StudyError::io(out))?;
    let path = out.join("runs.csv");
    std::fs::write(&path, to_csv(runs)).map_err(StudyError::io(&path))?;
    let cells = summarize(study, runs);
    write_json(&out.join("summary.json"), &cells)?;
    let path = out.join("summary.md");
    let summary = format!(
        "Efficiency: tasks per robot over one robot alone on the same floor with the same seed and no people (`alone`), mean over runs. People stalled: share of person-minutes in which a person moved less than 1 m.\n\n{}\nContacts of every cause, closeness and the safety layer (means per run):\n\n{}\nWhere the stuck robot-seconds went and what held the robots (shares of each cell's mean):\n\n{}",
        table(&cells),
        contacts_table(&cells),
        stuck_table(&cells)
    );
    std::fs::write(&path, summary).map_err(StudyError::io(&path))?;
    let panels: Vec<(String, Vec<Series>)> = study
        .sites
        .iter()
        .map(|site| {
            let on = |b: bool| if b { "on" } else { "off" };
            let series = study
                .policies
                .iter()
                .flat_map(|&p| study.layers.iter().map(move |&l| (p, l)))
                .map(|(policy, safety)| {
                    let points = cells
                        .iter()
                        .filter(|c| {
                            c.scenario == site.scenario.name
                                && c.policy == policy
                                && c.safety == safety
                        })
                        .map(|c| (c.robots as f64, c.tasks_per_min))
                        .collect();
                    let name = if study.layers.len() > 1 {
                        format!("policy {}, layer {}", on(policy), on(safety))
                    } else {
                        format!("policy {}", on(policy))
                    };
                    (name, points)
                })
                .collect();
            (format!("robots ({})", site.scenario.name), series)
        })
        .collect();
    let panels: Vec<_> = panels
        .iter()
        .map(|(x, series)| (x.as_str(), "tasks per minute", series.clone()))
        .collect();
    write_lines(
        &out.join("throughput.png"),
        "Fleet throughput against fleet size, traffic policy off and on",
        &panels,
    )?;
    // A site from a floor plan is drawn: nobody here laid it out.
    for site in study
        .sites
        .iter()
        .filter(|s| s.scenario.floor_plan.is_some())
    {
        let name = format!("site-{}.png", site.scenario.name);
        super::plots::write_site(&out.join(name), &site.scenario)?;
    }
    Ok(cells)
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
        super::super::plots::write_site(&path, &scenario).expect("drawn");
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
        let again = study
            .execute_reusing(std::slice::from_ref(&earlier), &|_| {})
            .expect("fleet sites");
        assert_eq!(again[0], earlier);
        assert_eq!(again[1..], runs[1..]);
    }
}
