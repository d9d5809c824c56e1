//! A check of `asfm`'s estimator on real and simulated people: the Â_o it reaches for each
//! person it tracks, (1) on recorded crowds (ETH, UCY), where people never react to the robot,
//! so Â_o should concentrate near 0, and (2) in the simulator's open space with people who
//! react to robots (Social Force) and, as a control, with people who do not.
//!
//! Per person, the last Â_o while they had been tracked for at least [`MIN_TRACKED_S`] (the
//! estimate of a person just seen is the prior's 0, whatever they do).

use super::laned::five_numbers;
use super::output::{StudyError, write_json};
use super::plots::write_boxes;
use agent::asfm::{Asfm, AsfmParams};
use agent::planner::{LocalPlan, LocalPlanner, PlannerSpec, PlannerStack, PlanningInput};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Arc, Mutex};
use world_sim::dataset::Recording;
use world_sim::episode::run_episode_with;
use world_sim::playback::{PlaybackOptions, PlaybackRun, RunKind, runs};
use world_sim::scenario::Scenario;

/// A person's estimate counts once they have been tracked this long (s).
pub const MIN_TRACKED_S: f64 = 2.0;

/// Per person id, the last Â_o after [`MIN_TRACKED_S`] of tracking.
type Finals = BTreeMap<u64, f64>;

/// `asfm` as a short-term planner that keeps each person's latest estimate.
#[derive(Debug)]
struct Recorded {
    asfm: Asfm,
    finals: Arc<Mutex<Finals>>,
}

impl Recorded {
    fn record(&self) {
        // A poisoned lock means another run panicked; its rows are lost anyway.
        if let Ok(mut finals) = self.finals.lock() {
            for (id, estimate, age) in self.asfm.tracked() {
                if age >= MIN_TRACKED_S {
                    finals.insert(id, estimate);
                }
            }
        }
    }
}

impl LocalPlanner for Recorded {
    fn subgoal_distance(&self) -> f64 {
        LocalPlanner::subgoal_distance(&self.asfm)
    }

    fn plan(&mut self, input: &PlanningInput<'_>, target: agent::math::Vec2) -> LocalPlan {
        let plan = LocalPlanner::plan(&mut self.asfm, input, target);
        self.record();
        plan
    }
}

/// One person's estimate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EstimateRow {
    /// Where: the recording's name, or `sim-reacting` / `sim-ignoring`.
    pub source: String,
    /// The run (replay run index, or simulator seed).
    pub run: u64,
    /// The person's id.
    pub person: u64,
    /// Their Â_o.
    pub estimate: f64,
}

/// Each recorded person's Â_o in `asfm`'s partial runs on `recording` (the first `limit`),
/// the robot with `params` at `options`' top speed under its safety layer setting.
pub fn recorded(
    recording: &Recording,
    map: &agent::map::StaticMap,
    options: &PlaybackOptions,
    params: &AsfmParams,
    limit: Option<usize>,
    progress: &(dyn Fn() + Sync),
) -> Vec<EstimateRow> {
    let mut all: Vec<PlaybackRun> = runs(recording, RunKind::Partial, options);
    if let Some(n) = limit {
        all.truncate(n);
    }
    all.par_iter()
        .enumerate()
        .flat_map_iter(|(i, run)| {
            let finals = Arc::new(Mutex::new(Finals::new()));
            let mut planner = Recorded {
                asfm: Asfm::new(AsfmParams {
                    v_max: options.robot.max_speed,
                    ..params.clone()
                }),
                finals: Arc::clone(&finals),
            };
            let robot = &options.robot;
            let mut guard = robot.guard(0.0);
            world_sim::playback::play(recording, map, run, options, &mut |input| {
                let planned = planner.plan(input, input.goal).command;
                guard
                    .as_mut()
                    .map_or(planned, |g| g.check(planned, input).command)
            });
            progress();
            let finals = finals.lock().map(|f| f.clone()).unwrap_or_default();
            finals
                .into_iter()
                .map(move |(person, estimate)| EstimateRow {
                    source: recording.name.clone(),
                    run: i as u64,
                    person,
                    estimate,
                })
        })
        .collect()
}

/// Each simulated person's Â_o in `asfm`'s open-space runs (seeds 1..=`seeds`) at
/// `density`, with people reacting to robots or not; the robot with `params`.
pub fn simulated(
    base: &Scenario,
    params: &AsfmParams,
    density: f64,
    seeds: u64,
    react: bool,
    progress: &(dyn Fn() + Sync),
) -> Vec<EstimateRow> {
    let source = if react {
        "sim-reacting"
    } else {
        "sim-ignoring"
    };
    (1..=seeds)
        .into_par_iter()
        .flat_map_iter(|seed| {
            let mut scenario = base.clone();
            if let Some(open) = scenario.open_space.as_mut() {
                open.density = density;
            }
            scenario.humans.react_to_robots = react;
            scenario.seed = seed;
            let finals = Arc::new(Mutex::new(Finals::new()));
            let spec: PlannerSpec = "asfm".parse().expect("a known planner");
            let v_max = scenario.robot.max_speed;
            run_episode_with(&scenario, |_| {
                PlannerStack::with_local(
                    spec,
                    Box::new(Recorded {
                        asfm: Asfm::new(AsfmParams {
                            v_max,
                            ..params.clone()
                        }),
                        finals: Arc::clone(&finals),
                    }),
                )
            });
            progress();
            let finals = finals.lock().map(|f| f.clone()).unwrap_or_default();
            finals
                .into_iter()
                .map(move |(person, estimate)| EstimateRow {
                    source: source.to_string(),
                    run: seed,
                    person,
                    estimate,
                })
        })
        .collect()
}

/// The spread of Â_o per source.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SourceSummary {
    /// Where.
    pub source: String,
    /// People.
    pub people: usize,
    /// Â_o: min, q1, median, q3, max.
    pub quartiles: [f64; 5],
    /// Mean Â_o.
    pub mean: f64,
    /// Share of people with |Â_o| < 2.
    pub near_zero: f64,
}

/// The summaries of `rows`, per source in order of first appearance.
pub fn summarize(rows: &[EstimateRow]) -> Vec<SourceSummary> {
    let mut sources: Vec<&str> = Vec::new();
    for r in rows {
        if !sources.contains(&r.source.as_str()) {
            sources.push(&r.source);
        }
    }
    sources
        .into_iter()
        .map(|source| {
            let values: Vec<f64> = rows
                .iter()
                .filter(|r| r.source == source)
                .map(|r| r.estimate)
                .collect();
            let n = values.len().max(1) as f64;
            SourceSummary {
                source: source.to_string(),
                people: values.len(),
                quartiles: five_numbers(&values),
                mean: values.iter().sum::<f64>() / n,
                near_zero: values.iter().filter(|v| v.abs() < 2.0).count() as f64 / n,
            }
        })
        .collect()
}

/// Writes `estimates.csv`, `summary.json` and `estimates.png` into `out`.
pub fn write_outputs(out: &Path, rows: &[EstimateRow]) -> Result<Vec<SourceSummary>, StudyError> {
    std::fs::create_dir_all(out).map_err(StudyError::io(out))?;
    let path = out.join("estimates.csv");
    std::fs::write(&path, super::csv_fields::to_csv(rows)).map_err(StudyError::io(&path))?;
    let summary = summarize(rows);
    write_json(&out.join("summary.json"), &summary)?;
    let boxes: Vec<(String, [f64; 5])> = summary
        .iter()
        .map(|s| (format!("{} ({})", s.source, s.people), s.quartiles))
        .collect();
    write_boxes(
        &out.join("estimates.png"),
        "asfm's Â_o per tracked person: recorded people (no reaction) against simulated ones",
        "source (people)",
        "Â_o",
        &boxes,
    )?;
    Ok(summary)
}
