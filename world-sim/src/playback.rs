//! The foIGP paper's evaluation on recorded crowds (Sec. 7): pick a pedestrian, remove them from
//! what the planner sees, give the planner their start and goal, and play everyone else back as
//! recorded (they do not react). The robot is judged against what that person actually did.
//!
//! Runs are *partial* (consecutive ≈ 10 m stretches of a pedestrian's path; only start and goal
//! are given) or *full* (a pedestrian's whole track; as in the paper, the goal at each step is
//! the person's recorded position one annotation step ahead). Per run: s, the smallest
//! centre-to-centre distance to any pedestrian; the path lengths d_r (robot) and d_h (the
//! person), both up to the point where they first come within the robot's goal tolerance of
//! the goal (the robot stops there, so a whole-path d_h would make d_r/d_h about 5 % low on a
//! 10 m run); the density of people within 3 m. The "human" row measures the removed person
//! the same way over their own time window, up to that same point.

use crate::dataset::{Recording, SAMPLE_DT, Track};
use crate::robot::RobotBody;
use crate::scenario::RobotSpec;
use agent::map::{MapError, Obstacle, StaticMap};
use agent::math::{Real, Vec2, angle_of, clamp_norm};
use agent::model::{AgentKind, Command, EgoState, Neighbour};
use agent::planner::PlanningInput;
use agent::route::Router;
use agent::safety::{LADDER, SafetyLayer, SafetyParams};
use exposure::Exposure;
use std::fmt;

mod exposure;
use std::str::FromStr;

/// Partial (≈ 10 m stretches) or full (whole tracks) runs.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
pub enum RunKind {
    /// Consecutive stretches of `segment_m` of a pedestrian's path; start and goal only.
    Partial,
    /// A pedestrian's whole track, the goal following the person one step ahead.
    Full,
}

/// A run kind that is neither `partial` nor `full`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown run kind {0:?}; expected partial or full")]
pub struct UnknownRunKind(pub String);

impl FromStr for RunKind {
    type Err = UnknownRunKind;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "partial" => Ok(Self::Partial),
            "full" => Ok(Self::Full),
            other => Err(UnknownRunKind(other.to_owned())),
        }
    }
}

impl fmt::Display for RunKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Partial => "partial",
            Self::Full => "full",
        })
    }
}

/// How runs are cut and played.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaybackOptions {
    /// Simulation step (s); the recording is interpolated to it.
    pub dt: Real,
    /// Planners replan this often and hold their command in between (s): the recordings'
    /// annotation step, as in the paper.
    pub replan_period: Real,
    /// Length of a partial run (m).
    pub segment_m: Real,
    /// Full runs need at least this much recorded path (m), so d_r / d_h means something.
    pub min_full_m: Real,
    /// Radius of the density circle (m).
    pub density_radius_m: Real,
    /// The robot perceives people within this range (m), through walls (the recordings have no
    /// occlusion model).
    pub sensor_range_m: Real,
    /// Body radius given to the recorded people (m).
    pub person_radius_m: Real,
    /// After the person's own end time, the robot gets this long, or as long as the person
    /// took, whichever is longer, to arrive (s).
    pub patience_s: Real,
    /// In partial runs, when the straight line to the goal does not keep this far from the
    /// scene's walls, the robot heads for the next corner of the shortest way round them
    /// instead ([`agent::route::Router::steer`]) (m); 0 gives the planner the goal alone.
    pub route_clearance_m: Real,
    /// The robot.
    pub robot: RobotSpec,
}

impl Default for PlaybackOptions {
    fn default() -> Self {
        Self {
            dt: 0.1,
            replan_period: SAMPLE_DT,
            segment_m: 10.0,
            min_full_m: 5.0,
            density_radius_m: 3.0,
            sensor_range_m: 12.0,
            person_radius_m: 0.3,
            patience_s: 10.0,
            // Room for the body and a body's width more round a wall's end.
            route_clearance_m: 0.6,
            // The PGP study's robot (Table I: 1 m/s), holonomic or unicycle as commanded.
            robot: RobotSpec {
                radius_m: 0.3,
                max_speed: 1.0,
                max_accel: 1.5,
                max_yaw_rate: 1.0,
                max_yaw_accel: 1.5,
                goal_tolerance_m: 0.5,
                sensor_range_m: 12.0,
                position_noise_m: 0.0,
                velocity_noise: 0.0,
                occlusion: false,
                body_occlusion: false,
                // Recorded people do not react: the robot yields alone, under the layer.
                safety: true,
                safety_layer: SafetyParams::default(),
            },
        }
    }
}

/// One run: whose place the robot takes, and when and where.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlaybackRun {
    /// The removed pedestrian.
    pub pedestrian: u64,
    /// Partial or full.
    pub kind: RunKind,
    /// Which stretch of the pedestrian's path (0 for full runs).
    pub segment: usize,
    /// First and last annotation index of the stretch.
    pub samples: (usize, usize),
    /// Start time (s).
    pub t_start: Real,
    /// The end of the person's stretch (s).
    pub t_end: Real,
    /// When the person first came within the robot's goal tolerance of `goal` (s): where the
    /// robot's run ends when it arrives, so the end of the person's comparable run.
    pub t_arrive: Real,
    /// Where the person was at `t_start`.
    pub start: Vec2,
    /// Where the person was at `t_end`.
    pub goal: Vec2,
    /// d_h: the person's annotated path length up to `t_arrive` (m).
    pub human_path_m: Real,
    /// The person's annotated path length over the whole stretch, to `goal` itself (m).
    pub human_whole_path_m: Real,
}

/// Where the segment a → b first enters the disc of radius `r` around `centre`, as a
/// fraction of the segment; `None` if it does not (a starts outside the disc).
fn entry_fraction(a: Vec2, b: Vec2, centre: Vec2, r: Real) -> Option<Real> {
    let d = b - a;
    let f = a - centre;
    let (qa, qb, qc) = (d.norm_squared(), 2.0 * f.dot(&d), f.norm_squared() - r * r);
    if qc < 0.0 {
        return Some(0.0);
    }
    let disc = qb * qb - 4.0 * qa * qc;
    if qa <= 0.0 || disc < 0.0 {
        return None;
    }
    let root = (-qb - disc.sqrt()) / (2.0 * qa);
    (0.0..=1.0).contains(&root).then_some(root)
}

/// The time at which the track, between samples `first` and `last`, first comes within `r`
/// of `goal`, and the path walked until then (linear between annotations). Samples are
/// checked from `first + 1`: a stretch that starts inside the disc is measured to its first
/// re-entry, or, if it never leaves, to `last`.
fn arrival(track: &Track, first: usize, last: usize, goal: Vec2, r: Real) -> (Real, Real) {
    let samples = &track.samples[first..=last];
    let mut walked = 0.0;
    let mut outside = false;
    for w in samples.windows(2) {
        let (a, b) = (w[0].position, w[1].position);
        let step = (b - a).norm();
        outside |= (a - goal).norm() >= r;
        if outside && let Some(f) = entry_fraction(a, b, goal, r) {
            return (w[0].t + f * (w[1].t - w[0].t), walked + f * step);
        }
        walked += step;
    }
    (samples[samples.len() - 1].t, walked)
}

/// The runs of a recording, by pedestrian id and stretch.
pub fn runs(recording: &Recording, kind: RunKind, options: &PlaybackOptions) -> Vec<PlaybackRun> {
    let mut out = Vec::new();
    for track in &recording.tracks {
        let run = |segment, first: usize, last: usize| {
            let goal = track.samples[last].position;
            let tolerance = options.robot.goal_tolerance_m;
            let (t_arrive, human_path_m) = arrival(track, first, last, goal, tolerance);
            PlaybackRun {
                pedestrian: track.id,
                kind,
                segment,
                samples: (first, last),
                t_start: track.samples[first].t,
                t_end: track.samples[last].t,
                t_arrive,
                start: track.samples[first].position,
                goal,
                human_path_m,
                human_whole_path_m: track.path_length(first, last),
            }
        };
        match kind {
            RunKind::Full => {
                let last = track.samples.len() - 1;
                if track.path_length(0, last) >= options.min_full_m {
                    out.push(run(0, 0, last));
                }
            }
            RunKind::Partial => {
                let (mut first, mut walked, mut segment) = (0, 0.0, 0);
                for i in 1..track.samples.len() {
                    walked += (track.samples[i].position - track.samples[i - 1].position).norm();
                    if walked >= options.segment_m {
                        out.push(run(segment, first, i));
                        (first, walked, segment) = (i, 0.0, segment + 1);
                    }
                }
            }
        }
    }
    out
}

/// How a run went, for the robot or for the person.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RunOutcome {
    /// Whether the goal was reached before time ran out (always true for the person).
    pub reached: bool,
    /// s: the smallest centre-to-centre distance to any pedestrian (m; ∞ if nobody was there).
    pub min_distance_m: Real,
    /// Who was that close, and when (s): for looking at the closest approaches in the data.
    pub closest: Option<(u64, Real)>,
    /// d_r (robot) or d_h (person): path length (m).
    pub path_m: Real,
    /// d_h, for the ratio.
    pub human_path_m: Real,
    /// How long it took (s).
    pub duration_s: Real,
    /// Mean over the run of the people within the density radius per m².
    pub mean_density: Real,
    /// The largest such density.
    pub max_density: Real,
    /// How many plans were made (0 for the person).
    pub replans: usize,
    /// Contacts (bodies overlapping) begun while the robot moved toward the person
    /// ([`contact_cause`](crate::metrics::contact_cause)); for the person's own row, while they moved toward the other. A
    /// contact under way when the run starts is not counted (it began before the robot was
    /// put in the person's place), nor one with a person whose annotated track begins inside
    /// the robot (they appear there).
    pub robot_caused_contacts: u64,
    /// Contacts begun otherwise: a recorded person, who does not react, walked into the robot.
    pub person_caused_contacts: u64,
    /// Contacts begun while the robot moved toward a person who appeared too close to stop
    /// for: their annotated track began during the run, and braking at full deceleration
    /// from the first plan at which the robot perceived them (or before it had perceived
    /// them at all), the robot would still have been moving at the onset. The recording has
    /// them appear within the robot's stopping distance (an annotation that begins mid-scene,
    /// a doorway); no planner and no safety layer can avoid these. Not counted in
    /// `robot_caused_contacts`; 0 for the person's own row.
    pub appeared_contacts: u64,
}

impl RunOutcome {
    /// d_r / d_h.
    pub fn path_ratio(&self) -> Real {
        self.path_m / self.human_path_m
    }
}

/// The median annotated walking speed of a recording (m/s): the default top speed of the
/// robot that takes a pedestrian's place.
pub fn median_speed(recording: &Recording) -> Real {
    let mut speeds: Vec<Real> = recording
        .tracks
        .iter()
        .flat_map(|t| t.samples.iter().map(|s| s.velocity.norm()))
        .collect();
    if speeds.is_empty() {
        return 0.0;
    }
    speeds.sort_by(Real::total_cmp);
    speeds[speeds.len() / 2]
}

/// The recording's obstacle lines as a planner map.
pub fn map_of(recording: &Recording) -> Result<StaticMap, MapError> {
    StaticMap::new(
        recording
            .walls
            .iter()
            .map(|&(a, b)| Obstacle::Wall(a, b))
            .collect(),
    )
}

fn simulation_steps(from: Real, to: Real, dt: Real) -> usize {
    ((to - from) / dt).round().max(0.0) as usize
}

/// The removed person's own outcome over their time window: the "Human" row.
pub fn human_outcome(
    recording: &Recording,
    run: &PlaybackRun,
    options: &PlaybackOptions,
) -> RunOutcome {
    let mut exposure = Exposure::new(options.density_radius_m, 2.0 * options.person_radius_m);
    let track = recording
        .track(run.pedestrian)
        .expect("runs come from this recording's tracks");
    for k in 0..=simulation_steps(run.t_start, run.t_arrive, options.dt) {
        let t = (run.t_start + k as Real * options.dt).min(run.t_arrive);
        let (at, velocity) = track.state_at(t).expect("inside the track's window");
        exposure.record(recording, t, at, velocity, run.pedestrian);
    }
    exposure.finish(
        true,
        run.human_path_m,
        run.human_path_m,
        run.t_arrive - run.t_start,
        0,
    )
}

/// The goal the planner gets at `t` with the robot `at`: in partial runs the run's goal, or
/// the way round a wall to it; in full runs the person one annotation step ahead (their
/// track is the way round).
fn goal_at(
    track: &Track,
    run: &PlaybackRun,
    t: Real,
    map: &StaticMap,
    router: &Router,
    at: Vec2,
) -> Vec2 {
    match run.kind {
        RunKind::Partial if router.clearance() > 0.0 => router.steer(map, at, run.goal),
        RunKind::Partial => run.goal,
        RunKind::Full => track
            .state_at((t + SAMPLE_DT).min(run.t_end))
            .map_or(run.goal, |(p, _)| p),
    }
}

/// What a robot at `at` perceives at `t` in place of pedestrian `removed`: everyone else
/// within the sensor range, as recorded.
pub fn perceived<'a>(
    recording: &'a Recording,
    t: Real,
    removed: u64,
    at: Vec2,
    options: &'a PlaybackOptions,
) -> impl Iterator<Item = Neighbour> + 'a {
    recording
        .people_at(t, Some(removed))
        .filter(move |(_, p, _)| (p - at).norm() <= options.sensor_range_m)
        .map(|(id, p, v)| Neighbour::new(id, p, v, options.person_radius_m, AgentKind::Human))
}

/// The robot in the removed person's recorded place at `t` (their position and velocity, the
/// options' body radius) and the people it perceives there: a recorded scene for benchmarks.
/// `None` outside the person's track.
pub fn scene_at(
    recording: &Recording,
    run: &PlaybackRun,
    t: Real,
    options: &PlaybackOptions,
) -> Option<(EgoState, Vec<Neighbour>)> {
    let (position, velocity) = recording.track(run.pedestrian)?.state_at(t)?;
    let seen = perceived(recording, t, run.pedestrian, position, options).collect();
    let ego = EgoState {
        position,
        heading: angle_of(&velocity),
        velocity,
        yaw_rate: 0.0,
        radius: options.robot.radius_m,
    };
    Some((ego, seen))
}

/// The largest fraction of `velocity` (on the safety layer's ladder, down to 0) at which a
/// robot entering at `ego`'s place and holding it passes the layer's protective check among
/// the people it perceives there.
fn safe_entry_fraction(
    recording: &Recording,
    map: &StaticMap,
    run: &PlaybackRun,
    options: &PlaybackOptions,
    ego: &EgoState,
    velocity: Vec2,
) -> Real {
    let seen: Vec<Neighbour> = perceived(
        recording,
        run.t_start,
        run.pedestrian,
        ego.position,
        options,
    )
    .collect();
    let limits = options.robot.safety_limits(options.replan_period);
    let mut layer = SafetyLayer::new(options.robot.safety_layer);
    LADDER
        .into_iter()
        .find(|&s| {
            let entering = EgoState {
                velocity: velocity * s,
                ..*ego
            };
            let command = Command::Velocity(velocity * s);
            layer
                .prepare(&entering, &limits, &seen, map)
                .admits(command)
        })
        .unwrap_or(0.0)
}

/// Plays one run with the robot in the person's place; `plan` is called every replan period
/// with what the robot perceives and returns the command it holds until the next plan.
pub fn play(
    recording: &Recording,
    map: &StaticMap,
    run: &PlaybackRun,
    options: &PlaybackOptions,
    plan: &mut dyn FnMut(&PlanningInput<'_>) -> Command,
) -> RunOutcome {
    let track = recording
        .track(run.pedestrian)
        .expect("runs come from this recording's tracks");
    let mut robot = RobotBody::new(run.start, run.goal, options.robot);
    // It arrives in the person's place walking as they were (within its limits), so that the
    // people walking with them do not run into a robot starting from rest; under the safety
    // layer, at the largest part of that speed from which the layer could still stop it (a
    // robot under the layer would not have been walking faster there).
    if let Some((_, velocity)) = track.state_at(run.t_start) {
        let velocity = clamp_norm(velocity, options.robot.max_speed);
        if velocity.norm() > 1e-3 {
            robot.state.heading = angle_of(&velocity);
            robot.state.velocity = if options.robot.safety {
                velocity * safe_entry_fraction(recording, map, run, options, &robot.state, velocity)
            } else {
                velocity
            };
        }
    }
    let braking = options.robot.safety_limits(options.replan_period).braking();
    let mut exposure = Exposure::new(
        options.density_radius_m,
        options.robot.radius_m + options.person_radius_m,
    )
    .for_robot(run.t_start, braking);
    let s = &robot.state;
    exposure.record(
        recording,
        run.t_start,
        s.position,
        s.velocity,
        run.pedestrian,
    );
    let duration = run.t_end - run.t_start;
    let deadline = run.t_end + options.patience_s.max(duration);
    let every = simulation_steps(0.0, options.replan_period, options.dt).max(1);
    let router = Router::new(options.route_clearance_m);
    let mut command = Command::STOP;
    let mut neighbours = Vec::new();
    let (mut path, mut replans, mut reached) = (0.0, 0, false);
    let steps = simulation_steps(run.t_start, deadline, options.dt);
    let mut t = run.t_start;
    for k in 0..steps {
        t = run.t_start + k as Real * options.dt;
        if k % every == 0 {
            let at = robot.state.position;
            neighbours.clear();
            neighbours.extend(perceived(recording, t, run.pedestrian, at, options));
            exposure.perceive(recording, t, robot.state.velocity.norm(), &neighbours);
            let input = PlanningInput {
                ego: &robot.state,
                neighbours: &neighbours,
                map,
                goal: goal_at(track, run, t, map, &router, at),
                dt: options.replan_period,
                visibility: None,
                safety: None,
            };
            command = plan(&input);
            replans += 1;
        }
        let before = robot.state.position;
        robot.apply(command, options.dt);
        let step = (robot.state.position - before).norm();
        t = run.t_start + (k + 1) as Real * options.dt;
        let s = &robot.state;
        exposure.record(recording, t, s.position, s.velocity, run.pedestrian);
        if (robot.state.position - run.goal).norm() < options.robot.goal_tolerance_m {
            // d_r up to where this step entered the tolerance disc, as d_h is measured.
            let tolerance = options.robot.goal_tolerance_m;
            let entered = entry_fraction(before, s.position, run.goal, tolerance).unwrap_or(1.0);
            path += entered * step;
            reached = true;
            break;
        }
        path += step;
    }
    exposure.finish(reached, path, run.human_path_m, t - run.t_start, replans)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::{Sample, Track};
    use agent::math::vec2;

    /// Two people: 1 walks +x along y = 0 for 12 s at 1 m/s, 2 stands at (6, 3).
    fn toy() -> Recording {
        let walker = Track {
            id: 1,
            samples: (0..=30)
                .map(|k| {
                    let t = k as Real * 0.4;
                    Sample {
                        t,
                        position: vec2(t, 0.0),
                        velocity: vec2(1.0, 0.0),
                    }
                })
                .collect(),
        };
        let stander = Track {
            id: 2,
            samples: (0..=40)
                .map(|k| Sample {
                    t: k as Real * 0.4,
                    position: vec2(6.0, 3.0),
                    velocity: vec2(0.0, 0.0),
                })
                .collect(),
        };
        Recording {
            name: "toy".into(),
            tracks: vec![walker, stander],
            walls: vec![],
            destinations: vec![],
            destinations_from_file: false,
            destinations_fit: 0.0,
            rejected_destinations_fit: None,
        }
    }

    #[test]
    fn partial_runs_are_consecutive_ten_metre_stretches() {
        let rec = toy();
        let runs = runs(&rec, RunKind::Partial, &PlaybackOptions::default());
        // 12 m walked: one 10 m stretch (samples 0..=25); the standing person walks nowhere.
        assert_eq!(runs.len(), 1);
        let r = &runs[0];
        assert_eq!((r.pedestrian, r.samples), (1, (0, 25)));
        assert!((r.human_whole_path_m - 10.0).abs() < 1e-9 && (r.t_end - 10.0).abs() < 1e-9);
        // d_h ends where the robot's run would: 0.5 m (the goal tolerance) short of the goal.
        assert!((r.human_path_m - 9.5).abs() < 1e-9 && (r.t_arrive - 9.5).abs() < 1e-9);
        let full = super::runs(&rec, RunKind::Full, &PlaybackOptions::default());
        assert_eq!(full.len(), 1);
        assert!((full[0].human_whole_path_m - 12.0).abs() < 1e-9);
        assert!((full[0].human_path_m - 11.5).abs() < 1e-9);
    }

    #[test]
    fn the_human_row_comes_from_the_data_alone() {
        let rec = toy();
        let options = PlaybackOptions::default();
        let run = &runs(&rec, RunKind::Partial, &options)[0];
        let human = human_outcome(&rec, run, &options);
        // Closest to the stander when passing x = 6: 3 m.
        assert!((human.min_distance_m - 3.0).abs() < 1e-9, "{human:?}");
        assert_eq!(human.path_ratio(), 1.0);
        // The stander is within 3 m only at x = 6 exactly: one of the 96 samples to 9.5 s.
        let one = 1.0 / (std::f64::consts::PI * 9.0);
        assert!((human.max_density - one).abs() < 1e-12);
        assert!((human.mean_density - one / 96.0).abs() < 1e-12, "{human:?}");
    }

    #[test]
    fn a_robot_driving_straight_takes_the_persons_path() {
        let rec = toy();
        let options = PlaybackOptions::default();
        let run = &runs(&rec, RunKind::Partial, &options)[0];
        let map = map_of(&rec).expect("no walls");
        let mut seen = Vec::new();
        let outcome = play(&rec, &map, run, &options, &mut |input| {
            seen.push(input.neighbours.iter().map(|n| n.id).collect::<Vec<_>>());
            Command::Velocity((input.goal - input.ego.position).normalize())
        });
        assert!(outcome.reached, "{outcome:?}");
        // The person is never among the neighbours; the stander always is (within 12 m).
        assert!(seen.iter().all(|ids| ids == &vec![2]));
        assert_eq!(outcome.replans, seen.len());
        // It stops within the tolerance, 0.5 m short: 9.5 m driven to the edge of the
        // tolerance disc, as the person walked to it, so d_r / d_h = 1.
        assert!((outcome.path_m - 9.5).abs() < 1e-9, "{outcome:?}");
        assert!((outcome.path_ratio() - 1.0).abs() < 1e-9, "{outcome:?}");
        // Sampled every 0.1 s, the robot passes x = 6 between samples: within a few mm.
        assert!((outcome.min_distance_m - 3.0).abs() < 1e-3, "{outcome:?}");
    }

    #[test]
    fn d_h_ends_where_a_winding_track_first_enters_the_goal_tolerance() {
        // Along x to (10, 0), then 2 m out to (10, 2) and back: the goal (10, 0) is first
        // within 0.5 m at (9.5, 0), 9.5 m in, although the stretch goes on for 4 m more.
        let points = [(0.0, 0.0), (10.0, 0.0), (10.0, 2.0), (10.0, 0.0)];
        let track = Track {
            id: 1,
            samples: points
                .iter()
                .enumerate()
                .map(|(k, &(x, y))| Sample {
                    t: k as Real,
                    position: vec2(x, y),
                    velocity: vec2(0.0, 0.0),
                })
                .collect(),
        };
        let (t, walked) = arrival(&track, 0, 3, vec2(10.0, 0.0), 0.5);
        assert!(
            (walked - 9.5).abs() < 1e-12 && (t - 0.95).abs() < 1e-12,
            "{t} {walked}"
        );
        // A stretch that starts inside the disc counts from where it re-enters it.
        let (t, walked) = arrival(&track, 1, 3, vec2(10.0, 0.0), 0.5);
        assert!(
            (walked - 3.5).abs() < 1e-12 && (t - 2.75).abs() < 1e-12,
            "{t} {walked}"
        );
        assert_eq!(
            entry_fraction(vec2(0.0, 1.0), vec2(4.0, 1.0), vec2(2.0, 0.0), 0.5),
            None
        );
    }

    /// Someone standing at `at` from `from` to `to` seconds.
    fn standing(id: u64, at: Vec2, from: Real, to: Real) -> Track {
        let n = ((to - from) / 0.4).round() as usize;
        Track {
            id,
            samples: (0..=n)
                .map(|k| Sample {
                    t: from + k as Real * 0.4,
                    position: at,
                    velocity: vec2(0.0, 0.0),
                })
                .collect(),
        }
    }

    #[test]
    fn a_person_appearing_within_the_stopping_distance_is_not_counted_as_robot_caused() {
        let mut rec = toy();
        // Both appear in the robot's path (it drives along y = 0 at 1 m/s): person 3 at
        // t = 3.2 s 1 m ahead of it, person 4 at t = 0.4 s, 7.6 m ahead.
        rec.tracks.push(standing(3, vec2(4.2, 0.0), 3.2, 5.2));
        rec.tracks.push(standing(4, vec2(8.0, 0.0), 0.4, 12.0));
        let options = PlaybackOptions::default();
        let run = &runs(&rec, RunKind::Partial, &options)[0];
        let map = map_of(&rec).expect("no walls");
        // A robot that drives straight at its goal whatever it sees.
        let outcome = play(&rec, &map, run, &options, &mut |input| {
            Command::Velocity((input.goal - input.ego.position).normalize())
        });
        // Person 3: seen at 3.2 s with the robot 1 m away at 1 m/s; braking at 1.5 m/s² it
        // stands at 3.87 s, and the bodies touch at ≈ 3.6 s. Person 4 had 7 s to be seen.
        assert_eq!(
            (
                outcome.robot_caused_contacts,
                outcome.appeared_contacts,
                outcome.person_caused_contacts
            ),
            (1, 1, 0),
            "{outcome:?}"
        );
        // The same recording with person 3 there from the start: both are the robot's.
        rec.tracks[2] = standing(3, vec2(4.2, 0.0), 0.0, 5.2);
        let outcome = play(&rec, &map, run, &options, &mut |input| {
            Command::Velocity((input.goal - input.ego.position).normalize())
        });
        assert_eq!(
            (outcome.robot_caused_contacts, outcome.appeared_contacts),
            (2, 0),
            "{outcome:?}"
        );
    }

    /// Regression: seq_eth's pedestrian 222 walked round the west end of the building's
    /// front; the robot in their place, a little east of their line, slid along the wall's
    /// far side until time ran out. Here a person walks 10 m round the end of a wall that
    /// the straight line from start to goal crosses: a robot driving straight at the goal
    /// it is given arrives, and never crosses the wall.
    #[test]
    fn a_goal_behind_a_wall_is_reached_round_the_wall_s_end() {
        let corners = [
            vec2(5.0, -2.0),
            vec2(1.0, -2.0),
            vec2(1.0, 2.0),
            vec2(3.0, 2.0),
        ];
        let mut samples = Vec::new();
        for leg in corners.windows(2) {
            let (a, b) = (leg[0], leg[1]);
            let along = (b - a).normalize();
            for k in 0..((b - a).norm() / 0.4).round() as usize {
                samples.push((a + along * (0.4 * k as Real), along));
            }
        }
        samples.push((corners[3], vec2(1.0, 0.0)));
        let walker = Track {
            id: 1,
            samples: samples
                .iter()
                .enumerate()
                .map(|(k, &(position, velocity))| Sample {
                    t: 0.4 * k as Real,
                    position,
                    velocity,
                })
                .collect(),
        };
        let rec = Recording {
            walls: vec![(vec2(2.0, 0.0), vec2(20.0, 0.0))],
            tracks: vec![walker, standing(2, vec2(-6.0, 6.0), 0.0, 12.0)],
            ..toy()
        };
        let map = map_of(&rec).expect("a wall");
        let options = PlaybackOptions::default();
        let run = &runs(&rec, RunKind::Partial, &options)[0];
        assert!(!map.line_of_sight(run.start, run.goal));
        let mut at = Vec::new();
        let outcome = play(&rec, &map, run, &options, &mut |input| {
            at.push(input.ego.position);
            Command::Velocity((input.goal - input.ego.position).normalize())
        });
        assert!(outcome.reached, "{outcome:?}");
        assert!(
            at.windows(2).all(|w| map.line_of_sight(w[0], w[1])),
            "{at:?}"
        );
        // Without the way round, the same robot drives into the wall.
        let straight = PlaybackOptions {
            route_clearance_m: 0.0,
            ..options.clone()
        };
        let mut crossed = false;
        let mut last = run.start;
        play(&rec, &map, run, &straight, &mut |input| {
            crossed |= !map.line_of_sight(last, input.ego.position);
            last = input.ego.position;
            Command::Velocity((input.goal - input.ego.position).normalize())
        });
        assert!(crossed);
    }

    #[test]
    fn a_robot_that_never_moves_runs_out_of_time() {
        let rec = toy();
        let options = PlaybackOptions::default();
        let run = &runs(&rec, RunKind::Full, &options)[0];
        let map = map_of(&rec).expect("no walls");
        let outcome = play(&rec, &map, run, &options, &mut |_| Command::STOP);
        assert!(!outcome.reached);
        // It enters walking as the person was (1 m/s) and brakes at 1.5 m/s²: ≈ 1/3 m.
        assert!((0.25..0.34).contains(&outcome.path_m), "{outcome:?}");
        // 12 s of the person's own time plus max(10 s, 12 s).
        assert!((outcome.duration_s - 24.0).abs() < 1e-6, "{outcome:?}");
    }
}
