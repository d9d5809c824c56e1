//! What the coordinator sends: each robot's observation and traffic constraint, the static
//! map served to agents, and the fleet metrics frame.

use super::links::Link;
use super::status::Status;
use agent::map::{LocalMap, StaticMap};
use agent::math::{Real, vec2};
use agent::runtime::wire;
use schemas::{
    FleetMetrics, Observation, RobotRow, StationMsg, TaskRef, TaskStage, TrafficConstraint,
    TrafficMsg,
};
use world_sim::fleet::{Fleet, Stage};
use world_sim::traffic_policy::Constraint;

/// Version of the map the coordinator serves (the generated map never changes during a run).
pub const MAP_VERSION: u32 = 1;

/// Robot `i`'s observation with sequence number `seq`.
pub fn observation(fleet: &mut Fleet, i: usize, seq: u64) -> Observation {
    let (ego, seen) = fleet.observe(i);
    let task = fleet.job(i).map(|job| TaskRef {
        task_id: job.task.id,
        stage: match job.stage {
            Stage::ToPick => TaskStage::Pick,
            Stage::ToDrop => TaskStage::Drop,
        },
    });
    Observation {
        robot_id: i as u32,
        seq,
        sim_time: fleet.world.time,
        dt: fleet.world.dt,
        map_version: MAP_VERSION,
        p: wire::p2(ego.position),
        heading: ego.heading,
        vel: wire::p2(ego.velocity),
        yaw_rate: ego.yaw_rate,
        radius: ego.radius,
        goal: fleet.goal(i).map(wire::p2),
        task,
        neighbours: seen.iter().map(wire::perceived).collect(),
        visibility: fleet
            .world
            .visibility(i, &mut LocalMap::default())
            .as_ref()
            .map(wire::visibility_to_wire),
    }
}

/// What the traffic policy asks of robot `i` at `tick`, when the policy is on.
pub fn traffic_message(fleet: &Fleet, i: usize, tick: u64) -> Option<TrafficMsg> {
    let policy = fleet.traffic_policy()?;
    let (constraint, goal) = match policy.constraint(i) {
        Constraint::Free => (TrafficConstraint::Free, None),
        Constraint::Lane(p) => (TrafficConstraint::Lane, Some(p)),
        Constraint::Hold { at, .. } => (TrafficConstraint::Hold, Some(at)),
        Constraint::Queue { at, .. } => (TrafficConstraint::Queue, Some(at)),
        Constraint::Retreat(p) => (TrafficConstraint::Retreat, Some(p)),
        Constraint::GiveWay(p) => (TrafficConstraint::GiveWay, Some(p)),
    };
    let waiting = match policy.constraint(i) {
        Constraint::Hold { segment, .. } => Some(segment),
        _ => None,
    };
    let held = (0..policy.segments().len()).find(|&s| policy.reservation(s).holders.contains(&i));
    let segment = waiting.or(held);
    let queued = match policy.constraint(i) {
        Constraint::Queue { station, .. } => Some(station),
        _ => None,
    };
    let holds_station = (0..fleet.site().stations.len())
        .find(|&s| policy.station_line(s).is_some_and(|l| l.holder == Some(i)));
    Some(TrafficMsg {
        tick,
        sim_time: fleet.world.time,
        constraint,
        goal: goal.map(wire::p2),
        segment: segment.map(|s| s as u32),
        direction: held.and_then(|s| policy.reservation(s).dir),
        station: queued.or(holds_station).map(|s| s as u32),
    })
}

/// The site's static map and stations as served by the `…/map` queryable.
pub fn map_message(fleet: &Fleet) -> schemas::MapMsg {
    let site = fleet.site();
    let stations = site
        .stations
        .iter()
        .map(|s| StationMsg {
            id: s.id as u32,
            p: wire::p2(s.position),
        })
        .collect();
    let map: &StaticMap = &fleet.world.map;
    wire::map_to_wire(map, MAP_VERSION, stations, [vec2(0.0, 0.0), site.size])
}

/// The fleet metrics frame published once per simulated second.
pub(super) fn metrics_frame(fleet: &Fleet, links: &[Link], status: &Status) -> FleetMetrics {
    let metrics: Vec<_> = (0..fleet.robots()).map(|i| fleet.metrics(i)).collect();
    let per_robot: Vec<RobotRow> = metrics
        .iter()
        .enumerate()
        .map(|(i, m)| RobotRow {
            robot_id: i as u32,
            alive: links[i].alive,
            tasks_done: fleet.tasks_done(i),
            collision_rate: m.collision_rate,
            svr: m.svr,
            min_human_distance: m
                .min_human_distance_m
                .is_finite()
                .then_some(m.min_human_distance_m),
            social_force: m.social_force,
            stuck: fleet.traffic().is_stuck(i),
            waits_on: fleet
                .traffic()
                .waits_on(i)
                .iter()
                .map(|&j| j as u32)
                .collect(),
        })
        .collect();
    let traffic = fleet.traffic().totals();
    let mean = |f: &dyn Fn(&RobotRow) -> Real| {
        if per_robot.is_empty() {
            0.0
        } else {
            per_robot.iter().map(f).sum::<Real>() / per_robot.len() as Real
        }
    };
    FleetMetrics {
        tick: status.tick,
        sim_time: fleet.world.time,
        robots: fleet.robots() as u32,
        alive: links.iter().filter(|l| l.alive).count() as u32,
        humans: fleet.world.humans.crowd.len() as u32,
        tasks_done: status.tasks_done,
        collision_rate: mean(&|r| r.collision_rate),
        svr: mean(&|r| r.svr),
        near_misses: metrics.iter().map(|m| m.robot_near_misses).sum(),
        robot_caused_contacts: metrics.iter().map(|m| m.robot_caused_contacts).sum(),
        person_caused_contacts: metrics.iter().map(|m| m.person_caused_contacts).sum(),
        dropped_commands: status.stale_commands,
        deadlocks: traffic.deadlocks,
        stuck_robots: per_robot.iter().filter(|r| r.stuck).count() as u32,
        stuck_robot_s: traffic.stuck_robot_s,
        per_robot,
    }
}
