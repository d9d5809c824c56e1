//! A warehouse fleet: the world plus pick/drop tasks, corridor routes for robots, shared
//! intents between robots, and continuous metrics. The coordinator drives one of these over
//! Zenoh; [`run_fleet`] drives one in-process with a planner per robot (batch experiments,
//! the intent-sharing study).
//!
//! Task cycle of a robot: idle → (assigned) drive to the pick station → drive to its dock →
//! done, idle again. Robots follow the site's corridor routes: the goal a planner gets is the
//! route's current waypoint; intermediate waypoints count as reached within
//! [`WAYPOINT_REACHED_M`], stations within the robot's goal tolerance.

use crate::impact::HumanImpact;
use crate::metrics::{MetricsRecorder, RobotMetrics};
use crate::scenario::Scenario;
use crate::warehouse::{Site, StationKind};
use crate::world::{ROBOT_ID_BIT, World};
use agent::map::LocalMap;
use agent::math::{Real, Vec2};
use agent::model::{AgentKind, Command, EgoState, Neighbour, SharedIntent, TrajectorySample};
use agent::planner::Plan;
use agent::planner::{PlannerSpec, PlannerStack, PlanningInput};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;

/// A robot on a route moves to the next waypoint within this distance of the current one (m).
pub const WAYPOINT_REACHED_M: Real = 1.0;
/// Intents older than this are not shared (s).
pub const INTENT_MAX_AGE_S: Real = 1.0;
/// Random stream of task draws (the world uses 1–3).
const TASK_STREAM: u64 = 4;

/// A pick/drop job.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Task {
    /// Unique within the run, from 0.
    pub id: u64,
    /// Station to pick at.
    pub pick: usize,
    /// Dock to drop at.
    pub drop: usize,
}

/// Which leg of its task a robot is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// Driving to the pick station.
    ToPick,
    /// Driving to the dock.
    ToDrop,
}

/// What happened in a fleet step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FleetEvent {
    /// A robot got a task.
    Assigned {
        /// Robot index.
        robot: usize,
        /// The task.
        task: Task,
    },
    /// A robot reached its pick station.
    Picked {
        /// Robot index.
        robot: usize,
        /// Task id.
        task: u64,
    },
    /// A robot dropped its load: the task is done.
    Done {
        /// Robot index.
        robot: usize,
        /// Task id.
        task: u64,
    },
}

/// A robot's current job: the task, its stage, and the waypoints left on this leg.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    /// The task.
    pub task: Task,
    /// The leg.
    pub stage: Stage,
    waypoints: VecDeque<Vec2>,
}

impl Job {
    /// The point the planner should drive to now.
    pub fn waypoint(&self) -> Option<Vec2> {
        self.waypoints.front().copied()
    }
}

/// The fleet world.
#[derive(Debug)]
pub struct Fleet {
    /// People, robots, map.
    pub world: World,
    site: Site,
    task_rng: ChaCha8Rng,
    next_task: u64,
    jobs: Vec<Option<Job>>,
    /// Robots that take no tasks and are held still (agent gone, or flagged).
    held: Vec<bool>,
    intents: Vec<Option<(Real, Vec<TrajectorySample>)>>,
    recorders: Vec<MetricsRecorder>,
    impact: Option<HumanImpact>,
    tasks_done: Vec<u64>,
    /// Whether observations carry other robots' intents.
    pub share_intents: bool,
}

/// Why a fleet could not be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("scenario {0:?} has no [warehouse] table; a fleet needs a warehouse")]
pub struct NotAWarehouse(pub String);

impl Fleet {
    /// The fleet of a warehouse scenario, every robot idle.
    pub fn new(scenario: &Scenario) -> Result<Self, NotAWarehouse> {
        let world = World::from_scenario(scenario);
        let site = world
            .site()
            .cloned()
            .ok_or_else(|| NotAWarehouse(scenario.name.clone()))?;
        let n = world.robots.len();
        let recorders = (0..n)
            .map(|i| MetricsRecorder::continuous(&world, i))
            .collect();
        let mut task_rng = ChaCha8Rng::seed_from_u64(scenario.seed);
        task_rng.set_stream(TASK_STREAM);
        Ok(Self {
            world,
            site,
            task_rng,
            next_task: 0,
            jobs: vec![None; n],
            held: vec![false; n],
            intents: vec![None; n],
            recorders,
            impact: None,
            tasks_done: vec![0; n],
            share_intents: true,
        })
    }

    /// The warehouse layout.
    pub fn site(&self) -> &Site {
        &self.site
    }

    /// Number of robots.
    pub fn robots(&self) -> usize {
        self.world.robots.len()
    }

    /// Robot `i`'s job, if it has one.
    pub fn job(&self, i: usize) -> Option<&Job> {
        self.jobs[i].as_ref()
    }

    /// Tasks robot `i` completed.
    pub fn tasks_done(&self, i: usize) -> u64 {
        self.tasks_done[i]
    }

    /// Holds robot `i` (no new tasks; the caller stops it) or releases it.
    pub fn set_held(&mut self, i: usize, held: bool) {
        self.held[i] = held;
    }

    /// Whether robot `i` is held.
    pub fn is_held(&self, i: usize) -> bool {
        self.held[i]
    }

    /// Gives every idle, unheld robot a new task: pick at a random shelf face, drop at a
    /// random dock.
    pub fn dispatch(&mut self) -> Vec<FleetEvent> {
        let picks: Vec<usize> = self
            .site
            .stations_of(StationKind::Pick)
            .map(|s| s.id)
            .collect();
        let docks: Vec<usize> = self
            .site
            .stations_of(StationKind::Dock)
            .map(|s| s.id)
            .collect();
        let mut events = Vec::new();
        for i in 0..self.robots() {
            if self.jobs[i].is_some() || self.held[i] {
                continue;
            }
            let task = Task {
                id: self.next_task,
                pick: picks[self.task_rng.random_range(0..picks.len())],
                drop: docks[self.task_rng.random_range(0..docks.len())],
            };
            self.next_task += 1;
            let from = self.world.robots[i].state.position;
            let to = self.site.stations[task.pick].position;
            self.jobs[i] = Some(Job {
                task,
                stage: Stage::ToPick,
                waypoints: self.site.route(from, to).into(),
            });
            events.push(FleetEvent::Assigned { robot: i, task });
        }
        self.update_goals();
        events
    }

    /// Robot `i`'s planner goal: its route's current waypoint, or its own position when idle.
    pub fn goal(&self, i: usize) -> Option<Vec2> {
        self.jobs[i].as_ref().and_then(Job::waypoint)
    }

    fn update_goals(&mut self) {
        for i in 0..self.robots() {
            let here = self.world.robots[i].state.position;
            self.world.robots[i].goal = self.goal(i).unwrap_or(here);
        }
    }

    /// Records robot `i`'s newest plan, stamped with the simulation time it was made for.
    pub fn set_intent(&mut self, i: usize, stamp: Real, trajectory: Vec<TrajectorySample>) {
        self.intents[i] = Some((stamp, trajectory));
    }

    /// Robot `i`'s newest intent: its stamp and trajectory (`t` after the stamp).
    pub fn intent(&self, i: usize) -> Option<(Real, &[TrajectorySample])> {
        self.intents[i]
            .as_ref()
            .map(|(stamp, t)| (*stamp, t.as_slice()))
    }

    /// What robot `i` perceives now, with the fresh intents of the robots it sees (when
    /// sharing is on), re-timed so that `t` counts from now.
    pub fn observe(&mut self, i: usize) -> (EgoState, Vec<Neighbour>) {
        let (ego, mut seen) = self.world.observe(i);
        if self.share_intents {
            let now = self.world.time;
            for n in seen.iter_mut().filter(|n| n.kind == AgentKind::Robot) {
                let j = (n.id & !ROBOT_ID_BIT) as usize;
                let Some((stamp, trajectory)) = &self.intents[j] else {
                    continue;
                };
                let age = now - stamp;
                if !(0.0..=INTENT_MAX_AGE_S).contains(&age) {
                    continue;
                }
                let samples = trajectory
                    .iter()
                    .filter(|s| s.t >= age)
                    .map(|s| TrajectorySample { t: s.t - age, ..*s })
                    .collect();
                n.intent = Some(SharedIntent { samples });
            }
        }
        (ego, seen)
    }

    /// Advances one step with one command per robot (held robots are stopped whatever their
    /// command), then moves robots along their routes and completes tasks.
    pub fn step(&mut self, commands: &[Command]) -> Vec<FleetEvent> {
        let commands: Vec<Command> = commands
            .iter()
            .zip(&self.held)
            .map(|(&c, &held)| if held { Command::STOP } else { c })
            .collect();
        self.world.step(&commands);
        for r in &mut self.recorders {
            r.record(&self.world);
        }
        if let Some(impact) = &mut self.impact {
            impact.record(&self.world);
        }
        let mut events = Vec::new();
        for i in 0..self.robots() {
            let robot = &self.world.robots[i];
            let (here, tolerance) = (robot.state.position, robot.spec.goal_tolerance_m);
            let Some(job) = &mut self.jobs[i] else {
                continue;
            };
            let Some(target) = job.waypoint() else {
                continue;
            };
            let last = job.waypoints.len() == 1;
            let reach = if last { tolerance } else { WAYPOINT_REACHED_M };
            if (target - here).norm() >= reach {
                continue;
            }
            job.waypoints.pop_front();
            if !last {
                continue;
            }
            match job.stage {
                Stage::ToPick => {
                    events.push(FleetEvent::Picked {
                        robot: i,
                        task: job.task.id,
                    });
                    job.stage = Stage::ToDrop;
                    let dock = self.site.stations[job.task.drop].position;
                    job.waypoints = self.site.route(here, dock).into();
                }
                Stage::ToDrop => {
                    events.push(FleetEvent::Done {
                        robot: i,
                        task: job.task.id,
                    });
                    self.tasks_done[i] += 1;
                    self.jobs[i] = None;
                }
            }
        }
        self.update_goals();
        events
    }

    /// Starts measuring the delay and extra path the robots cause people, in windows of
    /// `window_s` (a shadow crowd that ignores robots: one more crowd step per step).
    pub fn measure_human_impact(&mut self, window_s: Real) {
        self.impact = Some(HumanImpact::new(&self.world, window_s));
    }

    /// What the robots cost people, if measured.
    pub fn human_impact(&self) -> Option<&HumanImpact> {
        self.impact.as_ref()
    }

    /// Metrics of robot `i` so far.
    pub fn metrics(&self, i: usize) -> RobotMetrics {
        let mut m = self.recorders[i].finish();
        if let Some(impact) = &self.impact {
            (m.human_delay_s, m.human_extra_path_m) = impact.robot_totals(i);
            m.human_path_changes = impact.robot_path_changes(i);
        }
        m
    }
}

/// What an in-process fleet run produced.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetReport {
    /// Simulated seconds.
    pub seconds: Real,
    /// Tasks completed per robot.
    pub tasks_done: Vec<u64>,
    /// Metrics per robot.
    pub robots: Vec<RobotMetrics>,
    /// Commands the safety layer's warning field slowed, per robot (0 without the layer).
    pub warned: Vec<u64>,
    /// Commands its protective field slowed further or stopped, per robot.
    pub protective: Vec<u64>,
}

impl FleetReport {
    /// Tasks completed by the whole fleet.
    pub fn total_tasks(&self) -> u64 {
        self.tasks_done.iter().sum()
    }
}

/// Every robot with a task plans in-process on what it perceives now, as its agent would: the
/// plan's intent goes into the fleet's table (robots later in the order see it this tick) and
/// its command into `commands`; a robot without a task gets [`Command::STOP`]. `plan` runs
/// robot `i`'s planner (`|_, stack, input| stack.plan(input)`); callers wrap it to time or
/// inspect plans.
pub fn plan_all(
    fleet: &mut Fleet,
    stacks: &mut [PlannerStack],
    commands: &mut [Command],
    mut plan: impl FnMut(usize, &mut PlannerStack, &PlanningInput<'_>) -> Plan,
) {
    let mut local = LocalMap::default();
    for (i, stack) in stacks.iter_mut().enumerate() {
        let Some(goal) = fleet.goal(i) else {
            commands[i] = Command::STOP;
            continue;
        };
        let (ego, seen) = fleet.observe(i);
        let profile = fleet.world.visibility(i, &mut local);
        let planned = plan(
            i,
            stack,
            &PlanningInput {
                ego: &ego,
                neighbours: &seen,
                map: &fleet.world.map,
                goal,
                dt: fleet.world.dt,
                visibility: profile.as_ref(),
            },
        );
        let now = fleet.world.time;
        fleet.set_intent(i, now, planned.intent.trajectory);
        commands[i] = planned.command;
    }
}

/// Runs a warehouse for `seconds` with every robot planning in-process with `planner` (under
/// `agent::safety` unless the scenario's `[robot] safety` is off); `share_intents` switches
/// intent sharing between robots.
pub fn run_fleet(
    scenario: &Scenario,
    planner: PlannerSpec,
    seconds: Real,
    share_intents: bool,
) -> Result<FleetReport, NotAWarehouse> {
    let mut fleet = Fleet::new(scenario)?;
    fleet.share_intents = share_intents;
    let mut stacks: Vec<PlannerStack> = (0..fleet.robots())
        .map(|_| {
            let mut stack = PlannerStack::with_max_speed(planner, scenario.robot.max_speed);
            stack.set_record_fan(false);
            stack
        })
        .collect();
    let mut guards = crate::episode::guards(scenario, fleet.robots());
    let steps = (seconds / fleet.world.dt).round() as u64;
    let mut commands = vec![Command::STOP; fleet.robots()];
    for _ in 0..steps {
        fleet.dispatch();
        plan_all(&mut fleet, &mut stacks, &mut commands, |i, stack, input| {
            let mut plan = stack.plan(input);
            if let Some(guard) = &mut guards[i] {
                plan.command = guard.check(plan.command, input).command;
            }
            plan
        });
        fleet.step(&commands);
    }
    Ok(FleetReport {
        seconds: fleet.world.time,
        tasks_done: fleet.tasks_done.clone(),
        robots: (0..fleet.robots()).map(|i| fleet.metrics(i)).collect(),
        warned: guards
            .iter()
            .map(|g| g.as_ref().map_or(0, |g| g.warned))
            .collect(),
        protective: guards
            .iter()
            .map(|g| g.as_ref().map_or(0, |g| g.protective))
            .collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> Scenario {
        let mut s = Scenario::builtin("warehouse").expect("valid");
        let w = s.warehouse.as_mut().expect("layout");
        w.robots = 3;
        w.humans = 10;
        s
    }

    #[test]
    fn robots_complete_pick_and_drop_tasks_along_corridors() {
        let report = run_fleet(&small(), "pgp+orca".parse().expect("known"), 120.0, true)
            .expect("a warehouse");
        println!("{report:?}");
        assert!(
            report.tasks_done.iter().all(|&n| n >= 1),
            "every robot finishes a task in 2 minutes: {:?}",
            report.tasks_done
        );
        for m in &report.robots {
            assert!(m.path_length_m > 10.0, "{m:?}");
        }
    }

    #[test]
    fn fleet_runs_are_deterministic() {
        let spec = "pgp+dwa".parse().expect("known");
        let a = run_fleet(&small(), spec, 20.0, true).expect("warehouse");
        let b = run_fleet(&small(), spec, 20.0, true).expect("warehouse");
        assert_eq!(format!("{a:?}"), format!("{b:?}"));
    }

    #[test]
    fn shared_intents_reach_robots_that_see_each_other() {
        let mut fleet = Fleet::new(&small()).expect("warehouse");
        fleet.dispatch();
        let robot1 = fleet.world.robots[1].state.position;
        fleet.world.robots[0].state.position = robot1 + agent::math::vec2(2.0, 0.0);
        let samples: Vec<TrajectorySample> = (1..=4)
            .map(|k| TrajectorySample {
                t: 0.25 * k as Real,
                position: robot1,
                sigma: 0.2,
            })
            .collect();
        fleet.set_intent(1, 0.0, samples);
        fleet.step(&[Command::STOP; 3]);
        let (_, seen) = fleet.observe(0);
        let other = seen
            .iter()
            .find(|n| n.id == ROBOT_ID_BIT | 1)
            .expect("robot 1 is 2 m away");
        let intent = other.intent.as_ref().expect("shared");
        // 0.1 s later the samples start 0.1 s earlier; the first (t = 0.25) is kept.
        assert_eq!(intent.samples.len(), 4);
        assert!((intent.samples[0].t - 0.15).abs() < 1e-9);
        fleet.share_intents = false;
        let (_, seen) = fleet.observe(0);
        assert!(seen.iter().all(|n| n.intent.is_none()));
    }

    #[test]
    fn held_robots_take_no_tasks_and_stand_still() {
        let mut fleet = Fleet::new(&small()).expect("warehouse");
        fleet.set_held(2, true);
        let events = fleet.dispatch();
        assert_eq!(events.len(), 2);
        assert!(fleet.job(2).is_none());
        let start = fleet.world.robots[2].state.position;
        fleet.step(&[Command::Velocity(agent::math::vec2(1.0, 0.0)); 3]);
        assert_eq!(fleet.world.robots[2].state.position, start);
    }

    #[test]
    fn a_scenario_without_warehouse_is_refused() {
        let s = Scenario::builtin("open-space").expect("valid");
        assert!(Fleet::new(&s).is_err());
    }
}
