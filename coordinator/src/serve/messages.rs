//! What the coordinator sends: each robot's observation and traffic constraint, the static
//! map served to agents, and the fleet metrics frame.

use super::links::Link;
use super::status::Status;
use agent::map::{LocalMap, StaticMap};
use agent::runtime::wire;
use schemas::{
    FleetMetrics, Observation, RobotRow, StationMsg, StuckCausesMsg, TaskRef, TaskStage,
    TrafficConstraint, TrafficMsg,
};
use world_sim::efficiency::FreeFlow;
use world_sim::fleet::{Fleet, FleetSummary, Stage};
use world_sim::traffic_policy::Constraint;

/// Robot `i`'s observation with sequence number `seq`, naming the served map's version.
pub fn observation(fleet: &mut Fleet, i: usize, seq: u64, map_version: u32) -> Observation {
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
        map_version,
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
        real: false,
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

/// The site's static map, stations and safety-layer setting (`layer`) as served by the
/// `…/map` queryable. Its version is derived from its content ([`map_version`]): a
/// coordinator restarted on another site or scenario serves another version, and agents fetch
/// the new map.
pub fn map_message(fleet: &Fleet, layer: &agent::safety::SafetyParams) -> schemas::MapMsg {
    let mut msg = unversioned_map(fleet);
    let changes = layer.changes();
    msg.safety_layer = (!changes.is_empty()).then_some(changes);
    msg.map_version = map_version(&msg);
    msg
}

/// The version of `msg`'s content: FNV-1a (32 bits) of the message encoded with version 0,
/// never 0 (agents that hold no map yet compare against nothing).
pub fn map_version(msg: &schemas::MapMsg) -> u32 {
    let bytes = schemas::encode(&schemas::MapMsg {
        map_version: 0,
        ..msg.clone()
    });
    let hash = bytes.iter().fold(0x811c_9dc5_u32, |h, &b| {
        (h ^ u32::from(b)).wrapping_mul(0x0100_0193)
    });
    hash.max(1)
}

fn unversioned_map(fleet: &Fleet) -> schemas::MapMsg {
    let site = fleet.site();
    let stations = site
        .stations
        .iter()
        .map(|s| StationMsg {
            id: s.id as u32,
            p: wire::p2(s.position),
        })
        .collect();
    let map: &StaticMap = fleet.robot_map();
    let mut msg = wire::map_to_wire(map, 0, stations, [site.origin, site.origin + site.size]);
    msg.turn_places = fleet.world.turn_places().map(|places| {
        places
            .into_iter()
            .map(|(lo, hi)| [wire::p2(lo), wire::p2(hi)])
            .collect()
    });
    msg
}

/// The fleet metrics frame published once per simulated second: `summary`'s fleet-wide
/// figures, and a row per robot.
pub(super) fn metrics_frame(
    fleet: &Fleet,
    summary: &FleetSummary,
    links: &[Link],
    status: &Status,
) -> FleetMetrics {
    let per_robot: Vec<RobotRow> = (0..fleet.robots())
        .map(|i| {
            let m = fleet.metrics(i);
            RobotRow {
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
            }
        })
        .collect();
    let causes = &summary.stuck_causes;
    FleetMetrics {
        tick: status.tick,
        sim_time: summary.seconds,
        robots: summary.robots as u32,
        alive: links.iter().filter(|l| l.alive).count() as u32,
        humans: fleet.world.humans.crowd.len() as u32,
        tasks_done: summary.tasks,
        collision_rate: summary.collision_rate,
        svr: summary.svr,
        near_misses: summary.near_miss_steps,
        robot_caused_contacts: summary.robot_caused_contacts,
        person_caused_contacts: summary.person_caused_contacts,
        dropped_commands: status.stale_commands,
        deadlocks: summary.traffic.deadlocks,
        stuck_robots: summary.stuck_robots as u32,
        stuck_robot_s: summary.traffic.stuck_robot_s,
        per_robot,
        efficiency: summary.efficiency(),
        free_flow_tasks_per_min: summary.free_flow.as_ref().map(FreeFlow::tasks_per_min),
        gridlocks: summary.traffic.gridlocks,
        stuck_causes: StuckCausesMsg {
            policy_s: causes.policy_s,
            person_s: causes.person_s,
            robot_s: causes.robot_s,
            layer_s: causes.layer_s,
            planner_s: causes.planner_s,
        },
        robot_robot_contacts: summary.robot_robot_contacts,
        wall_contacts: summary.wall_contacts,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use world_sim::scenario::Scenario;

    fn version(name: &str) -> u32 {
        let scenario = Scenario::builtin(name).expect("built in");
        map_message(
            &Fleet::new(&scenario).expect("a warehouse"),
            &scenario.robot.safety_layer,
        )
        .map_version
    }

    /// The map's version follows its content: the same site gives the same version, another
    /// site another one (an agent that outlives a coordinator restarted on another scenario
    /// then fetches the new map).
    #[test]
    fn the_map_version_follows_the_map() {
        let (a, b) = (version("warehouse"), version("warehouse-narrow"));
        assert_eq!(a, version("warehouse"));
        assert_ne!(a, b);
        assert!(a != 0 && b != 0);
        let scenario = Scenario::builtin("warehouse").expect("built in");
        let msg = map_message(
            &Fleet::new(&scenario).expect("a warehouse"),
            &scenario.robot.safety_layer,
        );
        assert_eq!(map_version(&msg), msg.map_version);
        let mut moved = msg.clone();
        moved.bounds[1].0 += 0.01;
        assert_ne!(map_version(&moved), msg.map_version);
    }

    /// Agents are served the places where people turn that in-process fleets mark
    /// (`world_sim::episode::fleet_guards`): a warehouse's stations, none in the hallway fleet.
    #[test]
    fn agents_are_served_the_places_where_people_turn() {
        let served = |name: &str| {
            let scenario = Scenario::builtin(name).expect("built in");
            let fleet = Fleet::new(&scenario).expect("a fleet site");
            let msg = map_message(&fleet, &scenario.robot.safety_layer);
            (
                agent::runtime::wire::turn_places_from_wire(&msg),
                fleet.world.turn_places(),
            )
        };
        let (places, in_process) = served("warehouse");
        assert_eq!(places, in_process);
        assert!(places.is_some_and(|p| !p.is_empty()));
        assert_eq!(served("hallway-fleet"), (None, None));
    }

    /// Agents are served the layer in-process fleets run (`Scenario::robot.safety_layer`):
    /// the site's changes from the defaults, read back whole; none on a site that keeps the
    /// defaults, and another map version when the setting changes.
    #[test]
    fn agents_are_served_the_sites_safety_layer() {
        let mut scenario = Scenario::builtin("hallway-fleet").expect("built in");
        let fleet = Fleet::new(&scenario).expect("a fleet site");
        let read = |msg: &schemas::MapMsg| {
            agent::safety::SafetyParams::default()
                .with_overrides(msg.safety_layer.as_deref().unwrap_or(""))
                .expect("a valid setting")
        };
        let msg = map_message(&fleet, &scenario.robot.safety_layer);
        assert_eq!(read(&msg), scenario.robot.safety_layer);
        let open = Scenario::builtin("open-space").expect("built in");
        assert_ne!(
            open.robot.safety_layer,
            agent::safety::SafetyParams::default()
        );
        let served = map_message(&fleet, &open.robot.safety_layer);
        assert_eq!(read(&served), open.robot.safety_layer);
        assert_ne!(served.map_version, msg.map_version);
        scenario.robot.safety_layer = agent::safety::SafetyParams::default();
        let bare = map_message(&fleet, &scenario.robot.safety_layer);
        assert_eq!(bare.safety_layer, None);
    }

    /// On a floor plan with a keep-out mask, agents are served the robots' map: the zone is
    /// walled in it (no line of sight across it), not in the world's; and the dashboard
    /// draws the zone's edges apart from the walls.
    #[test]
    fn agents_are_served_the_keep_out_zones() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../world-sim/scenarios/aws-small-warehouse-keepout.toml"
        );
        let text = std::fs::read_to_string(path).expect("the sample scenario");
        let scenario = Scenario::from_toml(&text, path).expect("valid");
        let fleet = Fleet::new(&scenario).expect("a fleet site");
        let served =
            agent::runtime::wire::map_from_wire(&map_message(&fleet, &scenario.robot.safety_layer))
                .expect("decodes");
        let (west, east) = (agent::math::vec2(-2.5, -4.0), agent::math::vec2(2.0, -4.0));
        assert!(!served.line_of_sight(west, east));
        assert!(fleet.world.map.line_of_sight(west, east));
        let bare = Scenario::builtin("aws-small-warehouse").expect("built in");
        assert_ne!(
            map_message(&fleet, &scenario.robot.safety_layer).map_version,
            map_message(
                &Fleet::new(&bare).expect("a fleet site"),
                &bare.robot.safety_layer
            )
            .map_version
        );
        let drawn = crate::serve::dashboard::map_frame(&fleet).keepout;
        assert!(!drawn.is_empty());
        // Every edge drawn lies on the zone's outline (x -1.5 to 1.5, y -5 to -3), within the
        // one-cell simplification.
        for [a, b] in drawn {
            for q in [a, b] {
                let (x, y) = (f64::from(q[0]), f64::from(q[1]));
                let off_x = (x.abs() - 1.5).abs();
                let off_y = ((y + 4.0).abs() - 1.0).abs();
                assert!(
                    off_x.min(off_y) < 0.06 && x.abs() < 1.56 && (y + 4.0).abs() < 1.06,
                    "{q:?}"
                );
            }
        }
    }
}
