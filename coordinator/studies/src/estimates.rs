//! A check of `asfm`'s estimator on real and simulated people: the Â_o it reaches for each
//! person it tracks, (1) on recorded crowds (ETH, UCY), where people never react to the robot,
//! so Â_o should concentrate near 0, (2) in the simulator's open space with people who react
//! to robots (Social Force) and, as a control, with people who do not, and (3) in a mixed
//! crowd of both kinds, where Â_o should tell them apart (the area under the ROC curve).
//!
//! Per person, the last Â_o while they had been tracked for at least [`MIN_TRACKED_S`] (the
//! estimate of a person just seen is the prior's 0, whatever they do); in the mixed crowd, Â_o
//! once they have been [`NEAR_S`] near the robot. Every row also has the person's closest
//! approach to the robot.

use super::laned::five_numbers;
use super::output::{StudyError, write_json};
use super::plots::write_boxes;
use super::runner::Study;
use agent::asfm::{Asfm, AsfmParams};
use agent::planner::{LocalPlan, LocalPlanner, PlannerSpec, PlannerStack, PlanningInput};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Arc, Mutex};
use world_sim::dataset::Recording;
use world_sim::episode::run_episode_with;
use world_sim::playback::{PlaybackOptions, PlaybackRun, RunKind, runs};
use world_sim::scenario::Scenario;
use world_sim::world::World;

/// A person's estimate counts once they have been tracked this long (s).
pub const MIN_TRACKED_S: f64 = 2.0;

/// In the mixed crowd, a person's estimate is read once they have been this long near the
/// robot (s): the "after 3 s near the robot".
pub const NEAR_S: f64 = 3.0;

/// Near the robot: within Eq. 3's range B of it, between surfaces (m).
pub const NEAR_GAP_M: f64 = 2.0;

/// Per person id, the last Â_o after [`MIN_TRACKED_S`] of tracking.
type Finals = BTreeMap<u64, f64>;

/// What a run records per person, shared with the planner that records it.
#[derive(Debug, Clone, Default)]
struct Logs {
    /// The last Â_o after [`MIN_TRACKED_S`] of tracking.
    finals: Arc<Mutex<Finals>>,
    /// Â_o once they had been [`NEAR_S`] near the robot.
    at_near: Arc<Mutex<Finals>>,
    /// The smallest gap between them and the robot (m, between surfaces).
    closest: Arc<Mutex<Finals>>,
}

impl Logs {
    fn take(log: &Arc<Mutex<Finals>>) -> Finals {
        log.lock().map(|f| f.clone()).unwrap_or_default()
    }

    /// One row per person in `log`, with their closest approach.
    fn rows(
        &self,
        log: &Arc<Mutex<Finals>>,
        source: impl Fn(u64) -> String,
        run: u64,
    ) -> Vec<EstimateRow> {
        let closest = Self::take(&self.closest);
        Self::take(log)
            .into_iter()
            .map(|(person, estimate)| EstimateRow {
                source: source(person),
                run,
                person,
                estimate,
                closest_m: closest.get(&person).copied().unwrap_or(f64::INFINITY),
            })
            .collect()
    }
}

/// `asfm` as a short-term planner that keeps each person's latest estimate, their estimate
/// once they have been [`NEAR_S`] near the robot, and their closest approach.
#[derive(Debug)]
struct Recorded {
    asfm: Asfm,
    logs: Logs,
    /// Per person: the time spent near the robot so far (s).
    near: BTreeMap<u64, f64>,
}

impl Recorded {
    fn new(asfm: Asfm, logs: &Logs) -> Self {
        Self {
            asfm,
            logs: logs.clone(),
            near: BTreeMap::new(),
        }
    }

    fn record(&mut self, input: &PlanningInput<'_>) {
        // A poisoned lock means another run panicked; its rows are lost anyway.
        if let Ok(mut finals) = self.logs.finals.lock() {
            for (id, estimate, age) in self.asfm.tracked() {
                if age >= MIN_TRACKED_S {
                    finals.insert(id, estimate);
                }
            }
        }
        let ego = input.ego;
        for nb in input.neighbours {
            let gap = (nb.position - ego.position).norm() - nb.radius - ego.radius;
            if let Ok(mut closest) = self.logs.closest.lock() {
                let c = closest.entry(nb.id).or_insert(f64::INFINITY);
                *c = c.min(gap);
            }
            if gap > NEAR_GAP_M {
                continue;
            }
            let near = self.near.entry(nb.id).or_default();
            let before = *near;
            *near += input.dt;
            if before < NEAR_S && *near >= NEAR_S {
                let estimate = self.asfm.estimates().find(|(id, _)| *id == nb.id);
                if let (Some((_, a)), Ok(mut at)) = (estimate, self.logs.at_near.lock()) {
                    at.insert(nb.id, a);
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
        self.record(input);
        plan
    }
}

/// One person's estimate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EstimateRow {
    /// Where: the recording's name, or `sim-reacting` / `sim-ignoring`.
    pub source: String,
    /// The run (replay run index, or simulator seed).
    pub run: u64,
    /// The person's id.
    pub person: u64,
    /// Their Â_o.
    pub estimate: f64,
    /// The smallest gap between them and the robot over the run (m, between surfaces).
    pub closest_m: f64,
}

/// A recorded crowd the study plays `asfm` in: the recording, its obstacles and the options
/// (the robot's top speed, its safety layer setting).
#[derive(Debug, Clone)]
pub struct RecordedCrowd {
    /// The recording.
    pub recording: Recording,
    /// Its obstacle lines.
    pub map: agent::map::StaticMap,
    /// How runs are cut and played.
    pub options: PlaybackOptions,
}

/// The simulated crowd of a source.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum SimCrowd {
    /// Everyone steps aside for robots (Social Force).
    Reacting,
    /// Nobody does.
    Ignoring,
    /// This share of people does, the others do not (`humans.react_share`).
    Mixed(f64),
}

/// What to run: `asfm` with `params` in the partial runs of each recorded crowd (the first
/// `limit` of each), and in the simulator's open space for each (crowd, density) at every seed.
#[derive(Debug, Clone)]
pub struct EstimatesStudy {
    /// The recorded crowds.
    pub recorded: Vec<RecordedCrowd>,
    /// At most this many partial runs per recording.
    pub limit: Option<usize>,
    /// The open-space scenario the simulated crowds start from.
    pub base: Scenario,
    /// The simulated crowds and their densities (people per m²), in output order.
    pub crowds: Vec<(SimCrowd, f64)>,
    /// The simulator's seeds.
    pub seeds: std::ops::RangeInclusive<u64>,
    /// The planner's parameters (its top speed is the robot's).
    pub params: AsfmParams,
}

/// One run of the estimates study.
#[derive(Debug, Clone)]
pub enum EstimateRun {
    /// The `index`-th partial run of the `recording`-th recorded crowd.
    Recorded {
        /// Which recorded crowd.
        recording: usize,
        /// The run's index among the recording's runs.
        index: u64,
        /// The run.
        run: PlaybackRun,
    },
    /// A simulated crowd at a density, one seed.
    Simulated {
        /// Who reacts.
        crowd: SimCrowd,
        /// People per m².
        density: f64,
        /// The seed.
        seed: u64,
    },
}

/// Recorded runs first, recording by recording; then each simulated crowd, seed by seed. A
/// run's row is the estimates of the people it tracked: for a recorded crowd each person's
/// last Â_o after [`MIN_TRACKED_S`] of tracking (source: the recording's name); for a reacting
/// or ignoring crowd the same (sources `sim-reacting`, `sim-ignoring`); for a mixed crowd each
/// person's Â_o once they have been [`NEAR_S`] near the robot, by what they are
/// (`sim-mixed-reacting`, `sim-mixed-ignoring`).
impl Study for EstimatesStudy {
    type Key = EstimateRun;
    type Row = Vec<EstimateRow>;
    type Error = std::convert::Infallible;

    fn keys(&self) -> Vec<EstimateRun> {
        let mut keys = Vec::new();
        for (r, crowd) in self.recorded.iter().enumerate() {
            let mut all = runs(&crowd.recording, RunKind::Partial, &crowd.options);
            if let Some(n) = self.limit {
                all.truncate(n);
            }
            keys.extend(
                all.into_iter()
                    .enumerate()
                    .map(|(i, run)| EstimateRun::Recorded {
                        recording: r,
                        index: i as u64,
                        run,
                    }),
            );
        }
        for &(crowd, density) in &self.crowds {
            keys.extend(self.seeds.clone().map(|seed| EstimateRun::Simulated {
                crowd,
                density,
                seed,
            }));
        }
        keys
    }

    fn run(&self, key: &EstimateRun) -> Result<Vec<EstimateRow>, Self::Error> {
        Ok(match *key {
            EstimateRun::Recorded {
                recording,
                index,
                ref run,
            } => self.recorded_run(&self.recorded[recording], index, run),
            EstimateRun::Simulated {
                crowd,
                density,
                seed,
            } => self.simulated_run(crowd, density, seed),
        })
    }
}

impl EstimatesStudy {
    fn recorded_run(
        &self,
        crowd: &RecordedCrowd,
        index: u64,
        run: &PlaybackRun,
    ) -> Vec<EstimateRow> {
        let RecordedCrowd {
            recording,
            map,
            options,
        } = crowd;
        let logs = Logs::default();
        let mut planner = Recorded::new(
            Asfm::new(AsfmParams {
                v_max: options.robot.max_speed,
                ..self.params.clone()
            }),
            &logs,
        );
        let robot = &options.robot;
        let mut guard = robot.guard(0.0);
        world_sim::playback::play(recording, map, run, options, &mut |input| {
            let planned = planner.plan(input, input.goal).command;
            guard
                .as_mut()
                .map_or(planned, |g| g.check(planned, input).command)
        });
        logs.rows(&logs.finals, |_| recording.name.clone(), index)
    }

    fn simulated_run(&self, crowd: SimCrowd, density: f64, seed: u64) -> Vec<EstimateRow> {
        let mut scenario = self.base.clone();
        if let Some(open) = scenario.open_space.as_mut() {
            open.density = density;
        }
        scenario.humans.react_to_robots = crowd != SimCrowd::Ignoring;
        if let SimCrowd::Mixed(share) = crowd {
            scenario.humans.react_share = share;
        }
        scenario.seed = seed;
        let logs = Logs::default();
        let spec: PlannerSpec = "asfm".parse().expect("a known planner");
        let v_max = scenario.robot.max_speed;
        run_episode_with(&scenario, |_| {
            let asfm = Asfm::new(AsfmParams {
                v_max,
                ..self.params.clone()
            });
            PlannerStack::with_local(spec, Box::new(Recorded::new(asfm, &logs)))
        });
        let people = World::from_scenario(&scenario).humans;
        let log = match crowd {
            SimCrowd::Mixed(_) => &logs.at_near,
            _ => &logs.finals,
        };
        let source = |person: u64| {
            match crowd {
                SimCrowd::Reacting => "sim-reacting",
                SimCrowd::Ignoring => "sim-ignoring",
                SimCrowd::Mixed(_) if people.reacts(person as usize) => "sim-mixed-reacting",
                SimCrowd::Mixed(_) => "sim-mixed-ignoring",
            }
            .to_string()
        };
        logs.rows(log, source, seed)
    }
}

/// The area under the ROC curve of a score as a test of "reacts" (`positives`) against
/// "ignores" (`negatives`): the chance that a random reacting person's score exceeds a random
/// ignoring person's, ties counting half (Mann–Whitney). `None` without both kinds.
pub fn auc(positives: &[f64], negatives: &[f64]) -> Option<f64> {
    if positives.is_empty() || negatives.is_empty() {
        return None;
    }
    let mut wins = 0.0;
    for &p in positives {
        for &n in negatives {
            wins += if p > n {
                1.0
            } else if p == n {
                0.5
            } else {
                0.0
            };
        }
    }
    Some(wins / (positives.len() * negatives.len()) as f64)
}

/// The AUC of the mixed crowd's rows in `rows`, if it has both kinds.
pub fn mixed_auc(rows: &[EstimateRow]) -> Option<f64> {
    mixed_auc_of(rows, |r| r.estimate)
}

/// The same AUC for the people's closest approach to the robot (reacting people should keep
/// farther): how differently the two kinds behave near the robot at all, the most any
/// estimate read from their motion could separate them by.
pub fn mixed_closest_auc(rows: &[EstimateRow]) -> Option<f64> {
    mixed_auc_of(rows, |r| r.closest_m)
}

fn mixed_auc_of(rows: &[EstimateRow], value: impl Fn(&EstimateRow) -> f64) -> Option<f64> {
    let of = |source: &str| -> Vec<f64> {
        rows.iter()
            .filter(|r| r.source == source)
            .map(&value)
            .collect()
    };
    auc(&of("sim-mixed-reacting"), &of("sim-mixed-ignoring"))
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
    write_json(
        &out.join("summary.json"),
        &serde_json::json!({
            "sources": &summary,
            "mixed_auc": mixed_auc(rows),
            "mixed_closest_auc": mixed_closest_auc(rows),
        }),
    )?;
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
