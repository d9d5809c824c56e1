//! Conversions between the wire messages (`schemas`) and the planner core's types. Decoded
//! messages are already validated (finite numbers, positive radii), so these are plain maps.

use crate::map::{MapError, Obstacle, StaticMap};
use crate::math::{Real, Vec2, vec2};
use crate::model::{AgentKind, Command, EgoState, Neighbour, SharedIntent, TrajectorySample};
use crate::planner::Plan;
use crate::visibility::Visibility;
use schemas::{
    CommandMsg, IntentMsg, Kind, MapMsg, Motion, Observation, ObstacleMsg, P2, Perceived, Sample,
    VisibilityProfile,
};

/// A wire point as a vector.
pub fn vec(p: P2) -> Vec2 {
    vec2(p.0, p.1)
}

/// A vector as a wire point.
pub fn p2(v: Vec2) -> P2 {
    P2(v.x, v.y)
}

/// Wire samples as trajectory samples.
pub fn samples_from_wire(samples: &[Sample]) -> Vec<TrajectorySample> {
    samples
        .iter()
        .map(|s| TrajectorySample {
            t: s.t,
            position: vec(s.p),
            sigma: s.sigma,
        })
        .collect()
}

/// Trajectory samples as wire samples.
pub fn samples_to_wire(samples: &[TrajectorySample]) -> Vec<Sample> {
    samples
        .iter()
        .map(|s| Sample {
            t: s.t,
            p: p2(s.position),
            sigma: s.sigma,
        })
        .collect()
}

/// The robot's own state in an observation.
pub fn ego(obs: &Observation) -> EgoState {
    EgoState {
        position: vec(obs.p),
        heading: obs.heading,
        velocity: vec(obs.vel),
        yaw_rate: obs.yaw_rate,
        radius: obs.radius,
    }
}

/// A robot's state as its agent reports it ([`schemas::CommandMsg::state`]), from odometry
/// that arrived `age` ago.
pub fn robot_state(ego: &EgoState, age: std::time::Duration) -> schemas::RobotState {
    schemas::RobotState {
        p: p2(ego.position),
        heading: ego.heading,
        vel: p2(ego.velocity),
        yaw_rate: ego.yaw_rate,
        age: age.as_secs_f64(),
    }
}

/// The perceived bodies of an observation.
pub fn neighbours(obs: &Observation) -> Vec<Neighbour> {
    obs.neighbours
        .iter()
        .map(|n| Neighbour {
            id: n.id,
            position: vec(n.p),
            velocity: vec(n.vel),
            yaw_rate: 0.0,
            radius: n.radius,
            kind: match n.kind {
                Kind::Human => AgentKind::Human,
                Kind::Robot => AgentKind::Robot,
            },
            intent: n.intent.as_ref().map(|s| SharedIntent {
                samples: samples_from_wire(s),
            }),
        })
        .collect()
}

/// The sensor's visibility profile of an observation, if it carries one.
pub fn visibility(obs: &Observation) -> Option<Visibility> {
    obs.visibility.as_ref().map(|v| Visibility {
        origin: vec(obs.p),
        bearing0: v.bearing0,
        range: v.range,
        ranges: v.ranges.iter().map(|&r| Real::from(r)).collect(),
    })
}

/// A visibility profile on the wire (ranges as `f32`: a tenth of a millimetre at 1 km).
pub fn visibility_to_wire(v: &Visibility) -> VisibilityProfile {
    VisibilityProfile {
        bearing0: v.bearing0,
        range: v.range,
        ranges: v.ranges.iter().map(|&r| r as f32).collect(),
    }
}

/// A neighbour as a perceived body on the wire.
pub fn perceived(n: &Neighbour) -> Perceived {
    Perceived {
        id: n.id,
        kind: match n.kind {
            AgentKind::Human => Kind::Human,
            AgentKind::Robot => Kind::Robot,
        },
        p: p2(n.position),
        vel: p2(n.velocity),
        radius: n.radius,
        intent: n.intent.as_ref().map(|i| samples_to_wire(&i.samples)),
    }
}

/// A command as wire motion.
pub fn motion(command: Command) -> Motion {
    match command {
        Command::Velocity(v) => Motion::Velocity(p2(v)),
        Command::Unicycle { speed, yaw_rate } => Motion::Unicycle(speed, yaw_rate),
    }
}

/// Wire motion as a command.
pub fn command(motion: Motion) -> Command {
    match motion {
        Motion::Velocity(v) => Command::Velocity(vec(v)),
        Motion::Unicycle(speed, yaw_rate) => Command::Unicycle { speed, yaw_rate },
    }
}

/// The command and intent messages answering `obs` with `plan`.
pub fn answer(obs: &Observation, planner: &str, plan: &Plan) -> (CommandMsg, IntentMsg) {
    let cmd = CommandMsg {
        robot_id: obs.robot_id,
        obs_seq: obs.seq,
        stamp: obs.sim_time,
        motion: motion(plan.command),
        safe_stop: false,
        safety: schemas::SafetyZone::Clear,
        state: None,
    };
    let intent = IntentMsg {
        robot_id: obs.robot_id,
        obs_seq: obs.seq,
        stamp: obs.sim_time,
        planner: planner.to_owned(),
        subgoal: p2(plan.intent.subgoal),
        trajectory: samples_to_wire(&plan.intent.trajectory),
    };
    (cmd, intent)
}

/// PGP's evaluated fan for the plan answering `obs`.
pub fn fan(obs: &Observation, fan: &crate::pgp::Fan) -> schemas::FanMsg {
    schemas::FanMsg {
        robot_id: obs.robot_id,
        obs_seq: obs.seq,
        stamp: obs.sim_time,
        best: fan.best as u32,
        candidates: fan
            .candidates
            .iter()
            .take(schemas::codec::MAX_CANDIDATES)
            .map(|c| schemas::FanCandidate {
                path: c
                    .positions
                    .iter()
                    .take(schemas::codec::MAX_SAMPLES)
                    .map(|&v| p2(v))
                    .collect(),
                survival: c.survival.last().copied().unwrap_or(1.0),
                expected_utility: c.expected_utility,
            })
            .collect(),
    }
}

/// A static map as a wire message.
pub fn map_to_wire(
    map: &StaticMap,
    version: u32,
    stations: Vec<schemas::StationMsg>,
    bounds: [Vec2; 2],
) -> MapMsg {
    MapMsg {
        map_version: version,
        obstacles: map
            .obstacles()
            .iter()
            .map(|o| match o {
                Obstacle::Polygon(points) => {
                    ObstacleMsg::Polygon(points.iter().map(|&p| p2(p)).collect())
                }
                Obstacle::Wall(a, b) => ObstacleMsg::Wall(p2(*a), p2(*b)),
            })
            .collect(),
        stations,
        bounds: [p2(bounds[0]), p2(bounds[1])],
        turn_places: None,
        safety_layer: None,
    }
}

/// The places a wire map marks where people stop and turn (`MapMsg::turn_places`), as the
/// safety layer takes them (`Guard::set_turn_places`).
pub fn turn_places_from_wire(msg: &MapMsg) -> Option<Vec<(Vec2, Vec2)>> {
    msg.turn_places
        .as_ref()
        .map(|places| places.iter().map(|[lo, hi]| (vec(*lo), vec(*hi))).collect())
}

/// A wire map as a static map (fails on degenerate geometry the decoder cannot see).
pub fn map_from_wire(msg: &MapMsg) -> Result<StaticMap, MapError> {
    StaticMap::new(
        msg.obstacles
            .iter()
            .map(|o| match o {
                ObstacleMsg::Polygon(points) => {
                    Obstacle::Polygon(points.iter().map(|&p| vec(p)).collect())
                }
                ObstacleMsg::Wall(a, b) => Obstacle::Wall(vec(*a), vec(*b)),
            })
            .collect(),
    )
}
