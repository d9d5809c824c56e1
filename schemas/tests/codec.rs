//! Round trip and malformed input for every message.

mod common;

use common::*;
use schemas::codec::{MAX_NEIGHBOURS, MAX_RAYS, MAX_SAMPLES};
use schemas::*;
use serde::Serialize;

fn round_trip<M: Message + PartialEq + std::fmt::Debug>(m: M) {
    let bytes = encode(&m);
    assert_eq!(decode::<M>(&bytes), Ok(m));
    // Every prefix of a valid message is rejected, never a panic.
    for cut in 0..bytes.len() {
        assert!(decode::<M>(&bytes[..cut]).is_err(), "prefix {cut} decoded");
    }
}

#[test]
fn every_message_round_trips() {
    round_trip(observation());
    round_trip(intent());
    round_trip(command());
    round_trip(CommandMsg {
        motion: Motion::Unicycle(0.5, -0.2),
        safe_stop: true,
        safety: SafetyZone::Clear,
        state: None,
        ..command()
    });
    round_trip(CommandMsg {
        safety: SafetyZone::Protective,
        state: None,
        ..command()
    });
    round_trip(CommandMsg {
        state: Some(robot_state()),
        ..command()
    });
    round_trip(info());
    round_trip(task());
    round_trip(metrics());
    round_trip(map());
    round_trip(fan());
    round_trip(traffic());
    round_trip(TrafficMsg {
        constraint: TrafficConstraint::Free,
        goal: None,
        segment: Some(2),
        direction: Some(-1),
        ..traffic()
    });
    round_trip(TrafficMsg {
        constraint: TrafficConstraint::Queue,
        segment: None,
        station: Some(4),
        ..traffic()
    });
    let give_way = TrafficMsg {
        constraint: TrafficConstraint::GiveWay,
        segment: None,
        direction: None,
        ..traffic()
    };
    round_trip(give_way.clone());
    // On the wire as schemas/README.md names it.
    let bytes = encode(&give_way);
    assert!(bytes.windows(8).any(|w| w == b"give_way"));
}

/// A traffic constraint says where to go exactly when it constrains, a hold names its
/// segment, a queue its station, and directions are ±1.
#[test]
fn traffic_rules_are_enforced() {
    let rejected = |m: TrafficMsg| decode::<TrafficMsg>(&encode(&m)).is_err();
    assert!(rejected(TrafficMsg {
        goal: None,
        ..traffic()
    }));
    assert!(rejected(TrafficMsg {
        constraint: TrafficConstraint::Free,
        ..traffic()
    }));
    assert!(rejected(TrafficMsg {
        segment: None,
        ..traffic()
    }));
    assert!(rejected(TrafficMsg {
        direction: Some(0),
        ..traffic()
    }));
    assert!(rejected(TrafficMsg {
        segment: Some(u32::MAX),
        ..traffic()
    }));
    assert!(rejected(TrafficMsg {
        constraint: TrafficConstraint::Queue,
        station: None,
        ..traffic()
    }));
    assert!(rejected(TrafficMsg {
        station: Some(u32::MAX),
        ..traffic()
    }));
    assert!(rejected(TrafficMsg {
        goal: Some(P2(f64::NAN, 0.0)),
        ..traffic()
    }));
    assert!(rejected(TrafficMsg {
        sim_time: f64::INFINITY,
        ..traffic()
    }));
    // Metrics from a coordinator before the traffic fields still decode.
    #[derive(Serialize)]
    struct OldRow {
        robot_id: u32,
        alive: bool,
        tasks_done: u64,
        collision_rate: f64,
        svr: f64,
        min_human_distance: Option<f64>,
        social_force: f64,
    }
    #[derive(Serialize)]
    struct OldMetrics {
        v: u16,
        tick: u64,
        sim_time: f64,
        robots: u32,
        alive: u32,
        humans: u32,
        tasks_done: u64,
        collision_rate: f64,
        svr: f64,
        near_misses: u64,
        dropped_commands: u64,
        per_robot: Vec<OldRow>,
    }
    let old = OldMetrics {
        v: SCHEMA_VERSION,
        tick: 1,
        sim_time: 0.1,
        robots: 1,
        alive: 1,
        humans: 0,
        tasks_done: 0,
        collision_rate: 0.0,
        svr: 0.0,
        near_misses: 0,
        dropped_commands: 0,
        per_robot: vec![OldRow {
            robot_id: 0,
            alive: true,
            tasks_done: 0,
            collision_rate: 0.0,
            svr: 0.0,
            min_human_distance: None,
            social_force: 0.0,
        }],
    };
    let bytes = rmp_serde::to_vec_named(&old).expect("encodes");
    let m = decode::<FleetMetrics>(&bytes).expect("old metrics decode");
    assert_eq!((m.deadlocks, m.stuck_robots, m.gridlocks), (0, 0, 0));
    assert_eq!((m.efficiency, m.free_flow_tasks_per_min), (None, None));
    assert_eq!(m.stuck_causes, StuckCausesMsg::default());
    assert!(!m.per_robot[0].stuck && m.per_robot[0].waits_on.is_empty());
    // Negative figures are rejected and named.
    let mut negative = metrics();
    negative.efficiency = Some(-0.1);
    assert!(matches!(
        decode::<FleetMetrics>(&encode(&negative)),
        Err(DecodeError::Invalid {
            field: "efficiency",
            ..
        })
    ));
}

#[test]
fn fan_rules_are_enforced() {
    let mut f = fan();
    f.best = 3;
    assert!(matches!(
        decode::<FanMsg>(&encode(&f)),
        Err(DecodeError::Invalid { field: "best", .. })
    ));
    let mut f = fan();
    f.candidates[2].path[5].1 = f64::NAN;
    assert_eq!(
        decode::<FanMsg>(&encode(&f)),
        Err(DecodeError::NonFinite("candidates.path"))
    );
}

/// What a client in another language sees: a map with `v` first and the documented names.
#[test]
fn wire_shape_is_the_documented_one() {
    #[derive(serde::Deserialize, Debug)]
    struct Loose {
        v: u16,
        robot_id: u32,
        motion: std::collections::BTreeMap<String, (f64, f64)>,
    }
    let bytes = encode(&command());
    assert_eq!(bytes[0] & 0xf0, 0x80, "a fixmap");
    assert_eq!(&bytes[1..3], &[0xa1, b'v'], "first key is \"v\"");
    let loose: Loose = rmp_serde::from_slice(&bytes).unwrap();
    assert_eq!(loose.v, SCHEMA_VERSION);
    assert_eq!(loose.robot_id, 3);
    assert_eq!(loose.motion["velocity"], (0.5, -0.1));
    let obs = encode(&observation());
    let text = String::from_utf8_lossy(&obs);
    for name in ["human", "robot", "drop", "neighbours", "intent", "sigma"] {
        assert!(text.contains(name), "{name} missing on the wire");
    }
}

#[test]
fn a_command_without_a_safety_zone_is_clear_and_unknown_zones_are_rejected() {
    // What an agent without the layer (or from before the field) sends.
    #[derive(Serialize)]
    struct Older {
        robot_id: u32,
        obs_seq: u64,
        stamp: f64,
        motion: Motion,
        safe_stop: bool,
    }
    let older = Older {
        robot_id: 3,
        obs_seq: 9,
        stamp: 1.5,
        motion: Motion::Velocity(P2(0.5, -0.1)),
        safe_stop: false,
    };
    let decoded: CommandMsg = decode(&with_version(SCHEMA_VERSION, &older)).expect("decodes");
    assert_eq!(decoded.safety, SafetyZone::Clear);
    let text = String::from_utf8_lossy(&encode(&CommandMsg {
        safety: SafetyZone::Warning,
        state: None,
        ..command()
    }))
    .into_owned();
    assert!(text.contains("warning"), "the zone travels as a string");
    #[derive(Serialize)]
    struct Odd<'a> {
        #[serde(flatten)]
        older: &'a Older,
        safety: &'static str,
    }
    let odd = Odd {
        older: &older,
        safety: "amber",
    };
    assert!(decode::<CommandMsg>(&with_version(SCHEMA_VERSION, &odd)).is_err());
}

#[derive(Serialize)]
struct Versioned<'a, M> {
    v: u16,
    #[serde(flatten)]
    body: &'a M,
}

fn with_version<M: Serialize>(v: u16, m: &M) -> Vec<u8> {
    rmp_serde::to_vec_named(&Versioned { v, body: m }).expect("plain data encodes")
}

#[test]
fn other_versions_are_rejected() {
    let bytes = with_version(SCHEMA_VERSION + 1, &command());
    assert_eq!(
        decode::<CommandMsg>(&bytes),
        Err(DecodeError::Version {
            got: SCHEMA_VERSION + 1,
            expected: SCHEMA_VERSION
        })
    );
    // Without a version at all.
    let bare = rmp_serde::to_vec_named(&command()).unwrap();
    assert!(matches!(
        decode::<CommandMsg>(&bare),
        Err(DecodeError::Malformed(_))
    ));
}

/// `v` after the body, as another language's encoder may write it.
#[derive(Serialize)]
struct VersionLast<'a, M> {
    #[serde(flatten)]
    body: &'a M,
    v: u16,
}

#[test]
fn the_version_may_come_anywhere_in_the_map() {
    let bytes = rmp_serde::to_vec_named(&VersionLast {
        body: &observation(),
        v: SCHEMA_VERSION,
    })
    .unwrap();
    assert_ne!(&bytes[1..3], &[0xa1, b'v'], "v is not the first key here");
    assert_eq!(decode::<Observation>(&bytes), Ok(observation()));
    let wrong = rmp_serde::to_vec_named(&VersionLast {
        body: &command(),
        v: SCHEMA_VERSION + 1,
    })
    .unwrap();
    assert_eq!(
        decode::<CommandMsg>(&wrong),
        Err(DecodeError::Version {
            got: SCHEMA_VERSION + 1,
            expected: SCHEMA_VERSION
        })
    );
}

#[test]
fn garbage_and_oversized_input_is_rejected() {
    for bytes in [
        &b""[..],
        b"\xc1",
        b"hello world",
        b"\xdf\xff\xff\xff\xff",
        b"\xdd\xff\xff\xff\xff",
        b"\x81\xa1v\xcd\x00\x01",
    ] {
        assert!(decode::<Observation>(bytes).is_err());
        assert!(decode::<CommandMsg>(bytes).is_err());
    }
    let huge = vec![0x90; CommandMsg::MAX_BYTES + 1];
    assert!(matches!(
        decode::<CommandMsg>(&huge),
        Err(DecodeError::TooLarge { .. })
    ));
    // A message of the wrong type.
    assert!(decode::<CommandMsg>(&encode(&info())).is_err());
}

#[test]
fn non_finite_numbers_are_rejected_everywhere() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut o = observation();
        o.neighbours[1].intent.as_mut().unwrap()[1].p.0 = bad;
        assert_eq!(
            decode::<Observation>(&encode(&o)),
            Err(DecodeError::NonFinite("neighbours.intent"))
        );
        let mut o = observation();
        o.p.1 = bad;
        assert_eq!(
            decode::<Observation>(&encode(&o)),
            Err(DecodeError::NonFinite("p"))
        );
        let mut c = command();
        c.motion = Motion::Unicycle(bad, 0.0);
        assert_eq!(
            decode::<CommandMsg>(&encode(&c)),
            Err(DecodeError::NonFinite("motion"))
        );
        let mut i = intent();
        i.subgoal.0 = bad;
        assert_eq!(
            decode::<IntentMsg>(&encode(&i)),
            Err(DecodeError::NonFinite("subgoal"))
        );
        let mut t = task();
        t.drop.1 = bad;
        assert_eq!(
            decode::<TaskAssignment>(&encode(&t)),
            Err(DecodeError::NonFinite("drop"))
        );
        let mut m = metrics();
        m.per_robot[0].min_human_distance = Some(bad);
        assert!(decode::<FleetMetrics>(&encode(&m)).is_err());
        let mut m = metrics();
        m.efficiency = Some(bad);
        assert_eq!(
            decode::<FleetMetrics>(&encode(&m)),
            Err(DecodeError::NonFinite("efficiency"))
        );
        let mut m = metrics();
        m.stuck_causes.planner_s = bad;
        assert_eq!(
            decode::<FleetMetrics>(&encode(&m)),
            Err(DecodeError::NonFinite("stuck_causes.planner_s"))
        );
        let mut a = info();
        a.plan_p99_us = bad;
        assert!(decode::<AgentInfo>(&encode(&a)).is_err());
        let mut mp = map();
        mp.obstacles[1] = ObstacleMsg::Wall(P2(bad, 0.0), P2(0.0, 1.0));
        assert_eq!(
            decode::<MapMsg>(&encode(&mp)),
            Err(DecodeError::NonFinite("obstacles.wall"))
        );
    }
}

/// Finite but unphysical numbers are rejected too: a position of 1e308 m, a speed of 1 km/s,
/// a time of 1e300 s, a radius of 1 km.
#[test]
fn unphysical_numbers_are_rejected() {
    let invalid = |field: &'static str| move |e: DecodeError| matches!(e, DecodeError::Invalid { field: f, .. } if f == field);
    let mut o = observation();
    o.p.0 = 1e308;
    assert!(decode::<Observation>(&encode(&o)).is_err_and(invalid("p")));
    let mut o = observation();
    o.neighbours[0].vel = P2(1000.0, 0.0);
    assert!(decode::<Observation>(&encode(&o)).is_err_and(invalid("neighbours.vel")));
    let mut o = observation();
    o.neighbours[0].radius = 1000.0;
    assert!(decode::<Observation>(&encode(&o)).is_err_and(invalid("neighbours.radius")));
    let mut o = observation();
    o.sim_time = 1e300;
    assert!(decode::<Observation>(&encode(&o)).is_err_and(invalid("sim_time")));
    let mut c = command();
    c.motion = Motion::Velocity(P2(40.0, 40.0));
    assert!(decode::<CommandMsg>(&encode(&c)).is_err_and(invalid("motion")));
    let mut c = command();
    c.motion = Motion::Unicycle(1.0, 1e6);
    assert!(decode::<CommandMsg>(&encode(&c)).is_err_and(invalid("motion")));
    let mut i = intent();
    i.trajectory[3].p = P2(0.0, -2e6);
    assert!(decode::<IntentMsg>(&encode(&i)).is_err_and(invalid("trajectory")));
    let mut t = task();
    t.assigned_at = -1e10;
    assert!(decode::<TaskAssignment>(&encode(&t)).is_err_and(invalid("assigned_at")));
    // At the bounds: accepted.
    let mut c = command();
    c.motion = Motion::Velocity(P2(30.0, 40.0));
    assert!(decode::<CommandMsg>(&encode(&c)).is_ok());
    let mut o = observation();
    o.p = P2(-1e6, 1e6);
    assert!(decode::<Observation>(&encode(&o)).is_ok());
}

#[test]
fn an_observation_without_a_visibility_profile_decodes_and_bad_profiles_are_rejected() {
    // What a coordinator from before the field (or without body occlusion) sends.
    #[derive(Serialize)]
    struct Older {
        robot_id: u32,
        seq: u64,
        sim_time: f64,
        dt: f64,
        map_version: u32,
        p: P2,
        heading: f64,
        vel: P2,
        yaw_rate: f64,
        radius: f64,
        goal: Option<P2>,
        task: Option<TaskRef>,
        neighbours: Vec<Perceived>,
    }
    let o = observation();
    let older = Older {
        robot_id: o.robot_id,
        seq: o.seq,
        sim_time: o.sim_time,
        dt: o.dt,
        map_version: o.map_version,
        p: o.p,
        heading: o.heading,
        vel: o.vel,
        yaw_rate: o.yaw_rate,
        radius: o.radius,
        goal: o.goal,
        task: o.task.clone(),
        neighbours: o.neighbours.clone(),
    };
    let decoded: Observation = decode(&with_version(SCHEMA_VERSION, &older)).expect("decodes");
    assert_eq!(
        decoded,
        Observation {
            visibility: None,
            ..observation()
        }
    );

    let with = |edit: &dyn Fn(&mut VisibilityProfile)| {
        let mut o = observation();
        edit(o.visibility.as_mut().expect("the fixture has one"));
        decode::<Observation>(&encode(&o))
    };
    let invalid = |field: &'static str, r: Result<Observation, DecodeError>| {
        assert!(
            matches!(r, Err(DecodeError::Invalid { field: f, .. }) if f == field),
            "{field}: {r:?}"
        );
    };
    invalid("visibility.ranges", with(&|v| v.ranges[2] = -0.1));
    invalid("visibility.ranges", with(&|v| v.ranges[2] = 10.5));
    invalid("visibility.ranges", with(&|v| v.ranges.clear()));
    invalid("visibility.range", with(&|v| v.range = 0.0));
    invalid("visibility.range", with(&|v| v.range = 5000.0));
    assert_eq!(
        with(&|v| v.ranges[0] = f32::NAN),
        Err(DecodeError::NonFinite("visibility.ranges"))
    );
    assert_eq!(
        with(&|v| v.bearing0 = f64::INFINITY),
        Err(DecodeError::NonFinite("visibility.bearing0"))
    );
    assert!(matches!(
        with(&|v| v.ranges = vec![1.0; MAX_RAYS + 1]),
        Err(DecodeError::TooMany {
            field: "visibility.ranges",
            ..
        })
    ));
    // The largest profile decodes.
    assert!(with(&|v| v.ranges = vec![1.0; MAX_RAYS]).is_ok());
}

#[test]
fn domain_rules_are_enforced() {
    let mut o = observation();
    o.radius = 0.0;
    assert!(matches!(
        decode::<Observation>(&encode(&o)),
        Err(DecodeError::Invalid {
            field: "radius",
            ..
        })
    ));
    let mut o = observation();
    o.neighbours = vec![o.neighbours[0].clone(); MAX_NEIGHBOURS + 1];
    assert!(matches!(
        decode::<Observation>(&encode(&o)),
        Err(DecodeError::TooMany {
            field: "neighbours",
            ..
        })
    ));
    let mut i = intent();
    i.trajectory = (0..=MAX_SAMPLES).map(|k| sample(k as f64)).collect();
    assert!(matches!(
        decode::<IntentMsg>(&encode(&i)),
        Err(DecodeError::TooMany { .. }) | Err(DecodeError::TooLarge { .. })
    ));
    let mut i = intent();
    i.trajectory.swap(0, 1);
    assert!(matches!(
        decode::<IntentMsg>(&encode(&i)),
        Err(DecodeError::Invalid {
            field: "trajectory",
            ..
        })
    ));
    let mut i = intent();
    i.planner = "x".repeat(65);
    assert!(matches!(
        decode::<IntentMsg>(&encode(&i)),
        Err(DecodeError::TooMany {
            field: "planner",
            ..
        })
    ));
    let mut mp = map();
    mp.obstacles[0] = ObstacleMsg::Polygon(vec![P2(0.0, 0.0), P2(1.0, 0.0)]);
    assert!(matches!(
        decode::<MapMsg>(&encode(&mp)),
        Err(DecodeError::Invalid { .. })
    ));
}

mod fuzz {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
            let _ = decode::<Observation>(&bytes);
            let _ = decode::<IntentMsg>(&bytes);
            let _ = decode::<CommandMsg>(&bytes);
            let _ = decode::<MapMsg>(&bytes);
        }

        #[test]
        fn flipped_bytes_never_panic(pos in 0usize..400, byte in any::<u8>()) {
            let mut bytes = encode(&observation());
            let at = pos % bytes.len();
            bytes[at] = byte;
            if let Ok(o) = decode::<Observation>(&bytes) {
                // Whatever decodes satisfies the rules.
                prop_assert!(o.p.0.is_finite() && o.radius > 0.0);
            }
        }
    }
}

/// An agent from before `maps` and `map_version` were added still reports: both read as 0.
#[test]
fn agent_info_without_the_map_fields_decodes() {
    #[derive(Serialize)]
    struct OlderInfo {
        robot_id: u32,
        planner: String,
        version: String,
        plans: u64,
        rejected: u64,
        plan_p99_us: f64,
    }
    let older = OlderInfo {
        robot_id: 3,
        planner: "pgp+orca".into(),
        version: "0.1.0".into(),
        plans: 10,
        rejected: 0,
        plan_p99_us: 100.0,
    };
    let info = decode::<AgentInfo>(&with_version(SCHEMA_VERSION, &older)).expect("decodes");
    assert_eq!((info.plans, info.maps, info.map_version), (10, 0, 0));
}

/// A coordinator from before `turn_places` and `safety_layer` still serves its map: it reads
/// as no places marked and the layer's defaults.
#[test]
fn a_map_without_turn_places_decodes() {
    #[derive(Serialize)]
    struct OlderMap {
        map_version: u32,
        obstacles: Vec<ObstacleMsg>,
        stations: Vec<StationMsg>,
        bounds: [P2; 2],
    }
    let m = map();
    let older = OlderMap {
        map_version: m.map_version,
        obstacles: m.obstacles.clone(),
        stations: m.stations.clone(),
        bounds: m.bounds,
    };
    let decoded = decode::<MapMsg>(&with_version(SCHEMA_VERSION, &older)).expect("decodes");
    assert_eq!(
        decoded,
        MapMsg {
            turn_places: None,
            safety_layer: None,
            ..m
        }
    );
}

/// A turn place must be a finite box within the coordinate bounds, lower corner first.
#[test]
fn bad_turn_places_are_rejected() {
    let with = |place: [P2; 2]| {
        let mut m = map();
        m.turn_places = Some(vec![place]);
        decode::<MapMsg>(&encode(&m))
    };
    assert_eq!(
        with([P2(f64::NAN, 0.0), P2(1.0, 1.0)]),
        Err(DecodeError::NonFinite("turn_places"))
    );
    assert!(matches!(
        with([P2(0.0, 0.0), P2(2e6, 1.0)]),
        Err(DecodeError::Invalid {
            field: "turn_places",
            ..
        })
    ));
    assert!(matches!(
        with([P2(3.0, 0.0), P2(1.0, 1.0)]),
        Err(DecodeError::Invalid {
            field: "turn_places",
            ..
        })
    ));
    assert!(with([P2(1.0, 0.0), P2(3.0, 1.0)]).is_ok());
}

/// A site's safety-layer setting is bounded in length; what it says is the agent's to check.
#[test]
fn an_overlong_safety_layer_setting_is_rejected() {
    let mut m = map();
    m.safety_layer = Some("x".repeat(schemas::codec::MAX_LAYER_SETTING + 1));
    assert!(matches!(
        decode::<MapMsg>(&encode(&m)),
        Err(DecodeError::TooMany {
            field: "safety_layer",
            ..
        })
    ));
    m.safety_layer = Some("x".repeat(schemas::codec::MAX_LAYER_SETTING));
    assert!(decode::<MapMsg>(&encode(&m)).is_ok());
}

fn robot_state() -> RobotState {
    RobotState {
        p: P2(3.0, -2.5),
        heading: 1.2,
        vel: P2(0.4, 0.1),
        yaw_rate: -0.3,
        age: 0.04,
    }
}

/// A real robot's reported state: absent from older agents (and then not on the wire at all),
/// and every field checked when present.
#[test]
fn a_reported_robot_state_is_optional_and_checked() {
    let plain = encode(&command());
    assert!(!String::from_utf8_lossy(&plain).contains("state"));
    assert_eq!(decode::<CommandMsg>(&plain).map(|c| c.state), Ok(None));
    // An agent that sends no age: the odometry counts as fresh.
    #[derive(Serialize)]
    struct NoAge {
        p: P2,
        heading: f64,
        vel: P2,
        yaw_rate: f64,
    }
    #[derive(Serialize)]
    struct Cmd {
        v: u16,
        robot_id: u32,
        obs_seq: u64,
        stamp: f64,
        motion: Motion,
        safe_stop: bool,
        state: NoAge,
    }
    let bytes = rmp_serde::to_vec_named(&Cmd {
        v: SCHEMA_VERSION,
        robot_id: 0,
        obs_seq: 1,
        stamp: 0.1,
        motion: Motion::Velocity(P2(0.0, 0.0)),
        safe_stop: false,
        state: NoAge {
            p: P2(1.0, 2.0),
            heading: 0.0,
            vel: P2(0.0, 0.0),
            yaw_rate: 0.0,
        },
    })
    .expect("encodes");
    assert_eq!(
        decode::<CommandMsg>(&bytes).map(|c| c.state.map(|s| s.age)),
        Ok(Some(0.0))
    );
    let bad = [
        (
            "state.p",
            RobotState {
                p: P2(f64::NAN, 0.0),
                ..robot_state()
            },
        ),
        (
            "state.p",
            RobotState {
                p: P2(2e6, 0.0),
                ..robot_state()
            },
        ),
        (
            "state.heading",
            RobotState {
                heading: f64::INFINITY,
                ..robot_state()
            },
        ),
        (
            "state.vel",
            RobotState {
                vel: P2(60.0, 0.0),
                ..robot_state()
            },
        ),
        (
            "state.yaw_rate",
            RobotState {
                yaw_rate: 1e3,
                ..robot_state()
            },
        ),
        (
            "state.age",
            RobotState {
                age: -0.5,
                ..robot_state()
            },
        ),
        (
            "state.age",
            RobotState {
                age: f64::NAN,
                ..robot_state()
            },
        ),
    ];
    for (field, state) in bad {
        let cmd = CommandMsg {
            state: Some(state),
            ..command()
        };
        let err = decode::<CommandMsg>(&encode(&cmd)).expect_err(field);
        assert!(err.to_string().contains(field), "{field}: {err}");
    }
}
