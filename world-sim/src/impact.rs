//! What robots cost the people around them: the delay and the extra path they cause, measured
//! against a shadow of the same crowd in which nobody reacts to robots.
//!
//! At the start of each window the world is copied into a shadow whose people ignore robots;
//! both are stepped in lockstep (people are deterministic, so without robots the two stay
//! bit-identical). At the end of the window, for every person whose goal did not change in
//! either world during it:
//!
//! - **delay** = (progress in the shadow − progress in the real world) / desired speed, in
//!   seconds, where progress is how much closer to the goal the person got and the desired
//!   speed is the Social Force Model's (PySocialForce's max speed);
//! - **extra path** = (path − progress) in the real world − (path − progress) in the shadow, in
//!   metres: the detour beyond straight progress that robots added.
//!
//! Then the shadow is re-synchronised with the real world. Costs one extra crowd step per step.
//!
//! **Per robot**: one shadow cannot say which robot caused what, so each person's delay and
//! extra path are shared among the robots that were their nearest robot within
//! [`ATTRIBUTION_RANGE_M`] during the window, in proportion to the steps each one was. What
//! reaches people only through other people (nobody's nearest robot) stays in the fleet total.
//!
//! **Path changes** count how often people change their path because of robots, the social
//! metric of the peek-and-pass paper (Sharma et al., Sec. V-B: "the number of times a human
//! has to change their path to avoid the robot", given there without an operational
//! definition). Ours: a person changes path when their velocity departs from their shadow
//! self's by more than [`PATH_CHANGE_MPS`] (a 15° swerve at walking speed, or slowing by a
//! quarter), and the change counts once per avoidance: a new one only after their velocity has
//! stayed within that of the shadow's for [`PATH_CHANGE_SETTLE_S`]. Each is attributed to the
//! nearest robot within [`ATTRIBUTION_RANGE_M`] at its onset; changes with no robot that near
//! (knock-on effects through other people) count in the fleet total only.

use crate::world::World;
use agent::math::{Real, Vec2};

/// A person's delay is attributed to robots that came at least this close (m).
pub const ATTRIBUTION_RANGE_M: Real = 3.0;

/// A person's velocity departing from their shadow self's by more than this (m/s) is a path
/// change: a 15° swerve at 1 m/s departs by 0.26 m/s.
pub const PATH_CHANGE_MPS: Real = 0.25;

/// A new path change counts only after the person's velocity has stayed within
/// [`PATH_CHANGE_MPS`] of their shadow self's for this long (s): one avoidance, one change.
pub const PATH_CHANGE_SETTLE_S: Real = 1.0;

/// How many finished windows a [`HumanImpact`] keeps (one hour of 5 s windows); older ones are
/// dropped in batches (it holds between this many and twice as many), their per-robot sums kept
/// in running totals, so a run of any length holds bounded memory.
pub const KEPT_WINDOWS: usize = 720;

/// One finished window.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ImpactWindow {
    /// Simulation time at the window's end (s).
    pub end_time: Real,
    /// Window length (s).
    pub length_s: Real,
    /// People whose goal stayed the same in both worlds (the ones measured).
    pub people: usize,
    /// Σ delay over them (person-seconds).
    pub delay_s: Real,
    /// Σ extra path over them (m).
    pub extra_path_m: Real,
    /// The delay attributed to each robot (person-seconds), by robot index.
    pub robot_delay_s: Vec<Real>,
    /// The extra path attributed to each robot (m).
    pub robot_extra_path_m: Vec<Real>,
    /// Path changes begun in the window (everyone).
    pub path_changes: u64,
    /// Those attributed to each robot, by robot index.
    pub robot_path_changes: Vec<u64>,
    /// Where people lost time to robots: each measured person with a positive delay who came
    /// within attribution range of a robot, at the mean of where they were while in range,
    /// with their delay (s). For the dashboards' heatmap.
    pub delay_at: Vec<(Vec2, Real)>,
}

impl ImpactWindow {
    /// Person-seconds of delay per minute of simulation.
    pub fn delay_per_minute(&self) -> Real {
        self.delay_s / (self.length_s / 60.0)
    }

    /// Metres of extra path per minute of simulation.
    pub fn extra_path_per_minute(&self) -> Real {
        self.extra_path_m / (self.length_s / 60.0)
    }

    /// Robot `i`'s share, per minute: (person-seconds of delay, metres of extra path).
    pub fn robot_per_minute(&self, i: usize) -> Option<(Real, Real)> {
        let minutes = self.length_s / 60.0;
        Some((
            self.robot_delay_s.get(i)? / minutes,
            self.robot_extra_path_m.get(i)? / minutes,
        ))
    }
}

/// Measures robots' impact on people window by window.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct HumanImpact {
    shadow: World,
    window_steps: u64,
    steps: u64,
    goals: Vec<Vec2>,
    start_distance: Vec<Real>,
    path: Vec<Real>,
    shadow_path: Vec<Real>,
    last: Vec<Vec2>,
    /// Per person: (robot, steps it was their nearest robot within range).
    exposure: Vec<Vec<(usize, u32)>>,
    /// Per person: the sum of their positions while a robot was within range.
    exposed_at: Vec<Vec2>,
    /// Per person: steps since their velocity last departed from the shadow's (`None`: settled
    /// since the last change, or never departed). Kept across windows.
    departed: Vec<Option<u64>>,
    settle_steps: u64,
    path_changes: u64,
    robot_path_changes: Vec<u64>,
    /// The newest finished windows, oldest first.
    windows: Vec<ImpactWindow>,
    /// How many windows of `windows` to keep (at least; [`KEPT_WINDOWS`]).
    kept: usize,
    /// Windows finished since the start, kept or not.
    closed: u64,
    /// Per robot, over every finished window: delay (person-s), extra path (m), path changes.
    robot_delay_total: Vec<Real>,
    robot_extra_total: Vec<Real>,
    robot_changes_total: Vec<u64>,
}

fn shadow_of(world: &World) -> World {
    let mut shadow = world.clone();
    shadow.humans.react_to_robots = false;
    shadow.robots.clear();
    shadow
}

impl HumanImpact {
    /// Starts measuring `world` in windows of `window_s` seconds.
    pub fn new(world: &World, window_s: Real) -> Self {
        let mut impact = Self {
            shadow: shadow_of(world),
            window_steps: ((window_s / world.dt).round() as u64).max(1),
            steps: 0,
            goals: Vec::new(),
            start_distance: Vec::new(),
            path: Vec::new(),
            shadow_path: Vec::new(),
            last: Vec::new(),
            exposure: Vec::new(),
            exposed_at: Vec::new(),
            departed: vec![None; world.humans.crowd.positions.len()],
            settle_steps: ((PATH_CHANGE_SETTLE_S / world.dt).round() as u64).max(1),
            path_changes: 0,
            robot_path_changes: vec![0; world.robots.len()],
            windows: Vec::new(),
            kept: KEPT_WINDOWS,
            closed: 0,
            robot_delay_total: Vec::new(),
            robot_extra_total: Vec::new(),
            robot_changes_total: Vec::new(),
        };
        impact.restart(world);
        impact
    }

    /// Takes the parts a snapshot leaves out of its shadow world from `built`.
    pub(crate) fn adopt_static(&mut self, built: &World) {
        self.shadow.adopt_static(built);
    }

    fn restart(&mut self, world: &World) {
        self.shadow = shadow_of(world);
        let crowd = &world.humans.crowd;
        self.goals.clone_from(&crowd.goals);
        self.start_distance = crowd
            .positions
            .iter()
            .zip(&crowd.goals)
            .map(|(p, g)| (g - p).norm())
            .collect();
        self.path = vec![0.0; crowd.positions.len()];
        self.shadow_path = vec![0.0; crowd.positions.len()];
        self.last.clone_from(&crowd.positions);
        self.exposure = vec![Vec::new(); crowd.positions.len()];
        self.exposed_at = vec![Vec2::zeros(); crowd.positions.len()];
        self.departed.resize(crowd.positions.len(), None);
        self.path_changes = 0;
        self.robot_path_changes = vec![0; world.robots.len()];
        self.steps = 0;
    }

    /// Call after every step of `world`; steps the shadow alongside.
    pub fn record(&mut self, world: &World) {
        let before: Vec<Vec2> = self.shadow.humans.crowd.positions.clone();
        self.shadow.step(&[]);
        let shadow = &self.shadow.humans.crowd;
        for (i, (a, b)) in before.iter().zip(&shadow.positions).enumerate() {
            self.shadow_path[i] += (b - a).norm();
        }
        let crowd = &world.humans.crowd;
        for (i, (last, now)) in self.last.iter_mut().zip(&crowd.positions).enumerate() {
            self.path[i] += (now - *last).norm();
            *last = *now;
            let nearest = world
                .robots
                .iter()
                .enumerate()
                .map(|(r, robot)| (r, (robot.state.position - now).norm()))
                .filter(|&(_, d)| d <= ATTRIBUTION_RANGE_M)
                .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            if let Some((r, _)) = nearest {
                self.exposed_at[i] += now;
                match self.exposure[i].iter_mut().find(|(robot, _)| *robot == r) {
                    Some((_, steps)) => *steps += 1,
                    None => self.exposure[i].push((r, 1)),
                }
            }
            let departs = (crowd.velocities[i] - shadow.velocities[i]).norm() > PATH_CHANGE_MPS;
            match (&mut self.departed[i], departs) {
                (Some(since), true) => *since = 0,
                (Some(since), false) => {
                    *since += 1;
                    if *since >= self.settle_steps {
                        self.departed[i] = None;
                    }
                }
                (None, true) => {
                    self.departed[i] = Some(0);
                    self.path_changes += 1;
                    if let Some((r, _)) = nearest {
                        self.robot_path_changes[r] += 1;
                    }
                }
                (None, false) => {}
            }
        }
        self.steps += 1;
        if self.steps >= self.window_steps {
            self.close_window(world);
        }
    }

    /// Closes the window under way early (the end of a run), if it has any steps.
    pub fn flush(&mut self, world: &World) {
        if self.steps > 0 {
            self.close_window(world);
        }
    }

    /// The delay and extra path attributed to robot `i` over every finished window
    /// (person-seconds, metres), summed window by window in order.
    pub fn robot_totals(&self, i: usize) -> (Real, Real) {
        (
            self.robot_delay_total.get(i).copied().unwrap_or(0.0),
            self.robot_extra_total.get(i).copied().unwrap_or(0.0),
        )
    }

    /// The path changes attributed to robot `i` over every finished window.
    pub fn robot_path_changes(&self, i: usize) -> u64 {
        self.robot_changes_total.get(i).copied().unwrap_or(0)
    }

    /// Adds a finished window to the running totals and keeps it, dropping the oldest ones
    /// once twice [`KEPT_WINDOWS`] are held.
    fn keep(&mut self, window: ImpactWindow) {
        let robots = window.robot_delay_s.len();
        if self.robot_delay_total.len() < robots {
            self.robot_delay_total.resize(robots, 0.0);
            self.robot_extra_total.resize(robots, 0.0);
            self.robot_changes_total.resize(robots, 0);
        }
        for (total, v) in self.robot_delay_total.iter_mut().zip(&window.robot_delay_s) {
            *total += v;
        }
        for (total, v) in self
            .robot_extra_total
            .iter_mut()
            .zip(&window.robot_extra_path_m)
        {
            *total += v;
        }
        for (total, v) in self
            .robot_changes_total
            .iter_mut()
            .zip(&window.robot_path_changes)
        {
            *total += v;
        }
        self.windows.push(window);
        self.closed += 1;
        if self.windows.len() >= 2 * self.kept {
            let drop = self.windows.len() - self.kept;
            self.windows.drain(..drop);
        }
    }

    fn close_window(&mut self, world: &World) {
        let crowd = &world.humans.crowd;
        let shadow = &self.shadow.humans.crowd;
        let mut window = ImpactWindow {
            end_time: world.time,
            length_s: self.steps as Real * world.dt,
            people: 0,
            delay_s: 0.0,
            extra_path_m: 0.0,
            robot_delay_s: vec![0.0; world.robots.len()],
            robot_extra_path_m: vec![0.0; world.robots.len()],
            path_changes: self.path_changes,
            robot_path_changes: self.robot_path_changes.clone(),
            delay_at: Vec::new(),
        };
        for i in 0..crowd.positions.len() {
            let goal = self.goals[i];
            if crowd.goals[i] != goal || shadow.goals[i] != goal {
                continue;
            }
            let progress = self.start_distance[i] - (goal - crowd.positions[i]).norm();
            let shadow_progress = self.start_distance[i] - (goal - shadow.positions[i]).norm();
            let speed = crowd.max_speeds[i].max(1e-3);
            let delay = (shadow_progress - progress) / speed;
            let extra = (self.path[i] - progress) - (self.shadow_path[i] - shadow_progress);
            window.people += 1;
            window.delay_s += delay;
            window.extra_path_m += extra;
            let exposed: u32 = self.exposure[i].iter().map(|e| e.1).sum();
            if exposed > 0 && delay > 0.0 {
                window
                    .delay_at
                    .push((self.exposed_at[i] / Real::from(exposed), delay));
            }
            for &(r, steps) in &self.exposure[i] {
                let share = Real::from(steps) / Real::from(exposed);
                window.robot_delay_s[r] += delay * share;
                window.robot_extra_path_m[r] += extra * share;
            }
        }
        self.keep(window);
        self.restart(world);
    }

    /// The most recent finished window.
    pub fn latest(&self) -> Option<&ImpactWindow> {
        self.windows.last()
    }

    /// The newest finished windows, oldest first: every one for the first hour, then between
    /// [`KEPT_WINDOWS`] and twice as many.
    pub fn windows(&self) -> &[ImpactWindow] {
        &self.windows
    }

    /// How many windows have finished since the start (kept or not).
    pub fn windows_closed(&self) -> u64 {
        self.closed
    }

    /// The kept windows among those finished after the first `seen` (counting from the start),
    /// oldest first: for a reader that polls, such as a dashboard.
    pub fn windows_since(&self, seen: u64) -> &[ImpactWindow] {
        let first_kept = self.closed - self.windows.len() as u64;
        let from = seen
            .saturating_sub(first_kept)
            .min(self.windows.len() as u64);
        &self.windows[from as usize..]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;
    use agent::model::Command;

    /// The built-in hallway (seed 3), its people reacting to robots or not, its robot parked in
    /// the middle of the corridor, where people walk both ways, or far away.
    fn hallway(react: bool, park_at_crowd: bool) -> World {
        let mut s = Scenario::builtin("hallway").expect("builtin");
        s.seed = 3;
        s.humans.react_to_robots = react;
        let mut world = World::from_scenario(&s);
        let crowd = &world.humans.crowd;
        world.robots[0].state.position = if park_at_crowd {
            crowd.positions.iter().fold(Vec2::zeros(), |a, p| a + p) / crowd.positions.len() as Real
        } else {
            Vec2::new(-1e4, -1e4)
        };
        world
    }

    fn run(react: bool, park_at_crowd: bool) -> Vec<ImpactWindow> {
        let mut world = hallway(react, park_at_crowd);
        let mut impact = HumanImpact::new(&world, 5.0);
        let stop = vec![Command::STOP; world.robots.len()];
        for _ in 0..300 {
            world.step(&stop);
            impact.record(&world);
        }
        impact.windows().to_vec()
    }

    /// Where [`run`] parks its robot.
    fn run_robot_position(park_at_crowd: bool) -> Vec2 {
        hallway(true, park_at_crowd).robots[0].state.position
    }

    /// One person walking +x along the middle of the hallway from x = 3 m, robots parked on
    /// their line at `robots_x` (the hallway's own robot, and a copy for each further x); the
    /// path changes over 14 s, in total and attributed per robot.
    fn walk_past(robots_x: &[Real], react: bool) -> (u64, Vec<u64>) {
        let mut s = Scenario::builtin("hallway").expect("builtin");
        if let Some(h) = s.hallway.as_mut() {
            h.humans = 1;
        }
        s.humans.react_to_robots = react;
        let mut world = World::from_scenario(&s);
        let mid = 0.5 * s.hallway.as_ref().expect("a hallway").width_m;
        let crowd = &mut world.humans.crowd;
        crowd.positions[0] = Vec2::new(3.0, mid);
        crowd.velocities[0] = Vec2::new(1.0, 0.0);
        crowd.goals[0] = Vec2::new(24.0, mid);
        let parked = world.robots[0].clone();
        world.robots.clear();
        for &x in robots_x {
            let mut robot = parked.clone();
            robot.state.position = Vec2::new(x, mid);
            robot.state.velocity = Vec2::zeros();
            world.robots.push(robot);
        }
        let mut impact = HumanImpact::new(&world, 5.0);
        let stop = vec![Command::STOP; world.robots.len()];
        for _ in 0..140 {
            world.step(&stop);
            impact.record(&world);
        }
        impact.flush(&world);
        let total = impact.windows().iter().map(|w| w.path_changes).sum();
        let per_robot = (0..robots_x.len())
            .map(|i| impact.robot_path_changes(i))
            .collect();
        (total, per_robot)
    }

    #[test]
    fn a_person_who_steps_around_a_robot_changes_path_once_per_robot() {
        // A robot parked on their line: one avoidance, the robot's.
        assert_eq!(walk_past(&[8.0], true), (1, vec![1]));
        // Two robots 7 m apart: two avoidances, one each.
        assert_eq!(walk_past(&[8.0, 15.0], true), (2, vec![1, 1]));
        // A robot off their way, or people who ignore robots: none.
        assert_eq!(walk_past(&[-100.0], true), (0, vec![0]));
        assert_eq!(walk_past(&[8.0], false), (0, vec![0]));
    }

    /// A long run holds a bounded number of windows, and the per-robot totals and a poller's
    /// view are the same as if it held every window.
    #[test]
    fn old_windows_are_dropped_but_counted() {
        let mut world = hallway(true, true);
        // One window per step, at most 4 to 8 kept.
        let mut impact = HumanImpact::new(&world, world.dt);
        impact.kept = 4;
        let stop = vec![Command::STOP; world.robots.len()];
        let (mut all, mut seen, mut polled) = (Vec::new(), 0, Vec::new());
        for _ in 0..50 {
            world.step(&stop);
            impact.record(&world);
            all.push(impact.latest().expect("a window per step").clone());
            polled.extend(impact.windows_since(seen).iter().cloned());
            seen = impact.windows_closed();
            assert!(impact.windows().len() < 8);
        }
        assert_eq!(impact.windows_closed(), 50);
        assert_eq!(polled, all);
        let delay: Real = all
            .iter()
            .map(|w| w.robot_delay_s[0])
            .fold(0.0, |a, d| a + d);
        let changes: u64 = all.iter().map(|w| w.robot_path_changes[0]).sum();
        assert_eq!(impact.robot_totals(0).0, delay);
        assert_eq!(impact.robot_path_changes(0), changes);
        assert!(
            delay > 0.0 || changes > 0,
            "the parked robot is in people's way"
        );
        // A poller that fell behind gets what is still kept.
        assert_eq!(impact.windows_since(0), impact.windows());
    }

    #[test]
    fn people_who_never_meet_a_robot_lose_nothing() {
        let windows = run(true, false);
        assert_eq!(windows.len(), 6);
        for w in &windows {
            assert!(w.people > 0);
            assert!(
                w.delay_s.abs() < 1e-9 && w.extra_path_m.abs() < 1e-9,
                "{w:?}"
            );
        }
    }

    #[test]
    fn a_robot_parked_in_the_crowd_delays_people_and_makes_them_detour() {
        let windows = run(true, true);
        let delay: Real = windows.iter().map(|w| w.delay_s).sum();
        let extra: Real = windows.iter().map(|w| w.extra_path_m).sum();
        // Only the parked robot (index 0) was near anyone: it carries what was attributed.
        let attributed: Real = windows.iter().map(|w| w.robot_delay_s[0]).sum();
        assert!(
            attributed > 0.5 * delay,
            "attributed {attributed} of {delay}"
        );
        assert!(
            windows
                .iter()
                .all(|w| w.robot_delay_s[1..].iter().all(|&d| d == 0.0))
        );
        // Measured: 8.3 person-s and 1.1 m over the six 5 s windows (seed 3).
        assert!(delay > 2.0, "delay {delay} person-s over {windows:?}");
        // Where they lost it: near the parked robot (within attribution range), positive.
        let parked = run_robot_position(true);
        let placed: Vec<(Vec2, Real)> = windows.iter().flat_map(|w| w.delay_at.clone()).collect();
        assert!(!placed.is_empty());
        for (at, d) in &placed {
            assert!(
                *d > 0.0 && (at - parked).norm() <= ATTRIBUTION_RANGE_M,
                "{at:?} {d}"
            );
        }

        assert!(extra > 0.3, "extra path {extra} m");
        // People who ignore robots are not affected, whatever the robot does.
        for w in run(false, true) {
            assert_eq!((w.delay_s, w.extra_path_m), (0.0, 0.0), "{w:?}");
        }
    }
}
