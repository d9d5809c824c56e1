//! The frames the agent composes, and its ROS 2 odds and ends, at fixed values.

use super::frames::MAX_FRAMES;
use super::*;
use ros2_wire::msg::TransformStamped;

#[test]
fn commands_become_base_frame_twists() {
    let t = twist_of(
        Command::Velocity(Vec2::new(0.0, 1.0)),
        std::f64::consts::FRAC_PI_2,
    );
    assert!((t.linear.x - 1.0).abs() < 1e-12 && t.linear.y.abs() < 1e-12);
    let t = twist_of(
        Command::Unicycle {
            speed: 0.5,
            yaw_rate: -0.2,
        },
        1.0,
    );
    assert_eq!((t.linear.x, t.angular.z), (0.5, -0.2));
}

fn odometry(frame: &str, stamp: f64, x: Real, y: Real, yaw: Real, forward: Real) -> Odometry {
    let mut o = Odometry {
        header: Header {
            stamp: Time::from_secs(stamp),
            frame_id: frame.into(),
        },
        ..Default::default()
    };
    o.pose.pose.position = ros2_wire::msg::Point { x, y, z: 0.0 };
    o.pose.pose.orientation = ros2_wire::msg::Quaternion::from_yaw(yaw);
    o.twist.twist.linear.x = forward;
    o
}

fn near(a: Vec2, b: Vec2) -> bool {
    (a - b).norm() < 1e-9
}

/// Odometry in `odom`, map→odom from /tf (1 m along x, a quarter turn), people in the odom
/// frame, and a scan older than the newest odometry: all land in the map frame, the scan
/// at the pose of its own stamp.
#[test]
fn frames_compose_into_the_map_frame() {
    use std::f64::consts::FRAC_PI_2;
    let config = RosConfig::default();
    let mut l = Latest {
        odom: Some((odometry("odom", 2.0, 2.0, 0.0, 0.0, 0.5), Instant::now())),
        ..Default::default()
    };
    l.poses.push_back((1.9, Vec2::new(1.95, 0.0), 0.0));
    l.poses.push_back((2.0, Vec2::new(2.0, 0.0), 0.0));
    assert!(sense(&l, &config).is_none(), "no map→odom yet");
    l.map_from_odom = Some((Vec2::new(1.0, 0.0), FRAC_PI_2));
    l.people = Some(People {
        header: Header {
            stamp: Time::from_secs(2.0),
            frame_id: "odom".into(),
        },
        people: vec![ros2_wire::msg::Person {
            name: "a".into(),
            position: ros2_wire::msg::Point {
                x: 3.0,
                y: 0.0,
                z: 0.0,
            },
            velocity: ros2_wire::msg::Point {
                x: 1.0,
                y: 0.0,
                z: 0.0,
            },
            ..Default::default()
        }],
    });
    l.scan = Some(LaserScan {
        header: Header {
            stamp: Time::from_secs(1.9),
            frame_id: "base_link".into(),
        },
        angle_min: 0.5,
        angle_increment: 0.01,
        range_max: 10.0,
        ranges: vec![1.0],
        ..Default::default()
    });
    let s = sense(&l, &config).expect("sensed");
    // (2, 0) in odom is (1, 2) in the map; heading a quarter turn; forward is map +y.
    assert!(
        near(s.ego.position, Vec2::new(1.0, 2.0)),
        "{:?}",
        s.ego.position
    );
    assert!((s.ego.heading - FRAC_PI_2).abs() < 1e-12);
    assert!(
        near(s.ego.velocity, Vec2::new(0.0, 0.5)),
        "{:?}",
        s.ego.velocity
    );
    assert!(near(s.people[0].position, Vec2::new(1.0, 3.0)));
    assert!(near(s.people[0].velocity, Vec2::new(0.0, 1.0)));
    let scan = s.scan.expect("the scan, at its own pose");
    assert!(near(scan.origin, Vec2::new(1.0, 1.95)), "{:?}", scan.origin);
    assert!((scan.bearing0 - (FRAC_PI_2 + 0.5)).abs() < 1e-6);
    // A scan with no odometry near its stamp is not used.
    if let Some(scan) = l.scan.as_mut() {
        scan.header.stamp = Time::from_secs(1.0);
    }
    assert!(sense(&l, &config).expect("sensed").scan.is_none());
    // People in another frame are refused.
    if let Some(p) = l.people.as_mut() {
        p.header.frame_id = "camera".into();
    }
    assert!(sense(&l, &config).expect("sensed").people.is_empty());
}

fn transform(parent: &str, child: &str, x: Real, y: Real, yaw: Real) -> TransformStamped {
    TransformStamped {
        header: Header {
            stamp: Time::from_secs(0.0),
            frame_id: parent.into(),
        },
        child_frame_id: child.into(),
        transform: ros2_wire::msg::Transform {
            translation: Vector3 { x, y, z: 0.1 },
            rotation: ros2_wire::msg::Quaternion::from_yaw(yaw),
        },
    }
}

/// A scanner two links from the base (base_footprint → base_link → laser, the second
/// turned backwards) is placed where the chain puts it; the flag overrides the chain; a
/// scan whose frame has no chain to the base is reported and not used, and the robot holds.
#[test]
fn the_scanner_is_placed_where_the_transforms_mount_it() {
    use std::f64::consts::{FRAC_PI_2, PI};
    let mut config = RosConfig::default();
    let mut odom = odometry("map", 1.0, 1.0, 2.0, FRAC_PI_2, 0.0);
    odom.child_frame_id = "base_footprint".into();
    let mut l = Latest {
        odom: Some((odom, Instant::now())),
        scan: Some(LaserScan {
            header: Header {
                stamp: Time::from_secs(1.0),
                frame_id: "laser".into(),
            },
            angle_min: -0.5,
            angle_increment: 0.01,
            range_max: 10.0,
            ranges: vec![1.0],
            ..Default::default()
        }),
        ..Default::default()
    };
    l.poses.push_back((1.0, Vec2::new(1.0, 2.0), FRAC_PI_2));
    let counters = RosCounters::default();
    let unplaced = sense(&l, &config).expect("sensed");
    assert_eq!(unplaced.scan_mount, Some(("laser".into(), None)));
    assert!(unplaced.scan.is_none(), "an unplaced scan is not used");
    assert!(unplaced.scanner_unplaced(), "the robot holds");

    let tf = TFMessage {
        transforms: vec![
            transform("base_footprint", "base_link", 0.1, 0.0, 0.0),
            transform("/base_link", "laser", 0.2, 0.1, PI),
        ],
    };
    take_transforms(&mut l, &tf, "map", true, &counters);
    assert_eq!(counters.tf.load(Ordering::Relaxed), 2);
    let s = sense(&l, &config).expect("sensed");
    assert!(!s.scanner_unplaced());
    let (frame, mount) = s.scan_mount.expect("a scan");
    let (offset, yaw) = mount.expect("the chain reaches the base");
    assert_eq!(frame, "laser");
    assert!(near(offset, Vec2::new(0.3, 0.1)) && (yaw - PI).abs() < 1e-12);
    // (0.3, 0.1) on a base at (1, 2) heading +y is (0.9, 2.3) in the map.
    let scan = s.scan.expect("placed");
    assert!(near(scan.origin, Vec2::new(0.9, 2.3)), "{:?}", scan.origin);
    assert!((scan.bearing0 - (FRAC_PI_2 + PI - 0.5)).abs() < 1e-6);

    config.scan_mount = Some((Vec2::new(-0.1, 0.0), 0.0));
    let scan = sense(&l, &config).expect("sensed").scan.expect("placed");
    assert!(near(scan.origin, Vec2::new(1.0, 1.9)), "{:?}", scan.origin);
    assert!((scan.bearing0 - (FRAC_PI_2 - 0.5)).abs() < 1e-6);
}

/// Untrusted transforms stay bounded, and a loop of frames never hangs the placement.
#[test]
fn the_robots_frames_stay_bounded_and_loops_end() {
    let counters = RosCounters::default();
    let mut l = Latest::default();
    let flood = TFMessage {
        transforms: (0..1000)
            .map(|i| transform("base_link", &format!("f{i}"), 0.0, 0.0, 0.0))
            .collect(),
    };
    take_transforms(&mut l, &flood, "map", true, &counters);
    assert_eq!(l.frames.len(), MAX_FRAMES);
    let cycle = TFMessage {
        transforms: vec![
            transform("b", "a", 0.0, 0.0, 0.0),
            transform("a", "b", 0.0, 0.0, 0.0),
        ],
    };
    l.frames.clear();
    take_transforms(&mut l, &cycle, "map", true, &counters);
    assert_eq!(mount_of(&l.frames, "a", "base_link"), None);
}

/// A map pose (AMCL's) gives map→odom through the odometry pose at its stamp; a pose in
/// another frame, or far from any odometry, is refused.
#[test]
fn a_map_pose_gives_map_from_odom() {
    use std::f64::consts::FRAC_PI_2;
    let config = RosConfig::default();
    let counters = RosCounters::default();
    let mut l = Latest {
        odom: Some((odometry("odom", 1.5, 2.0, 0.0, 0.0, 0.0), Instant::now())),
        ..Default::default()
    };
    l.poses.push_back((1.0, Vec2::new(1.0, 0.0), 0.0));
    l.poses.push_back((1.5, Vec2::new(2.0, 0.0), 0.0));
    let mut pose = PoseWithCovarianceStamped {
        header: Header {
            stamp: Time::from_secs(1.0),
            frame_id: "map".into(),
        },
        ..Default::default()
    };
    pose.pose.pose.position = ros2_wire::msg::Point {
        x: 3.0,
        y: 4.0,
        z: 0.0,
    };
    pose.pose.pose.orientation = ros2_wire::msg::Quaternion::from_yaw(FRAC_PI_2);
    take_map_pose(&mut l, &pose, "map", &counters);
    let (offset, yaw) = l.map_from_odom.expect("map→odom");
    assert!(near(offset, Vec2::new(3.0, 3.0)) && (yaw - FRAC_PI_2).abs() < 1e-12);
    // The newest odometry, (2, 0) in odom, is one metre on along map +y.
    let s = sense(&l, &config).expect("sensed");
    assert!(
        near(s.ego.position, Vec2::new(3.0, 5.0)),
        "{:?}",
        s.ego.position
    );
    assert_eq!(counters.poses.load(Ordering::Relaxed), 1);

    l.map_from_odom = None;
    pose.header.frame_id = "odom".into();
    take_map_pose(&mut l, &pose, "map", &counters);
    pose.header.frame_id = "map".into();
    pose.header.stamp = Time::from_secs(5.0);
    take_map_pose(&mut l, &pose, "map", &counters);
    assert!(l.map_from_odom.is_none());
    assert_eq!(counters.rejected.load(Ordering::Relaxed), 2);
}

#[test]
fn rejections_are_logged_at_powers_of_ten() {
    let logged: Vec<u64> = (0..2000).filter(|&n| log_now(n)).collect();
    assert_eq!(logged, vec![1, 10, 100, 1000]);
}
