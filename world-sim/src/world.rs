//! The world: people walking in groups (PySocialForce's model) and robots; what each robot
//! perceives is in `perception`, how a scenario becomes a world in `world/build.rs`. Fixed
//! steps, one seed, no clock: the same scenario gives the same numbers.

use crate::crowd::{Crowd, Walls};
use crate::robot::RobotBody;
use crate::scenario::{Scenario, WallModel};
use crate::warehouse::Site;
use agent::map::{Obstacle, StaticMap};
use agent::math::{Real, Vec2, unit, vec2};
use agent::model::Command;
use agent::social_force::SfParams;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::VecDeque;

mod build;
mod perception;

/// Random streams, one per purpose, so that adding a draw in one does not shift the others.
const SPAWN_STREAM: u64 = 1;
const GOAL_STREAM: u64 = 2;
const NOISE_STREAM: u64 = 3;
const LANE_STREAM: u64 = 4;
const REACT_STREAM: u64 = 5;

/// Group members keep goals within this radius of the group's goal (m).
const GROUP_SPREAD_M: Real = 0.6;
/// People do not spawn closer than this to a robot's start (m).
const ROBOT_CLEARANCE_M: Real = 1.5;
/// Perceived robots carry this bit in their neighbour id; the low 32 bits are the robot's
/// index. People's ids are their index (< 2^32).
pub const ROBOT_ID_BIT: u64 = 1 << 32;
/// A group on a multi-leg route moves to its next waypoint when a member is this close to its
/// current one (m).
const WAYPOINT_REACHED_M: Real = 1.0;

/// The people of a world.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Humans {
    /// Their state, stepped by PySocialForce's model.
    pub crowd: Crowd,
    /// Each member's offset from its group's goal.
    offsets: Vec<Vec2>,
    /// Body radius (m).
    pub radius: Real,
    /// Whether robots push on people.
    pub react_to_robots: bool,
}

impl Humans {
    /// Whether person `i` steps aside for robots: people react when the world's people do,
    /// unless `humans.react_share` left them out.
    pub fn reacts(&self, i: usize) -> bool {
        self.react_to_robots
            && !self
                .crowd
                .ignores_externals
                .get(i)
                .copied()
                .unwrap_or(false)
    }
}

/// A world: map, people, robots, time.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct World {
    /// Seconds since the start.
    pub time: Real,
    /// Steps since the start.
    pub step: u64,
    /// Step length (s).
    pub dt: Real,
    /// Walls and shelves (not in a snapshot: [`Fleet::restore`](crate::fleet::Fleet::restore) takes them
    /// from the scenario).
    #[serde(skip)]
    pub map: StaticMap,
    /// People.
    pub humans: Humans,
    /// Robots.
    pub robots: Vec<RobotBody>,
    sf: SfParams,
    #[serde(skip)]
    walls: Walls,
    stage_min: Vec2,
    stage_max: Vec2,
    goal_rule: GoalRule,
    /// The warehouse, when the scenario is one.
    site: Option<Site>,
    /// Whether people walk between the site's stations.
    people_to_stations: bool,
    /// Per group: the waypoints after its current goal (warehouse routes).
    routes: Vec<VecDeque<Vec2>>,
    /// On a fleet site with `humans.regoal_stalled_s`: that time, and per group its nearest
    /// distance to its goal so far and when it last came 0.5 m nearer.
    #[serde(default)]
    regoal_stalled: Option<(Real, Vec<(Real, Real)>)>,
    /// In a laned hallway, each person's lane (its y) and the hallway's length: people stay
    /// on their lane line while inside it. Empty otherwise.
    lanes: Vec<Real>,
    lanes_end: Real,
    goal_rng: ChaCha8Rng,
    /// The scenario's seed: sensor noise is drawn from a stream of its own per (step,
    /// robot), so what a robot perceives does not depend on who else was observed, or how
    /// often ([`World::observe`]).
    seed: u64,
    scratch: Vec<Vec2>,
    externals: Vec<(Vec2, Vec2)>,
}

impl World {
    /// Takes the parts a snapshot leaves out (walls and shelves, and the crowd's wall
    /// points) from `built`, the same scenario's world built afresh.
    pub(crate) fn adopt_static(&mut self, built: &World) {
        self.map = built.map.clone();
        self.walls = built.walls.clone();
        if let (Some(site), Some(b)) = (&mut self.site, &built.site) {
            site.adopt_router(b);
        }
    }
}

/// The sensor-noise stream of robot `robot`'s observation at step `step`.
fn noise_stream(seed: u64, step: u64, robot: usize) -> ChaCha8Rng {
    let mut key = [0; 32];
    key[..8].copy_from_slice(&seed.to_le_bytes());
    key[8..16].copy_from_slice(&step.to_le_bytes());
    key[16..24].copy_from_slice(&(robot as u64).to_le_bytes());
    let mut rng = ChaCha8Rng::from_seed(key);
    rng.set_stream(NOISE_STREAM);
    rng
}

fn stream(seed: u64, stream: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream);
    rng
}

impl World {
    /// The warehouse layout, when the scenario is a warehouse.
    pub fn site(&self) -> Option<&Site> {
        self.site.as_ref()
    }

    /// Where people go, when the world knows: the site's stations if people walk between
    /// them (foIGP's intents), else none.
    pub fn people_destinations(&self) -> Vec<Vec2> {
        match &self.site {
            Some(site) if self.people_to_stations => {
                site.stations.iter().map(|s| s.position).collect()
            }
            _ => Vec::new(),
        }
    }

    /// The Social Force parameters people walk with.
    pub fn sf_params(&self) -> &SfParams {
        &self.sf
    }

    /// Advances one step: robots execute `commands` (one per robot), people walk.
    pub fn step(&mut self, commands: &[Command]) {
        assert_eq!(commands.len(), self.robots.len(), "one command per robot");
        // People react to where the robots are at the start of the step, as to each other.
        self.externals.clear();
        if self.humans.react_to_robots {
            self.externals.extend(
                self.robots
                    .iter()
                    .map(|r| (r.state.position, r.state.velocity)),
            );
        }
        for (robot, command) in self.robots.iter_mut().zip(commands) {
            robot.apply(*command, self.dt);
        }
        self.humans.crowd.step_with_externals(
            &self.walls,
            &self.sf,
            &self.externals,
            &mut self.scratch,
        );
        // Lanes hold people like rails: no sideways motion inside the hallway (HighwayEnv's
        // vehicles without lane changes); they slow behind slower ones instead.
        for (i, &y) in self.lanes.iter().enumerate() {
            let crowd = &mut self.humans.crowd;
            if crowd.positions[i].x <= self.lanes_end {
                crowd.positions[i].y = y;
                crowd.velocities[i].y = 0.0;
            }
        }
        self.regoal_arrived_groups();
        self.time += self.dt;
        self.step += 1;
    }

    /// Where people stop, turn and set off, as boxes (lower and upper corners; points here):
    /// on a fleet site whose people walk station to station, its stations, where robots dock
    /// and people arrive and set off again. `None` where people walk to goals anywhere (open
    /// ground, the fleet hallway) or by a floor plan's routes. What a site's operator would
    /// mark for the safety layer's field set (`agent::safety::SafetyParams::person_accel_away`).
    pub fn turn_places(&self) -> Option<Vec<(Vec2, Vec2)>> {
        self.site
            .as_ref()
            .filter(|_| self.people_to_stations)
            .and_then(Site::turn_places)
    }

    /// When any member of a group arrives, the whole group gets a new goal (PGP paper,
    /// Sec. IV-A), so that nobody stands still on the stage.
    /// In a warehouse, groups walk station to station along corridor routes, moving to the
    /// next waypoint as soon as a member is near the current one.
    fn regoal_arrived_groups(&mut self) {
        let crowd = &mut self.humans.crowd;
        for (g, group) in crowd.groups.iter().enumerate() {
            let on_route = !self.routes[g].is_empty();
            let reach = if on_route {
                WAYPOINT_REACHED_M.max(self.sf.arrival_distance)
            } else {
                self.sf.arrival_distance
            };
            let arrived = group
                .iter()
                .any(|&i| (crowd.goals[i] - crowd.positions[i]).norm() < reach);
            // Stalled: none nearer its goal by STALL_PROGRESS_M for the set time. The
            // group gives its goal, and its route, up.
            let stalled = self
                .regoal_stalled
                .as_mut()
                .is_some_and(|(after, progress)| {
                    let nearest = group
                        .iter()
                        .map(|&i| (crowd.goals[i] - crowd.positions[i]).norm())
                        .fold(Real::INFINITY, Real::min);
                    let (best, since) = &mut progress[g];
                    if nearest <= *best - STALL_PROGRESS_M {
                        (*best, *since) = (nearest, self.time);
                    }
                    self.time - *since >= *after
                });
            if stalled {
                self.routes[g].clear();
            }
            if arrived || stalled {
                if let Some((_, progress)) = &mut self.regoal_stalled {
                    progress[g] = (Real::INFINITY, self.time);
                }
                let here = crowd.positions[group[0]];
                let stations = self.site.as_ref().filter(|_| self.people_to_stations);
                let goal = match (stations, self.routes[g].pop_front()) {
                    (_, Some(waypoint)) => waypoint,
                    (Some(site), None) => {
                        let station = self.goal_rng.random_range(0..site.stations.len());
                        let mut route: VecDeque<Vec2> = site
                            .people_route(here, site.stations[station].position)
                            .into();
                        let first = route.pop_front().unwrap_or(here);
                        self.routes[g] = route;
                        first
                    }
                    (None, None) => self.goal_rule.next(
                        &mut self.goal_rng,
                        here,
                        self.stage_min,
                        self.stage_max,
                    ),
                };
                for &i in group {
                    crowd.goals[i] = clamp_box(
                        goal + self.humans.offsets[i],
                        self.stage_min,
                        self.stage_max,
                    );
                }
            }
        }
    }
}

/// A group has come nearer its goal when it is this much nearer than its nearest so far (m).
const STALL_PROGRESS_M: Real = 0.5;

/// People keep this far from a hallway's open ends (m); robots start and stop there too.
const END_MARGIN_M: Real = 0.5;

/// A hallway's end walls stand this far beyond its ends (m): room for a robot pushed back at
/// its start, and far enough from where people turn back that they feel no push from them.
const HALLWAY_END_ROOM_M: Real = 2.0;

/// Where a group goes when one of its members arrives.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
enum GoalRule {
    /// Anywhere on the stage (the PGP paper's open space).
    Anywhere,
    /// The far end of a hallway along x, at a random height: two-way traffic.
    OppositeEnd,
}

impl GoalRule {
    /// The first goal of a newly spawned group.
    fn first(self, rng: &mut ChaCha8Rng, min: Vec2, max: Vec2) -> Vec2 {
        match self {
            GoalRule::Anywhere => uniform(rng, min, max),
            // Half the groups head each way.
            GoalRule::OppositeEnd => {
                let x = if rng.random::<bool>() { max.x } else { min.x };
                vec2(x, rng.random_range(min.y..=max.y))
            }
        }
    }

    /// The next goal of a group that arrived at `at`.
    fn next(self, rng: &mut ChaCha8Rng, at: Vec2, min: Vec2, max: Vec2) -> Vec2 {
        match self {
            GoalRule::Anywhere => uniform(rng, min, max),
            GoalRule::OppositeEnd => {
                let x = if at.x - min.x > max.x - at.x {
                    min.x
                } else {
                    max.x
                };
                vec2(x, rng.random_range(min.y..=max.y))
            }
        }
    }
}

fn uniform(rng: &mut ChaCha8Rng, min: Vec2, max: Vec2) -> Vec2 {
    vec2(
        rng.random_range(min.x..=max.x),
        rng.random_range(min.y..=max.y),
    )
}

fn clamp_box(p: Vec2, min: Vec2, max: Vec2) -> Vec2 {
    vec2(p.x.clamp(min.x, max.x), p.y.clamp(min.y, max.y))
}

/// A standard normal 2-D sample (Box–Muller).
fn gaussian2(rng: &mut ChaCha8Rng) -> Vec2 {
    let u1: Real = rng.random::<Real>().max(Real::MIN_POSITIVE);
    let u2: Real = rng.random();
    unit(std::f64::consts::TAU * u2) * (-2.0 * u1.ln()).sqrt()
}

#[cfg(test)]
mod tests;
