//! Fleet traffic, measured: stuck robots, the wait-for graph between robots, and deadlocks
//! (cycles in that graph that last).
//!
//! - A robot is **stuck** when it has a task and for [`TrafficParams::stuck_after_s`] the
//!   route it has left to drive has not come [`TrafficParams::progress_m`] below the shortest
//!   it has been on this leg: a detour that lengthens the route counts as no progress until
//!   the robot is nearer than before it.
//! - Robot i **waits on** robot j when i has a task and is (nearly) stopped, and j is in its
//!   way: in i's line of sight, within [`TrafficParams::blocking_gap_m`] of i (surface to
//!   surface) and ahead of i (within [`TrafficParams::blocking_cone_rad`] of the direction to
//!   the point i drives to: its waypoint, or the traffic policy's goal in its place), where j is now or where j's shared intent puts it within
//!   [`TrafficParams::intent_horizon_s`] (intents count only for a j not behind i: a robot
//!   behind that means to overtake blocks nobody). The traffic policy adds its own edges: a
//!   robot held at a reserved segment waits on the robots holding it. A robot on the point it
//!   drives to (within its own radius: a hold or queue place it has reached) heads nowhere and
//!   waits only on whom the policy says.
//! - A **deadlock** is a set of robots each waiting on another in the set: a strongly
//!   connected component of two or more robots of the wait-for graph, every member of which has
//!   been in such a component for [`TrafficParams::deadlock_after_s`] (brief cycles, two
//!   robots stopping for a moment face to face, are not deadlocks). A deadlock is counted once,
//!   however its set regroups (a bystander joining and leaving it), until its members have all
//!   been out of the wait-for cycles.
//! - A **gridlock** is robots stuck together, cycle or not: stuck robots are together when one
//!   waits on the other, or when they see each other within [`TrafficParams::gridlock_gap_m`]
//!   (surface to surface), and together by a chain of such links. A set of two or more
//!   together, every member of which has been in such a set for
//!   [`TrafficParams::gridlock_after_s`], is a gridlock; like a deadlock, it is counted once
//!   however it regroups, until its members have all come apart. A robot is stuck only after
//!   [`TrafficParams::stuck_after_s`] without progress, so a gridlock's robots have made none
//!   for at least the sum of the two. A deadlock whose robots are stuck is also a gridlock.
//!
//! The monitor is pure bookkeeping: positions in, events out, no clock but the simulation's.

use agent::map::StaticMap;
use agent::math::{Real, Vec2};

/// What the monitor counts as stuck, waiting and deadlocked. None of it is from a paper.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TrafficParams {
    /// A robot with a task is stuck after this long without progress (s). 30 s, the issue's
    /// example: longer than any wait for a person or an oncoming robot to clear an aisle.
    pub stuck_after_s: Real,
    /// Progress is the route left to drive shrinking by at least this much (m). 0.5 m:
    /// about a body, more than a robot jostled in place moves.
    pub progress_m: Real,
    /// A robot slower than this is waiting (m/s). 0.1 m/s: a tenth of top speed.
    pub waiting_speed: Real,
    /// A robot in the way is at most this far, surface to surface (m). 1 m: one robot's
    /// stopping distance at top speed and then some.
    pub blocking_gap_m: Real,
    /// "Ahead": within this angle of the direction to the waypoint (rad). 60°.
    pub blocking_cone_rad: Real,
    /// Shared intents count up to this far ahead (s). 2 s.
    pub intent_horizon_s: Real,
    /// A cycle is a deadlock once every member has been in one this long (s). 10 s.
    pub deadlock_after_s: Real,
    /// Stuck robots this close, surface to surface and in sight of each other, are stuck
    /// together (m). 2 m: a robot's length of floor between them, too little for a person
    /// and a robot to pass side by side in an aisle.
    pub gridlock_gap_m: Real,
    /// Robots stuck together are a gridlock once every member has been so this long (s).
    /// 60 s: added to the 30 s without progress that makes a robot stuck, a minute and a half
    /// in which none of them got anywhere.
    pub gridlock_after_s: Real,
}

impl Default for TrafficParams {
    fn default() -> Self {
        Self {
            stuck_after_s: 30.0,
            progress_m: 0.5,
            waiting_speed: 0.1,
            blocking_gap_m: 1.0,
            blocking_cone_rad: 60.0_f64.to_radians(),
            intent_horizon_s: 2.0,
            deadlock_after_s: 10.0,
            gridlock_gap_m: 2.0,
            gridlock_after_s: 60.0,
        }
    }
}

/// One robot as the monitor sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotView<'a> {
    /// Position.
    pub position: Vec2,
    /// Velocity.
    pub velocity: Vec2,
    /// Body radius.
    pub radius: Real,
    /// Its task: which leg (task id, stage) it is on, the point it drives to now and the
    /// route it has left (m); `None` when idle.
    pub task: Option<TaskView>,
    /// Its fresh shared intent, positions with `t` from now (s).
    pub intent: &'a [(Real, Vec2)],
}

/// A robot's task, as the monitor sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TaskView {
    /// Changes whenever the robot starts a new leg (task id × 2 + stage).
    pub leg: u64,
    /// The point it drives to now: its route's waypoint, or the goal the traffic policy gives
    /// it in its place (a robot waiting at a hold or queue place heads nowhere, and waits on
    /// whom the policy says).
    pub waypoint: Vec2,
    /// Route left to drive (m).
    pub remaining_m: Real,
}

/// Something the monitor saw begin or end.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum TrafficEvent {
    /// A robot became stuck.
    Stuck {
        /// Robot index.
        robot: usize,
    },
    /// A stuck robot made progress again (or lost its task).
    Unstuck {
        /// Robot index.
        robot: usize,
    },
    /// A set of robots became deadlocked.
    Deadlock {
        /// The robots, ascending.
        robots: Vec<usize>,
    },
    /// A set of robots became gridlocked: stuck together, cycle or not.
    Gridlock {
        /// The robots, ascending.
        robots: Vec<usize>,
    },
}

/// Totals over a run.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct TrafficTotals {
    /// Deadlocks that began.
    pub deadlocks: u64,
    /// Robot-seconds spent deadlocked.
    pub deadlocked_robot_s: Real,
    /// Times a robot became stuck.
    pub stuck_onsets: u64,
    /// Robot-seconds spent stuck.
    pub stuck_robot_s: Real,
    /// Most robots stuck at once.
    pub max_stuck: usize,
    /// Gridlocks that began.
    #[serde(default)]
    pub gridlocks: u64,
    /// Robot-seconds spent gridlocked.
    #[serde(default)]
    pub gridlocked_robot_s: Real,
}

#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
struct Progress {
    leg: u64,
    best_m: Real,
    since: Real,
}

/// Watches a fleet step by step.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct TrafficMonitor {
    /// The thresholds.
    pub params: TrafficParams,
    progress: Vec<Option<Progress>>,
    stuck: Vec<bool>,
    cyclic_since: Vec<Option<Real>>,
    waits_on: Vec<Vec<usize>>,
    cycles: Vec<Vec<usize>>,
    deadlocked: Vec<Vec<usize>>,
    /// Per robot: in a deadlock that began and whose members have not left the wait-for
    /// cycles since (the cycle may regroup, a bystander joining and leaving it: still the same
    /// deadlock).
    in_deadlock: Vec<bool>,
    /// Per robot: since when it has been stuck together with another, if it is.
    together_since: Vec<Option<Real>>,
    gridlocked: Vec<Vec<usize>>,
    /// Per robot: in a gridlock that began and that it has not come out of since.
    in_gridlock: Vec<bool>,
    totals: TrafficTotals,
}

impl TrafficMonitor {
    /// A monitor for `robots` robots.
    pub fn new(robots: usize, params: TrafficParams) -> Self {
        Self {
            params,
            progress: vec![None; robots],
            stuck: vec![false; robots],
            cyclic_since: vec![None; robots],
            waits_on: vec![Vec::new(); robots],
            cycles: Vec::new(),
            deadlocked: Vec::new(),
            in_deadlock: vec![false; robots],
            together_since: vec![None; robots],
            gridlocked: Vec::new(),
            in_gridlock: vec![false; robots],
            totals: TrafficTotals::default(),
        }
    }

    /// Takes the robots' state at simulation time `now` after a step of `dt`; `extra` are
    /// wait-for edges from elsewhere (the traffic policy's holds). Returns what began or ended.
    pub fn record(
        &mut self,
        now: Real,
        dt: Real,
        robots: &[RobotView<'_>],
        map: &StaticMap,
        extra: &[(usize, usize)],
    ) -> Vec<TrafficEvent> {
        let mut events = Vec::new();
        self.track_progress(now, dt, robots, &mut events);
        self.build_graph(robots, map, extra);
        self.find_deadlocks(now, dt, &mut events);
        self.find_gridlocks(now, dt, robots, map, &mut events);
        events
    }

    fn track_progress(
        &mut self,
        now: Real,
        dt: Real,
        robots: &[RobotView<'_>],
        events: &mut Vec<TrafficEvent>,
    ) {
        let p = self.params;
        for (i, r) in robots.iter().enumerate() {
            let stuck_now = match (r.task, &mut self.progress[i]) {
                (None, slot) => {
                    *slot = None;
                    false
                }
                (Some(task), slot) => {
                    let restart = !matches!(slot, Some(g) if g.leg == task.leg);
                    if restart {
                        *slot = Some(Progress {
                            leg: task.leg,
                            best_m: task.remaining_m,
                            since: now,
                        });
                    }
                    let g = slot.as_mut().expect("set above");
                    if task.remaining_m <= g.best_m - p.progress_m {
                        g.best_m = task.remaining_m;
                        g.since = now;
                    }
                    now - g.since >= p.stuck_after_s
                }
            };
            if stuck_now != self.stuck[i] {
                events.push(if stuck_now {
                    self.totals.stuck_onsets += 1;
                    TrafficEvent::Stuck { robot: i }
                } else {
                    TrafficEvent::Unstuck { robot: i }
                });
                self.stuck[i] = stuck_now;
            }
        }
        let stuck = self.stuck.iter().filter(|&&s| s).count();
        self.totals.stuck_robot_s += stuck as Real * dt;
        self.totals.max_stuck = self.totals.max_stuck.max(stuck);
    }

    fn build_graph(&mut self, robots: &[RobotView<'_>], map: &StaticMap, extra: &[(usize, usize)]) {
        let p = self.params;
        let cos_cone = p.blocking_cone_rad.cos();
        for (i, r) in robots.iter().enumerate() {
            let edges = &mut self.waits_on[i];
            edges.clear();
            let Some(task) = r.task else { continue };
            if r.velocity.norm() >= p.waiting_speed {
                continue;
            }
            let ahead = task.waypoint - r.position;
            let ahead_len = ahead.norm();
            // On the point it drives to (a hold or queue place it has reached): it heads
            // nowhere, and the direction to a point under its own body is noise.
            if ahead_len <= r.radius {
                continue;
            }
            let ahead = Some(ahead / ahead_len);
            for (j, o) in robots.iter().enumerate() {
                if j == i {
                    continue;
                }
                let reach = p.blocking_gap_m + r.radius + o.radius;
                let in_way = |q: Vec2| ahead_within(r.position, ahead, q, reach, cos_cone);
                let now_in_way = in_way(o.position);
                let behind = ahead.is_some_and(|h| (o.position - r.position).dot(&h) < 0.0);
                let soon_in_way = || {
                    !behind
                        && o.intent
                            .iter()
                            .take_while(|(t, _)| *t <= p.intent_horizon_s)
                            .any(|&(_, q)| in_way(q))
                };
                if (now_in_way || soon_in_way()) && map.line_of_sight(r.position, o.position) {
                    edges.push(j);
                }
            }
        }
        for &(i, j) in extra {
            if i != j && i < robots.len() && j < robots.len() && !self.waits_on[i].contains(&j) {
                self.waits_on[i].push(j);
            }
        }
    }

    fn find_deadlocks(&mut self, now: Real, dt: Real, events: &mut Vec<TrafficEvent>) {
        let p = self.params;
        self.cycles = strongly_connected(&self.waits_on)
            .into_iter()
            .filter(|c| c.len() >= 2)
            .collect();
        let cycles = self.cycles.clone();
        let found = lasting(
            cycles,
            &mut self.cyclic_since,
            &mut self.in_deadlock,
            now,
            p.deadlock_after_s,
        );
        let mut deadlocked = Vec::with_capacity(found.len());
        for (set, new) in found {
            if new {
                self.totals.deadlocks += 1;
                events.push(TrafficEvent::Deadlock {
                    robots: set.clone(),
                });
            }
            self.totals.deadlocked_robot_s += set.len() as Real * dt;
            deadlocked.push(set);
        }
        self.deadlocked = deadlocked;
    }

    fn find_gridlocks(
        &mut self,
        now: Real,
        dt: Real,
        robots: &[RobotView<'_>],
        map: &StaticMap,
        events: &mut Vec<TrafficEvent>,
    ) {
        let sets = self.stuck_together(robots, map);
        let found = lasting(
            sets,
            &mut self.together_since,
            &mut self.in_gridlock,
            now,
            self.params.gridlock_after_s,
        );
        self.gridlocked.clear();
        for (set, new) in found {
            if new {
                self.totals.gridlocks += 1;
                events.push(TrafficEvent::Gridlock {
                    robots: set.clone(),
                });
            }
            self.totals.gridlocked_robot_s += set.len() as Real * dt;
            self.gridlocked.push(set);
        }
    }

    /// The sets of two or more stuck robots linked, by chains, by waiting on each other or by
    /// standing within [`TrafficParams::gridlock_gap_m`] in sight of each other; each
    /// ascending, in order of their smallest member.
    fn stuck_together(&self, robots: &[RobotView<'_>], map: &StaticMap) -> Vec<Vec<usize>> {
        let stuck: Vec<usize> = (0..robots.len()).filter(|&i| self.stuck[i]).collect();
        if stuck.len() < 2 {
            return Vec::new();
        }
        // Union-find over the stuck robots (indices into `stuck`).
        let mut parent: Vec<usize> = (0..stuck.len()).collect();
        fn root(parent: &mut [usize], mut a: usize) -> usize {
            while parent[a] != a {
                parent[a] = parent[parent[a]];
                a = parent[a];
            }
            a
        }
        for a in 0..stuck.len() {
            for b in a + 1..stuck.len() {
                let (i, j) = (stuck[a], stuck[b]);
                let (ri, rj) = (&robots[i], &robots[j]);
                let gap = (ri.position - rj.position).norm() - ri.radius - rj.radius;
                let linked = self.waits_on[i].contains(&j)
                    || self.waits_on[j].contains(&i)
                    || (gap <= self.params.gridlock_gap_m
                        && map.line_of_sight(ri.position, rj.position));
                if linked {
                    let (x, y) = (root(&mut parent, a), root(&mut parent, b));
                    parent[x.max(y)] = x.min(y);
                }
            }
        }
        let mut sets: Vec<Vec<usize>> = Vec::new();
        let mut slot = vec![usize::MAX; stuck.len()];
        for (a, &i) in stuck.iter().enumerate() {
            let r = root(&mut parent, a);
            if slot[r] == usize::MAX {
                slot[r] = sets.len();
                sets.push(Vec::new());
            }
            sets[slot[r]].push(i);
        }
        sets.retain(|s| s.len() >= 2);
        sets
    }

    /// How long robot `i` has gone without progress toward its goal at time `now` (s): 0
    /// while it makes progress, `None` while it has no task.
    pub fn without_progress(&self, i: usize, now: Real) -> Option<Real> {
        self.progress[i].map(|g| now - g.since)
    }

    /// Whether robot `i` is stuck now.
    pub fn is_stuck(&self, i: usize) -> bool {
        self.stuck[i]
    }

    /// The robots robot `i` waits on now.
    pub fn waits_on(&self, i: usize) -> &[usize] {
        &self.waits_on[i]
    }

    /// The wait-for cycles now: strongly connected sets of two or more robots, each ascending.
    pub fn cycles(&self) -> &[Vec<usize>] {
        &self.cycles
    }

    /// Since when robot `i` has been in a wait-for cycle without a break, if it is in one.
    pub fn in_cycle_since(&self, i: usize) -> Option<Real> {
        self.cyclic_since[i]
    }

    /// The deadlocked sets now, each ascending.
    pub fn deadlocked(&self) -> &[Vec<usize>] {
        &self.deadlocked
    }

    /// The gridlocked sets now, each ascending.
    pub fn gridlocked(&self) -> &[Vec<usize>] {
        &self.gridlocked
    }

    /// Whether robot `i` is in a gridlock now.
    pub fn is_gridlocked(&self, i: usize) -> bool {
        self.gridlocked.iter().any(|s| s.contains(&i))
    }

    /// Totals so far.
    pub fn totals(&self) -> TrafficTotals {
        self.totals
    }
}

/// Whether `q` is in the way of a body at `p` heading along the unit vector `heading`: within
/// `reach` of it and within the cone whose half-angle has cosine `cos_cone` about the
/// heading (anywhere within reach when the body heads nowhere, `heading` `None`). Robots in
/// each other's way for the wait-for graph, and people in a stuck robot's way
/// (`stuck::in_the_way`), are told by it.
pub(crate) fn ahead_within(
    p: Vec2,
    heading: Option<Vec2>,
    q: Vec2,
    reach: Real,
    cos_cone: Real,
) -> bool {
    let d = q - p;
    let dist = d.norm();
    dist <= reach && (dist == 0.0 || heading.is_none_or(|h| d.dot(&h) >= cos_cone * dist))
}

/// Sets of robots that last, each counted once however it regroups (deadlocks, gridlocks).
/// `since` holds, per robot, since when it has been in one of the sets without a break, and
/// `counted` whether it is in a lasting set already counted and has not been out of every set
/// since; both are brought up to date with this step's `sets`. Returns the sets every member
/// of which has been in one for `after` (s), each with whether it is new: none of its members
/// in a set counted before.
fn lasting(
    sets: Vec<Vec<usize>>,
    since: &mut [Option<Real>],
    counted: &mut [bool],
    now: Real,
    after: Real,
) -> Vec<(Vec<usize>, bool)> {
    let mut inside = vec![false; since.len()];
    for &i in sets.iter().flatten() {
        inside[i] = true;
    }
    for (since, &now_inside) in since.iter_mut().zip(&inside) {
        *since = match (*since, now_inside) {
            (_, false) => None,
            (None, true) => Some(now),
            (kept, true) => kept,
        };
    }
    for (member, since) in counted.iter_mut().zip(since.iter()) {
        *member &= since.is_some();
    }
    let long = |i: &usize| since[*i].is_some_and(|s| now - s >= after - 1e-9);
    let mut out = Vec::new();
    for set in sets.into_iter().filter(|set| set.iter().all(long)) {
        let new = !set.iter().any(|&i| counted[i]);
        for &i in &set {
            counted[i] = true;
        }
        out.push((set, new));
    }
    out
}

/// The strongly connected components of a directed graph given as out-edge lists (Tarjan's
/// algorithm, iterative), each ascending, in a fixed order.
pub fn strongly_connected(edges: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let n = edges.len();
    let mut index = vec![usize::MAX; n];
    let mut low = vec![0; n];
    let mut on_stack = vec![false; n];
    let mut stack = Vec::new();
    let mut components = Vec::new();
    let mut next = 0;
    let mut call: Vec<(usize, usize)> = Vec::new();
    for root in 0..n {
        if index[root] != usize::MAX {
            continue;
        }
        call.push((root, 0));
        while let Some(&mut (v, ref mut k)) = call.last_mut() {
            if *k == 0 && index[v] == usize::MAX {
                index[v] = next;
                low[v] = next;
                next += 1;
                stack.push(v);
                on_stack[v] = true;
            }
            if let Some(&w) = edges[v].get(*k) {
                *k += 1;
                if index[w] == usize::MAX {
                    call.push((w, 0));
                } else if on_stack[w] {
                    low[v] = low[v].min(index[w]);
                }
                continue;
            }
            call.pop();
            if let Some(&(parent, _)) = call.last() {
                low[parent] = low[parent].min(low[v]);
            }
            if low[v] == index[v] {
                let mut component = Vec::new();
                while let Some(w) = stack.pop() {
                    on_stack[w] = false;
                    component.push(w);
                    if w == v {
                        break;
                    }
                }
                component.sort_unstable();
                components.push(component);
            }
        }
    }
    components
}

#[cfg(test)]
mod tests;
