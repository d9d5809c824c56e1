//! The ROS path's codec on the agent's hot path: one scan, one odometry and one people message
//! decoded per control period, one command encoded. Targets (schemas/ros2/README.md): a
//! 1,080-ray scan and 20 people decoded in ≤ 20 µs each, odometry ≤ 2 µs, a command encoded
//! ≤ 1 µs: together under 0.1 % of a 100 ms control period.

use criterion::{Criterion, criterion_group, criterion_main};
use ros2_wire::msg::{
    Header, LaserScan, Odometry, People, Person, Point, Quaternion, Time, Twist, TwistStamped,
};
use ros2_wire::{decode, encode};
use std::hint::black_box;

fn scan(rays: usize) -> LaserScan {
    LaserScan {
        header: Header {
            stamp: Time::from_secs(12.5),
            frame_id: "robot1/base_scan".into(),
        },
        angle_min: -2.356,
        angle_max: 2.356,
        angle_increment: 4.712 / (rays - 1) as f32,
        scan_time: 0.1,
        range_min: 0.05,
        range_max: 25.0,
        ranges: (0..rays).map(|i| 1.0 + (i % 97) as f32 * 0.1).collect(),
        ..Default::default()
    }
}

fn people(n: usize) -> People {
    People {
        header: Header {
            stamp: Time::from_secs(3.0),
            frame_id: "map".into(),
        },
        people: (0..n)
            .map(|i| Person {
                name: format!("person_{i}"),
                position: Point {
                    x: i as f64,
                    y: 2.0,
                    z: 0.0,
                },
                velocity: Point {
                    x: 1.2,
                    y: 0.0,
                    z: 0.0,
                },
                reliability: 1.0,
                ..Default::default()
            })
            .collect(),
    }
}

fn bench(c: &mut Criterion) {
    let scan_bytes = encode(&scan(1080));
    c.bench_function("decode LaserScan 1080 rays", |b| {
        b.iter(|| decode::<LaserScan>(black_box(&scan_bytes)))
    });
    let mut odom = Odometry::default();
    odom.pose.pose.orientation = Quaternion::from_yaw(0.3);
    let odom_bytes = encode(&odom);
    c.bench_function("decode Odometry", |b| {
        b.iter(|| decode::<Odometry>(black_box(&odom_bytes)))
    });
    let people_bytes = encode(&people(20));
    c.bench_function("decode People 20", |b| {
        b.iter(|| decode::<People>(black_box(&people_bytes)))
    });
    let cmd = TwistStamped::default();
    c.bench_function("encode TwistStamped", |b| {
        b.iter(|| encode(black_box(&cmd)))
    });
    let twist = Twist::default();
    c.bench_function("encode Twist", |b| b.iter(|| encode(black_box(&twist))));
}

criterion_group!(benches, bench);
criterion_main!(benches);
