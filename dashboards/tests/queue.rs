//! The dashboard never makes its caller wait: frames beyond the queue are dropped and counted,
//! and every frame is either logged or counted as dropped.

use dashboards::{Dashboard, Frame, MapFrame, QUEUE_FRAMES, RobotView, Sinks};

fn frame(tick: u64) -> Frame {
    Frame {
        tick,
        sim_time: tick as f64 * 0.1,
        humans: (0..500)
            .map(|i| [i as f32 * 0.1, (tick % 7) as f32])
            .collect(),
        human_groups: (0..500).map(|i| i / 3).collect(),
        human_radius: 0.35,
        robots: vec![RobotView {
            id: 0,
            position: [1.0, 2.0],
            heading: 0.3,
            radius: 0.3,
            planner: "pgp+orca".into(),
            alive: true,
        }],
        fleet_metrics: vec![("svr", 0.1)],
        robot_metrics: vec![(0, vec![("svr", 0.1)])],
        ..Frame::default()
    }
}

#[test]
fn a_burst_of_frames_is_logged_or_counted_never_lost() {
    let tmp = tempfile::tempdir().expect("a temporary folder");
    let dir = tmp.path().join("rrd");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let rrd = dir.join("burst.rrd");
    let sinks = Sinks {
        rrd: Some(rrd.clone()),
        ..Sinks::default()
    };
    let map = MapFrame {
        shelves: vec![vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]],
        walls: vec![[[0.0, 0.0], [0.0, 5.0]]],
        stations: vec![([2.0, 2.0], "dock 0".into())],
        keepout: vec![[[3.0, 3.0], [4.0, 3.0]]],
    };
    let dashboard = Dashboard::start("gapfleet-test", &sinks, map).expect("rrd sink opens");
    let sent = 2_000;
    for tick in 0..sent {
        dashboard.send(frame(tick));
    }
    let stats = dashboard.finish();
    println!("{stats:?}");
    assert_eq!(stats.logged + stats.dropped, sent, "{stats:?}");
    assert!(
        stats.logged >= QUEUE_FRAMES as u64,
        "at least a queue's worth is logged"
    );
    assert!(
        std::fs::metadata(&rrd).is_ok_and(|m| m.len() > 0),
        "the recording was written"
    );
}
