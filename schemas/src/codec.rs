//! Encoding and strict decoding.
//!
//! On the wire every message is a MessagePack map: `{"v": SCHEMA_VERSION, <fields>...}`.
//! [`decode`] checks, in order: the byte length against the type's limit, that the bytes are a
//! map carrying `"v"` equal to [`SCHEMA_VERSION`], that the fields decode, then the type's
//! [`Message::validate`] rules (finite numbers within physical bounds: positions within
//! [`MAX_COORD_M`], speeds below [`MAX_SPEED_MPS`], times within [`MAX_TIME_S`]; bounded list
//! lengths, positive radii). Any
//! failure is a [`DecodeError`]; nothing panics on untrusted input.

use crate::SCHEMA_VERSION;
use crate::messages::*;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// Most perceived bodies one observation may carry.
pub const MAX_NEIGHBOURS: usize = 512;
/// Most samples in one trajectory.
pub const MAX_SAMPLES: usize = 128;
/// Longest planner name.
pub const MAX_NAME: usize = 64;
/// Longest safety-layer setting a map may carry (`MapMsg::safety_layer`, bytes).
pub const MAX_LAYER_SETTING: usize = 1024;
/// Most rays in a visibility profile (a quarter of a degree apart).
pub const MAX_RAYS: usize = 1440;
/// Largest sensor range a visibility profile may state (m).
pub const MAX_SENSOR_RANGE: f64 = 1000.0;
/// Most robots in one metrics frame.
pub const MAX_ROBOTS: usize = 4096;
/// Most obstacles (and most vertices of one polygon) in a map.
pub const MAX_OBSTACLES: usize = 100_000;
/// Largest coordinate a position may have (m): ±1000 km, beyond any site.
pub const MAX_COORD_M: f64 = 1e6;
/// Fastest a robot or a person may move (m/s).
pub const MAX_SPEED_MPS: f64 = 50.0;
/// Fastest a robot may turn (rad/s).
pub const MAX_YAW_RATE: f64 = 100.0;
/// Largest time a message may state (s): 30 years of simulation.
pub const MAX_TIME_S: f64 = 1e9;
/// Largest body radius (m).
pub const MAX_RADIUS_M: f64 = 100.0;

/// Why bytes were rejected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecodeError {
    /// Longer than the message type allows.
    #[error("message of {len} bytes exceeds the limit of {max}")]
    TooLarge {
        /// Bytes received.
        len: usize,
        /// The type's limit.
        max: usize,
    },
    /// Not MessagePack of the expected shape.
    #[error("malformed message: {0}")]
    Malformed(String),
    /// Another schema version.
    #[error("schema version {got} is not the supported version {expected}")]
    Version {
        /// Version in the message.
        got: u16,
        /// [`SCHEMA_VERSION`].
        expected: u16,
    },
    /// A number that must be finite is NaN or infinite.
    #[error("field {0} is not finite")]
    NonFinite(&'static str),
    /// A list longer than its bound.
    #[error("field {field} has {len} entries, more than {max}")]
    TooMany {
        /// The list.
        field: &'static str,
        /// Its length.
        len: usize,
        /// The bound.
        max: usize,
    },
    /// A value outside its domain (negative radius, unsorted samples, …).
    #[error("field {field}: {reason}")]
    Invalid {
        /// The field.
        field: &'static str,
        /// What is wrong.
        reason: &'static str,
    },
}

/// A wire message: its size limit and its validity rules.
pub trait Message: Serialize + DeserializeOwned {
    /// Largest encoded size accepted.
    const MAX_BYTES: usize;
    /// Structural checks after decoding.
    fn validate(&self) -> Result<(), DecodeError>;
}

#[derive(Serialize)]
struct Wire<'a, M> {
    v: u16,
    #[serde(flatten)]
    body: &'a M,
}

#[derive(Deserialize)]
struct VersionProbe {
    v: u16,
}

/// Encodes `message` as a MessagePack map with the schema version.
pub fn encode<M: Message>(message: &M) -> Vec<u8> {
    let wire = Wire {
        v: SCHEMA_VERSION,
        body: message,
    };
    // Encoding plain data into a Vec cannot fail: every type here has string keys and no
    // custom serializer.
    rmp_serde::to_vec_named(&wire).unwrap_or_default()
}

/// Decodes and validates one message.
pub fn decode<M: Message>(bytes: &[u8]) -> Result<M, DecodeError> {
    if bytes.len() > M::MAX_BYTES {
        return Err(DecodeError::TooLarge {
            len: bytes.len(),
            max: M::MAX_BYTES,
        });
    }
    let version = match leading_version(bytes) {
        Some(v) => v,
        None => {
            let probe: VersionProbe =
                rmp_serde::from_slice(bytes).map_err(|e| DecodeError::Malformed(e.to_string()))?;
            probe.v
        }
    };
    if version != SCHEMA_VERSION {
        return Err(DecodeError::Version {
            got: version,
            expected: SCHEMA_VERSION,
        });
    }
    let message: M =
        rmp_serde::from_slice(bytes).map_err(|e| DecodeError::Malformed(e.to_string()))?;
    message.validate()?;
    Ok(message)
}

/// The schema version when it is the map's first entry, as [`encode`] writes it: read without
/// walking the rest of the message. Other encoders may put `v` anywhere; then this is `None`
/// and [`decode`] probes the whole map.
fn leading_version(bytes: &[u8]) -> Option<u16> {
    let mut rd = bytes;
    rmp::decode::read_map_len(&mut rd).ok()?;
    let (key, mut rest) = rmp::decode::read_str_from_slice(rd).ok()?;
    if key != "v" {
        return None;
    }
    rmp::decode::read_int(&mut rest).ok()
}

fn finite(field: &'static str, x: f64) -> Result<(), DecodeError> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(DecodeError::NonFinite(field))
    }
}

/// Finite and at most `max` in magnitude.
fn within(field: &'static str, x: f64, max: f64, reason: &'static str) -> Result<(), DecodeError> {
    finite(field, x)?;
    if x.abs() > max {
        return Err(DecodeError::Invalid { field, reason });
    }
    Ok(())
}

/// A position: finite, each coordinate within [`MAX_COORD_M`].
fn finite_p(field: &'static str, p: &P2) -> Result<(), DecodeError> {
    within(field, p.0, MAX_COORD_M, "beyond ±1e6 m")?;
    within(field, p.1, MAX_COORD_M, "beyond ±1e6 m")
}

/// A velocity: finite, slower than [`MAX_SPEED_MPS`].
fn velocity(field: &'static str, v: &P2) -> Result<(), DecodeError> {
    finite(field, v.0)?;
    finite(field, v.1)?;
    within(field, v.0.hypot(v.1), MAX_SPEED_MPS, "faster than 50 m/s")
}

/// A time: finite, within [`MAX_TIME_S`].
fn time(field: &'static str, t: f64) -> Result<(), DecodeError> {
    within(field, t, MAX_TIME_S, "beyond ±1e9 s")
}

/// A body radius: positive, at most [`MAX_RADIUS_M`].
fn radius(field: &'static str, r: f64) -> Result<(), DecodeError> {
    positive(field, r)?;
    within(field, r, MAX_RADIUS_M, "larger than 100 m")
}

fn bounded(field: &'static str, len: usize, max: usize) -> Result<(), DecodeError> {
    if len > max {
        Err(DecodeError::TooMany { field, len, max })
    } else {
        Ok(())
    }
}

fn non_negative(field: &'static str, x: f64) -> Result<(), DecodeError> {
    finite(field, x)?;
    if x < 0.0 {
        return Err(DecodeError::Invalid {
            field,
            reason: "must not be negative",
        });
    }
    Ok(())
}

fn positive(field: &'static str, x: f64) -> Result<(), DecodeError> {
    finite(field, x)?;
    if x <= 0.0 {
        return Err(DecodeError::Invalid {
            field,
            reason: "must be positive",
        });
    }
    Ok(())
}

fn trajectory(field: &'static str, samples: &[Sample]) -> Result<(), DecodeError> {
    bounded(field, samples.len(), MAX_SAMPLES)?;
    let mut last = f64::NEG_INFINITY;
    for s in samples {
        time(field, s.t)?;
        finite_p(field, &s.p)?;
        non_negative(field, s.sigma)?;
        if s.t < last {
            return Err(DecodeError::Invalid {
                field,
                reason: "sample times must be sorted",
            });
        }
        last = s.t;
    }
    Ok(())
}

fn name(field: &'static str, s: &str) -> Result<(), DecodeError> {
    bounded(field, s.len(), MAX_NAME)
}

impl Message for Observation {
    const MAX_BYTES: usize = 1 << 20;
    fn validate(&self) -> Result<(), DecodeError> {
        time("sim_time", self.sim_time)?;
        positive("dt", self.dt)?;
        within("dt", self.dt, 10.0, "longer than 10 s")?;
        finite_p("p", &self.p)?;
        finite("heading", self.heading)?;
        velocity("vel", &self.vel)?;
        within(
            "yaw_rate",
            self.yaw_rate,
            MAX_YAW_RATE,
            "faster than 100 rad/s",
        )?;
        radius("radius", self.radius)?;
        if let Some(goal) = &self.goal {
            finite_p("goal", goal)?;
        }
        bounded("neighbours", self.neighbours.len(), MAX_NEIGHBOURS)?;
        for n in &self.neighbours {
            finite_p("neighbours.p", &n.p)?;
            velocity("neighbours.vel", &n.vel)?;
            radius("neighbours.radius", n.radius)?;
            if let Some(intent) = &n.intent {
                trajectory("neighbours.intent", intent)?;
            }
        }
        if let Some(v) = &self.visibility {
            finite("visibility.bearing0", v.bearing0)?;
            positive("visibility.range", v.range)?;
            if v.range > MAX_SENSOR_RANGE {
                return Err(DecodeError::Invalid {
                    field: "visibility.range",
                    reason: "beyond 1000 m",
                });
            }
            if v.ranges.is_empty() {
                return Err(DecodeError::Invalid {
                    field: "visibility.ranges",
                    reason: "must not be empty",
                });
            }
            bounded("visibility.ranges", v.ranges.len(), MAX_RAYS)?;
            for &r in &v.ranges {
                finite("visibility.ranges", f64::from(r))?;
                if r < 0.0 || f64::from(r) > v.range * (1.0 + 1e-6) {
                    return Err(DecodeError::Invalid {
                        field: "visibility.ranges",
                        reason: "outside [0, range]",
                    });
                }
            }
        }
        Ok(())
    }
}

impl Message for IntentMsg {
    const MAX_BYTES: usize = 16 << 10;
    fn validate(&self) -> Result<(), DecodeError> {
        time("stamp", self.stamp)?;
        name("planner", &self.planner)?;
        finite_p("subgoal", &self.subgoal)?;
        trajectory("trajectory", &self.trajectory)
    }
}

impl Message for CommandMsg {
    const MAX_BYTES: usize = 512;
    fn validate(&self) -> Result<(), DecodeError> {
        time("stamp", self.stamp)?;
        if let Some(state) = &self.state {
            finite_p("state.p", &state.p)?;
            within("state.heading", state.heading, 1e3, "beyond ±1000 rad")?;
            velocity("state.vel", &state.vel)?;
            within(
                "state.yaw_rate",
                state.yaw_rate,
                MAX_YAW_RATE,
                "faster than 100 rad/s",
            )?;
            within("state.age", state.age, 1e3, "older than 1000 s")?;
            if state.age < 0.0 {
                return Err(DecodeError::Invalid {
                    field: "state.age",
                    reason: "negative",
                });
            }
        }
        match self.motion {
            Motion::Velocity(v) => velocity("motion", &v),
            Motion::Unicycle(speed, yaw_rate) => {
                within("motion", speed, MAX_SPEED_MPS, "faster than 50 m/s")?;
                within("motion", yaw_rate, MAX_YAW_RATE, "faster than 100 rad/s")
            }
        }
    }
}

/// Most candidates in a fan.
pub const MAX_CANDIDATES: usize = 64;

impl Message for FanMsg {
    const MAX_BYTES: usize = 256 << 10;
    fn validate(&self) -> Result<(), DecodeError> {
        time("stamp", self.stamp)?;
        bounded("candidates", self.candidates.len(), MAX_CANDIDATES)?;
        if self.best as usize >= self.candidates.len().max(1) {
            return Err(DecodeError::Invalid {
                field: "best",
                reason: "must index a candidate",
            });
        }
        for c in &self.candidates {
            bounded("candidates.path", c.path.len(), MAX_SAMPLES)?;
            for p in &c.path {
                finite_p("candidates.path", p)?;
            }
            finite("candidates.survival", c.survival)?;
            finite("candidates.expected_utility", c.expected_utility)?;
        }
        Ok(())
    }
}

impl Message for AgentInfo {
    const MAX_BYTES: usize = 1024;
    fn validate(&self) -> Result<(), DecodeError> {
        name("planner", &self.planner)?;
        name("version", &self.version)?;
        non_negative("plan_p99_us", self.plan_p99_us)
    }
}

impl Message for TaskAssignment {
    const MAX_BYTES: usize = 512;
    fn validate(&self) -> Result<(), DecodeError> {
        finite_p("pick", &self.pick)?;
        finite_p("drop", &self.drop)?;
        time("assigned_at", self.assigned_at)
    }
}

impl Message for FleetMetrics {
    const MAX_BYTES: usize = 4 << 20;
    fn validate(&self) -> Result<(), DecodeError> {
        finite("sim_time", self.sim_time)?;
        non_negative("collision_rate", self.collision_rate)?;
        non_negative("svr", self.svr)?;
        non_negative("stuck_robot_s", self.stuck_robot_s)?;
        if let Some(e) = self.efficiency {
            non_negative("efficiency", e)?;
        }
        if let Some(f) = self.free_flow_tasks_per_min {
            non_negative("free_flow_tasks_per_min", f)?;
        }
        let c = &self.stuck_causes;
        non_negative("stuck_causes.policy_s", c.policy_s)?;
        non_negative("stuck_causes.person_s", c.person_s)?;
        non_negative("stuck_causes.robot_s", c.robot_s)?;
        non_negative("stuck_causes.layer_s", c.layer_s)?;
        non_negative("stuck_causes.planner_s", c.planner_s)?;
        bounded("per_robot", self.per_robot.len(), MAX_ROBOTS)?;
        for r in &self.per_robot {
            non_negative("per_robot.collision_rate", r.collision_rate)?;
            non_negative("per_robot.svr", r.svr)?;
            non_negative("per_robot.social_force", r.social_force)?;
            if let Some(d) = r.min_human_distance {
                finite("per_robot.min_human_distance", d)?;
            }
            bounded("per_robot.waits_on", r.waits_on.len(), MAX_ROBOTS)?;
        }
        Ok(())
    }
}

/// Largest segment index a [`TrafficMsg`] may name.
pub const MAX_SEGMENTS: u32 = 1_000_000;
/// Largest station index a [`TrafficMsg`] may name.
pub const MAX_STATIONS: u32 = 1_000_000;

impl Message for TrafficMsg {
    const MAX_BYTES: usize = 256;
    fn validate(&self) -> Result<(), DecodeError> {
        finite("sim_time", self.sim_time)?;
        if let Some(goal) = &self.goal {
            finite_p("goal", goal)?;
        }
        let needs_goal = self.constraint != TrafficConstraint::Free;
        if needs_goal != self.goal.is_some() {
            return Err(DecodeError::Invalid {
                field: "goal",
                reason: "present exactly when the constraint is not free",
            });
        }
        if self.constraint == TrafficConstraint::Hold && self.segment.is_none() {
            return Err(DecodeError::Invalid {
                field: "segment",
                reason: "a hold names the segment it waits for",
            });
        }
        if self.constraint == TrafficConstraint::Queue && self.station.is_none() {
            return Err(DecodeError::Invalid {
                field: "station",
                reason: "a queue names the station it waits for",
            });
        }
        if self.station.is_some_and(|s| s >= MAX_STATIONS) {
            return Err(DecodeError::Invalid {
                field: "station",
                reason: "beyond the largest station index",
            });
        }
        if self.segment.is_some_and(|s| s >= MAX_SEGMENTS) {
            return Err(DecodeError::Invalid {
                field: "segment",
                reason: "beyond the largest segment index",
            });
        }
        if self.direction.is_some_and(|d| d != 1 && d != -1) {
            return Err(DecodeError::Invalid {
                field: "direction",
                reason: "must be +1 or -1",
            });
        }
        Ok(())
    }
}

impl Message for MapMsg {
    const MAX_BYTES: usize = 64 << 20;
    fn validate(&self) -> Result<(), DecodeError> {
        bounded("obstacles", self.obstacles.len(), MAX_OBSTACLES)?;
        for o in &self.obstacles {
            match o {
                ObstacleMsg::Polygon(points) => {
                    bounded("obstacles.polygon", points.len(), MAX_OBSTACLES)?;
                    if points.len() < 3 {
                        return Err(DecodeError::Invalid {
                            field: "obstacles.polygon",
                            reason: "a polygon needs at least 3 vertices",
                        });
                    }
                    for p in points {
                        finite_p("obstacles.polygon", p)?;
                    }
                }
                ObstacleMsg::Wall(a, b) => {
                    finite_p("obstacles.wall", a)?;
                    finite_p("obstacles.wall", b)?;
                }
            }
        }
        bounded("stations", self.stations.len(), MAX_OBSTACLES)?;
        for s in &self.stations {
            finite_p("stations.p", &s.p)?;
        }
        if let Some(places) = &self.turn_places {
            bounded("turn_places", places.len(), MAX_OBSTACLES)?;
            for [lo, hi] in places {
                finite_p("turn_places", lo)?;
                finite_p("turn_places", hi)?;
                if lo.0 > hi.0 || lo.1 > hi.1 {
                    return Err(DecodeError::Invalid {
                        field: "turn_places",
                        reason: "a box's lower corner must not exceed its upper one",
                    });
                }
            }
        }
        if let Some(setting) = &self.safety_layer {
            bounded("safety_layer", setting.len(), MAX_LAYER_SETTING)?;
        }
        finite_p("bounds", &self.bounds[0])?;
        finite_p("bounds", &self.bounds[1])
    }
}
