//! The traffic policy's tests: one-way segments, station lines, keep right.

use super::stations::back_along;
use super::*;
use crate::scenario::Scenario;
use crate::traffic::TrafficParams;
use crate::warehouse::StationKind;

fn narrow() -> (Site, Real) {
    let s = Scenario::builtin("warehouse-narrow").expect("valid");
    let site = Site::generate(&s.warehouse.expect("layout"));
    (site, s.robot.radius_m)
}

/// The narrow warehouse's aisles are one-way segments; its corridors and cross-aisles are
/// not. The default warehouse (2.5 m aisles) has none.
#[test]
fn narrow_aisles_are_segments_and_wide_ones_are_not() {
    let (site, radius) = narrow();
    let policy = TrafficPolicy::new(&site, 1, radius, PolicyParams::default());
    // 5 aisles between 6 rows, 4 blocks each.
    assert_eq!(policy.segments().len(), 20);
    let s = Scenario::builtin("warehouse").expect("valid");
    let wide = Site::generate(&s.warehouse.expect("layout"));
    let policy = TrafficPolicy::new(&wide, 1, s.robot.radius_m, PolicyParams::default());
    assert!(policy.segments().is_empty());
}

fn step(policy: &mut TrafficPolicy, now: Real, robots: &[PolicyRobot<'_>]) -> Vec<PolicyEvent> {
    let monitor = TrafficMonitor::new(robots.len(), TrafficParams::default());
    policy.step(now, robots, &monitor)
}

/// Robots at `xs` along the hallway's centre line (y = 1.5), each on `route` to `station`.
fn bound_for<const N: usize>(
    xs: [Real; N],
    route: &[Vec2],
    station: usize,
) -> [PolicyRobot<'_>; N] {
    xs.map(|x| PolicyRobot {
        position: vec2(x, 1.5),
        route,
        station: Some(station),
        held: false,
    })
}

/// Views of `robots` standing still, each with a task (leg `i`, `remaining[i]` m left).
fn standing(
    robots: &[PolicyRobot<'_>],
    radius: Real,
    remaining: &[Real],
) -> Vec<crate::traffic::RobotView<'static>> {
    use crate::traffic::{RobotView, TaskView};
    robots
        .iter()
        .zip(remaining)
        .enumerate()
        .map(|(i, (r, &remaining_m))| RobotView {
            position: r.position,
            velocity: vec2(0.0, 0.0),
            radius,
            task: Some(TaskView {
                leg: i as u64,
                waypoint: r.route[0],
                remaining_m,
            }),
            intent: &[],
        })
        .collect()
}

/// Two robots head for the same segment from its two ends: the first to ask gets it, the
/// other waits short of the mouth, outside the segment and clear of the crossing, until
/// the first has left; a third behind the first, going the same way, does not get in
/// while the other way waits.
#[test]
fn one_direction_at_a_time_and_the_waiting_side_goes_next() {
    let (site, radius) = narrow();
    let mut policy = TrafficPolicy::new(&site, 3, radius, PolicyParams::default());
    let s = policy.segments()[0];
    let (west, east) = (vec2(s.x0 - 1.0, s.y), vec2(s.x1 + 1.0, s.y));
    let route_east = [vec2(s.x1 + 1.5, s.y)];
    let route_west = [vec2(s.x0 - 1.5, s.y)];
    let mut robots = [
        PolicyRobot {
            position: west,
            route: &route_east,
            station: None,
            held: false,
        },
        PolicyRobot {
            position: east + vec2(3.0, 0.0),
            route: &route_west,
            station: None,
            held: false,
        },
        PolicyRobot {
            position: west - vec2(6.0, 0.0),
            route: &route_east,
            station: None,
            held: false,
        },
    ];
    let events = step(&mut policy, 0.1, &robots);
    assert!(events.contains(&PolicyEvent::Granted {
        robot: 0,
        segment: s.id,
        dir: 1
    }));
    assert_eq!(policy.constraint(0), Constraint::Free);
    // Robot 1 comes within reach of the east mouth and must wait.
    robots[1].position = east;
    step(&mut policy, 0.2, &robots);
    let Constraint::Hold { at, segment } = policy.constraint(1) else {
        panic!("robot 1 should wait: {:?}", policy.constraint(1));
    };
    assert_eq!(segment, s.id);
    assert!(!s.contains(at) && at.x > s.x1, "{at:?}");
    // Robot 0 enters; robot 2 comes up behind it, the same way: not let in while robot 1
    // waits the other way.
    robots[0].position = vec2(s.x0 + 2.0, s.y);
    robots[2].position = west;
    step(&mut policy, 0.3, &robots);
    assert!(matches!(policy.constraint(2), Constraint::Hold { .. }));
    assert_eq!(policy.reservation(s.id).holders, vec![0]);
    assert_eq!(policy.wait_edges(), vec![(1, 0), (2, 0)]);
    // Robot 0 leaves by the far end: the segment turns to robot 1.
    robots[0].position = vec2(s.x1 + 1.2, s.y + 1.0);
    let events = step(&mut policy, 0.4, &robots);
    assert!(events.contains(&PolicyEvent::Released {
        robot: 0,
        segment: s.id
    }));
    assert!(events.contains(&PolicyEvent::Granted {
        robot: 1,
        segment: s.id,
        dir: -1
    }));
    assert!(matches!(policy.constraint(2), Constraint::Hold { .. }));
    // Alone in it with nobody near, robot 1 may leave by either end (`alone_exit_clear_m`).
    assert_eq!(policy.exit_of(1), None);
}

/// After a pick, a robot leaves its segment by the far end of the flow; when it is the
/// segment's only holder and nobody is within `alone_exit_clear_m` of the segment or its
/// mouths, by either end (its shortest route); not with the rule off.
#[test]
fn a_robot_alone_in_its_aisle_with_nobody_near_may_leave_by_either_end() {
    let (site, radius) = narrow();
    let s = TrafficPolicy::new(&site, 1, radius, PolicyParams::default()).segments()[0];
    let route = [vec2(s.x1 + 1.5, s.y)];
    let inside = |x: Real| PolicyRobot {
        position: vec2(x, s.y),
        route: &route,
        station: None,
        held: false,
    };
    // The way out of robot 0 at x0 + 6 m, eastbound, with `others` in the segment behind it
    // and `people` about.
    let exit = |params: PolicyParams, others: usize, people: &[Vec2]| {
        let robots: Vec<_> = (0..=others)
            .map(|k| inside(s.x0 + 6.0 - 2.0 * k as Real))
            .collect();
        let mut policy = TrafficPolicy::new(&site, robots.len(), radius, params);
        policy.set_people(people.iter().map(|&q| (q, vec2(0.0, 0.0))));
        step(&mut policy, 0.0, &robots);
        policy.exit_of(0)
    };
    let params = PolicyParams::default();
    assert_eq!(params.alone_exit_clear_m, 3.0);
    let flow_end = Some(s.ends.1);
    assert_eq!(exit(params, 0, &[]), None);
    assert_eq!(exit(params, 1, &[]), flow_end, "another robot holds it too");
    // Someone 2.5 m beyond the west mouth, or in the aisle: by the far end.
    assert_eq!(exit(params, 0, &[vec2(s.x0 - 2.5, s.y)]), flow_end);
    assert_eq!(exit(params, 0, &[vec2(s.x0 + 9.0, s.y)]), flow_end);
    // Someone 3.5 m beyond the east mouth: nobody near.
    assert_eq!(exit(params, 0, &[vec2(s.x1 + 3.5, s.y)]), None);
    let off = PolicyParams {
        alone_exit_clear_m: 0.0,
        ..params
    };
    assert_eq!(exit(off, 0, &[]), flow_end);
    // A snapshot keeps the people it saw: a pick just after a restore leaves the same way.
    let mut policy = TrafficPolicy::new(&site, 1, radius, params);
    policy.set_people([(vec2(s.x0 - 2.5, s.y), vec2(0.0, 0.0))]);
    step(&mut policy, 0.0, &[inside(s.x0 + 6.0)]);
    let mut bytes = Vec::new();
    rmp_serde::encode::write(&mut bytes, &policy).expect("encodes");
    let restored: TrafficPolicy = rmp_serde::from_slice(&bytes).expect("decodes");
    assert_eq!(restored.exit_of(0), flow_end);
    assert!(
        TrafficPolicy::new(
            &site,
            1,
            radius,
            PolicyParams {
                people_turn_after_s: 0.0,
                ..params
            }
        )
        .watches_people()
    );
}

/// One robot at a time at a station: the first to ask (lower index on a tie) drives to
/// it, the others wait in line on the right-hand lane at distinct places, and the station
/// passes to the oldest in line when its holder's leg ends there. Stations inside a
/// one-way segment have no line (the segment already admits one direction).
#[test]
fn one_robot_at_a_time_at_a_station_and_the_rest_in_line() {
    let site = Site::hallway(40.0, 3.0, 3);
    let dock = site.stations[0];
    assert_eq!(dock.position, vec2(1.0, 0.5));
    let mut policy = TrafficPolicy::new(&site, 3, 0.3, PolicyParams::default());
    let route = [dock.position];
    let mut robots = bound_for([5.0, 6.5, 6.9], &route, dock.id);
    let events = step(&mut policy, 0.1, &robots);
    assert!(events.contains(&PolicyEvent::StationGranted {
        robot: 0,
        station: dock.id
    }));
    assert!(policy.constraint(0).goal().is_none_or(|g| g.x < 5.0));
    let place = |policy: &TrafficPolicy, i: usize| match policy.constraint(i) {
        Constraint::Queue { at, station } => {
            assert_eq!(station, dock.id);
            at
        }
        c => panic!("robot {i} should wait in line: {c:?}"),
    };
    let (first, second) = (place(&policy, 1), place(&policy, 2));
    // Westbound: the right-hand lane is a quarter of the width north of the centre line.
    assert!((first.y - 2.25).abs() < 1e-9 && (second.y - 2.25).abs() < 1e-9);
    assert!(
        ((first - dock.position).norm() - 3.0).abs() < 0.8,
        "{first:?}"
    );
    assert!(second.x - first.x >= 1.0 - 1e-9, "{first:?} {second:?}");
    assert_eq!(policy.wait_edges(), vec![(1, 0), (2, 0)]);
    // Robot 0 reaches the dock, its leg ends, its next leg goes elsewhere: the dock is not
    // granted again before it has left.
    let far = [site.stations[3].position];
    robots[0].position = dock.position;
    robots[0].route = &far;
    robots[0].station = Some(3);
    let events = step(&mut policy, 0.2, &robots);
    assert!(events.is_empty(), "{events:?}");
    assert_eq!(
        policy.station_line(dock.id).and_then(|l| l.leaving),
        Some(0)
    );
    assert_eq!(policy.wait_edges(), vec![(1, 0), (2, 0)]);
    robots[0].position = dock.position + vec2(2.5, 0.5);
    let events = step(&mut policy, 0.3, &robots);
    assert!(events.contains(&PolicyEvent::StationGranted {
        robot: 1,
        station: dock.id
    }));
    assert_eq!(policy.station_line(dock.id).and_then(|l| l.holder), Some(1));
    assert!(((place(&policy, 2) - dock.position).norm() - 3.0).abs() < 0.8);
    // In the narrow warehouse, docks have lines and pick faces in aisles do not.
    let (narrow, radius) = narrow();
    let policy = TrafficPolicy::new(&narrow, 1, radius, PolicyParams::default());
    for st in &narrow.stations {
        let in_segment = policy.segments().iter().any(|s| s.contains(st.position));
        assert_eq!(policy.station_line(st.id).is_none(), in_segment, "{st:?}");
        if st.kind == crate::warehouse::StationKind::Dock {
            assert!(!in_segment);
        }
    }
}

/// A held robot (lost, or without an agent) is in no station line: the station its lost
/// holder was bound for, or was leaving, passes to the robot waiting in line, and the held
/// robot does not join a line while held. Released, it asks again like anyone.
#[test]
fn a_held_robot_keeps_no_station_from_the_others() {
    let site = Site::hallway(40.0, 3.0, 3);
    let dock = site.stations[0];
    let route = [dock.position];
    // The holder is lost on its way to the dock.
    let mut policy = TrafficPolicy::new(&site, 2, 0.3, PolicyParams::default());
    let mut robots = bound_for([5.0, 6.5], &route, dock.id);
    step(&mut policy, 0.1, &robots);
    assert_eq!(policy.station_line(dock.id).and_then(|l| l.holder), Some(0));
    assert!(matches!(policy.constraint(1), Constraint::Queue { .. }));
    robots[0].held = true;
    let events = step(&mut policy, 0.2, &robots);
    assert!(
        events.contains(&PolicyEvent::StationGranted {
            robot: 1,
            station: dock.id
        }),
        "{events:?}"
    );
    assert!(policy.wait_edges().is_empty(), "{:?}", policy.wait_edges());
    // Released, it is in line again: nearer to the dock than the holder, it takes the dock
    // over (as anyone in line ahead of the holder does) and the holder waits.
    robots[0].held = false;
    step(&mut policy, 0.3, &robots);
    assert_eq!(policy.station_line(dock.id).and_then(|l| l.holder), Some(0));
    assert!(matches!(policy.constraint(1), Constraint::Queue { .. }));
    // A robot lost where the first place in line is: the place moves back past it.
    let mut policy = TrafficPolicy::new(&site, 3, 0.3, PolicyParams::default());
    let mut robots = bound_for([5.0, 6.5, 20.0], &route, dock.id);
    robots[2].station = None;
    step(&mut policy, 0.1, &robots);
    let Constraint::Queue { at: first, .. } = policy.constraint(1) else {
        panic!("robot 1 waits in line: {:?}", policy.constraint(1));
    };
    robots[2].position = first;
    robots[2].held = true;
    step(&mut policy, 0.2, &robots);
    let Constraint::Queue { at: moved, .. } = policy.constraint(1) else {
        panic!("robot 1 waits in line: {:?}", policy.constraint(1));
    };
    // A body length (0.6 m) plus the gap (0.4 m) from it.
    assert!((moved - first).norm() >= 1.0 - 1e-9, "{first:?} {moved:?}");
    // The holder is lost beside the dock it has just left: the dock is granted at once,
    // not once it has moved away (it will not).
    let mut policy = TrafficPolicy::new(&site, 2, 0.3, PolicyParams::default());
    let far = [site.stations[3].position];
    let mut robots = bound_for([5.0, 6.5], &route, dock.id);
    step(&mut policy, 0.1, &robots);
    robots[0].position = dock.position;
    robots[0].route = &far;
    robots[0].station = Some(3);
    step(&mut policy, 0.2, &robots);
    assert_eq!(
        policy.station_line(dock.id).and_then(|l| l.leaving),
        Some(0)
    );
    robots[0].held = true;
    let events = step(&mut policy, 0.3, &robots);
    assert!(
        events.contains(&PolicyEvent::StationGranted {
            robot: 1,
            station: dock.id
        }),
        "{events:?}"
    );
}

/// A robot at `position` driving along `route`, with no station and not held.
fn on_route(position: Vec2, route: &[Vec2]) -> PolicyRobot<'_> {
    PolicyRobot {
        position,
        route,
        station: None,
        held: false,
    }
}

/// A held (lost) robot standing on the lane ahead ends the lane rule for the robot behind it,
/// which then drives to its waypoint and round it; one on the other lane, or behind, does not.
#[test]
fn a_held_robot_on_the_lane_ahead_is_driven_round() {
    let (site, radius) = narrow();
    let policy = TrafficPolicy::new(&site, 2, radius, PolicyParams::default());
    // The bottom corridor driving west, as in `keep_right_in_wide_corridors`: the lane is
    // y = 2.25 and the goal leads 3 m.
    let route = [vec2(5.0, 1.5)];
    let r = on_route(vec2(30.0, 2.25), &route);
    for (held, lane) in [
        (vec2(28.0, 2.25), false),
        (vec2(26.5, 2.0), false),
        // Past the lookahead and a body length.
        (vec2(26.0, 2.25), true),
        // On the oncoming lane.
        (vec2(28.0, 0.75), true),
        // Behind.
        (vec2(31.0, 2.25), true),
    ] {
        assert_eq!(
            policy.lane(&r, &[held]).is_some(),
            lane,
            "held robot at {held:?}"
        );
    }
}

/// In a corridor wide enough for two, the goal leads along the right-hand lane, and more
/// steeply toward it from the oncoming lane.
#[test]
fn keep_right_in_wide_corridors() {
    let (site, radius) = narrow();
    let policy = TrafficPolicy::new(&site, 1, radius, PolicyParams::default());
    // The bottom corridor (3 m, centre y = 1.5), driving west: right is +y, 0.25 × 3 m.
    let route = [vec2(5.0, 1.5)];
    let r = on_route(vec2(30.0, 1.5), &route);
    let lane = policy.lane(&r, &[]).expect("a lane");
    assert!((lane - vec2(27.0, 2.25)).norm() < 1e-9, "{lane:?}");
    // In the oncoming lane (across the centre line), it changes lanes first: the goal leads
    // by 1 m.
    let across = on_route(vec2(30.0, 0.6), &route);
    let lane = policy.lane(&across, &[]).expect("a lane");
    assert!((lane - vec2(29.0, 2.25)).norm() < 1e-9, "{lane:?}");
    // Close to the waypoint the goal is the waypoint itself.
    let near = on_route(vec2(8.0, 1.5), &route);
    assert_eq!(policy.lane(&near, &[]), None);
}

/// A robot inside a segment against its flow (pushed in, or sent back by a new route) stops
/// further entries until it is out; while a robot of the flow comes at it, it is turned
/// round to leave by the end the flow leads to; once only it is left, the segment turns to
/// its way.
#[test]
fn a_robot_against_the_flow_stops_entries_and_turns_round() {
    let (site, radius) = narrow();
    let mut policy = TrafficPolicy::new(&site, 3, radius, PolicyParams::default());
    let s = policy.segments()[0];
    let route_east = [vec2(s.x1 + 1.5, s.y)];
    let route_west = [vec2(s.x0 - 1.5, s.y)];
    let mut robots = [
        PolicyRobot {
            position: vec2(s.x0 + 2.0, s.y),
            route: &route_east,
            station: None,
            held: false,
        },
        PolicyRobot {
            position: vec2(s.x0 + 6.0, s.y),
            route: &route_west,
            station: None,
            held: false,
        },
        PolicyRobot {
            position: vec2(s.x0 - 1.0, s.y),
            route: &route_east,
            station: None,
            held: false,
        },
    ];
    step(&mut policy, 0.1, &robots);
    let res = policy.reservation(s.id);
    assert_eq!((res.dir, res.against), (Some(1), true));
    assert_eq!(res.holders, vec![0, 1]);
    assert_eq!(policy.totals().intrusions, 1);
    // Robot 2 goes the flow's way, but does not get in past robot 1.
    assert!(matches!(policy.constraint(2), Constraint::Hold { .. }));
    assert_eq!(policy.turned(1), Some(s.ends.1));
    assert_eq!(policy.turned(0), None);
    assert_eq!(policy.flow_exit(robots[1].position), Some(s.ends.1));
    // With no one of the flow ahead of it, it is left to go its way.
    robots[0].position = vec2(s.x0 + 7.0, s.y);
    step(&mut policy, 0.2, &robots);
    assert_eq!(policy.turned(1), None);
    assert!(matches!(policy.constraint(2), Constraint::Hold { .. }));
    // Robot 0 leaves: the segment turns to robot 1's way, and robot 2 keeps waiting.
    robots[0].position = vec2(s.x1 + 1.2, s.y + 1.0);
    step(&mut policy, 0.3, &robots);
    let res = policy.reservation(s.id);
    assert_eq!((res.dir, res.against), (Some(-1), false));
    assert!(matches!(policy.constraint(2), Constraint::Hold { .. }));
    assert_eq!(policy.flow_exit(robots[1].position), Some(s.ends.0));
}

/// A robot nearer its station than its place in line backs up straight along the hallway,
/// not along its slanted leg extended (which left the hallway: places at y < 0 that robots
/// drove at for good, in `hallway-fleet` seed 44 at 20 robots).
#[test]
fn places_in_line_stay_in_the_hallway() {
    let (at, heading) = back_along(vec2(34.0, 0.4), &[vec2(39.0, 2.5)], 6.0);
    assert_eq!((at, heading), (vec2(33.0, 2.5), vec2(1.0, 0.0)));
    let site = Site::hallway(40.0, 3.0, 3);
    let pick = site.stations[5];
    let mut policy = TrafficPolicy::new(&site, 5, 0.3, PolicyParams::default());
    let route = [pick.position];
    let robots: Vec<PolicyRobot<'_>> = [
        (35.5, 0.4),
        (34.8, 0.4),
        (34.0, 0.4),
        (34.0, 1.2),
        (35.0, 1.5),
    ]
    .map(|(x, y)| PolicyRobot {
        position: vec2(x, y),
        route: &route,
        station: Some(pick.id),
        held: false,
    })
    .to_vec();
    step(&mut policy, 0.1, &robots);
    for i in 0..robots.len() {
        if let Constraint::Queue { at, .. } = policy.constraint(i) {
            assert!(
                (0.3..=2.7).contains(&at.y) && at.x < pick.position.x,
                "{i}: {at:?}"
            );
        }
    }
    assert_eq!(
        policy.station_line(pick.id).map(|l| l.waiting.len()),
        Some(4)
    );
}

/// A robot refused a segment after it has come nearer than the hold point along a
/// cross-aisle backs up along the cross-aisle to the hold point, out of the crossing in front
/// of the mouth, instead of stopping where it is.
#[test]
fn a_robot_refused_late_backs_up_out_of_the_crossing() {
    let (site, radius) = narrow();
    let mut policy = TrafficPolicy::new(&site, 2, radius, PolicyParams::default());
    let s = policy.segments()[1];
    let (x, _) = site.cross_aisle(s.ends.0);
    // Robot 0 drives west through the segment; robot 1 comes up the cross-aisle at its west
    // end, 1 m below the aisle, bound east into it.
    let out_west = [vec2(x, s.y)];
    let into = [vec2(x, s.y), vec2(s.x1 + 1.5, s.y)];
    let robots = [
        PolicyRobot {
            position: vec2(s.x0 + 4.0, s.y),
            route: &out_west,
            station: None,
            held: false,
        },
        PolicyRobot {
            position: vec2(x, s.y - 1.0),
            route: &into,
            station: None,
            held: false,
        },
    ];
    step(&mut policy, 0.1, &robots);
    let Constraint::Hold { at, segment } = policy.constraint(1) else {
        panic!("robot 1 should wait: {:?}", policy.constraint(1));
    };
    assert_eq!(segment, s.id);
    // 3.5 m before the mouth along its route: 1 m up, 1.5 m across to the mouth, so 1 m
    // below where it is, on its lane.
    let to_mouth = 1.0 + (s.x0 - x);
    let expected = s.y - 1.0 - (3.5 - to_mouth);
    assert!(
        (at.y - expected).abs() < 1e-9,
        "{at:?}, expected y {expected}"
    );
    assert!(at.y < robots[1].position.y);
}

/// A robot in a station's line that comes nearer to the station than its holder takes the
/// station over, and the holder waits in line: the one let through never has to pass.
#[test]
fn a_robot_in_line_ahead_of_the_holder_takes_the_station() {
    let site = Site::hallway(40.0, 3.0, 3);
    let dock = site.stations[0];
    let mut policy = TrafficPolicy::new(&site, 2, 0.3, PolicyParams::default());
    let route = [dock.position];
    let mut robots = bound_for([5.0, 6.0], &route, dock.id);
    step(&mut policy, 0.1, &robots);
    assert_eq!(policy.station_line(dock.id).and_then(|l| l.holder), Some(0));
    // Robot 1 is pushed ahead of robot 0.
    robots[1].position = vec2(3.0, 2.2);
    let events = step(&mut policy, 0.2, &robots);
    assert!(events.contains(&PolicyEvent::StationGranted {
        robot: 1,
        station: dock.id
    }));
    let line = policy.station_line(dock.id).expect("a line");
    assert_eq!(line.holder, Some(1));
    assert_eq!(
        line.waiting.iter().map(|w| w.0).collect::<Vec<_>>(),
        vec![0]
    );
    assert!(matches!(policy.constraint(0), Constraint::Queue { .. }));
    // Jostling by less than the margin changes nothing.
    robots[0].position = vec2(3.0 - 0.2, 2.2);
    step(&mut policy, 0.3, &robots);
    assert_eq!(policy.station_line(dock.id).and_then(|l| l.holder), Some(1));
}

/// Two robots face to face in a cross-aisle, each with a robot right behind it: neither can
/// back straight off. Once the cycle has lasted [`PolicyParams::retreat_after_s`], one of
/// them backs off to a point beside or behind it where its body fits, clear of the shelves
/// and of every other robot.
#[test]
fn a_robot_with_a_robot_behind_it_backs_off_to_the_side() {
    let (site, radius) = narrow();
    let params = PolicyParams::default();
    let mut policy = TrafficPolicy::new(&site, 4, radius, params);
    let segment = policy.segments()[5];
    let (x, _) = site.cross_aisle(segment.ends.0);
    // Between two aisle mouths: the pair at y ± 0.45, the robots behind 1 m further out.
    let y = segment.y + 1.35;
    let (up, down) = ([vec2(x, y + 20.0)], [vec2(x, y - 20.0)]);
    let robots = [
        (y - 0.45, &up),
        (y + 0.45, &down),
        (y - 1.45, &up),
        (y + 1.45, &down),
    ]
    .map(|(at, route)| PolicyRobot {
        position: vec2(x, at),
        route: route.as_slice(),
        station: None,
        held: false,
    });
    let views = standing(&robots, radius, &[20.0; 4]);
    let map = site.map();
    let mut monitor = TrafficMonitor::new(4, TrafficParams::default());
    let mut retreats = Vec::new();
    for k in 1..=50 {
        let now = Real::from(k) * 0.1;
        monitor.record(now, 0.1, &views, &map, &[]);
        let events = policy.step(now, &robots, &monitor);
        retreats.extend(events.into_iter().filter_map(|e| match e {
            PolicyEvent::Retreat { robot } => Some((now, robot)),
            _ => None,
        }));
    }
    assert_eq!(monitor.cycles(), &[vec![0, 1]]);
    let [(when, robot)] = retreats[..] else {
        panic!("one retreat expected: {retreats:?}");
    };
    assert!((when - params.retreat_after_s).abs() < 0.15, "{when}");
    // Lowest priority: neither holds a segment, so the higher index.
    assert_eq!(robot, 1);
    let Constraint::Retreat(to) = policy.constraint(1) else {
        panic!("{:?}", policy.constraint(1));
    };
    let from = robots[1].position;
    assert!((to.x - from.x).abs() > 0.5, "not straight back: {to:?}");
    assert!(to.y >= from.y - 1e-9, "not toward robot 0: {to:?}");
    assert!(map.distance(&to) > radius, "{to:?} against a shelf");
    for (j, o) in robots.iter().enumerate().filter(|&(j, _)| j != 1) {
        assert!(
            (o.position - to).norm() > 2.0 * radius,
            "{to:?} on robot {j}"
        );
    }
}

/// A robot coming up to a station's line joins it at its tail: it asks for the station
/// where it can still stop short of the first free place, not only
/// [`PolicyParams::station_request_m`] before the station, and so never drives in among the
/// robots already waiting.
#[test]
fn a_robot_joins_a_long_line_at_its_tail() {
    let site = Site::hallway(40.0, 3.0, 3);
    // The dock across the right-hand lane's side of the hallway's left end.
    let dock = *site
        .stations_of(StationKind::Dock)
        .max_by(|a, b| a.position.y.total_cmp(&b.position.y))
        .expect("docks");
    let params = PolicyParams::default();
    let mut policy = TrafficPolicy::new(&site, 5, 0.3, params);
    let route = [dock.position];
    let mut robots = [4.0, 4.5, 5.0, 5.5, 12.0].map(|x| PolicyRobot {
        position: vec2(dock.position.x + x, dock.position.y),
        route: &route,
        station: Some(dock.id),
        held: false,
    });
    step(&mut policy, 0.1, &robots);
    step(&mut policy, 0.2, &robots);
    // Robot 0 has the dock; 1–3 wait 3, 4 and 5 m back; robot 4, 12 m away, drives on.
    assert_eq!(policy.station_line(dock.id).and_then(|l| l.holder), Some(0));
    let places: Vec<Real> = (1..4)
        .map(|i| match policy.constraint(i) {
            Constraint::Queue { at, .. } => at.x - dock.position.x,
            c => panic!("robot {i}: {c:?}"),
        })
        .collect();
    assert_eq!(places, vec![3.0, 4.0, 5.0]);
    assert!(!matches!(policy.constraint(4), Constraint::Queue { .. }));
    // 8.5 m away, 2.5 m short of the line's first free place (6 m back; asking 3 m short of
    // it, as the first in line asks 6 m before the station to stop 3 m before it): it joins
    // and stops there.
    robots[4].position.x = dock.position.x + 8.5;
    step(&mut policy, 0.3, &robots);
    let Constraint::Queue { at, .. } = policy.constraint(4) else {
        panic!("{:?}", policy.constraint(4));
    };
    assert!((at.x - dock.position.x - 6.0).abs() < 1e-9, "{at:?}");
    assert!(params.station_request_m < 8.5);
}

/// A bystander joining a lasting wait-for cycle (the component regroups) does not hold the
/// retreat back: two robots that have waited on each other for
/// [`PolicyParams::retreat_after_s`] are enough. (A hallway too narrow for two lanes: in a
/// two-lane one, robots of both directions give way instead.)
#[test]
fn a_bystander_joining_a_cycle_does_not_hold_the_retreat_back() {
    let site = Site::hallway(40.0, 1.3, 3);
    let params = PolicyParams::default();
    let mut policy = TrafficPolicy::new(&site, 3, 0.3, params);
    let (east, west) = ([vec2(30.0, 0.65)], [vec2(5.0, 0.65)]);
    let robots = [
        (vec2(10.0, 0.65), &east),
        (vec2(10.7, 0.65), &west),
        (vec2(11.4, 0.65), &west),
    ]
    .map(|(position, route)| PolicyRobot {
        position,
        route: route.as_slice(),
        station: None,
        held: false,
    });
    let views = standing(&robots, 0.3, &[20.0; 3]);
    let map = site.map();
    let mut monitor = TrafficMonitor::new(3, TrafficParams::default());
    let mut first_retreat = None;
    for k in 1..=60 {
        let now = Real::from(k) * 0.1;
        // Robot 2 and robot 0 wait on each other from 3.5 s on.
        let extra: &[(usize, usize)] = if now >= 3.5 { &[(2, 0), (0, 2)] } else { &[] };
        monitor.record(now, 0.1, &views, &map, extra);
        let events = policy.step(now, &robots, &monitor);
        if first_retreat.is_none()
            && events
                .iter()
                .any(|e| matches!(e, PolicyEvent::Retreat { .. }))
        {
            first_retreat = Some(now);
        }
    }
    assert_eq!(monitor.cycles(), &[vec![0, 1, 2]]);
    let when = first_retreat.expect("a retreat");
    assert!((when - 4.1).abs() < 0.15, "{when}");
}

/// Robots of both directions knotted in a two-lane hallway: once the cycle has lasted
/// [`PolicyParams::retreat_after_s`], the direction with fewer robots in it stops where it
/// stands (no retreat) while the other keeps its lane, and the robot giving way drives on
/// once they are past it; if they never pass, after [`PolicyParams::give_way_s`], and the
/// retreat rule takes the cycle over.
#[test]
fn robots_knotted_both_ways_in_a_hallway_let_one_direction_pass() {
    let site = Site::hallway(40.0, 3.0, 3);
    let params = PolicyParams::default();
    let map = site.map();
    let (east, west) = ([vec2(30.0, 1.0)], [vec2(5.0, 1.0)]);
    let mut robots = [
        (vec2(10.0, 1.0), &east),
        (vec2(10.7, 1.0), &west),
        (vec2(11.4, 1.2), &west),
    ]
    .map(|(position, route)| PolicyRobot {
        position,
        route: route.as_slice(),
        station: None,
        held: false,
    });
    // Policy steps `from`..=`to` (× 0.1 s), robot 2 and robot 0 waiting on each other too;
    // the give-way and retreat events.
    let run = |robots: &[PolicyRobot<'_>],
               policy: &mut TrafficPolicy,
               monitor: &mut TrafficMonitor,
               from: u32,
               to: u32| {
        let views = standing(robots, 0.3, &[20.0; 3]);
        let mut seen = Vec::new();
        for k in from..=to {
            let now = Real::from(k) * 0.1;
            monitor.record(now, 0.1, &views, &map, &[(2, 0), (0, 2)]);
            seen.extend(
                policy
                    .step(now, robots, monitor)
                    .into_iter()
                    .filter(|e| {
                        matches!(e, PolicyEvent::GiveWay { .. } | PolicyEvent::Retreat { .. })
                    })
                    .map(|e| (now, e)),
            );
        }
        seen
    };
    let mut policy = TrafficPolicy::new(&site, 3, 0.3, params);
    let mut monitor = TrafficMonitor::new(3, TrafficParams::default());
    let seen = run(&robots, &mut policy, &mut monitor, 1, 50);
    let [(when, PolicyEvent::GiveWay { robot: 0 })] = seen[..] else {
        panic!("robot 0 alone gives way: {seen:?}");
    };
    assert!((when - params.retreat_after_s).abs() < 0.15, "{when}");
    assert_eq!(policy.totals().give_ways, 1);
    // Robot 0 stops where it stands.
    let Constraint::GiveWay(at) = policy.constraint(0) else {
        panic!("{:?}", policy.constraint(0));
    };
    assert_eq!(at, robots[0].position);
    // The other two keep their lane (right of travel: above the centre line), ahead.
    for i in [1, 2] {
        let Constraint::Lane(p) = policy.constraint(i) else {
            panic!("robot {i}: {:?}", policy.constraint(i));
        };
        assert!((p.y - 2.25).abs() < 1e-9, "robot {i}: {p:?}");
        assert!(p.x < robots[i].position.x, "robot {i}: {p:?}");
    }
    // Both past robot 0: it drives on along its lane.
    robots[1].position = vec2(8.0, 1.5);
    robots[2].position = vec2(7.0, 1.5);
    run(&robots, &mut policy, &mut monitor, 51, 51);
    assert!(
        matches!(policy.constraint(0), Constraint::Lane(p) if (p.y - 0.75).abs() < 1e-9),
        "{:?}",
        policy.constraint(0)
    );
    // Never passed: it drives on after give_way_s all the same.
    robots[1].position = vec2(10.7, 1.0);
    robots[2].position = vec2(11.4, 1.2);
    let mut policy = TrafficPolicy::new(&site, 3, 0.3, params);
    let mut monitor = TrafficMonitor::new(3, TrafficParams::default());
    let steps = ((when + params.give_way_s) / 0.1).round() as u32;
    run(&robots, &mut policy, &mut monitor, 1, steps - 1);
    assert!(matches!(policy.constraint(0), Constraint::GiveWay(_)));
    let seen = run(&robots, &mut policy, &mut monitor, steps, steps);
    assert!(!matches!(policy.constraint(0), Constraint::GiveWay(_)));
    assert!(
        matches!(seen[..], [(_, PolicyEvent::Retreat { .. })]),
        "{seen:?}"
    );
}

/// One policy step after the monitor has seen `robots` (each with a task whose route left is
/// `remaining[i]` m, standing still).
fn step_watched(
    policy: &mut TrafficPolicy,
    monitor: &mut TrafficMonitor,
    map: &StaticMap,
    now: Real,
    robots: &[PolicyRobot<'_>],
    remaining: &[Real],
) -> Vec<PolicyEvent> {
    let views = standing(robots, 0.4, remaining);
    monitor.record(now, 0.1, &views, map, &policy.wait_edges());
    policy.step(now, robots, monitor)
}

/// A robot waiting at one end of a segment travelled the other way by a robot that makes no
/// progress (stuck) goes round to the far end after [`PolicyParams::detour_after_s`],
/// entering with the flow; not before, and once per leg. It waits instead while the robot
/// inside makes progress (the segment is busy, not blocked), or while the segment is
/// travelled its own way.
#[test]
fn a_robot_waiting_long_at_a_blocked_segment_goes_round_to_the_far_end() {
    let (site, radius) = narrow();
    let map = site.map();
    let params = PolicyParams::default();
    let (s, pick) = TrafficPolicy::new(&site, 2, radius, params)
        .segments()
        .iter()
        .find_map(|s| {
            let st = site.stations.iter().find(|st| s.contains(st.position))?;
            Some((*s, *st))
        })
        .expect("a pick inside a segment");
    let (east_x, west_x) = (site.cross_aisle(s.ends.1).0, site.cross_aisle(s.ends.0).0);
    let through = [vec2(east_x, s.y)];
    let in_from_east = [vec2(east_x, s.y), pick.position];
    let robots = [
        // Inside, travelling east.
        PolicyRobot {
            position: vec2(s.x1 - 0.5, s.y),
            route: &through,
            station: None,
            held: false,
        },
        // In the east cross-aisle, below the mouth, bound for the pick: west, against it.
        PolicyRobot {
            position: vec2(east_x, s.y - 2.0),
            route: &in_from_east,
            station: Some(pick.id),
            held: false,
        },
    ];
    // Robot 0 makes progress (its route left shrinks 0.1 m a step), or none.
    for moving in [false, true] {
        let mut policy = TrafficPolicy::new(&site, 2, radius, params);
        let mut monitor = TrafficMonitor::new(2, TrafficParams::default());
        let mut detours = Vec::new();
        for k in 1..=200 {
            let now = Real::from(k) * 0.1;
            let left = if moving { 100.0 - now } else { 100.0 };
            let events = step_watched(&mut policy, &mut monitor, &map, now, &robots, &[left, 20.0]);
            for e in events {
                if let PolicyEvent::Detour { robot, segment } = e {
                    let round = policy.detour(robot).expect("the new route").to_vec();
                    detours.push((now, robot, segment, round));
                }
            }
        }
        if moving {
            assert!(detours.is_empty(), "{detours:?}");
            assert!(matches!(policy.constraint(1), Constraint::Hold { .. }));
            continue;
        }
        assert_eq!(detours.len(), 1, "{detours:?}");
        let (when, robot, segment, round) = &detours[0];
        assert_eq!((*robot, *segment), (1, s.id));
        assert!((when - 0.1 - params.detour_after_s).abs() < 0.05, "{when}");
        // In through the west end, eastward, to the pick.
        let n = round.len();
        assert_eq!(round[n - 1], pick.position);
        assert_eq!(round[n - 2], vec2(west_x, s.y));
        assert_eq!(policy.totals().detours, 1);
    }
    // Travelled its way, by a robot that does not come out either, while a robot waits at
    // the other end to go the other way: robot 1 waits as long, and is not sent round.
    let mut policy = TrafficPolicy::new(&site, 3, radius, params);
    let mut monitor = TrafficMonitor::new(3, TrafficParams::default());
    let west_route = [pick.position];
    let east_route = [vec2(east_x, s.y)];
    let robots = [
        PolicyRobot {
            position: vec2(s.x1 - 0.5, s.y),
            route: &west_route,
            station: None,
            held: false,
        },
        robots[1],
        PolicyRobot {
            position: vec2(west_x, s.y - 2.0),
            route: &[vec2(west_x, s.y), east_route[0]],
            station: None,
            held: false,
        },
    ];
    for k in 1..=200 {
        let now = Real::from(k) * 0.1;
        let left = [100.0, 20.0, 20.0];
        let events = step_watched(&mut policy, &mut monitor, &map, now, &robots, &left);
        assert!(!events.contains(&PolicyEvent::Detour {
            robot: 1,
            segment: s.id
        }));
    }
    assert!(matches!(policy.constraint(1), Constraint::Hold { .. }));
}

#[test]
fn policy_parameters_change_by_name_and_bad_ones_are_named() {
    let p = PolicyParams::default()
        .with_overrides("people_route_weight_m=3, retreat_m=2")
        .expect("valid");
    assert_eq!((p.people_route_weight_m, p.retreat_m), (3.0, 2.0));
    assert_eq!(p.changes(), "retreat_m=2,people_route_weight_m=3");
    assert_eq!(PolicyParams::default().with_overrides(&p.changes()), Ok(p));
    assert_eq!(PolicyParams::default().changes(), "");
    assert_eq!(
        PolicyParams::default().with_overrides(""),
        Ok(PolicyParams::default())
    );
    for (bad, named) in [
        ("people_route_weight=3", "people_route_weight"),
        ("retreat_m=-1", "retreat_m"),
        ("retreat_m=inf", "retreat_m"),
        ("retreat_m", "retreat_m"),
        ("retreat_m=x", "retreat_m"),
    ] {
        let e = PolicyParams::default().with_overrides(bad).expect_err(bad);
        assert!(e.contains(named), "{bad}: {e}");
    }
}

/// People-aware aisle entry: a robot about to enter a segment waits at its hold point while
/// someone inside walks along it toward the robot, even with the segment granted; someone
/// walking its way, or standing, does not hold it; with the parameter at 0 nobody does.
#[test]
fn a_robot_waits_at_the_mouth_while_someone_walks_out_toward_it() {
    let (site, radius) = narrow();
    let params = PolicyParams {
        people_hold_speed_m_s: 0.3,
        ..PolicyParams::default()
    };
    let s = {
        let policy = TrafficPolicy::new(&site, 1, radius, params);
        policy.segments()[0]
    };
    let route = [vec2(s.x1 + 1.5, s.y)];
    let robots = [PolicyRobot {
        position: vec2(s.x0 - 1.0, s.y),
        route: &route,
        station: None,
        held: false,
    }];
    let middle = vec2(0.5 * (s.x0 + s.x1), s.y);
    let held = |params: PolicyParams, person: (Vec2, Vec2)| {
        let mut policy = TrafficPolicy::new(&site, 1, radius, params);
        policy.set_people([person]);
        step(&mut policy, 0.0, &robots);
        step(&mut policy, 0.1, &robots);
        matches!(policy.constraint(0), Constraint::Hold { .. })
    };
    // Walking west, toward the robot entering eastward.
    assert!(held(params, (middle, vec2(-1.0, 0.0))));
    // The same person walking east, standing, or outside the aisle.
    assert!(!held(params, (middle, vec2(1.0, 0.0))));
    assert!(!held(params, (middle, vec2(0.0, 0.0))));
    assert!(!held(params, (middle + vec2(0.0, 5.0), vec2(-1.0, 0.0))));
    // Off by default.
    assert!(!held(PolicyParams::default(), (middle, vec2(-1.0, 0.0))));
}

/// Turning round from people: two robots in a segment, eastbound, with a person standing
/// in the leading robot's way turn round together, both to leave by the west end, once the
/// person has been there `people_turn_after_s`; not before, not when the person walks on
/// eastward ahead of them, not when the person is beside the aisle, not when the leading
/// robot's station is in the segment or a robot's lies farther along the row, and not with
/// the rule off.
#[test]
fn robots_in_an_aisle_turn_round_from_someone_standing_in_their_way() {
    let (site, radius) = narrow();
    let params = PolicyParams {
        people_turn_after_s: 10.0,
        ..PolicyParams::default()
    };
    let s = TrafficPolicy::new(&site, 1, radius, params).segments()[0];
    let route = [vec2(s.x1 + 1.5, s.y)];
    let lead = vec2(s.x0 + 6.0, s.y);
    let robots = [
        PolicyRobot {
            position: vec2(s.x0 + 4.5, s.y),
            route: &route,
            station: None,
            held: false,
        },
        PolicyRobot {
            position: lead,
            route: &route,
            station: None,
            held: false,
        },
    ];
    // The turns robot 0 and robot 1 were given at each of the steps 0, 5, 10 s.
    let turns = |params: PolicyParams, robots: &[PolicyRobot<'_>], person: (Vec2, Vec2)| {
        let mut policy = TrafficPolicy::new(&site, robots.len(), radius, params);
        [0.0, 5.0, 10.0]
            .map(|now| {
                policy.set_people([person]);
                step(&mut policy, now, robots);
                (policy.turned(0), policy.turned(1))
            })
            .to_vec()
    };
    let standing = (lead + vec2(1.2, 0.0), vec2(0.0, 0.0));
    let back = Some(s.ends.0);
    assert_eq!(
        turns(params, &robots, standing),
        vec![(None, None), (None, None), (back, back)]
    );
    let never = vec![(None, None); 3];
    // Walking on eastward at 0.6 m/s, ahead of them: they follow.
    let walking_on = (standing.0, vec2(0.6, 0.0));
    assert_eq!(turns(params, &robots, walking_on), never);
    // Coming at them: they turn round.
    let coming = (standing.0, vec2(-0.6, 0.0));
    assert_eq!(turns(params, &robots, coming)[2], (back, back));
    // Beside the aisle (behind a shelf), or farther ahead than the reach.
    let beside = (standing.0 + vec2(0.0, 1.5), vec2(0.0, 0.0));
    assert_eq!(turns(params, &robots, beside), never);
    let reach = TrafficPolicy::new(&site, 1, radius, params).people_turn_reach();
    assert_eq!(
        reach, 1.7,
        "a 0.4 m robot, a 0.3 m person, the 1 m blocking gap"
    );
    let far = (lead + vec2(reach + 0.1, 0.0), vec2(0.0, 0.0));
    assert_eq!(turns(params, &robots, far), never);
    // The leading robot's station is in the segment: it waits for it.
    let station = site
        .stations
        .iter()
        .position(|st| s.contains(st.position))
        .expect("a pick face in the first aisle");
    let bound_for_station = [
        robots[0],
        PolicyRobot {
            station: Some(station),
            held: false,
            ..robots[1]
        },
    ];
    assert_eq!(turns(params, &bound_for_station, standing), never);
    // The robot behind is bound for a station farther along the same aisle row, beyond the
    // segment: the end behind them is no way out for it, so neither turns.
    let further = site
        .stations
        .iter()
        .position(|st| (st.position.y - s.y).abs() <= s.half_width && st.position.x > s.x1)
        .expect("a pick face farther along the row");
    let bound_further = [
        PolicyRobot {
            station: Some(further),
            held: false,
            ..robots[0]
        },
        robots[1],
    ];
    assert_eq!(turns(params, &bound_further, standing), never);
    // On by default; off at 0.
    assert_eq!(PolicyParams::default().people_turn_after_s, 10.0);
    let off = PolicyParams {
        people_turn_after_s: 0.0,
        ..PolicyParams::default()
    };
    assert_eq!(turns(off, &robots, standing), never);
    let blind = PolicyParams {
        alone_exit_clear_m: 0.0,
        ..off
    };
    assert!(!TrafficPolicy::new(&site, 2, radius, blind).watches_people());
    // A third robot granted the segment on its way in, still outside: it is not turned, it
    // waits again at its hold point, and the segment now runs the turned robots' way.
    let mut three = robots.to_vec();
    three.push(PolicyRobot {
        position: vec2(s.x0 - 2.0, s.y),
        route: &route,
        station: None,
        held: false,
    });
    let mut policy = TrafficPolicy::new(&site, 3, radius, params);
    for now in [0.0, 5.0, 10.0] {
        policy.set_people([standing]);
        step(&mut policy, now, &three);
    }
    assert_eq!(
        (policy.turned(0), policy.turned(1), policy.turned(2)),
        (back, back, None)
    );
    let res = policy.reservation(s.id);
    assert_eq!((res.dir, res.holders.clone()), (Some(-1), vec![0, 1]));
    assert!(matches!(policy.constraint(2), Constraint::Hold { .. }));
    assert_eq!(policy.totals().people_turns, 1);
    // A robot granted the segment, not yet in, with someone standing at the mouth: nobody
    // inside to turn, and its grant stands.
    let outside = [three[2]];
    let mut policy = TrafficPolicy::new(&site, 1, radius, params);
    let at_mouth = (vec2(s.x0 - 0.8, s.y), vec2(0.0, 0.0));
    for now in [0.0, 5.0, 10.0, 15.0] {
        policy.set_people([at_mouth]);
        step(&mut policy, now, &outside);
    }
    let res = policy.reservation(s.id);
    assert_eq!((res.dir, res.holders.clone()), (Some(1), vec![0]));
    assert_eq!(policy.totals().people_turns, 0);
}

/// Lines keep crossings clear ([`PolicyParams::queue_crossing_gap_m`]): in the narrow
/// warehouse, robots coming along the bottom corridor to the dock west of the middle
/// cross-aisle wait beyond the crossing at its foot instead of in it, at distinct places in
/// the same order; with the gap at 0 (the default) the line runs through the crossing.
#[test]
fn lines_keep_crossings_clear() {
    let (site, radius) = narrow();
    // The middle cross-aisle meets the bottom corridor at (31.5, 1.5); a dock stands 5.25 m
    // west of it.
    assert!(site.in_crossing(vec2(31.5, 1.5), 0.0));
    assert!(!site.in_crossing(vec2(26.25, 1.5), 0.6));
    assert!(site.in_crossing(vec2(29.5, 1.5), 0.6));
    assert!(!Site::hallway(40.0, 3.0, 3).in_crossing(vec2(20.0, 1.5), 1.0));
    let dock = *site
        .stations_of(StationKind::Dock)
        .find(|d| (d.position.x - 26.25).abs() < 1e-9)
        .expect("a dock at x = 26.25");
    let places = |gap: Real| {
        let params = PolicyParams {
            queue_crossing_gap_m: gap,
            ..PolicyParams::default()
        };
        let mut policy = TrafficPolicy::new(&site, 5, radius, params);
        let route = [dock.position];
        // y = 1.5 m is the bottom corridor's centre line.
        let robots = bound_for([27.5, 28.5, 29.0, 29.5, 30.0], &route, dock.id);
        step(&mut policy, 0.1, &robots);
        step(&mut policy, 0.2, &robots);
        assert_eq!(policy.station_line(dock.id).and_then(|l| l.holder), Some(0));
        (1..5)
            .map(|i| match policy.constraint(i) {
                Constraint::Queue { at, .. } => at,
                c => panic!("robot {i}: {c:?}"),
            })
            .collect::<Vec<Vec2>>()
    };
    let gap = 0.2;
    let (open, clear) = (places(0.0), places(gap));
    assert!(
        open.iter().any(|&p| site.in_crossing(p, radius + gap)),
        "{open:?}"
    );
    assert!(
        clear.iter().all(|&p| !site.in_crossing(p, radius + gap)),
        "{clear:?}"
    );
    // The line still starts at the first place back from the dock, west of the crossing, and
    // goes on east beyond it, in order.
    assert_eq!(clear[0], open[0]);
    assert!(clear.windows(2).all(|w| w[1].x > w[0].x), "{clear:?}");
    assert!(clear[1].x > 31.5 + 1.5 + radius + gap, "{clear:?}");
}
