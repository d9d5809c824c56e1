//! The traffic monitor's tests: stuck robots, waiting, deadlocks, gridlocks.

use super::*;
use agent::map::Obstacle;
use agent::math::vec2;

#[test]
fn components_of_a_ring_a_pair_and_a_chain() {
    // 0 → 1 → 2 → 0 (a ring), 3 ⇄ 4 (a pair), 5 → 0 (waits on the ring, not in it).
    let edges = vec![vec![1], vec![2], vec![0], vec![4], vec![3], vec![0], vec![]];
    let mut sccs = strongly_connected(&edges);
    sccs.sort();
    assert_eq!(sccs, vec![vec![0, 1, 2], vec![3, 4], vec![5], vec![6]]);
}

fn robot(position: Vec2, waypoint: Vec2, leg: u64, remaining_m: Real) -> RobotView<'static> {
    RobotView {
        position,
        velocity: vec2(0.0, 0.0),
        radius: 0.4,
        task: Some(TaskView {
            leg,
            waypoint,
            remaining_m,
        }),
        intent: &[],
    }
}

/// Records `robots`, unchanged, for the steps after `from` up to `to` (s).
fn run(
    monitor: &mut TrafficMonitor,
    from: Real,
    to: Real,
    robots: &[RobotView<'_>],
    map: &StaticMap,
) -> Vec<TrafficEvent> {
    let mut events = Vec::new();
    let (first, last) = (
        (from / 0.1).round() as usize + 1,
        (to / 0.1).round() as usize,
    );
    for k in first..=last {
        events.extend(monitor.record(k as Real * 0.1, 0.1, robots, map, &[]));
    }
    events
}

/// Two robots face to face in a 1.5 m aisle, each driving for the other's side: a
/// deadlock after 10 s, one event, both stuck after 30 s.
#[test]
fn two_robots_face_to_face_in_an_aisle_deadlock() {
    let map = StaticMap::new(vec![
        Obstacle::Wall(vec2(0.0, 0.0), vec2(20.0, 0.0)),
        Obstacle::Wall(vec2(0.0, 1.5), vec2(20.0, 1.5)),
    ])
    .expect("walls");
    let robots = [
        robot(vec2(9.5, 0.75), vec2(18.0, 0.75), 0, 8.5),
        robot(vec2(10.5, 0.75), vec2(2.0, 0.75), 2, 8.5),
    ];
    let mut monitor = TrafficMonitor::new(2, TrafficParams::default());
    let events = run(&mut monitor, 0.0, 10.0, &robots, &map);
    assert!(events.is_empty(), "{events:?}");
    assert_eq!(monitor.waits_on(0), &[1]);
    assert_eq!(monitor.waits_on(1), &[0]);
    let events = run(&mut monitor, 10.0, 10.1, &robots, &map);
    assert_eq!(events, vec![TrafficEvent::Deadlock { robots: vec![0, 1] }]);
    assert_eq!(monitor.totals().deadlocks, 1);
    // It lasts: still one deadlock, and 30 s after the first step both are stuck.
    let events = run(&mut monitor, 10.1, 30.1, &robots, &map);
    assert_eq!(
        events,
        vec![
            TrafficEvent::Stuck { robot: 0 },
            TrafficEvent::Stuck { robot: 1 }
        ]
    );
    assert_eq!(monitor.totals().deadlocks, 1);
    assert!(monitor.is_stuck(0) && monitor.is_stuck(1));
}

/// Robots one behind the other, both waiting, wait on each other only one way: no cycle.
/// A robot that moves, or one whose waypoint points away, waits on nobody.
#[test]
fn a_queue_is_no_deadlock() {
    let map = StaticMap::empty();
    let robots = [
        robot(vec2(0.0, 0.0), vec2(10.0, 0.0), 0, 10.0),
        robot(vec2(1.2, 0.0), vec2(10.0, 0.0), 2, 8.8),
        RobotView {
            velocity: vec2(0.5, 0.0),
            ..robot(vec2(2.4, 0.0), vec2(10.0, 0.0), 4, 7.6)
        },
    ];
    let mut monitor = TrafficMonitor::new(3, TrafficParams::default());
    run(&mut monitor, 0.0, 15.0, &robots, &map);
    assert_eq!(monitor.waits_on(0), &[1]);
    assert_eq!(monitor.waits_on(1), &[2]);
    assert!(monitor.waits_on(2).is_empty());
    assert_eq!(monitor.totals().deadlocks, 0);
}

/// Three robots in a line, none moving, form no cycle, so no deadlock; stuck from 30 s
/// and together (the first step is at 0.1 s, so from 30.1 s), they are one gridlock from
/// 90.1 s, counted once. A robot stuck far from
/// the others is in none.
#[test]
fn a_queue_that_never_moves_is_a_gridlock() {
    let map = StaticMap::empty();
    let robots = [
        robot(vec2(0.0, 0.0), vec2(10.0, 0.0), 0, 10.0),
        robot(vec2(1.2, 0.0), vec2(10.0, 0.0), 2, 8.8),
        robot(vec2(2.4, 0.0), vec2(10.0, 0.0), 4, 7.6),
        robot(vec2(30.0, 0.0), vec2(40.0, 0.0), 6, 10.0),
    ];
    let mut monitor = TrafficMonitor::new(4, TrafficParams::default());
    let events = run(&mut monitor, 0.0, 90.0, &robots, &map);
    assert!(
        !events
            .iter()
            .any(|e| matches!(e, TrafficEvent::Gridlock { .. })),
        "{events:?}"
    );
    assert!(monitor.is_stuck(3));
    let events = run(&mut monitor, 90.0, 90.1, &robots, &map);
    assert_eq!(
        events,
        vec![TrafficEvent::Gridlock {
            robots: vec![0, 1, 2]
        }]
    );
    run(&mut monitor, 90.1, 100.0, &robots, &map);
    let t = monitor.totals();
    assert_eq!((t.gridlocks, t.deadlocks), (1, 0));
    assert!(monitor.is_gridlocked(1) && !monitor.is_gridlocked(3));
    // Three robots for the 100 steps from 90.1 s to 100 s.
    assert!((t.gridlocked_robot_s - 3.0 * 10.0).abs() < 0.05, "{t:?}");
}

/// Stuck robots on either side of a shelf are not together, however close.
#[test]
fn a_shelf_between_stuck_robots_keeps_them_apart() {
    let map = StaticMap::new(vec![Obstacle::Wall(vec2(1.0, -2.0), vec2(1.0, 2.0))]).expect("wall");
    let robots = [
        robot(vec2(0.0, 0.0), vec2(0.0, 10.0), 0, 10.0),
        robot(vec2(2.0, 0.0), vec2(2.0, 10.0), 2, 10.0),
    ];
    let mut monitor = TrafficMonitor::new(2, TrafficParams::default());
    run(&mut monitor, 0.0, 120.0, &robots, &map);
    assert!(monitor.is_stuck(0) && monitor.is_stuck(1));
    assert_eq!(monitor.totals().gridlocks, 0);
}

/// A shelf between two robots hides them from each other: no edge, however close.
#[test]
fn robots_that_cannot_see_each_other_do_not_wait_on_each_other() {
    let map = StaticMap::new(vec![Obstacle::Wall(vec2(1.0, -2.0), vec2(1.0, 2.0))]).expect("wall");
    let robots = [
        robot(vec2(0.5, 0.0), vec2(10.0, 0.0), 0, 10.0),
        robot(vec2(1.5, 0.0), vec2(-10.0, 0.0), 2, 10.0),
    ];
    let mut monitor = TrafficMonitor::new(2, TrafficParams::default());
    run(&mut monitor, 0.0, 12.0, &robots, &map);
    assert!(monitor.waits_on(0).is_empty() && monitor.waits_on(1).is_empty());
}

/// Progress resets the stuck clock; a new leg restarts it.
#[test]
fn progress_and_new_legs_keep_a_robot_from_being_stuck() {
    let map = StaticMap::empty();
    let mut monitor = TrafficMonitor::new(1, TrafficParams::default());
    let mut events = Vec::new();
    for k in 1..=600 {
        let t = k as Real * 0.1;
        // 0.1 m of progress every 10 s: too little; at 25 s a new leg starts.
        let leg = if t < 25.0 { 0 } else { 1 };
        let remaining = 10.0 - 0.01 * t.floor();
        let robots = [robot(vec2(0.0, 0.0), vec2(5.0, 0.0), leg, remaining)];
        events.extend(monitor.record(t, 0.1, &robots, &map, &[]));
    }
    // New leg at 25 s: stuck only from 55 s (to 60 s: 51 steps).
    assert_eq!(events, vec![TrafficEvent::Stuck { robot: 0 }]);
    let stuck_s = monitor.totals().stuck_robot_s;
    assert!((stuck_s - 5.1).abs() < 0.15, "{stuck_s}");
}

/// A robot on its hold point heads nowhere: a robot beside it is not in its way, whatever
/// noise the few millimetres to the point give its heading. It still waits on whom the
/// policy says.
#[test]
fn a_robot_at_its_hold_point_waits_only_on_the_policy() {
    let map = StaticMap::empty();
    let robots = [
        robot(vec2(0.0, 0.0), vec2(0.001, 0.0), 0, 10.0),
        robot(vec2(0.9, 0.0), vec2(-10.0, 0.0), 2, 10.0),
        robot(vec2(5.0, 0.0), vec2(10.0, 0.0), 4, 10.0),
    ];
    let mut monitor = TrafficMonitor::new(3, TrafficParams::default());
    for k in 1..=150 {
        monitor.record(k as Real * 0.1, 0.1, &robots, &map, &[(0, 2)]);
    }
    assert_eq!(monitor.waits_on(0), &[2]);
    assert_eq!(monitor.waits_on(1), &[0]);
    assert_eq!(monitor.totals().deadlocks, 0);
}

/// A deadlock that a bystander joins and leaves (the set regroups: {0, 1}, {0, 1, 2},
/// {0, 1}) is one deadlock; once its robots have left the cycles, a new one counts again.
#[test]
fn a_deadlock_that_regroups_counts_once() {
    let map = StaticMap::empty();
    let robots = [
        robot(vec2(0.0, 0.0), vec2(10.0, 0.0), 0, 10.0),
        robot(vec2(0.9, 0.0), vec2(-10.0, 0.0), 2, 10.0),
        robot(vec2(5.0, 5.0), vec2(10.0, 5.0), 4, 10.0),
    ];
    let mut monitor = TrafficMonitor::new(3, TrafficParams::default());
    let mut deadlocks = Vec::new();
    for k in 1..=420 {
        let t = k as Real * 0.1;
        // Robot 2 waits on robot 0 and robot 0 on it from 12 s to 12.5 s; from 30 s to
        // 31 s robot 1 moves off; then the pair is back.
        let mut extra = Vec::new();
        if (12.0..12.5).contains(&t) {
            extra.extend([(2, 0), (0, 2)]);
        }
        let mut now = robots;
        if (30.0..31.0).contains(&t) {
            now[1].velocity = vec2(0.0, 0.5);
        }
        for e in monitor.record(t, 0.1, &now, &map, &extra) {
            if let TrafficEvent::Deadlock { robots } = e {
                deadlocks.push((t, robots));
            }
        }
    }
    let when: Vec<(i64, Vec<usize>)> = deadlocks
        .into_iter()
        .map(|(t, r)| (t.round() as i64, r))
        .collect();
    assert_eq!(when, vec![(10, vec![0, 1]), (41, vec![0, 1])], "{when:?}");
    assert_eq!(monitor.totals().deadlocks, 2);
}

/// The policy's holds count: a robot held at a segment waits on its holder.
#[test]
fn extra_edges_close_cycles() {
    let map = StaticMap::empty();
    let robots = [
        robot(vec2(0.0, 0.0), vec2(10.0, 0.0), 0, 10.0),
        robot(vec2(1.2, 0.0), vec2(20.0, 5.0), 2, 10.0),
    ];
    let mut monitor = TrafficMonitor::new(2, TrafficParams::default());
    for k in 1..=110 {
        monitor.record(k as Real * 0.1, 0.1, &robots, &map, &[(1, 0)]);
    }
    assert_eq!(monitor.deadlocked(), &[vec![0, 1]]);
}
