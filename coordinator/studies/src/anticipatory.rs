//! The anticipatory Social Force paper's experiment (Sec. IV): a robot and one Social Force
//! obstacle swap places head-on on a 3 × 3 m floor (Table I), the obstacle avoiding the robot
//! with A_o = 20 or not at all (A_o = 0), the robot observing it through N(0, 0.1²) noise. The
//! robot's planner estimates Â_o (the paper's method) or fixes it at 0 or 20. Per run the
//! minimum distance between the two and the robot's movement time; in one run per A_o, Â_o
//! over time (Figs. 3–4).
//!
//! Each seed's noise is the same for the three methods (paired runs). In-process and in
//! parallel; the output depends only on the inputs.

use super::csv_fields::{fixed1_or_empty, fixed4, to_csv};
use super::laned::five_numbers;
use super::output::{StudyError, write_json};
use super::plots::{write_boxes, write_lines};
use super::runner::Study;
use agent::asfm::model::{attraction, desired_toward, repulsion, step};
use agent::asfm::{Asfm, AsfmParams, Estimation};
use agent::map::StaticMap;
use agent::math::{Real, vec2};
use agent::model::{AgentKind, EgoState, Neighbour};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::Serialize;
use std::path::Path;

/// Table I: the obstacle's and the robot's start, initial velocity and goal.
pub const OBSTACLE: (Vec2Tuple, Vec2Tuple, Vec2Tuple) = ((1.5, 0.8), (0.0, 1.0), (1.5, 2.2));
/// Table I: the robot's.
pub const ROBOT: (Vec2Tuple, Vec2Tuple, Vec2Tuple) = ((1.5, 2.2), (0.0, -1.0), (1.5, 0.8));
/// An (x, y) pair.
pub type Vec2Tuple = (Real, Real);

/// The paper's observation noise: N(0, 0.1²) per axis (m).
pub const NOISE_SIGMA: Real = 0.1;
/// A run ends when the robot is within the planner's goal tolerance of its goal, or after this
/// long (s): four times what the swap takes at 1 m/s.
pub const MAX_TIME_S: Real = 6.0;

/// The robot's methods of Sec. IV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Â_o estimated (the paper's method).
    Estimated,
    /// Â_o fixed.
    Fixed(Real),
}

impl Method {
    /// The three methods of Figs. 5–6.
    pub const ALL: [Method; 3] = [Method::Estimated, Method::Fixed(0.0), Method::Fixed(20.0)];

    /// Its name in the outputs.
    pub fn name(&self) -> String {
        match self {
            Method::Estimated => "estimated".to_string(),
            Method::Fixed(a) => format!("fixed {a}"),
        }
    }
}

/// One run's outcome.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct Row {
    /// The obstacle's true A_o.
    pub a_o: Real,
    /// The robot's method.
    pub method: String,
    /// Seed of the observation noise.
    pub seed: u64,
    /// Whether the robot reached its goal within the time limit.
    pub reached: bool,
    /// The robot's movement time to the goal (s; empty if not reached).
    #[serde(with = "fixed1_or_empty")]
    pub movement_time_s: Option<Real>,
    /// The smallest distance between the robot and the obstacle (m, centres: the paper's
    /// bodies are points).
    #[serde(with = "fixed4")]
    pub min_distance_m: Real,
    /// Â_o at the end of the run.
    #[serde(with = "fixed4")]
    pub final_estimate: Real,
}

/// One step of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TraceStep {
    /// Time (s).
    pub t: Real,
    /// Â_o.
    pub estimate: Real,
    /// The distance between the two (m).
    pub distance: Real,
    /// The robot's position.
    pub robot: (Real, Real),
    /// The obstacle's position.
    pub obstacle: (Real, Real),
}

/// One run's time series (for Figs. 3–4).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trace {
    /// Per step.
    pub steps: Vec<TraceStep>,
}

/// Runs the paper's setting once.
pub fn run(a_o: Real, method: Method, seed: u64, params: &AsfmParams) -> (Row, Trace) {
    let estimation = match method {
        Method::Estimated => Estimation::Estimated,
        Method::Fixed(a) => Estimation::Fixed(a),
    };
    let mut planner = Asfm::with_estimation(params.clone(), estimation);
    let v = |t: Vec2Tuple| vec2(t.0, t.1);
    let (mut r, mut rv, goal) = (v(ROBOT.0), v(ROBOT.1), v(ROBOT.2));
    let (mut o, mut ov, o_goal) = (v(OBSTACLE.0), v(OBSTACLE.1), v(OBSTACLE.2));
    planner.know_goal(0, o_goal);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let noise = Normal::new(0.0, NOISE_SIGMA).expect("a valid σ");
    let map = StaticMap::empty();
    let dt = params.dt;
    let steps = (MAX_TIME_S / dt).round() as usize;
    let mut trace = Trace::default();
    let mut min_distance = (r - o).norm();
    let mut movement = None;
    for k in 0..steps {
        let observed = o + vec2(noise.sample(&mut rng), noise.sample(&mut rng));
        let ego = EgoState {
            position: r,
            heading: 0.0,
            velocity: rv,
            yaw_rate: 0.0,
            radius: 0.0,
        };
        // The velocity matters only at first sight: Table I's initial velocity.
        let seen = Neighbour::new(0, observed, ov, 0.0, AgentKind::Human);
        let out = planner.step(&ego, &[seen], &map, goal, dt);
        // The obstacle (Eqs. 1–5 against the robot as it stands now), and the robot on its
        // command (Eq. 1 with the acceleration the command implies).
        let a = repulsion(o - r, 0.0, a_o, params.range)
            + attraction(
                desired_toward(o_goal, o, params.people_speed),
                ov,
                params.tau,
            );
        (o, ov) = step(o, ov, a, dt);
        let ra = (out.command - rv) / dt;
        (r, rv) = step(r, rv, ra, dt);
        let d = (r - o).norm();
        min_distance = min_distance.min(d);
        let estimate = planner.estimates().next().map_or(0.0, |(_, e)| e);
        trace.steps.push(TraceStep {
            t: (k + 1) as Real * dt,
            estimate,
            distance: d,
            robot: (r.x, r.y),
            obstacle: (o.x, o.y),
        });
        if (goal - r).norm() <= params.goal_tolerance {
            movement = Some((k + 1) as Real * dt);
            break;
        }
    }
    let row = Row {
        a_o,
        method: method.name(),
        seed,
        reached: movement.is_some(),
        movement_time_s: movement,
        min_distance_m: min_distance,
        final_estimate: trace.steps.last().map_or(0.0, |s| s.estimate),
    };
    (row, trace)
}

/// What to run.
#[derive(Debug, Clone)]
pub struct AnticipatoryStudy {
    /// The planner's parameters (Table II's by default).
    pub params: AsfmParams,
    /// The obstacle's A_o values.
    pub a_o: Vec<Real>,
    /// Seeds 1..=runs per (A_o, method).
    pub runs: u64,
}

impl AnticipatoryStudy {
    /// Every (A_o, method, seed) in report order.
    pub fn runs(&self) -> Vec<(Real, Method, u64)> {
        self.a_o
            .iter()
            .flat_map(|&a| {
                Method::ALL
                    .into_iter()
                    .flat_map(move |m| (1..=self.runs).map(move |s| (a, m, s)))
            })
            .collect()
    }
}

impl Study for AnticipatoryStudy {
    type Key = (Real, Method, u64);
    type Row = Row;
    type Error = std::convert::Infallible;

    fn keys(&self) -> Vec<Self::Key> {
        self.runs()
    }

    fn run(&self, &(a, m, s): &Self::Key) -> Result<Row, Self::Error> {
        Ok(run(a, m, s, &self.params).0)
    }
}

/// One (A_o, method) cell.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cell {
    /// The obstacle's A_o.
    pub a_o: Real,
    /// The method.
    pub method: String,
    /// Runs.
    pub runs: usize,
    /// Share that reached the goal.
    pub reached: Real,
    /// Minimum distance: min, q1, median, q3, max (m).
    pub min_distance: [Real; 5],
    /// Share of runs whose minimum distance is below d_min.
    pub below_d_min: Real,
    /// Movement time of the runs that reached: min, q1, median, q3, max (s).
    pub movement_time: [Real; 5],
    /// Final Â_o: min, q1, median, q3, max.
    pub final_estimate: [Real; 5],
}

/// The cells of `rows`.
pub fn summarize(study: &AnticipatoryStudy, rows: &[Row]) -> Vec<Cell> {
    let mut cells = Vec::new();
    for &a in &study.a_o {
        for m in Method::ALL {
            let name = m.name();
            let mine: Vec<&Row> = rows
                .iter()
                .filter(|r| r.a_o == a && r.method == name)
                .collect();
            let n = mine.len().max(1) as Real;
            let col = |f: &dyn Fn(&Row) -> Option<Real>| -> Vec<Real> {
                mine.iter().filter_map(|r| f(r)).collect()
            };
            cells.push(Cell {
                a_o: a,
                method: name,
                runs: mine.len(),
                reached: mine.iter().filter(|r| r.reached).count() as Real / n,
                min_distance: five_numbers(&col(&|r| Some(r.min_distance_m))),
                below_d_min: mine
                    .iter()
                    .filter(|r| r.min_distance_m < study.params.d_min)
                    .count() as Real
                    / n,
                movement_time: five_numbers(&col(&|r| r.movement_time_s)),
                final_estimate: five_numbers(&col(&|r| Some(r.final_estimate))),
            });
        }
    }
    cells
}

/// Writes `runs.csv`, `summary.json`, `estimate.csv` and the figures into `out`.
pub fn write_outputs(
    out: &Path,
    study: &AnticipatoryStudy,
    rows: &[Row],
) -> Result<Vec<Cell>, StudyError> {
    std::fs::create_dir_all(out).map_err(StudyError::io(out))?;
    let path = out.join("runs.csv");
    std::fs::write(&path, to_csv(rows)).map_err(StudyError::io(&path))?;
    let cells = summarize(study, rows);
    write_json(&out.join("summary.json"), &cells)?;
    // Figs. 3–4: Â_o over time in seed 1's estimated run, per A_o.
    let mut csv =
        String::from("a_o,t_s,estimate,distance_m,robot_x,robot_y,obstacle_x,obstacle_y\n");
    let mut series = Vec::new();
    for &a in &study.a_o {
        let (_, trace) = run(a, Method::Estimated, 1, &study.params);
        for s in &trace.steps {
            csv.push_str(&format!(
                "{a},{:.1},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}\n",
                s.t, s.estimate, s.distance, s.robot.0, s.robot.1, s.obstacle.0, s.obstacle.1
            ));
        }
        series.push((
            format!("A_o = {a}"),
            trace
                .steps
                .iter()
                .map(|s| (s.t, s.estimate))
                .collect::<Vec<_>>(),
        ));
    }
    let path = out.join("estimate.csv");
    std::fs::write(&path, csv).map_err(StudyError::io(&path))?;
    write_lines(
        &out.join("estimate.png"),
        "Estimated Â_o over time, one run per A_o (cf. Figs. 3–4)",
        &[("time (s)", "Â_o", series)],
    )?;
    // Figs. 5–6: the distributions per method, per A_o.
    for &a in &study.a_o {
        let mine: Vec<&Cell> = cells.iter().filter(|c| c.a_o == a).collect();
        let boxes = |f: &dyn Fn(&Cell) -> [Real; 5]| -> Vec<(String, [Real; 5])> {
            mine.iter().map(|c| (c.method.clone(), f(c))).collect()
        };
        write_boxes(
            &out.join(format!("min_distance_ao{a}.png")),
            &format!("Minimum distance, obstacle A_o = {a} (cf. Figs. 5(a)–6(a))"),
            "method (Â_o)",
            "minimum distance (m)",
            &boxes(&|c| c.min_distance),
        )?;
        write_boxes(
            &out.join(format!("movement_time_ao{a}.png")),
            &format!("Movement time, obstacle A_o = {a} (cf. Figs. 5(b)–6(b))"),
            "method (Â_o)",
            "movement time (s)",
            &boxes(&|c| c.movement_time),
        )?;
    }
    Ok(cells)
}
