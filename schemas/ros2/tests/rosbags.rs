//! Byte for byte against rosbags: every case of `fixtures/rosbags.json` (written by
//! `fixtures/make_fixtures.py` from the same values as here) encodes to rosbags' bytes and decodes
//! back to the value; every type's RIHS01 hash is rosbags' on Jazzy and Kilted.

use ros2_wire::msg::{
    Covariance, Header, LaserScan, Odometry, People, Person, Point, Pose, PoseWithCovariance,
    PoseWithCovarianceStamped, Quaternion, TFMessage, Time, Transform, TransformStamped, Twist,
    TwistStamped, TwistWithCovariance, Vector3,
};
use ros2_wire::{Message, decode, encode};
use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Deserialize)]
struct Fixtures {
    rihs01: BTreeMap<String, BTreeMap<String, String>>,
    cases: Vec<Case>,
}

#[derive(Deserialize)]
struct Case {
    name: String,
    #[serde(rename = "type")]
    ty: String,
    cdr_hex: String,
}

fn fixtures() -> Fixtures {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/rosbags.json");
    let text = std::fs::read_to_string(path).expect("fixtures/rosbags.json");
    serde_json::from_str(&text).expect("fixtures parse")
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn unhex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).expect("hex"))
        .collect()
}

fn header(sec: i32, nanosec: u32, frame: &str) -> Header {
    Header {
        stamp: Time { sec, nanosec },
        frame_id: frame.into(),
    }
}

fn cov(scale: f64) -> Covariance {
    let mut c = [0.0; 36];
    for (i, x) in c.iter_mut().enumerate() {
        *x = i as f64 * scale;
    }
    Covariance(c)
}

fn twist() -> Twist {
    Twist {
        linear: Vector3 {
            x: 0.5,
            y: -0.25,
            z: 0.0,
        },
        angular: Vector3 {
            x: 0.0,
            y: 0.0,
            z: 1.25,
        },
    }
}

const YAW_Q: Quaternion = Quaternion {
    x: 0.0,
    y: 0.0,
    z: 0.34289780745545134,
    w: 0.9393727128473789,
};

fn pose() -> Pose {
    Pose {
        position: Point {
            x: 1.5,
            y: -2.25,
            z: 0.0,
        },
        orientation: YAW_Q,
    }
}

fn scan(frame: &str, intensities: Vec<f32>) -> LaserScan {
    LaserScan {
        header: header(3, 250, frame),
        angle_min: -1.5,
        angle_max: 1.5,
        angle_increment: 0.75,
        time_increment: 0.0001,
        scan_time: 0.1,
        range_min: 0.05,
        range_max: 25.0,
        ranges: vec![0.5, f32::INFINITY, f32::NAN, 2.0, 30.0],
        intensities,
    }
}

/// Encodes the case's value, checks it decodes back to the same bytes, and returns the bytes.
fn case_bytes(name: &str) -> Vec<u8> {
    fn both<M: Message>(m: M) -> Vec<u8> {
        let bytes = encode(&m);
        let back: M = decode(&bytes).unwrap_or_else(|e| panic!("{}: {e}", M::NAME));
        assert_eq!(encode(&back), bytes, "{} round trip", M::NAME);
        bytes
    }
    match name {
        "twist" => both(twist()),
        "twist_stamped" => both(TwistStamped {
            header: header(1_700_000_000, 123_456_789, "base_link"),
            twist: twist(),
        }),
        "pose_with_covariance_stamped" => both(PoseWithCovarianceStamped {
            header: header(7, 1, "map"),
            pose: PoseWithCovariance {
                pose: pose(),
                covariance: cov(0.5),
            },
        }),
        "odometry" => both(Odometry {
            header: header(42, 500_000_000, "odom"),
            child_frame_id: "base_footprint".into(),
            pose: PoseWithCovariance {
                pose: pose(),
                covariance: cov(0.01),
            },
            twist: TwistWithCovariance {
                twist: twist(),
                covariance: cov(-0.02),
            },
        }),
        "laser_scan" => both(scan("lidar", vec![])),
        "laser_scan_intensities" => both(scan("robot1/base_scan", vec![1.0, 2.0, 3.0, 4.0, 5.0])),
        "tf" => both(TFMessage {
            transforms: vec![
                TransformStamped {
                    header: header(9, 9, "map"),
                    child_frame_id: "odom".into(),
                    transform: Transform {
                        translation: Vector3 {
                            x: 0.1,
                            y: 0.2,
                            z: 0.0,
                        },
                        rotation: Quaternion {
                            x: 0.0,
                            y: 0.0,
                            z: 0.0,
                            w: 1.0,
                        },
                    },
                },
                TransformStamped {
                    header: header(9, 10, "odom"),
                    child_frame_id: "robot1/base_link".into(),
                    transform: Transform {
                        translation: Vector3 {
                            x: -3.0,
                            y: 4.5,
                            z: 0.0,
                        },
                        rotation: YAW_Q,
                    },
                },
            ],
        }),
        "tf_empty" => both(TFMessage::default()),
        "people" => both(People {
            header: header(11, 0, "map"),
            people: vec![
                Person {
                    name: "p1".into(),
                    position: Point {
                        x: 1.0,
                        y: 2.0,
                        z: 0.0,
                    },
                    velocity: Point {
                        x: -1.25,
                        y: 0.5,
                        z: 0.0,
                    },
                    reliability: 0.9,
                    tagnames: vec!["group".into()],
                    tags: vec!["3".into()],
                },
                Person {
                    name: "walker_22".into(),
                    position: Point {
                        x: -4.0,
                        y: 0.25,
                        z: 0.0,
                    },
                    velocity: Point::default(),
                    reliability: 1.0,
                    tagnames: vec![],
                    tags: vec![],
                },
            ],
        }),
        other => panic!("no value for fixture case {other}"),
    }
}

#[test]
fn every_message_is_byte_for_byte_rosbags() {
    let fixtures = fixtures();
    assert_eq!(fixtures.cases.len(), 9);
    for case in &fixtures.cases {
        let ours = case_bytes(&case.name);
        assert_eq!(hex(&ours), case.cdr_hex, "{} ({})", case.name, case.ty);
    }
}

#[test]
fn rosbags_bytes_decode() {
    for case in &fixtures().cases {
        let bytes = unhex(&case.cdr_hex);
        let ok = match case.ty.as_str() {
            "geometry_msgs/msg/Twist" => decode::<Twist>(&bytes).map(|m| encode(&m)),
            "geometry_msgs/msg/TwistStamped" => decode::<TwistStamped>(&bytes).map(|m| encode(&m)),
            "geometry_msgs/msg/PoseWithCovarianceStamped" => {
                decode::<PoseWithCovarianceStamped>(&bytes).map(|m| encode(&m))
            }
            "nav_msgs/msg/Odometry" => decode::<Odometry>(&bytes).map(|m| encode(&m)),
            "sensor_msgs/msg/LaserScan" => decode::<LaserScan>(&bytes).map(|m| encode(&m)),
            "tf2_msgs/msg/TFMessage" => decode::<TFMessage>(&bytes).map(|m| encode(&m)),
            "people_msgs/msg/People" => decode::<People>(&bytes).map(|m| encode(&m)),
            other => panic!("unknown type {other}"),
        };
        assert_eq!(ok.as_deref(), Ok(bytes.as_slice()), "{}", case.name);
    }
}

#[test]
fn type_hashes_are_rosbags_on_jazzy_and_kilted() {
    fn hash_of(name: &str) -> &'static str {
        match name {
            "geometry_msgs/msg/Twist" => Twist::RIHS01,
            "geometry_msgs/msg/TwistStamped" => TwistStamped::RIHS01,
            "geometry_msgs/msg/PoseWithCovarianceStamped" => PoseWithCovarianceStamped::RIHS01,
            "nav_msgs/msg/Odometry" => Odometry::RIHS01,
            "sensor_msgs/msg/LaserScan" => LaserScan::RIHS01,
            "tf2_msgs/msg/TFMessage" => TFMessage::RIHS01,
            "people_msgs/msg/People" => People::RIHS01,
            other => panic!("unknown type {other}"),
        }
    }
    let fixtures = fixtures();
    for distro in ["jazzy", "kilted"] {
        let hashes = &fixtures.rihs01[distro];
        assert_eq!(hashes.len(), 7);
        for (name, hash) in hashes {
            assert_eq!(hash_of(name), hash, "{distro} {name}");
        }
    }
}

/// The AFL++ harness for these decoders (`schemas/fuzz/`, target `ros2`) starts from rosbags'
/// bytes, one file per case in `schemas/fuzz/seeds-ros2/`. They are kept equal to the fixtures;
/// `GAPFLEET_WRITE_AFL_SEEDS=1` writes them anew.
#[test]
fn the_afl_seeds_are_rosbags_bytes() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/seeds-ros2");
    let write = std::env::var("GAPFLEET_WRITE_AFL_SEEDS").is_ok_and(|v| v == "1");
    let cases = fixtures().cases;
    for case in &cases {
        let path = dir.join(format!("{}.cdr", case.name));
        let bytes = unhex(&case.cdr_hex);
        if write {
            std::fs::create_dir_all(&dir).expect("seed folder");
            std::fs::write(&path, &bytes).expect("seed written");
        }
        let committed = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(
            committed,
            bytes,
            "{} is stale: rerun with GAPFLEET_WRITE_AFL_SEEDS=1",
            path.display()
        );
    }
    let files = std::fs::read_dir(&dir).map_or(0, |d| d.count());
    assert_eq!(files, cases.len(), "only rosbags' cases are seeds");
}
