//! The traffic study's summary: its cells (one per site, fleet size, policy and layer
//! setting), the tables of `summary.md`, and the files the study writes.

use super::{TrafficRun, TrafficStudy};
use crate::csv_fields::to_csv;
use crate::output::{StudyError, write_json};
use crate::plots::{Series, write_lines};
use crate::stats::mean;
use serde::Serialize;
use std::path::Path;
use world_sim::stuck::{StuckBreakdown, StuckCauses};

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
/// `site-NAME.png` for each site from a floor plan ([`crate::plots::write_site`]).
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
        crate::plots::write_site(&out.join(name), &site.scenario)?;
    }
    Ok(cells)
}
