//! A warehouse fleet: the world plus pick/drop tasks, corridor routes for robots, shared
//! intents between robots, and continuous metrics. The coordinator drives one of these over
//! Zenoh; [`run_fleet`] drives one in-process with a planner per robot (batch experiments,
//! the intent-sharing study). [`FleetSummary`] holds its fleet-wide figures, computed in one
//! place for every consumer.
//!
//! Task cycle of a robot: idle → (assigned) drive to the pick station → drive to its dock →
//! done, idle again. Robots follow the site's corridor routes: the goal a planner gets is the
//! route's current waypoint; intermediate waypoints count as reached within
//! [`WAYPOINT_REACHED_M`] (corners on a narrow aisle closer, `Site::corner_reach`, unless the
//! way on clears the shelves), stations within the robot's goal tolerance.

use crate::impact::HumanImpact;
use crate::metrics::{MetricsRecorder, RobotMetrics};
use crate::scenario::Scenario;
use crate::stuck::{self, Hold, Places, StuckBreakdown, StuckCauses};
use crate::traffic::{RobotView, TaskView, TrafficEvent, TrafficMonitor, TrafficParams};
use crate::traffic_policy::{PolicyEvent, PolicyParams, PolicyRobot, TrafficPolicy, route_length};
use crate::warehouse::{Site, StationKind};
use crate::world::{ROBOT_ID_BIT, World};
use agent::map::StaticMap;
use agent::math::{Real, Vec2};
use agent::model::{AgentKind, Command, EgoState, Neighbour, SharedIntent, TrajectorySample};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;

/// A robot on a route moves to the next waypoint within this distance of the current one (m).
pub const WAYPOINT_REACHED_M: Real = 1.0;
/// The clearance a cut corner's straight way keeps from every shelf beyond the robot's radius
/// (m): the sampling step of [`clear_leg`] (5 cm) plus the safety layer's 5 cm margin.
const CORNER_CLEARANCE_M: Real = 0.1;
/// Intents older than this are not shared (s).
pub const INTENT_MAX_AGE_S: Real = 1.0;
/// Random stream of task draws (the world uses 1–3).
const TASK_STREAM: u64 = 4;

/// A pick/drop job.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Task {
    /// Unique within the run, from 0.
    pub id: u64,
    /// Station to pick at.
    pub pick: usize,
    /// Dock to drop at.
    pub drop: usize,
}

/// Which leg of its task a robot is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
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
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
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

    /// The route left to drive from `here` (m): to the waypoint, then along the rest.
    pub fn remaining(&self, here: Vec2) -> Real {
        route_length(here, &self.waypoints)
    }

    /// The station this leg ends at: the pick station, then the dock.
    pub fn station(&self) -> usize {
        match self.stage {
            Stage::ToPick => self.task.pick,
            Stage::ToDrop => self.task.drop,
        }
    }

    /// Which leg this is, as a number that changes with every leg of every task.
    pub fn leg(&self) -> u64 {
        2 * self.task.id + u64::from(self.stage == Stage::ToDrop)
    }
}

/// The fleet world.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
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
    traffic: TrafficMonitor,
    traffic_events: Vec<TrafficEvent>,
    intent_scratch: Vec<Vec<(Real, Vec2)>>,
    policy: Option<TrafficPolicy>,
    policy_events: Vec<PolicyEvent>,
    route_scratch: Vec<Vec<Vec2>>,
    reroutes: u64,
    places: Places,
    stuck_where: StuckBreakdown,
    stuck_causes: StuckCauses,
    /// Per robot: whether its safety layer held back the command it drives on this step
    /// ([`Fleet::set_layer_held`]).
    layer_held: Vec<bool>,
    /// Whether observations carry other robots' intents.
    pub share_intents: bool,
    /// The map robots plan on when a keep-out mask makes it differ from the world's
    /// ([`Fleet::robot_map`]). Not in snapshots: it follows from the site.
    #[serde(skip)]
    robot_map: Option<StaticMap>,
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
        let places = Places::new(&site);
        let robot_map = site.robot_map();
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
            traffic: TrafficMonitor::new(n, TrafficParams::default()),
            traffic_events: Vec::new(),
            intent_scratch: vec![Vec::new(); n],
            policy: None,
            reroutes: 0,
            policy_events: Vec::new(),
            route_scratch: vec![Vec::new(); n],
            places,
            stuck_where: StuckBreakdown::default(),
            stuck_causes: StuckCauses::default(),
            layer_held: vec![false; n],
            share_intents: true,
            robot_map,
        })
    }

    /// The map robots plan, guard and are served: the world's walls and shelves, and a
    /// floor plan's keep-out zones as walls (people walk there, sensors see through them).
    pub fn robot_map(&self) -> &StaticMap {
        self.robot_map.as_ref().unwrap_or(&self.world.map)
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

    /// Makes robot `i` a real robot the fleet does not simulate (or a simulated one again):
    /// its body moves only when placed ([`Fleet::place`]), from what the robot reports.
    pub fn set_external(&mut self, i: usize, external: bool) {
        self.world.robots[i].external = external;
    }

    /// Whether robot `i` is a real robot the fleet does not simulate.
    pub fn is_external(&self, i: usize) -> bool {
        self.world.robots[i].external
    }

    /// Puts robot `i`'s body where the robot reported itself, before the next step.
    pub fn place(
        &mut self,
        i: usize,
        position: Vec2,
        heading: Real,
        velocity: Vec2,
        yaw_rate: Real,
    ) {
        self.world.robots[i].place(position, heading, velocity, yaw_rate);
    }

    /// Whether robot `i` is held.
    pub fn is_held(&self, i: usize) -> bool {
        self.held[i]
    }

    /// Tells the fleet whether robot `i`'s safety layer held back the command it drives on
    /// in the next step (a protective stop or slow-down, or a yield's way out): the stuck
    /// robot-seconds count it as the cause when nothing else holds the robot
    /// ([`stuck::Hold::Layer`]). It stays as set until set again.
    pub fn set_layer_held(&mut self, i: usize, held: bool) {
        self.layer_held[i] = held;
    }

    /// Whether robot `i`'s safety layer held back its last command, as last set.
    pub fn is_layer_held(&self, i: usize) -> bool {
        self.layer_held[i]
    }

    /// Gives every idle, unheld robot a new task: pick at a random shelf face, drop at a
    /// random dock, both among the stations no held robot blocks ([`Fleet::blocked_by_held`];
    /// among all of them when every one is blocked). With no robot held the draws are the same
    /// as without the rule.
    pub fn dispatch(&mut self) -> Vec<FleetEvent> {
        let any_held = self.held.contains(&true);
        let open = |fleet: &Self, kind| {
            let all: Vec<usize> = fleet.site.stations_of(kind).map(|s| s.id).collect();
            if !any_held {
                return all;
            }
            let free: Vec<usize> = all
                .iter()
                .copied()
                .filter(|&s| !fleet.blocked_by_held(s))
                .collect();
            if free.is_empty() { all } else { free }
        };
        let picks = open(self, StationKind::Pick);
        let docks = open(self, StationKind::Dock);
        let mut events = Vec::new();
        for i in 0..self.robots() {
            if self.jobs[i].is_some() || self.held[i] {
                continue;
            }
            let pick = picks[self.task_rng.random_range(0..picks.len())];
            let drawn = docks[self.task_rng.random_range(0..docks.len())];
            let task = Task {
                id: self.next_task,
                pick,
                drop: self.balanced_dock(drawn, &docks),
            };
            self.next_task += 1;
            let from = self.world.robots[i].state.position;
            let to = self.site.stations[task.pick].position;
            let route = match self.pick_entry(from, to) {
                Some(j) => self.site.route_via(from, to, j),
                None => self.route_among_people(from, to),
            };
            self.jobs[i] = Some(Job {
                task,
                stage: Stage::ToPick,
                waypoints: route.into(),
            });
            events.push(FleetEvent::Assigned { robot: i, task });
        }
        self.update_goals();
        events
    }

    /// The dock a new task drawn for `drawn` drops at, among the open `docks`: `drawn`, unless
    /// the traffic policy shares docks out by load
    /// ([`PolicyParams::dock_balance_excess`]) and
    /// `drawn` has that many more robots' tasks bound for it than the least-loaded open dock;
    /// then the least-loaded dock nearest `drawn` (ties to the lower id).
    fn balanced_dock(&self, drawn: usize, docks: &[usize]) -> usize {
        let excess = self
            .policy
            .as_ref()
            .map_or(0.0, |p| p.params.dock_balance_excess);
        if excess <= 0.0 {
            return drawn;
        }
        let load = |dock: usize| {
            self.jobs
                .iter()
                .flatten()
                .filter(|job| job.task.drop == dock)
                .count()
        };
        let least = docks.iter().map(|&d| load(d)).min().unwrap_or(0);
        if ((load(drawn) - least) as Real) < excess {
            return drawn;
        }
        let at = self.site.stations[drawn].position;
        docks
            .iter()
            .copied()
            .filter(|&d| load(d) == least)
            .min_by(|&a, &b| {
                let (da, db) = (
                    (self.site.stations[a].position - at).norm(),
                    (self.site.stations[b].position - at).norm(),
                );
                da.total_cmp(&db).then(a.cmp(&b))
            })
            .unwrap_or(drawn)
    }

    /// Whether a held robot stands where it keeps others from station `station`: its centre
    /// within two robot radii plus its goal tolerance of the station, so that another robot
    /// may not get within the goal tolerance beside it. A lost robot stands where it was lost
    /// until it is found, and new tasks are not sent to a station it blocks.
    pub fn blocked_by_held(&self, station: usize) -> bool {
        let at = self.site.stations[station].position;
        self.world
            .robots
            .iter()
            .zip(&self.held)
            .filter(|&(_, &held)| held)
            .any(|(r, _)| {
                let reach = 2.0 * r.state.radius + r.spec.goal_tolerance_m;
                (r.state.position - at).norm() < reach
            })
    }

    /// Robot `i`'s planner goal: its route's current waypoint, or where the traffic policy
    /// asks it to go instead; `None` when idle.
    pub fn goal(&self, i: usize) -> Option<Vec2> {
        let waypoint = self.jobs[i].as_ref().and_then(Job::waypoint)?;
        let constrained = self.policy.as_ref().and_then(|p| p.constraint(i).goal());
        Some(constrained.unwrap_or(waypoint))
    }

    /// Turns the traffic policy (`traffic_policy`) on with `params`, or off with `None`.
    pub fn set_traffic_policy(&mut self, params: Option<PolicyParams>) {
        self.policy = params.map(|params| {
            let radius = self
                .world
                .robots
                .iter()
                .map(|r| r.state.radius)
                .fold(0.0, Real::max);
            TrafficPolicy::new(&self.site, self.robots(), radius, params)
        });
        self.update_goals();
    }

    /// The traffic policy, when on.
    pub fn traffic_policy(&self) -> Option<&TrafficPolicy> {
        self.policy.as_ref()
    }

    /// What the traffic policy did in the last step.
    pub fn policy_events(&self) -> &[PolicyEvent] {
        &self.policy_events
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
                // A held robot stands still whatever it last planned.
                if self.held[j] {
                    continue;
                }
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
    /// command; a robot in a speed zone is held to its limit, `Site::speed_limit`), then moves
    /// robots along their routes and completes tasks.
    pub fn step(&mut self, commands: &[Command]) -> Vec<FleetEvent> {
        let commands: Vec<Command> = commands
            .iter()
            .zip(&self.held)
            .zip(&self.world.robots)
            .map(|((&c, &held), robot)| {
                if held {
                    return Command::STOP;
                }
                match self.site.speed_limit(robot.state.position) {
                    Some(limit) => crate::floor_plan::speed::limit_speed(c, limit),
                    None => c,
                }
            })
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
            let reach = if last {
                tolerance
            } else {
                let margin = PolicyParams::default().passing_margin_m;
                let radius = robot.state.radius;
                self.site
                    .corner_reach(target, radius, margin, WAYPOINT_REACHED_M)
            };
            let distance = (target - here).norm();
            // A corner reached closely (it lies on a narrow aisle) is passed within the usual
            // reach all the same when the straight way from here to the next waypoint clears
            // every shelf: cutting it then aims the robot at no shelf's end. A robot leaving
            // an aisle turns for the cross-aisle without first driving to its centre, where
            // the robots waiting to go in stand.
            let cut = self.site.cut_clear_corners
                && !last
                && reach < distance
                && distance < WAYPOINT_REACHED_M
                && clear_leg(
                    self.robot_map.as_ref().unwrap_or(&self.world.map),
                    here,
                    job.waypoints[1],
                    robot.state.radius + CORNER_CLEARANCE_M,
                );
            if distance >= reach && !cut {
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
                    // Out of a one-way segment by its far end.
                    let exit = self.policy.as_ref().and_then(|p| p.exit_of(i));
                    let route = match exit {
                        Some(j) => self.site.route_via(here, dock, j),
                        None => self.route_among_people(here, dock),
                    };
                    if let Some(job) = &mut self.jobs[i] {
                        job.waypoints = route.into();
                    }
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
        self.keep_on_route();
        self.update_goals();
        self.update_traffic();
        events
    }

    /// The coordinator's traffic step, run at the end of every [`Fleet::step`]: the monitor
    /// takes the robots' state (stuck robots, the wait-for graph, deadlocks), then the policy,
    /// when on, sets each robot's constraint and goal.
    pub fn update_traffic(&mut self) {
        self.watch_traffic();
        self.apply_policy();
    }

    /// Runs the traffic policy on the state after a step and puts its goals in place.
    fn apply_policy(&mut self) {
        let Some(policy) = &mut self.policy else {
            return;
        };
        if policy.watches_people() {
            let crowd = &self.world.humans.crowd;
            policy.set_people(
                crowd
                    .positions
                    .iter()
                    .copied()
                    .zip(crowd.velocities.iter().copied()),
            );
        }
        for (buffer, job) in self.route_scratch.iter_mut().zip(&self.jobs) {
            buffer.clear();
            if let Some(job) = job {
                buffer.extend(job.waypoints.iter().copied());
            }
        }
        let robots: Vec<PolicyRobot<'_>> = self
            .world
            .robots
            .iter()
            .zip(&self.route_scratch)
            .zip(&self.jobs)
            .zip(&self.held)
            .map(|(((r, route), job), &held)| PolicyRobot {
                position: r.state.position,
                route,
                station: job.as_ref().map(Job::station),
                held,
            })
            .collect();
        self.policy_events = policy.step(self.world.time, &robots, &self.traffic);
        for i in 0..self.robots() {
            if let Some(exit) = self.policy.as_ref().and_then(|p| p.turned(i)) {
                self.reroute(i, Through::Exit(exit));
            }
            let round = self.policy.as_ref().and_then(|p| p.detour(i));
            if let (Some(round), Some(job)) = (round, &mut self.jobs[i]) {
                job.waypoints = round.iter().copied().collect();
            }
        }
        self.update_goals();
    }

    /// Feeds the traffic monitor the robots' state after a step.
    fn watch_traffic(&mut self) {
        let now = self.world.time;
        for (i, buffer) in self.intent_scratch.iter_mut().enumerate() {
            buffer.clear();
            if let Some((stamp, trajectory)) = &self.intents[i] {
                let age = now - stamp;
                if (0.0..=INTENT_MAX_AGE_S).contains(&age) {
                    buffer.extend(
                        trajectory
                            .iter()
                            .filter(|s| s.t >= age)
                            .map(|s| (s.t - age, s.position)),
                    );
                }
            }
        }
        let views: Vec<RobotView<'_>> = self
            .world
            .robots
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let here = r.state.position;
                RobotView {
                    position: here,
                    velocity: r.state.velocity,
                    radius: r.state.radius,
                    task: self.jobs[i].as_ref().and_then(|job| {
                        job.waypoint()?;
                        Some(TaskView {
                            leg: job.leg(),
                            // Its planner's goal: the waypoint, or the policy's goal instead.
                            waypoint: r.goal,
                            remaining_m: job.remaining(here),
                        })
                    }),
                    intent: &self.intent_scratch[i],
                }
            })
            .collect();
        let holds = self
            .policy
            .as_ref()
            .map_or_else(Vec::new, TrafficPolicy::wait_edges);
        self.traffic_events =
            self.traffic
                .record(now, self.world.dt, &views, &self.world.map, &holds);
        if !(0..self.robots()).any(|i| self.traffic.is_stuck(i)) {
            return;
        }
        let robots: Vec<Vec2> = self.world.robots.iter().map(|r| r.state.position).collect();
        let people = &self.world.humans.crowd.positions;
        for (i, &p) in robots.iter().enumerate() {
            if self.traffic.is_stuck(i) {
                let who = stuck::company(i, p, people, &robots);
                self.stuck_where.add(self.places.of(p), who, self.world.dt);
                let hold = self.hold(i);
                self.stuck_causes.add(hold, self.world.dt);
            }
        }
    }

    /// What holds robot `i` now, if it is stuck ([`stuck::Hold`]).
    pub fn stuck_hold(&self, i: usize) -> Option<Hold> {
        self.traffic.is_stuck(i).then(|| self.hold(i))
    }

    /// What holds stuck robot `i` now ([`stuck::Hold`]).
    fn hold(&self, i: usize) -> Hold {
        use crate::traffic_policy::Constraint;
        let held_by_policy = self
            .policy
            .as_ref()
            .is_some_and(|p| !matches!(p.constraint(i), Constraint::Free | Constraint::Lane(_)));
        let robot = &self.world.robots[i];
        let person = || {
            stuck::in_the_way(
                robot.state.position,
                robot.state.radius,
                robot.goal,
                &self.world.humans.crowd.positions,
                self.world.humans.radius,
                &self.traffic.params,
                &self.world.map,
            )
        };
        if held_by_policy {
            Hold::Policy
        } else if person() {
            Hold::Person
        } else if !self.traffic.waits_on(i).is_empty() {
            Hold::Robot
        } else if self.layer_held[i] {
            Hold::Layer
        } else {
            Hold::Planner
        }
    }

    /// Stuck robot-seconds so far, by place and by who stood next to the robot.
    pub fn stuck_where(&self) -> StuckBreakdown {
        self.stuck_where
    }

    /// Stuck robot-seconds so far, by what held the robot.
    pub fn stuck_causes(&self) -> StuckCauses {
        self.stuck_causes
    }

    /// The traffic monitor: stuck robots, who waits on whom, deadlocks.
    pub fn traffic(&self) -> &TrafficMonitor {
        &self.traffic
    }

    /// What the traffic monitor saw begin or end in the last step.
    pub fn traffic_events(&self) -> &[TrafficEvent] {
        &self.traffic_events
    }

    /// Starts measuring the delay and extra path the robots cause people, in windows of
    /// `window_s` (a shadow crowd that ignores robots: one more crowd step per step).
    pub fn measure_human_impact(&mut self, window_s: Real) {
        self.impact = Some(HumanImpact::new(&self.world, window_s));
    }

    /// Stops measuring what the robots cost people (drops the measurement).
    pub fn stop_measuring_human_impact(&mut self) {
        self.impact = None;
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

/// Whether every point of segment `a`–`b`, sampled every 5 cm, is out of every obstacle and
/// at least `need` (m) from its surface.
fn clear_leg(map: &StaticMap, a: Vec2, b: Vec2, need: Real) -> bool {
    let steps = ((b - a).norm() / 0.05).ceil().max(1.0) as usize;
    (0..=steps).all(|s| {
        let p = a + (b - a) * (s as Real / steps as Real);
        !map.is_inside(&p) && map.distance(&p) >= need
    })
}

mod routes;
use routes::Through;
mod run;
pub use run::{
    FleetOptions, FleetReport, STALLED_M, Stalls, drive, plan_all, run_fleet, run_fleet_with,
    stacks,
};

mod summary;
pub use summary::FleetSummary;

mod snapshot;
pub use snapshot::{SNAPSHOT_FORMAT, SnapshotError};

#[cfg(test)]
mod tests;
