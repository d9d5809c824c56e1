//! Untrusted bytes never panic and never allocate past the limits: random bytes, every
//! truncation and every flipped byte of valid messages, and lying lengths, for every type.
//! Round trips hold for arbitrary values (proptest).

use proptest::prelude::*;
use ros2_wire::fuzzing::decode_as_every_type;
use ros2_wire::msg::{
    Header, LaserScan, Odometry, People, Person, Point, PoseWithCovarianceStamped, Quaternion,
    TFMessage, Time, TransformStamped, Twist, TwistStamped,
};
use ros2_wire::{CdrError, Message, decode, encode};

/// Decodes `bytes` as every type and as an attachment (`ros2_wire::fuzzing`, the oracle the
/// AFL++ harness runs): none may panic, and what decodes must round-trip.
fn decode_all(bytes: &[u8]) {
    if let Err(e) = decode_as_every_type(bytes) {
        panic!("{e}");
    }
}

fn samples() -> Vec<Vec<u8>> {
    let mut odom = Odometry::default();
    odom.pose.pose.orientation = Quaternion::from_yaw(1.0);
    odom.header.frame_id = "odom".into();
    let scan = LaserScan {
        angle_increment: 0.1,
        range_max: 10.0,
        ranges: vec![1.0; 9],
        intensities: vec![2.0; 9],
        ..Default::default()
    };
    let mut tf = TFMessage::default();
    tf.transforms.push(TransformStamped {
        child_frame_id: "base_link".into(),
        transform: ros2_wire::msg::Transform {
            rotation: Quaternion::from_yaw(0.2),
            ..Default::default()
        },
        ..Default::default()
    });
    let people = People {
        header: Header {
            stamp: Time::from_secs(1.0),
            frame_id: "map".into(),
        },
        people: vec![Person {
            name: "a".into(),
            tagnames: vec!["k".into()],
            tags: vec!["v".into()],
            ..Default::default()
        }],
    };
    let mut pose = PoseWithCovarianceStamped::default();
    pose.header.frame_id = "map".into();
    pose.pose.pose.orientation = Quaternion::from_yaw(-2.0);
    vec![
        encode(&Twist::default()),
        encode(&TwistStamped::default()),
        encode(&odom),
        encode(&scan),
        encode(&tf),
        encode(&people),
        encode(&pose),
    ]
}

#[test]
fn truncations_and_flipped_bytes_never_panic() {
    for bytes in samples() {
        for cut in 0..bytes.len() {
            decode_all(&bytes[..cut]);
        }
        for i in 0..bytes.len() {
            for flip in [0x01, 0x80, 0xff] {
                let mut b = bytes.clone();
                b[i] ^= flip;
                decode_all(&b);
            }
        }
    }
}

#[test]
fn every_truncation_of_a_message_is_refused() {
    fn check<M: Message>(bytes: &[u8]) {
        // Up to 3 bytes short can only be alignment padding that a shorter encoding would not
        // have; every shorter prefix ends inside a field.
        for cut in 0..bytes.len() {
            assert!(
                decode::<M>(&bytes[..cut]).is_err(),
                "{}: {cut}-byte prefix decoded",
                M::NAME
            );
        }
        assert!(decode::<M>(bytes).is_ok(), "{}", M::NAME);
    }
    let s = samples();
    check::<Twist>(&s[0]);
    check::<TwistStamped>(&s[1]);
    check::<Odometry>(&s[2]);
    check::<LaserScan>(&s[3]);
    check::<TFMessage>(&s[4]);
    check::<People>(&s[5]);
    check::<PoseWithCovarianceStamped>(&s[6]);
}

#[test]
fn lying_lengths_are_refused_before_allocation() {
    // A People message claiming u32::MAX people, and one claiming 1,000 in 20 bytes.
    let mut bytes = encode(&People::default());
    let n = bytes.len();
    bytes[n - 4..].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(matches!(
        decode::<People>(&bytes),
        Err(CdrError::TooLong { .. })
    ));
    bytes[n - 4..].copy_from_slice(&1000u32.to_le_bytes());
    assert!(matches!(
        decode::<People>(&bytes),
        Err(CdrError::Truncated { .. })
    ));
    // Oversized payloads are refused before reading.
    let big = vec![0u8; LaserScan::LIMITS.max_bytes + 1];
    assert!(matches!(
        decode::<LaserScan>(&big),
        Err(CdrError::TooLarge { .. })
    ));
    assert!(matches!(
        decode::<Twist>(&[0u8; 65]),
        Err(CdrError::TooLarge { .. })
    ));
}

#[test]
fn an_overlong_frame_id_is_refused() {
    let long = TwistStamped {
        header: Header {
            frame_id: "x".repeat(300),
            ..Default::default()
        },
        ..Default::default()
    };
    assert!(matches!(
        decode::<TwistStamped>(&encode(&long)),
        Err(CdrError::TooLong { .. })
    ));
}

fn finite() -> impl Strategy<Value = f64> {
    -50.0..50.0f64
}

prop_compose! {
    fn arb_person()(name in "[a-z_0-9]{0,12}", x in finite(), y in finite(), vx in -3.0..3.0f64,
                    vy in -3.0..3.0f64, r in 0.0..1.0f64, tags in prop::collection::vec(("[a-z]{1,5}", "[0-9]{0,3}"), 0..3))
                    -> Person {
        let (tagnames, tags) = tags.into_iter().unzip();
        Person {
            name,
            position: Point { x, y, z: 0.0 },
            velocity: Point { x: vx, y: vy, z: 0.0 },
            reliability: r,
            tagnames,
            tags,
        }
    }
}

proptest! {
    #[test]
    fn random_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        decode_all(&bytes);
        let mut with_header = vec![0, 1, 0, 0];
        with_header.extend_from_slice(&bytes);
        decode_all(&with_header);
    }

    #[test]
    fn people_round_trip(people in prop::collection::vec(arb_person(), 0..20), sec in 0..i32::MAX,
                         frame in "[a-z/_]{0,20}") {
        let m = People { header: Header { stamp: Time { sec, nanosec: 5 }, frame_id: frame }, people };
        prop_assert_eq!(decode::<People>(&encode(&m)), Ok(m));
    }

    #[test]
    fn odometry_and_scans_round_trip(x in finite(), y in finite(), yaw in -3.1..3.1f64, v in -2.0..2.0f64,
                                     ranges in prop::collection::vec(0.0..30.0f32, 0..400)) {
        let mut odom = Odometry::default();
        odom.pose.pose.position = Point { x, y, z: 0.0 };
        odom.pose.pose.orientation = Quaternion::from_yaw(yaw);
        odom.twist.twist.linear.x = v;
        prop_assert_eq!(decode::<Odometry>(&encode(&odom)), Ok(odom));
        let scan = LaserScan { angle_increment: 0.01, range_max: 30.0, ranges, ..Default::default() };
        prop_assert_eq!(decode::<LaserScan>(&encode(&scan)), Ok(scan));
    }
}

/// Every input the coverage-guided fuzzer started from or kept (`schemas/fuzz/seeds-ros2/`,
/// `schemas/fuzz/corpus-ros2/`) decodes or is refused, without a panic, and round-trips; the
/// seeds, rosbags' own bytes, decode as their type.
#[test]
fn every_committed_fuzz_input_decodes_or_is_refused() {
    let fuzz = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz");
    let read = |dir: &str| -> Vec<Vec<u8>> {
        let mut files: Vec<_> = std::fs::read_dir(fuzz.join(dir))
            .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).collect())
            .unwrap_or_default();
        files.sort();
        files.iter().filter_map(|f| std::fs::read(f).ok()).collect()
    };
    let seeds = read("seeds-ros2");
    assert_eq!(seeds.len(), 9, "one seed per rosbags case");
    for seed in &seeds {
        assert_eq!(
            decode_as_every_type(seed),
            Ok(1),
            "a seed decodes as its own type"
        );
    }
    let corpus = read("corpus-ros2");
    assert!(!corpus.is_empty(), "the fuzzer's corpus is committed");
    for bytes in &corpus {
        decode_all(bytes);
    }
}
