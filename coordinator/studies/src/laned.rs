//! The peek-and-pass paper's laned study (Sec. V-A, Fig. 4): a laned hallway in which people
//! walk the same way at varied speeds, a robot with a top speed of 3 m/s behind them, and the
//! planner's exploration-to-exploitation ratio 1/(c1·c3) swept. Per ratio, the distribution
//! of the robot's average speed over the seeds; the paper chooses the c's where it peaks.
//! In-process and in parallel; the output depends only on the inputs.

use super::csv_fields::{fixed1_or_empty, fixed4, to_csv};
use super::output::{StudyError, write_json};
use super::plots::write_boxes;
use super::runner::Study;
use agent::planner::PlannerStack;
use agent::pnp::PnpParams;
use serde::Serialize;
use std::path::Path;
use world_sim::episode::run_episode_with;
use world_sim::scenario::Scenario;

/// The study's hallway: `length` m with `lanes` lanes 1.2 m apart, people at the hallway
/// study's density walking at ½–1½ × `human_speed`, a robot with top speed `robot_speed`,
/// body occlusion on, the safety layer as asked, and 60 s + 2 s per metre to get through.
pub fn laned_hallway(
    length: f64,
    lanes: usize,
    human_speed: f64,
    robot_speed: f64,
    safety: bool,
) -> Result<Scenario, world_sim::scenario::ScenarioError> {
    let mut scenario = Scenario::builtin("hallway")?;
    if let Some(h) = scenario.hallway.as_mut() {
        h.length_m = length;
        h.width_m = 1.2 * lanes as f64;
        h.lanes = Some(lanes);
        h.humans = (length * super::hallway::PEOPLE_PER_METRE).round() as usize;
    }
    scenario.humans.speed = human_speed;
    scenario.robot.max_speed = robot_speed;
    scenario.robot.body_occlusion = true;
    scenario.robot.safety = safety;
    scenario.max_time_s = 60.0 + 2.0 * length;
    scenario.validate("study laned")?;
    Ok(scenario)
}

/// What to run.
#[derive(Debug, Clone)]
pub struct LanedStudy {
    /// The laned hallway (its seed is set per run).
    pub scenario: Scenario,
    /// The ratios 1/(c1·c3) to sweep (c1 stays at its default).
    pub ratios: Vec<f64>,
    /// Seeds 1..=seeds per ratio.
    pub seeds: u64,
}

/// One run.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct LanedRow {
    /// 1/(c1·c3).
    pub ratio: f64,
    /// The c3 it gives.
    pub c3: f64,
    /// Seed.
    pub seed: u64,
    /// Whether the robot reached the far end in time.
    pub reached: bool,
    /// Seconds to the goal (empty if not reached).
    #[serde(with = "fixed1_or_empty")]
    pub time_to_goal_s: Option<f64>,
    /// Metres driven over the run's duration (to the goal, or the time limit) (m/s).
    #[serde(with = "fixed4")]
    pub average_speed: f64,
    /// Contacts the robot caused.
    pub robot_caused_contacts: u64,
}

impl LanedStudy {
    /// Every (ratio, seed) in report order.
    pub fn runs(&self) -> Vec<(f64, u64)> {
        self.ratios
            .iter()
            .flat_map(|&r| (1..=self.seeds).map(move |s| (r, s)))
            .collect()
    }

    /// The planner's parameters at `ratio`: the defaults at the robot's top speed, with
    /// c3 = 1/(c1·ratio).
    pub fn params(&self, ratio: f64) -> PnpParams {
        let d = PnpParams::default();
        PnpParams {
            v_max: self.scenario.robot.max_speed,
            c3: 1.0 / (d.c1 * ratio),
            ..d
        }
    }
}

impl Study for LanedStudy {
    type Key = (f64, u64);
    type Row = LanedRow;
    type Error = std::convert::Infallible;

    fn keys(&self) -> Vec<Self::Key> {
        self.runs()
    }

    fn run(&self, &(ratio, seed): &Self::Key) -> Result<LanedRow, Self::Error> {
        let mut scenario = self.scenario.clone();
        scenario.seed = seed;
        let params = self.params(ratio);
        let c3 = params.c3;
        let m = run_episode_with(&scenario, |_| PlannerStack::pnp(params.clone()))[0];
        let duration = if m.success {
            m.time_to_goal_s
        } else {
            scenario.max_time_s
        };
        Ok(LanedRow {
            ratio,
            c3,
            seed,
            reached: m.success,
            time_to_goal_s: m.success.then_some(m.time_to_goal_s),
            average_speed: m.path_length_m / duration,
            robot_caused_contacts: m.robot_caused_contacts,
        })
    }
}

/// The spread of the average speed at one ratio.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LanedCell {
    /// 1/(c1·c3).
    pub ratio: f64,
    /// Runs.
    pub runs: usize,
    /// Share that reached the end.
    pub reached: f64,
    /// Average speed: minimum, lower quartile, median, upper quartile, maximum (m/s).
    pub speed_quartiles: [f64; 5],
    /// Robot-caused contacts, summed.
    pub robot_caused_contacts: u64,
}

/// The five-number summary of `values` (quartiles by linear interpolation).
pub fn five_numbers(values: &[f64]) -> [f64; 5] {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return [f64::NAN; 5];
    }
    v.sort_by(f64::total_cmp);
    let at = |q: f64| {
        let pos = q * (v.len() - 1) as f64;
        let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
        v[lo] + (v[hi] - v[lo]) * (pos - lo as f64)
    };
    [at(0.0), at(0.25), at(0.5), at(0.75), at(1.0)]
}

/// The cells of `rows`, by ratio.
pub fn summarize(study: &LanedStudy, rows: &[LanedRow]) -> Vec<LanedCell> {
    study
        .ratios
        .iter()
        .map(|&ratio| {
            let mine: Vec<&LanedRow> = rows.iter().filter(|r| r.ratio == ratio).collect();
            let speeds: Vec<f64> = mine.iter().map(|r| r.average_speed).collect();
            LanedCell {
                ratio,
                runs: mine.len(),
                reached: mine.iter().filter(|r| r.reached).count() as f64
                    / mine.len().max(1) as f64,
                speed_quartiles: five_numbers(&speeds),
                robot_caused_contacts: mine.iter().map(|r| r.robot_caused_contacts).sum(),
            }
        })
        .collect()
}

/// Writes `runs.csv`, `summary.json` and `average_speed.png` into `out`.
pub fn write_outputs(
    out: &Path,
    study: &LanedStudy,
    rows: &[LanedRow],
) -> Result<Vec<LanedCell>, StudyError> {
    std::fs::create_dir_all(out).map_err(StudyError::io(out))?;
    let path = out.join("runs.csv");
    std::fs::write(&path, to_csv(rows)).map_err(StudyError::io(&path))?;
    let cells = summarize(study, rows);
    write_json(&out.join("summary.json"), &cells)?;
    let boxes: Vec<(String, [f64; 5])> = cells
        .iter()
        .map(|c| (format!("{}", c.ratio), c.speed_quartiles))
        .collect();
    write_boxes(
        &out.join("average_speed.png"),
        "Robot's average speed against exploration / exploitation 1/(c1·c3) (cf. Fig. 4)",
        "1/(c1·c3)",
        "average speed (m/s)",
        &boxes,
    )?;
    Ok(cells)
}
