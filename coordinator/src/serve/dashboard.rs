//! Feeds a running coordinator's fleet to a Rerun [`Dashboard`]: one [`Frame`] per tick,
//! events (agents joining, leaving, crashing, tasks done, contacts at their onset with who
//! caused them, near misses, protective stops), each robot's safety fields, and the social
//! metrics, fleet-wide and per robot.

use super::status::{Event, Observer, Status};
use agent::safety::{SafetyLimits, field_reach};
use dashboards::{
    Dashboard, EventView, FanView, FieldState, FieldView, Frame, HeatEvent, HeatKind, IntentView,
    MapFrame, P, RobotRow, RobotView, SegmentView, Sinks, TrafficGoal, TrafficView,
};
use schemas::SafetyZone;
use std::collections::HashSet;
use world_sim::fleet::{Fleet, FleetEvent, Stage};
use world_sim::metrics::{ContactCause, NEAR_MISS_GAP, contact_cause};
use world_sim::traffic::TrafficEvent;
use world_sim::traffic_policy::{Constraint, PolicyEvent};

fn p(v: agent::math::Vec2) -> P {
    [v.x as f32, v.y as f32]
}

/// A wall of the robots' map this far (m) from every wall of the world's is a keep-out zone's
/// edge: farther than the one cell (5 cm on the sample map) the two simplifications of the
/// floor's edge may differ by.
const KEEPOUT_APART_M: agent::math::Real = 0.1;

/// The static map of a fleet's site.
pub fn map_frame(fleet: &Fleet) -> MapFrame {
    use agent::map::Obstacle;
    let mut map = MapFrame::default();
    for o in fleet.world.map.obstacles() {
        match o {
            Obstacle::Polygon(points) => map.shelves.push(points.iter().map(|&v| p(v)).collect()),
            Obstacle::Wall(a, b) => map.walls.push([p(*a), p(*b)]),
        }
    }
    // The robots' map's walls that are not the world's: the edges of keep-out zones.
    if fleet.site().robot_obstacles.is_some() {
        for o in fleet.robot_map().obstacles() {
            if let Obstacle::Wall(a, b) = o
                && fleet.world.map.distance(&((a + b) / 2.0)) > KEEPOUT_APART_M
            {
                map.keepout.push([p(*a), p(*b)]);
            }
        }
    }
    for s in &fleet.site().stations {
        let kind = match s.kind {
            world_sim::warehouse::StationKind::Dock => "dock",
            world_sim::warehouse::StationKind::Pick => "pick",
        };
        map.stations
            .push((p(s.position), format!("{kind} {}", s.id)));
    }
    map
}

/// Bodies in contact (or nearly) this tick, to report each contact once at its onset.
#[derive(Debug, Default)]
struct Contacts {
    human: HashSet<(usize, usize)>,
    robot_contact: HashSet<(usize, usize)>,
    robot_near: HashSet<(usize, usize)>,
}

/// A coordinator observer that draws the fleet.
#[derive(Debug)]
pub struct DashboardObserver {
    dashboard: Dashboard,
    planner: String,
    contacts: Contacts,
    seen_events: u64,
    /// The zone of each robot's previous command, for protective stops at their onset.
    zones: Vec<SafetyZone>,
    /// Per robot: its agent left ("left") or crashed ("crashed"), until it joins again.
    gone: Vec<Option<&'static str>>,
    /// Per robot: when (simulated s) it last touched a person.
    last_contact: Vec<f64>,
    /// Human-impact windows already put on the delay heatmap.
    seen_windows: u64,
}

/// A robot counts as near people when its body comes this close to a person's (m).
pub const NEAR_PEOPLE_M: f64 = 1.0;

/// A robot that touched a person stays "in trouble" in the robot table this long (s).
pub const CONTACT_TROUBLE_S: f64 = 60.0;

/// Dashboards show the delay and extra path robots cause people over windows this long (s);
/// commands that draw turn the measurement on (`Fleet::measure_human_impact`: one more crowd
/// step per tick, for a shadow crowd that ignores robots).
pub const HUMAN_IMPACT_WINDOW_S: f64 = 10.0;

impl DashboardObserver {
    /// Starts a dashboard on `sinks` for `fleet`, labelling robots with `planner`.
    pub fn start(
        fleet: &Fleet,
        sinks: &Sinks,
        planner: &str,
    ) -> Result<Self, dashboards::DashboardError> {
        let dashboard = Dashboard::start("gapfleet", sinks, map_frame(fleet))?;
        Ok(Self {
            dashboard,
            planner: planner.to_owned(),
            contacts: Contacts::default(),
            seen_events: 0,
            zones: Vec::new(),
            gone: vec![None; fleet.robots()],
            last_contact: vec![f64::NEG_INFINITY; fleet.robots()],
            seen_windows: 0,
        })
    }

    /// The served web viewer's URL, if `--web`.
    pub fn web_url(&self) -> Option<&str> {
        self.dashboard.web_url()
    }

    /// Flushes and stops; returns (frames logged, frames dropped).
    pub fn finish(self) -> dashboards::DashboardStats {
        self.dashboard.finish()
    }

    /// Contacts and near misses at their onset, heatmap events (robots near people, contacts),
    /// and each robot's distance to its nearest person (centre to centre, m).
    fn contact_events(
        &mut self,
        fleet: &Fleet,
        out: &mut Vec<EventView>,
        heat: &mut Vec<HeatEvent>,
    ) -> Vec<Option<f64>> {
        let world = &fleet.world;
        let crowd = &world.humans.crowd;
        let mut now = Contacts::default();
        let mut nearest = vec![None; world.robots.len()];
        for (i, r) in world.robots.iter().enumerate() {
            let (rp, rr) = (r.state.position, r.state.radius);
            let mut closest = f64::INFINITY;
            for h in 0..crowd.len() {
                let d = (crowd.positions[h] - rp).norm();
                closest = closest.min(d);
                if d < rr + world.humans.radius {
                    now.human.insert((i, h));
                }
            }
            if closest.is_finite() {
                nearest[i] = Some(closest);
                if closest - rr - world.humans.radius < NEAR_PEOPLE_M {
                    heat.push(HeatEvent {
                        kind: HeatKind::NearPeople,
                        at: p(rp),
                        weight: world.dt as f32,
                    });
                }
            }
            for (j, o) in world.robots.iter().enumerate().skip(i + 1) {
                let gap = (o.state.position - rp).norm() - rr - o.state.radius;
                if gap < 0.0 {
                    now.robot_contact.insert((i, j));
                } else if gap < NEAR_MISS_GAP {
                    now.robot_near.insert((i, j));
                }
            }
        }
        let at = |i: usize| p(world.robots[i].state.position);
        for &(i, h) in now.human.difference(&self.contacts.human) {
            let r = &world.robots[i].state;
            self.last_contact
                .resize(world.robots.len(), f64::NEG_INFINITY);
            self.last_contact[i] = world.time;
            heat.push(HeatEvent {
                kind: HeatKind::Contact,
                at: p((r.position + crowd.positions[h]) / 2.0),
                weight: 1.0,
            });
            let text = match contact_cause(r.position, r.velocity, crowd.positions[h]) {
                ContactCause::Robot => format!("collision: robot {i} drove into person {h}"),
                ContactCause::Other => {
                    format!("contact: person {h} walked into robot {i} (stopped or moving away)")
                }
            };
            out.push(EventView {
                text,
                position: Some(at(i)),
                warning: true,
            });
        }
        for &(i, j) in now.robot_contact.difference(&self.contacts.robot_contact) {
            out.push(EventView {
                text: format!("collision: robots {i} and {j}"),
                position: Some(at(i)),
                warning: true,
            });
        }
        for &(i, j) in now.robot_near.difference(&self.contacts.robot_near) {
            out.push(EventView {
                text: format!("near miss: robots {i} and {j}"),
                position: Some(at(i)),
                warning: true,
            });
        }
        self.contacts = now;
        nearest
    }

    /// The robot table's rows.
    fn robot_rows(
        &self,
        fleet: &Fleet,
        metrics: &[world_sim::metrics::RobotMetrics],
        nearest: &[Option<f64>],
        delay_share: impl Fn(usize) -> Option<f64>,
    ) -> Vec<RobotRow> {
        let now = fleet.world.time;
        (0..fleet.robots())
            .map(|i| {
                let m = &metrics[i];
                let gone = self.gone.get(i).copied().flatten();
                let stuck = fleet.traffic().is_stuck(i);
                let touched = self
                    .last_contact
                    .get(i)
                    .is_some_and(|&t| now - t < CONTACT_TROUBLE_S);
                let stage = match fleet.job(i) {
                    _ if fleet.is_held(i) && gone.is_none() => "held",
                    None => "idle",
                    Some(job) if job.stage == Stage::ToPick => "to pick",
                    Some(_) => "to drop",
                };
                let mut state = gone.unwrap_or(stage).to_owned();
                if stuck {
                    state = format!("stuck ({state})");
                }
                if touched {
                    state += ", touched a person";
                }
                RobotRow {
                    id: i as u32,
                    planner: self.planner.clone(),
                    state,
                    trouble: gone.is_some() || stuck || touched,
                    tasks_done: fleet.tasks_done(i),
                    contacts: m.robot_caused_contacts + m.person_caused_contacts,
                    svr: m.svr,
                    closest_person_m: nearest.get(i).copied().flatten().map(|d| d as f32),
                    delay_share: delay_share(i).map(|s| s as f32),
                }
            })
            .collect()
    }
}

impl DashboardObserver {
    /// A protective stop or a yield at its onset: the robot's newest command was slowed or
    /// stopped by its protective field (or replaced by a way out), and the one before was not.
    fn safety_events(&mut self, fleet: &Fleet, status: &Status, out: &mut Vec<EventView>) {
        self.zones.resize(status.safety.len(), SafetyZone::Clear);
        for (i, (&now, before)) in status.safety.iter().zip(&mut self.zones).enumerate() {
            if now == SafetyZone::Protective && *before != SafetyZone::Protective {
                out.push(EventView {
                    text: format!(
                        "robot {i}: protective stop (slowed or stopped by its safety layer)"
                    ),
                    position: fleet.world.robots.get(i).map(|r| p(r.state.position)),
                    warning: false,
                });
            }
            if now == SafetyZone::Yield && *before != SafetyZone::Yield {
                out.push(EventView {
                    text: format!("robot {i}: yields (someone would walk into it were it to stop)"),
                    position: fleet.world.robots.get(i).map(|r| p(r.state.position)),
                    warning: false,
                });
            }
            *before = now;
        }
    }
}

/// The traffic policy's segments and goals (when it runs) and the monitor's wait-for graph
/// and stuck robots.
fn traffic_view(fleet: &Fleet) -> TrafficView {
    let at = |i: usize| p(fleet.world.robots[i].state.position);
    let monitor = fleet.traffic();
    let mut view = TrafficView::default();
    if let Some(policy) = fleet.traffic_policy() {
        view.segments = policy
            .segments()
            .iter()
            .map(|s| {
                let r = policy.reservation(s.id);
                SegmentView {
                    id: s.id as u32,
                    min: [s.x0 as f32, (s.y - s.half_width) as f32],
                    max: [s.x1 as f32, (s.y + s.half_width) as f32],
                    direction: r.dir,
                    holders: r.holders.iter().map(|&h| h as u32).collect(),
                    waiting: r.waiting.iter().map(|w| w.0 as u32).collect(),
                }
            })
            .collect();
        view.goals = (0..fleet.robots())
            .filter(|&i| fleet.job(i).is_some())
            .filter_map(|i| {
                let (goal, kind) = match policy.constraint(i) {
                    Constraint::Hold { at, .. } => (at, TrafficGoal::Hold),
                    Constraint::Queue { at, .. } => (at, TrafficGoal::Queue),
                    Constraint::Retreat(at) => (at, TrafficGoal::Retreat),
                    Constraint::GiveWay(at) => (at, TrafficGoal::GiveWay),
                    Constraint::Free | Constraint::Lane(_) => return None,
                };
                Some((i as u32, p(goal), kind))
            })
            .collect();
    }
    let cycle_of = |i: usize| monitor.cycles().iter().position(|c| c.contains(&i));
    for i in 0..fleet.robots() {
        for &j in monitor.waits_on(i) {
            let in_cycle = cycle_of(i).is_some() && cycle_of(i) == cycle_of(j);
            view.waits.push((at(i), at(j), in_cycle));
        }
        if monitor.is_stuck(i) {
            let r = &fleet.world.robots[i].state;
            view.stuck.push((i as u32, at(i), r.radius as f32));
        }
    }
    view
}

/// The monitor's and the policy's events of the last step, for the log: deadlocks, gridlocks,
/// robots getting stuck, segments granted and released, retreats, detours.
fn traffic_events(fleet: &Fleet, out: &mut Vec<EventView>) {
    let at = |i: usize| Some(p(fleet.world.robots[i].state.position));
    for e in fleet.traffic_events() {
        match e {
            TrafficEvent::Deadlock { robots } => out.push(EventView {
                text: format!("deadlock: robots {robots:?} wait on each other"),
                position: robots.first().and_then(|&i| at(i)),
                warning: true,
            }),
            TrafficEvent::Gridlock { robots } => out.push(EventView {
                text: format!("gridlock: robots {robots:?} stuck together for a minute"),
                position: robots.first().and_then(|&i| at(i)),
                warning: true,
            }),
            TrafficEvent::Stuck { robot } => out.push(EventView {
                text: format!("robot {robot} stuck: no progress toward its goal"),
                position: at(*robot),
                warning: true,
            }),
            TrafficEvent::Unstuck { .. } => {}
        }
    }
    for e in fleet.policy_events() {
        let text = match *e {
            PolicyEvent::Granted {
                robot,
                segment,
                dir,
            } => {
                let arrow = if dir > 0 { "→" } else { "←" };
                format!("segment {segment} {arrow} granted to robot {robot}")
            }
            PolicyEvent::Released { robot, segment } => {
                format!("robot {robot} left segment {segment}")
            }
            PolicyEvent::Retreat { robot } => {
                format!("robot {robot} retreats: a wait-for cycle lasted")
            }
            PolicyEvent::GiveWay { robot } => {
                format!("robot {robot} gives way: robots of both directions knotted")
            }
            PolicyEvent::Detour { robot, segment } => {
                format!("robot {robot} goes round to segment {segment}'s far end, with its flow")
            }
            PolicyEvent::StationGranted { robot, station } => {
                format!("station {station} granted to robot {robot}")
            }
            PolicyEvent::Waiting { .. } | PolicyEvent::Queued { .. } => continue,
        };
        let robot = match *e {
            PolicyEvent::Granted { robot, .. }
            | PolicyEvent::Released { robot, .. }
            | PolicyEvent::Retreat { robot }
            | PolicyEvent::GiveWay { robot }
            | PolicyEvent::Detour { robot, .. }
            | PolicyEvent::StationGranted { robot, .. }
            | PolicyEvent::Waiting { robot, .. }
            | PolicyEvent::Queued { robot, .. } => robot,
        };
        out.push(EventView {
            text,
            position: at(robot),
            warning: false,
        });
    }
}

/// Each robot's protective and warning fields at its current speed, as its scenario's layer
/// parameters size them (`agent::safety::field_reach`): capsules from the robot along its
/// direction of travel, as wide as the robot plus the margin.
fn safety_fields(fleet: &Fleet, status: &Status) -> Vec<FieldView> {
    let dt = fleet.world.dt;
    fleet
        .world
        .robots
        .iter()
        .enumerate()
        // Robots whose scenario runs the layer (`[robot] safety`; agents started with
        // `--no-safety` report every command clear, so their fields stay grey).
        .filter(|(_, r)| r.spec.safety)
        .map(|(i, r)| {
            let limits: SafetyLimits = r.spec.safety_limits(dt);
            let params = r.spec.safety_layer;
            let s = &r.state;
            let speed = s.velocity.norm();
            let direction = if speed > 1e-3 {
                s.velocity / speed
            } else {
                agent::math::unit(s.heading)
            };
            let (protective, warning) = field_reach(speed, &limits, &params);
            let width = s.radius + params.margin;
            let state = match status.safety.get(i) {
                Some(SafetyZone::Warning) => FieldState::Warning,
                Some(SafetyZone::Protective) => FieldState::Protective,
                Some(SafetyZone::Yield) => FieldState::Yield,
                _ => FieldState::Clear,
            };
            FieldView {
                robot: i as u32,
                protective: capsule(s.position, direction, protective, width),
                warning: capsule(s.position, direction, warning, width),
                state,
            }
        })
        .collect()
}

/// A closed outline: a half circle of `width` behind `from`, straight sides `length` long
/// along `direction`, and a half circle in front.
fn capsule(
    from: agent::math::Vec2,
    direction: agent::math::Vec2,
    length: f64,
    width: f64,
) -> Vec<P> {
    const HALF: usize = 8;
    let normal = agent::math::vec2(-direction.y, direction.x);
    let tip = from + direction * length;
    let arc = |centre: agent::math::Vec2, start: f64| {
        (0..=HALF).map(move |k| {
            let a = start + std::f64::consts::PI * k as f64 / HALF as f64;
            centre + (normal * a.cos() + direction * a.sin()) * width
        })
    };
    // From the right side behind, round the back, then round the front.
    let mut points: Vec<P> = arc(from, std::f64::consts::PI).map(p).collect();
    points.extend(arc(tip, 0.0).map(p));
    points.push(points[0]);
    points
}

impl Observer for DashboardObserver {
    fn tick(&mut self, fleet: &Fleet, status: &Status, _events: &[FleetEvent]) {
        let world = &fleet.world;
        let crowd = &world.humans.crowd;
        let mut groups = vec![0_u32; crowd.len()];
        for (g, members) in crowd.groups.iter().enumerate() {
            for &m in members {
                groups[m] = g as u32;
            }
        }
        let flagged: HashSet<u32> = status.flagged.iter().copied().collect();
        let robots = world
            .robots
            .iter()
            .enumerate()
            .map(|(i, r)| RobotView {
                id: i as u32,
                position: p(r.state.position),
                heading: r.state.heading as f32,
                radius: r.state.radius as f32,
                planner: self.planner.clone(),
                alive: !fleet.is_held(i) && !flagged.contains(&(i as u32)),
            })
            .collect();
        let intents = (0..fleet.robots())
            .filter_map(|i| {
                let (_, trajectory) = fleet.intent(i)?;
                let goal = fleet.goal(i)?;
                Some(IntentView {
                    robot: i as u32,
                    path: trajectory.iter().map(|s| p(s.position)).collect(),
                    subgoal: p(goal),
                })
            })
            .collect();
        let mut events = Vec::new();
        self.gone.resize(fleet.robots(), None);
        for e in status.events_since(self.seen_events) {
            let gone = match e {
                Event::Joined(i) => Some((*i, None)),
                Event::Left(i) => Some((*i, Some("left"))),
                Event::Crashed(i) => Some((*i, Some("crashed"))),
                Event::Lost(i) => Some((*i, Some("lost"))),
                Event::Found(i) => Some((*i, None)),
                Event::TaskDone { .. } => None,
            };
            if let Some((i, how)) = gone
                && let Some(slot) = self.gone.get_mut(i as usize)
            {
                *slot = how;
            }
            let (text, robot, warning) = match e {
                Event::Joined(i) => (format!("agent {i} joined"), *i, false),
                Event::Left(i) => (format!("agent {i} left"), *i, true),
                Event::Crashed(i) => (format!("agent {i} crashed: robot stopped"), *i, true),
                Event::Lost(i) => (format!("robot {i} lost: no state report"), *i, true),
                Event::Found(i) => (format!("robot {i} reports again"), *i, false),
                Event::TaskDone { robot, task } => {
                    (format!("robot {robot} finished task {task}"), *robot, false)
                }
            };
            let position = world
                .robots
                .get(robot as usize)
                .map(|r| p(r.state.position));
            events.push(EventView {
                text,
                position,
                warning,
            });
        }
        self.seen_events = status.events_total();
        let mut heat = Vec::new();
        let nearest = self.contact_events(fleet, &mut events, &mut heat);
        self.safety_events(fleet, status, &mut events);
        traffic_events(fleet, &mut events);
        let traffic = traffic_view(fleet);
        heat.extend(traffic.stuck.iter().map(|s| HeatEvent {
            kind: HeatKind::Stuck,
            at: s.1,
            weight: world.dt as f32,
        }));

        let per_robot: Vec<_> = (0..fleet.robots()).map(|i| fleet.metrics(i)).collect();
        let mut fleet_metrics = vec![
            ("live_agents", status.alive as f64),
            ("planner_p99_us", status.planner_p99_us),
            ("stale_commands", status.stale_commands as f64),
            (
                "yielding_robots",
                status
                    .safety
                    .iter()
                    .filter(|z| **z == SafetyZone::Yield)
                    .count() as f64,
            ),
            (
                "protective_robots",
                status
                    .safety
                    .iter()
                    .filter(|z| **z == SafetyZone::Protective)
                    .count() as f64,
            ),
        ];
        // The fleet-wide figures, as the newest metrics frame summarised them.
        if let Some(s) = &status.summary {
            fleet_metrics.extend([
                ("svr", s.svr),
                ("collision_rate", s.collision_rate),
                ("social_force", s.social_force),
                ("tasks_per_minute", s.tasks_per_min()),
                ("robot_caused_contacts", s.robot_caused_contacts as f64),
                ("person_caused_contacts", s.person_caused_contacts as f64),
                ("robot_robot_contacts", s.robot_robot_contacts as f64),
                ("total_contacts", s.total_contacts as f64),
                ("stuck_robots", s.stuck_robots as f64),
                ("deadlocks", s.traffic.deadlocks as f64),
                ("gridlocks", s.traffic.gridlocks as f64),
                ("stuck_s_policy", s.stuck_causes.policy_s),
                ("stuck_s_person", s.stuck_causes.person_s),
                ("stuck_s_robot", s.stuck_causes.robot_s),
                ("stuck_s_layer", s.stuck_causes.layer_s),
                ("stuck_s_planner", s.stuck_causes.planner_s),
            ]);
            if let Some(e) = s.efficiency() {
                fleet_metrics.push(("efficiency_pct", 100.0 * e));
            }
            if s.min_human_distance_m.is_finite() {
                fleet_metrics.push(("min_human_distance", s.min_human_distance_m));
            }
        }
        if let Some(policy) = fleet.traffic_policy() {
            let waiting = (0..fleet.robots())
                .filter(|&i| {
                    fleet.job(i).is_some()
                        && matches!(
                            policy.constraint(i),
                            Constraint::Hold { .. } | Constraint::Queue { .. }
                        )
                })
                .count();
            fleet_metrics.push(("waiting_robots", waiting as f64));
        }
        if let Some(impact) = fleet.human_impact() {
            // Where people lost time to robots, once per finished window.
            for w in impact.windows_since(self.seen_windows) {
                heat.extend(w.delay_at.iter().map(|&(at, delay)| HeatEvent {
                    kind: HeatKind::PeopleDelay,
                    at: p(at),
                    weight: delay as f32,
                }));
            }
            self.seen_windows = impact.windows_closed();
        }
        let impact = fleet.human_impact().and_then(|i| i.latest());
        if let Some(w) = impact {
            fleet_metrics.push(("human_delay_s_per_min", w.delay_per_minute()));
            fleet_metrics.push(("human_extra_path_m_per_min", w.extra_path_per_minute()));
        }
        let robot_rows = self.robot_rows(fleet, &per_robot, &nearest, |i| {
            let w = impact?;
            (w.delay_s > 0.0).then(|| w.robot_delay_s.get(i).copied().unwrap_or(0.0) / w.delay_s)
        });
        let robot_metrics = per_robot
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let mut series = vec![
                    ("svr", m.svr),
                    ("collision_rate", m.collision_rate),
                    ("social_force", m.social_force),
                ];
                if m.min_human_distance_m.is_finite() {
                    series.push(("min_human_distance", m.min_human_distance_m));
                }
                if let Some((delay, extra)) = impact.and_then(|w| w.robot_per_minute(i)) {
                    series.push(("human_delay_s_per_min", delay));
                    series.push(("human_extra_path_m_per_min", extra));
                }
                (i as u32, series)
            })
            .collect();
        self.dashboard.send(Frame {
            tick: status.tick,
            sim_time: status.sim_time,
            humans: crowd.positions.iter().map(|&v| p(v)).collect(),
            human_groups: groups,
            human_radius: world.humans.radius as f32,
            robots,
            intents,
            fields: safety_fields(fleet, status),
            fans: status
                .fans
                .iter()
                .flatten()
                .filter(|f| !fleet.is_held(f.robot_id as usize))
                .map(|f| FanView {
                    robot: f.robot_id,
                    candidates: f
                        .candidates
                        .iter()
                        .map(|c| {
                            let path = c.path.iter().map(|q| [q.0 as f32, q.1 as f32]).collect();
                            (path, c.survival as f32)
                        })
                        .collect(),
                })
                .collect(),
            events,
            traffic: Some(traffic),
            fleet_metrics,
            robot_metrics,
            robot_rows,
            heat,
        });
    }
}
