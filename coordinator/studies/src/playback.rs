//! `gapfleet study playback`: planners in recorded pedestrians' places (the foIGP paper's
//! protocol, Sec. 7; see `world_sim::playback`), run in parallel, summarised like the paper's
//! Tables 1 and 2. Replan times are the only wall-clock figures; everything else is a function
//! of the recording and the planners.

use super::csv_fields::{fixed1, fixed1_or_empty, fixed4, fixed6_or_empty};
use super::output::{StudyError, write_json};
use super::runner::Study;
use agent::igp::{IgpParams, IgpPlanner, SeedRule};
use agent::map::StaticMap;
use agent::planner::{LocalKind, PlannerSpec, PlannerStack};
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;
use world_sim::dataset::Recording;
use world_sim::playback::{self, PlaybackOptions, PlaybackRun, RunKind, RunOutcome};

/// The name of the row measuring the removed people themselves.
pub const HUMAN: &str = "human";

/// What to run.
#[derive(Debug, Clone)]
pub struct PlaybackStudy {
    /// The recorded crowd.
    pub recording: Recording,
    /// Its obstacle lines.
    pub map: StaticMap,
    /// The planners, in table order.
    pub planners: Vec<PlannerSpec>,
    /// Partial or full runs.
    pub kind: RunKind,
    /// How runs are cut and played.
    pub options: PlaybackOptions,
    /// Only the first N runs (for smoke tests).
    pub limit: Option<usize>,
    /// Where foIGP's Newton seeds lie.
    pub igp_seeds: SeedRule,
    /// Only the runs that start in this half of the recording's time (a tuning set and a
    /// held-out set).
    pub half: Option<Half>,
}

/// A half of a recording's time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Half {
    /// Runs starting before the recording's midpoint.
    First,
    /// Runs starting at or after it.
    Second,
}

impl std::str::FromStr for Half {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "first" => Ok(Self::First),
            "second" => Ok(Self::Second),
            other => Err(format!("{other:?}: expected first or second")),
        }
    }
}

/// One planner (or the human) on one run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlaybackRow {
    /// Planner name, or [`HUMAN`].
    pub planner: String,
    /// The run.
    pub run: PlaybackRun,
    /// What happened.
    pub outcome: RunOutcome,
    /// Wall time spent planning in this run (s).
    pub planning_s: f64,
}

impl PlaybackStudy {
    /// The runs, in order.
    pub fn runs(&self) -> Vec<PlaybackRun> {
        let mut runs = playback::runs(&self.recording, self.kind, &self.options);
        if let Some(half) = self.half {
            let middle = self.recording.end() / 2.0;
            runs.retain(|r| (r.t_start < middle) == (half == Half::First));
        }
        if let Some(limit) = self.limit {
            runs.truncate(limit);
        }
        runs
    }

    fn play(&self, spec: PlannerSpec, run: &PlaybackRun) -> PlaybackRow {
        let speed = self.options.robot.max_speed;
        let mut stack = match spec.local {
            LocalKind::Igp(variant) if !spec.pgp && self.igp_seeds != SeedRule::PerBody => {
                let params = IgpParams {
                    preferred_speed: speed,
                    max_speed: speed,
                    seeds: self.igp_seeds,
                    ..IgpParams::default()
                };
                PlannerStack::with_local(spec, Box::new(IgpPlanner::new(variant, params)))
            }
            _ => PlannerStack::with_max_speed(spec, speed),
        };
        stack.set_record_fan(false);
        stack.set_destinations(&self.recording.destinations);
        let robot = &self.options.robot;
        // The control period is each plan's dt (the recording's frame step).
        let mut guard = robot.guard(0.0);
        let mut planning_s = 0.0;
        let outcome = playback::play(
            &self.recording,
            &self.map,
            run,
            &self.options,
            &mut |input| {
                let started = Instant::now();
                let command = match guard.as_mut() {
                    Some(g) => g.plan(&mut stack, input).0.command,
                    None => stack.plan(input).command,
                };
                planning_s += started.elapsed().as_secs_f64();
                command
            },
        );
        PlaybackRow {
            planner: spec.to_string(),
            run: run.clone(),
            outcome,
            planning_s,
        }
    }
}

/// Every run played by every planner, plus the human rows: human first, then planner by
/// planner (`None` is the human).
impl Study for PlaybackStudy {
    type Key = (Option<PlannerSpec>, PlaybackRun);
    type Row = PlaybackRow;
    type Error = std::convert::Infallible;

    fn keys(&self) -> Vec<Self::Key> {
        let runs = self.runs();
        let mut keys: Vec<Self::Key> = runs.iter().map(|r| (None, r.clone())).collect();
        for &spec in &self.planners {
            keys.extend(runs.iter().map(|r| (Some(spec), r.clone())));
        }
        keys
    }

    fn run(&self, (spec, run): &Self::Key) -> Result<PlaybackRow, Self::Error> {
        Ok(match spec {
            None => PlaybackRow {
                planner: HUMAN.into(),
                run: run.clone(),
                outcome: playback::human_outcome(&self.recording, run, &self.options),
                planning_s: 0.0,
            },
            Some(spec) => self.play(*spec, run),
        })
    }
}

/// One line of `runs.csv`: a planner (or the human) on one run.
#[derive(Debug, Clone, Serialize, Deserialize)]
struct RunRecord {
    planner: String,
    pedestrian: u64,
    segment: usize,
    #[serde(with = "fixed1")]
    t_start_s: f64,
    #[serde(with = "fixed1")]
    t_end_s: f64,
    reached: bool,
    #[serde(with = "fixed4")]
    s_m: f64,
    #[serde(with = "fixed4")]
    path_m: f64,
    /// d_h: the person's path to the goal tolerance, where the robot's run ends.
    #[serde(with = "fixed4")]
    human_path_m: f64,
    /// The person's whole stretch, to the goal itself.
    #[serde(with = "fixed4")]
    human_whole_path_m: f64,
    /// d_r / d_h.
    #[serde(with = "fixed4")]
    ratio: f64,
    #[serde(with = "fixed1")]
    duration_s: f64,
    #[serde(with = "fixed4")]
    mean_density: f64,
    #[serde(with = "fixed4")]
    max_density: f64,
    replans: usize,
    /// Wall time per replanning step (s); empty without replans.
    #[serde(with = "fixed6_or_empty")]
    mean_replan_s: Option<f64>,
    closest_pedestrian: Option<u64>,
    #[serde(with = "fixed1_or_empty")]
    closest_t_s: Option<f64>,
    robot_caused_contacts: u64,
    person_caused_contacts: u64,
    appeared_contacts: u64,
}

impl From<&PlaybackRow> for RunRecord {
    fn from(r: &PlaybackRow) -> Self {
        let o = &r.outcome;
        Self {
            planner: r.planner.clone(),
            pedestrian: r.run.pedestrian,
            segment: r.run.segment,
            t_start_s: r.run.t_start,
            t_end_s: r.run.t_end,
            reached: o.reached,
            s_m: o.min_distance_m,
            path_m: o.path_m,
            human_path_m: o.human_path_m,
            human_whole_path_m: r.run.human_whole_path_m,
            ratio: o.path_ratio(),
            duration_s: o.duration_s,
            mean_density: o.mean_density,
            max_density: o.max_density,
            replans: o.replans,
            mean_replan_s: (o.replans > 0).then(|| r.planning_s / o.replans as f64),
            closest_pedestrian: o.closest.map(|c| c.0),
            closest_t_s: o.closest.map(|c| c.1),
            robot_caused_contacts: o.robot_caused_contacts,
            person_caused_contacts: o.person_caused_contacts,
            appeared_contacts: o.appeared_contacts,
        }
    }
}

/// `runs.csv`: one line per (planner, run).
pub fn runs_csv(rows: &[PlaybackRow]) -> String {
    super::csv_fields::to_csv(rows.iter().map(RunRecord::from))
}

/// One row of the paper's tables, keyed as `table.json` spells it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableRow {
    /// Planner name or "human".
    pub planner: String,
    /// Runs in the row.
    pub runs: usize,
    /// Share of runs that reached the goal in time (%).
    pub pct_reached: f64,
    /// Runs in which nobody else was ever present (s = ∞): left out of μ(s) and σ(s), counted
    /// as s ≥ 0.3 m.
    pub runs_alone: usize,
    /// μ(s): mean over runs of the smallest distance to a pedestrian (m).
    pub mean_s: f64,
    /// Its standard deviation.
    pub sd_s: f64,
    /// % of runs with s < 0.3 m.
    pub pct_s_lt_0_3: f64,
    /// % of runs with s < 0.21 m (the closest two people passed in the paper's data).
    pub pct_s_lt_0_21: f64,
    /// μ(d_r): mean path length (m).
    pub mean_path_m: f64,
    /// Its standard deviation.
    pub sd_path_m: f64,
    /// % of runs with d_r / d_h > 1.25 (null for the human row).
    pub pct_ratio_gt_1_25: Option<f64>,
    /// max(d_r / d_h) (null for the human row).
    pub max_ratio: Option<f64>,
    /// μ(t): mean time of all replanning steps (s; null for the human row).
    pub mean_replan_s: Option<f64>,
    /// μ(ρ): mean over runs of the run's mean density within 3 m (people/m²).
    pub mean_density: f64,
    /// Its standard deviation.
    pub sd_density: f64,
    /// Mean over runs of the run's largest density (Table 2's μ(max ρ)).
    pub mean_max_density: f64,
    /// Contacts with people the robot caused (moving toward them at the onset), summed over
    /// the runs; for the human row, the recorded person moving toward another.
    pub robot_caused_contacts: u64,
    /// Contacts begun otherwise (a recorded person, who does not react, walked in), summed.
    pub person_caused_contacts: u64,
    /// Contacts with people who appeared in the recording too close for the robot to stop
    /// ([`RunOutcome::appeared_contacts`]), summed; 0 for the human row.
    pub appeared_contacts: u64,
}

/// Mean and standard deviation (population), through `stats::mean`; NaN for no values.
fn mean_sd(values: impl Iterator<Item = f64> + Clone) -> (f64, f64) {
    let Some(mean) = super::stats::mean(values.clone()) else {
        return (f64::NAN, f64::NAN);
    };
    let var = super::stats::mean(values.map(|v| (v - mean).powi(2))).unwrap_or(f64::NAN);
    (mean, var.sqrt())
}

fn pct(count: usize, of: usize) -> f64 {
    100.0 * count as f64 / of.max(1) as f64
}

/// The table: the human row first, then the planners in the given order.
pub fn table(rows: &[PlaybackRow], planners: &[PlannerSpec]) -> Vec<TableRow> {
    let names = std::iter::once(HUMAN.to_string()).chain(planners.iter().map(|p| p.to_string()));
    names
        .map(|name| {
            let mine: Vec<&PlaybackRow> = rows.iter().filter(|r| r.planner == name).collect();
            let outcomes = mine.iter().map(|r| &r.outcome);
            let n = mine.len();
            let met = outcomes
                .clone()
                .map(|o| o.min_distance_m)
                .filter(|s| s.is_finite());
            let (mean_s, sd_s) = mean_sd(met.clone());
            let (mean_path_m, sd_path_m) = mean_sd(outcomes.clone().map(|o| o.path_m));
            let (mean_density, sd_density) = mean_sd(outcomes.clone().map(|o| o.mean_density));
            let (mean_max_density, _) = mean_sd(outcomes.clone().map(|o| o.max_density));
            let robot = name != HUMAN;
            let replans: usize = outcomes.clone().map(|o| o.replans).sum();
            let planning: f64 = mine.iter().map(|r| r.planning_s).sum();
            TableRow {
                planner: name.clone(),
                runs: n,
                runs_alone: n - met.count(),
                pct_reached: pct(outcomes.clone().filter(|o| o.reached).count(), n),
                mean_s,
                sd_s,
                pct_s_lt_0_3: pct(
                    outcomes.clone().filter(|o| o.min_distance_m < 0.3).count(),
                    n,
                ),
                pct_s_lt_0_21: pct(
                    outcomes.clone().filter(|o| o.min_distance_m < 0.21).count(),
                    n,
                ),
                mean_path_m,
                sd_path_m,
                pct_ratio_gt_1_25: robot.then(|| {
                    pct(
                        outcomes.clone().filter(|o| o.path_ratio() > 1.25).count(),
                        n,
                    )
                }),
                max_ratio: robot.then(|| {
                    outcomes
                        .clone()
                        .map(RunOutcome::path_ratio)
                        .fold(0.0, f64::max)
                }),
                mean_replan_s: (robot && replans > 0).then(|| planning / replans as f64),
                mean_density,
                sd_density,
                mean_max_density,
                robot_caused_contacts: outcomes.clone().map(|o| o.robot_caused_contacts).sum(),
                person_caused_contacts: outcomes.clone().map(|o| o.person_caused_contacts).sum(),
                appeared_contacts: outcomes.clone().map(|o| o.appeared_contacts).sum(),
            }
        })
        .collect()
}

/// The table as Markdown, laid out like the paper's Tables 1 and 2.
pub fn table_markdown(table: &[TableRow]) -> String {
    let mut out = String::from(
        "| | runs | alone | reached | μ(s) | %s<0.3 | %s<0.21 | μ(d_r) | %d_r/d_h>1.25 | max(d_r/d_h) | μ(t) | μ(ρ) | μ(max ρ) | contacts caused / suffered / appeared / total |\n\
         |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let na = |v: Option<f64>, f: &dyn Fn(f64) -> String| v.map_or("NA".to_string(), f);
    for r in table {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.0}% | {:.2} ± {:.2} m | {:.0}% | {:.0}% | {:.1} ± {:.1} m | {} | {} | {} | {:.2} ± {:.2} | {:.2} | {} / {} / {} / {} |",
            r.planner,
            r.runs,
            r.runs_alone,
            r.pct_reached,
            r.mean_s,
            r.sd_s,
            r.pct_s_lt_0_3,
            r.pct_s_lt_0_21,
            r.mean_path_m,
            r.sd_path_m,
            na(r.pct_ratio_gt_1_25, &|v| format!("{v:.0}%")),
            na(r.max_ratio, &|v| format!("{v:.2}")),
            na(r.mean_replan_s, &|v| format!("{:.2} ms", v * 1e3)),
            r.mean_density,
            r.sd_density,
            r.mean_max_density,
            r.robot_caused_contacts,
            r.person_caused_contacts,
            r.appeared_contacts,
            r.robot_caused_contacts + r.person_caused_contacts + r.appeared_contacts,
        );
    }
    out
}

/// The human runs in which the person came closer than 0.21 m to someone (the paper's d_min,
/// "the closest distance two humans passed" in its data), as a Markdown list.
pub fn close_human_runs_markdown(rows: &[PlaybackRow]) -> String {
    let close: Vec<&PlaybackRow> = rows
        .iter()
        .filter(|r| r.planner == HUMAN && r.outcome.min_distance_m < 0.21)
        .collect();
    let mut out = format!(
        "Human runs with s < 0.21 m: {} of {}.\n",
        close.len(),
        rows.iter().filter(|r| r.planner == HUMAN).count()
    );
    for r in close {
        let (with, at) = r.outcome.closest.unwrap_or((0, f64::NAN));
        let _ = writeln!(
            out,
            "- pedestrian {} stretch {}: s = {:.3} m to pedestrian {with} at t = {at:.1} s",
            r.run.pedestrian, r.run.segment, r.outcome.min_distance_m
        );
    }
    out
}

/// `table.json`: the dataset, the kind of runs and the table.
#[derive(Debug, Serialize)]
struct TableFile<'a> {
    dataset: &'a str,
    runs: String,
    rows: &'a [TableRow],
}

/// Writes `runs.csv`, `table.json`, `table.md` and `safety_vs_path.png` into `out`.
pub fn write_outputs(
    out: &Path,
    study: &PlaybackStudy,
    rows: &[PlaybackRow],
) -> Result<Vec<TableRow>, StudyError> {
    std::fs::create_dir_all(out).map_err(StudyError::io(out))?;
    let path = out.join("runs.csv");
    std::fs::write(&path, runs_csv(rows)).map_err(StudyError::io(&path))?;
    let table = table(rows, &study.planners);
    let file = TableFile {
        dataset: &study.recording.name,
        runs: study.kind.to_string(),
        rows: &table,
    };
    // Through a JSON value, whose keys are in alphabetical order at every level.
    let sorted = serde_json::to_value(&file).expect("the table serialises to JSON");
    write_json(&out.join("table.json"), &sorted)?;
    let md = format!(
        "# {} — {} runs\n\n{}\n{}",
        study.recording.name,
        study.kind,
        table_markdown(&table),
        close_human_runs_markdown(rows)
    );
    let path = out.join("table.md");
    std::fs::write(&path, md).map_err(StudyError::io(&path))?;
    let points: Vec<super::plots::ReplayPoints<'_>> = table
        .iter()
        .filter(|t| t.planner != HUMAN)
        .map(|t| {
            let mine = rows.iter().filter(|r| r.planner == t.planner);
            let points = mine
                .map(|r| (r.outcome.min_distance_m, r.outcome.path_ratio()))
                .collect();
            (t.planner.as_str(), points)
        })
        .collect();
    let human_s: Vec<f64> = rows
        .iter()
        .filter(|r| r.planner == HUMAN)
        .map(|r| r.outcome.min_distance_m)
        .collect();
    let title = format!(
        "{} — {} runs: safety vs path length (cf. foIGP paper Figs. 5c/6c)",
        study.recording.name, study.kind
    );
    super::plots::write_playback_figure(
        &out.join("safety_vs_path.png"),
        &title,
        &points,
        &human_s,
    )?;
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn seq_eth() -> Recording {
        let dir =
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../world-sim/datasets/ETH/seq_eth");
        Recording::load(&dir).expect("seq_eth loads")
    }

    #[test]
    fn smoke_study_on_seq_eth() {
        let recording = seq_eth();
        let map = playback::map_of(&recording).expect("valid walls");
        let study = PlaybackStudy {
            recording,
            map,
            planners: vec![
                "foigp".parse().expect("known"),
                "dwa".parse().expect("known"),
            ],
            kind: RunKind::Partial,
            options: PlaybackOptions::default(),
            limit: Some(4),
            igp_seeds: SeedRule::PerBody,
            half: None,
        };
        let Ok(rows) = study.execute(&|| {});
        assert_eq!(rows.len(), study.keys().len());
        assert_eq!(rows.len(), 12);
        let t = table(&rows, &study.planners);
        assert_eq!(
            t.iter().map(|r| r.planner.as_str()).collect::<Vec<_>>(),
            ["human", "foigp", "dwa"]
        );
        let human = &t[0];
        assert_eq!(human.runs, 4);
        assert!(human.max_ratio.is_none() && human.mean_replan_s.is_none());
        assert!((9.4..12.0).contains(&human.mean_path_m), "{human:?}");
        for r in &t[1..] {
            assert_eq!(r.runs, 4);
            assert!(r.mean_path_m > 0.0 && r.mean_s.is_finite(), "{r:?}");
            assert!(r.mean_replan_s.is_some_and(|s| s > 0.0));
        }
        // Deterministic apart from the replan times.
        let Ok(again) = study.execute(&|| {});
        let strip = |rows: &[PlaybackRow]| {
            rows.iter()
                .map(|r| (r.planner.clone(), r.outcome))
                .collect::<Vec<_>>()
        };
        assert_eq!(strip(&rows), strip(&again));
        let md = table_markdown(&t);
        assert!(
            md.lines().count() == 5 && md.contains("| human | 4 | 0 |"),
            "{md}"
        );
    }
}
