//! The peek-and-pass paper's hallway study (Sec. V-B, Fig. 6): a two-way unlaned hallway of
//! several lengths, people walking at one fixed speed per trial, a fast differential-drive
//! robot driving from one end to the other. Every planner × length × human speed × seed runs
//! in-process and in parallel, with identical seeds across planners; `runs.csv` holds one row
//! per run, `summary.json` the means per (planner, length, speed), and three figures the
//! paper's panels. The output depends only on the inputs, not on the number of threads.

use super::csv_fields::{fixed1_or_empty, fixed4, to_csv};
use super::output::{StudyError, write_json};
use super::plots::{Series, write_lines};
use super::runner::Study;
use agent::planner::PlannerSpec;
use serde::Serialize;
use std::path::Path;
use world_sim::episode::run_episode;
use world_sim::scenario::Scenario;

/// People per metre of hallway: the built-in hallway's 12 in 25 m.
pub const PEOPLE_PER_METRE: f64 = 12.0 / 25.0;

/// The study's base scenario: the built-in hallway with a robot of top speed `robot_speed`,
/// body occlusion on and the safety layer as asked (lengths, people and speeds are set per
/// run by [`HallwayStudy::scenario_for`]).
pub fn hallway_scenario(
    robot_speed: f64,
    safety: bool,
) -> Result<Scenario, world_sim::scenario::ScenarioError> {
    let mut scenario = Scenario::builtin("hallway")?;
    scenario.robot.max_speed = robot_speed;
    scenario.robot.body_occlusion = true;
    scenario.robot.safety = safety;
    Ok(scenario)
}

/// What to run.
#[derive(Debug, Clone)]
pub struct HallwayStudy {
    /// The base scenario: a hallway (its length, people, walking speed, seed and time limit
    /// are set per run).
    pub scenario: Scenario,
    /// Planners, in report order.
    pub planners: Vec<PlannerSpec>,
    /// Hallway lengths (m).
    pub lengths: Vec<f64>,
    /// Hallway width (m).
    pub width_m: f64,
    /// People's walking speeds (m/s), one per trial.
    pub speeds: Vec<f64>,
    /// The first seed: runs take seeds `first_seed..first_seed + seeds` for every (planner,
    /// length, speed); 1 for the tuning seeds, 101 for the held-out ones.
    pub first_seed: u64,
    /// Seeds per (planner, length, speed).
    pub seeds: u64,
}

/// One run.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct HallwayRow {
    /// Planner name.
    pub planner: String,
    /// Hallway length (m).
    pub length_m: f64,
    /// People's walking speed (m/s).
    pub human_speed: f64,
    /// Seed.
    pub seed: u64,
    /// Whether the robot reached the far end in time.
    pub reached: bool,
    /// Seconds to the goal (empty if not reached).
    #[serde(with = "fixed1_or_empty")]
    pub time_to_goal_s: Option<f64>,
    /// Metres driven.
    #[serde(with = "fixed4")]
    pub path_m: f64,
    /// Times people changed path because of the robot (`world_sim::impact`).
    pub path_changes: u64,
    /// Times the robot entered a person's personal space (0.5 m between bodies).
    pub personal_space_entries: u64,
    /// Contacts the robot caused.
    pub robot_caused_contacts: u64,
    /// Contacts people caused.
    pub person_caused_contacts: u64,
}

impl HallwayStudy {
    /// Every (planner, length, speed, seed) in report order.
    pub fn runs(&self) -> Vec<(PlannerSpec, f64, f64, u64)> {
        let mut out = Vec::new();
        for &p in &self.planners {
            for &l in &self.lengths {
                for &v in &self.speeds {
                    for seed in self.first_seed..self.first_seed + self.seeds {
                        out.push((p, l, v, seed));
                    }
                }
            }
        }
        out
    }

    /// The scenario of one run: the hallway `length` long with its share of people walking at
    /// `speed`, and time for the robot to cover it at a walk (60 s + 2 s per metre).
    pub fn scenario_for(&self, length: f64, speed: f64, seed: u64) -> Scenario {
        let mut s = self.scenario.clone();
        if let Some(h) = s.hallway.as_mut() {
            h.length_m = length;
            h.width_m = self.width_m;
            h.humans = (length * PEOPLE_PER_METRE).round() as usize;
        }
        s.humans.speed = speed;
        s.seed = seed;
        s.max_time_s = 60.0 + 2.0 * length;
        s
    }
}

impl Study for HallwayStudy {
    type Key = (PlannerSpec, f64, f64, u64);
    type Row = HallwayRow;
    type Error = std::convert::Infallible;

    fn keys(&self) -> Vec<Self::Key> {
        self.runs()
    }

    fn run(&self, &(planner, length, speed, seed): &Self::Key) -> Result<HallwayRow, Self::Error> {
        let m = run_episode(&self.scenario_for(length, speed, seed), planner)[0];
        Ok(HallwayRow {
            planner: planner.to_string(),
            length_m: length,
            human_speed: speed,
            seed,
            reached: m.success,
            time_to_goal_s: m.success.then_some(m.time_to_goal_s),
            path_m: m.path_length_m,
            path_changes: m.human_path_changes,
            personal_space_entries: m.personal_space_entries,
            robot_caused_contacts: m.robot_caused_contacts,
            person_caused_contacts: m.person_caused_contacts,
        })
    }
}

/// The means of one (planner, length, speed) cell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HallwayCell {
    /// Planner name.
    pub planner: String,
    /// Hallway length (m).
    pub length_m: f64,
    /// People's walking speed (m/s).
    pub human_speed: f64,
    /// Runs.
    pub runs: usize,
    /// Share of runs that reached the end.
    pub reached: f64,
    /// Mean time to goal over the runs that reached it (s; null if none did).
    pub time_to_goal_s: Option<f64>,
    /// Mean path changes per run.
    pub path_changes: f64,
    /// Mean personal-space entries per run.
    pub personal_space_entries: f64,
    /// Robot-caused contacts, summed.
    pub robot_caused_contacts: u64,
    /// Person-caused contacts, summed.
    pub person_caused_contacts: u64,
}

/// One (planner, length) over every human speed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HallwayLength {
    /// Planner name.
    pub planner: String,
    /// Hallway length (m).
    pub length_m: f64,
    /// Runs.
    pub runs: usize,
    /// Share of runs that reached the end.
    pub reached: f64,
    /// Median time to goal over every run, a run that did not reach the end counting as
    /// never (s; null when half the runs or more did not).
    pub median_time_to_goal_s: Option<f64>,
    /// Mean time to goal over the runs that reached it (s).
    pub mean_time_to_goal_s: Option<f64>,
    /// Mean path changes per run.
    pub path_changes: f64,
    /// Mean personal-space entries per run.
    pub personal_space_entries: f64,
    /// Robot-caused contacts, summed.
    pub robot_caused_contacts: u64,
    /// Person-caused contacts, summed.
    pub person_caused_contacts: u64,
}

/// `summary.json`: every cell, in report order, and every (planner, length).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HallwaySummary {
    /// The first seed.
    pub first_seed: u64,
    /// Seeds per cell.
    pub seeds: u64,
    /// The cells.
    pub cells: Vec<HallwayCell>,
    /// Per planner and length, over every human speed.
    pub lengths: Vec<HallwayLength>,
}

/// The median of `times`, `None` (never) counting as longer than any time; `None` when half
/// of them or more are never.
pub fn median_time(times: &[Option<f64>]) -> Option<f64> {
    let mut t: Vec<f64> = times.iter().map(|t| t.unwrap_or(f64::INFINITY)).collect();
    if t.is_empty() {
        return None;
    }
    t.sort_by(f64::total_cmp);
    let n = t.len();
    let m = if n % 2 == 1 {
        t[n / 2]
    } else {
        (t[n / 2 - 1] + t[n / 2]) / 2.0
    };
    m.is_finite().then_some(m)
}

/// Per planner and length, over every human speed.
pub fn per_length(study: &HallwayStudy, rows: &[HallwayRow]) -> Vec<HallwayLength> {
    let mut out = Vec::new();
    for p in &study.planners {
        let name = p.to_string();
        for &l in &study.lengths {
            let mine: Vec<&HallwayRow> = rows
                .iter()
                .filter(|r| r.planner == name && r.length_m == l)
                .collect();
            if mine.is_empty() {
                continue;
            }
            let n = mine.len();
            let times: Vec<Option<f64>> = mine.iter().map(|r| r.time_to_goal_s).collect();
            out.push(HallwayLength {
                planner: name.clone(),
                length_m: l,
                runs: n,
                reached: mine.iter().filter(|r| r.reached).count() as f64 / n as f64,
                median_time_to_goal_s: median_time(&times),
                mean_time_to_goal_s: mean(times.iter().flatten().copied()),
                path_changes: mean(mine.iter().map(|r| r.path_changes as f64)).unwrap_or(0.0),
                personal_space_entries: mean(mine.iter().map(|r| r.personal_space_entries as f64))
                    .unwrap_or(0.0),
                robot_caused_contacts: mine.iter().map(|r| r.robot_caused_contacts).sum(),
                person_caused_contacts: mine.iter().map(|r| r.person_caused_contacts).sum(),
            });
        }
    }
    out
}

fn mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    super::stats::mean(values)
}

/// The cells of `rows`, in the study's order.
pub fn summarize(study: &HallwayStudy, rows: &[HallwayRow]) -> HallwaySummary {
    let mut cells = Vec::new();
    for p in &study.planners {
        let name = p.to_string();
        for &l in &study.lengths {
            for &v in &study.speeds {
                let mine: Vec<&HallwayRow> = rows
                    .iter()
                    .filter(|r| r.planner == name && r.length_m == l && r.human_speed == v)
                    .collect();
                if mine.is_empty() {
                    continue;
                }
                let n = mine.len();
                cells.push(HallwayCell {
                    planner: name.clone(),
                    length_m: l,
                    human_speed: v,
                    runs: n,
                    reached: mine.iter().filter(|r| r.reached).count() as f64 / n as f64,
                    time_to_goal_s: mean(mine.iter().filter_map(|r| r.time_to_goal_s)),
                    path_changes: mean(mine.iter().map(|r| r.path_changes as f64)).unwrap_or(0.0),
                    personal_space_entries: mean(
                        mine.iter().map(|r| r.personal_space_entries as f64),
                    )
                    .unwrap_or(0.0),
                    robot_caused_contacts: mine.iter().map(|r| r.robot_caused_contacts).sum(),
                    person_caused_contacts: mine.iter().map(|r| r.person_caused_contacts).sum(),
                });
            }
        }
    }
    HallwaySummary {
        first_seed: study.first_seed,
        seeds: study.seeds,
        cells,
        lengths: per_length(study, rows),
    }
}

/// Per planner, `get` of the runs against `x` of the runs (means over the runs at each x,
/// runs where `get` gives nothing left out).
fn series(
    study: &HallwayStudy,
    rows: &[HallwayRow],
    keep: impl Fn(&HallwayRow) -> bool,
    x: impl Fn(&HallwayRow) -> f64,
    get: impl Fn(&HallwayRow) -> Option<f64>,
) -> Vec<Series> {
    study
        .planners
        .iter()
        .map(|p| {
            let name = p.to_string();
            let mut xs: Vec<f64> = rows
                .iter()
                .filter(|r| r.planner == name && keep(r))
                .map(&x)
                .collect();
            xs.sort_by(f64::total_cmp);
            xs.dedup();
            let points = xs
                .iter()
                .filter_map(|&at| {
                    let at_x = rows
                        .iter()
                        .filter(|r| r.planner == name && keep(r) && x(r) == at);
                    mean(at_x.filter_map(&get)).map(|y| (at, y))
                })
                .collect();
            (name, points)
        })
        .collect()
}

/// Writes `runs.csv`, `summary.json` and the figures into `out`.
pub fn write_outputs(
    out: &Path,
    study: &HallwayStudy,
    rows: &[HallwayRow],
) -> Result<HallwaySummary, StudyError> {
    std::fs::create_dir_all(out).map_err(StudyError::io(out))?;
    let path = out.join("runs.csv");
    std::fs::write(&path, to_csv(rows)).map_err(StudyError::io(&path))?;
    let summary = summarize(study, rows);
    write_json(&out.join("summary.json"), &summary)?;
    let all = |_: &HallwayRow| true;
    let length = |r: &HallwayRow| r.length_m;
    write_lines(
        &out.join("time_vs_length.png"),
        "Time to goal against hallway length, all human speeds (cf. Fig. 6)",
        &[(
            "hallway length (m)",
            "time to goal (s, runs that reached it)",
            series(study, rows, all, length, |r| r.time_to_goal_s),
        )],
    )?;
    write_lines(
        &out.join("social.png"),
        "What the robot costs people (cf. Fig. 6)",
        &[
            (
                "hallway length (m)",
                "human path changes per run",
                series(study, rows, all, length, |r| Some(r.path_changes as f64)),
            ),
            (
                "hallway length (m)",
                "personal-space entries per run",
                series(study, rows, all, length, |r| {
                    Some(r.personal_space_entries as f64)
                }),
            ),
        ],
    )?;
    let at_50 = |r: &HallwayRow| r.length_m == 50.0;
    if rows.iter().any(at_50) {
        write_lines(
            &out.join("time_vs_human_speed_50m.png"),
            "Time to goal against human speed, 50 m hallway (cf. Fig. 6)",
            &[(
                "human speed (m/s)",
                "time to goal (s, runs that reached it)",
                series(study, rows, at_50, |r| r.human_speed, |r| r.time_to_goal_s),
            )],
        )?;
    }
    Ok(summary)
}
