//! Sample messages of every type, shared by the codec tests and the fuzzer (which starts from
//! their encodings).

#![allow(dead_code)]

use schemas::*;

pub fn sample(t: f64) -> Sample {
    Sample {
        t,
        p: P2(t, -t),
        sigma: 0.1 + t,
    }
}

pub fn observation() -> Observation {
    Observation {
        robot_id: 3,
        seq: 17,
        sim_time: 12.5,
        dt: 0.1,
        map_version: 1,
        p: P2(1.0, 2.0),
        heading: 0.5,
        vel: P2(0.3, 0.0),
        yaw_rate: 0.0,
        radius: 0.3,
        goal: Some(P2(10.0, 2.0)),
        task: Some(TaskRef {
            task_id: 9,
            stage: TaskStage::Drop,
        }),
        neighbours: vec![
            Perceived {
                id: 1 << 33,
                kind: Kind::Human,
                p: P2(2.0, 2.0),
                vel: P2(-1.0, 0.0),
                radius: 0.35,
                intent: None,
            },
            Perceived {
                id: 4,
                kind: Kind::Robot,
                p: P2(4.0, 2.0),
                vel: P2(0.0, 1.0),
                radius: 0.3,
                intent: Some(vec![sample(0.25), sample(0.5)]),
            },
        ],
        visibility: Some(VisibilityProfile {
            bearing0: -0.5,
            range: 10.0,
            ranges: vec![10.0, 2.5, 2.5, 10.0, 0.0, 9.5],
        }),
        real: false,
    }
}

pub fn intent() -> IntentMsg {
    IntentMsg {
        robot_id: 3,
        obs_seq: 17,
        stamp: 12.5,
        planner: "pgp+orca".into(),
        subgoal: P2(1.4, 2.0),
        trajectory: (1..=32).map(|i| sample(0.25 * i as f64)).collect(),
    }
}

pub fn command() -> CommandMsg {
    CommandMsg {
        robot_id: 3,
        obs_seq: 17,
        stamp: 12.5,
        motion: Motion::Velocity(P2(0.5, -0.1)),
        safe_stop: false,
        safety: SafetyZone::Clear,
        state: None,
    }
}

pub fn info() -> AgentInfo {
    AgentInfo {
        robot_id: 3,
        planner: "pgp+dwa".into(),
        version: "0.1.0".into(),
        plans: 100,
        rejected: 2,
        plan_p99_us: 154.0,
        maps: 1,
        map_version: 0x1234_5678,
    }
}

pub fn task() -> TaskAssignment {
    TaskAssignment {
        robot_id: 3,
        task_id: 9,
        pick_station: 0,
        pick: P2(0.0, 1.0),
        drop_station: 5,
        drop: P2(30.0, 1.0),
        assigned_at: 3.0,
    }
}

pub fn metrics() -> FleetMetrics {
    FleetMetrics {
        tick: 100,
        sim_time: 10.0,
        robots: 2,
        alive: 1,
        humans: 50,
        tasks_done: 3,
        collision_rate: 0.01,
        svr: 0.2,
        near_misses: 1,
        robot_caused_contacts: 0,
        person_caused_contacts: 2,
        dropped_commands: 0,
        per_robot: vec![RobotRow {
            robot_id: 0,
            alive: true,
            tasks_done: 3,
            collision_rate: 0.0,
            svr: 0.1,
            min_human_distance: Some(0.4),
            social_force: 0.7,
            stuck: true,
            waits_on: vec![1, 4],
        }],
        deadlocks: 1,
        stuck_robots: 1,
        stuck_robot_s: 31.5,
        efficiency: Some(0.62),
        free_flow_tasks_per_min: Some(1.2),
        gridlocks: 1,
        stuck_causes: StuckCausesMsg {
            policy_s: 1.0,
            person_s: 20.0,
            robot_s: 0.5,
            layer_s: 0.0,
            planner_s: 10.0,
        },
        robot_robot_contacts: 2,
        wall_contacts: 0,
    }
}

pub fn traffic() -> TrafficMsg {
    TrafficMsg {
        tick: 120,
        sim_time: 12.0,
        constraint: TrafficConstraint::Hold,
        goal: Some(P2(15.0, 4.5)),
        segment: Some(7),
        direction: None,
        station: None,
    }
}

pub fn fan() -> FanMsg {
    FanMsg {
        robot_id: 3,
        obs_seq: 17,
        stamp: 12.5,
        best: 1,
        candidates: (0..3)
            .map(|k| FanCandidate {
                path: (0..33).map(|i| P2(0.25 * i as f64, k as f64)).collect(),
                survival: 0.9 - 0.1 * k as f64,
                expected_utility: 5.0 + k as f64,
            })
            .collect(),
    }
}

pub fn map() -> MapMsg {
    MapMsg {
        map_version: 1,
        obstacles: vec![
            ObstacleMsg::Polygon(vec![P2(0.0, 0.0), P2(1.0, 0.0), P2(1.0, 1.0)]),
            ObstacleMsg::Wall(P2(0.0, 0.0), P2(0.0, 5.0)),
        ],
        stations: vec![StationMsg {
            id: 0,
            p: P2(2.0, 2.0),
        }],
        bounds: [P2(0.0, 0.0), P2(10.0, 10.0)],
        turn_places: Some(vec![[P2(2.0, 2.0), P2(2.0, 2.0)]]),
        safety_layer: Some("warning_time=0.5".to_owned()),
    }
}
