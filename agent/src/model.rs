//! The planner core's own view of the world: the ego robot, its neighbours, the goal, and what
//! a planner hands back (a command, an intent other robots can use, and optional debug data).
//!
//! These types are validated domain types: whoever builds them (the agent runtime from wire
//! messages, the simulator from its state) guarantees finite numbers and positive radii.

use crate::math::{Real, Vec2};

/// What kind of body a neighbour is. Planners may treat people and robots differently.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum AgentKind {
    /// A person.
    Human,
    /// Another robot of the fleet (or any other machine).
    Robot,
}

/// One sample of a planned or predicted trajectory: where, when and how uncertain.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct TrajectorySample {
    /// Seconds after the intent's stamp.
    pub t: Real,
    /// Mean position (world frame, metres).
    pub position: Vec2,
    /// Standard deviation of the position (metres, isotropic).
    pub sigma: Real,
}

/// A trajectory another robot has announced, with its uncertainty. Samples are sorted by `t`,
/// `t` starts at or after 0 (the time of the observation the planner works on).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SharedIntent {
    /// The announced samples.
    pub samples: Vec<TrajectorySample>,
}

/// Another body the ego perceives.
#[derive(Debug, Clone, PartialEq)]
pub struct Neighbour {
    /// Stable identifier while the body stays perceived (used for tie-breaking only).
    pub id: u64,
    /// Position (world frame, metres).
    pub position: Vec2,
    /// Velocity (world frame, m/s).
    pub velocity: Vec2,
    /// Turn rate of the velocity direction (rad/s); 0 when unknown.
    pub yaw_rate: Real,
    /// Body radius (metres).
    pub radius: Real,
    /// Person or robot.
    pub kind: AgentKind,
    /// The future trajectory it announced, if it is a robot that shares intents.
    pub intent: Option<SharedIntent>,
}

impl Neighbour {
    /// A neighbour without shared intent or turn rate.
    pub fn new(id: u64, position: Vec2, velocity: Vec2, radius: Real, kind: AgentKind) -> Self {
        Self {
            id,
            position,
            velocity,
            yaw_rate: 0.0,
            radius,
            kind,
            intent: None,
        }
    }
}

/// The robot doing the planning.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EgoState {
    /// Position (world frame, metres).
    pub position: Vec2,
    /// Body heading (radians, world frame). For a holonomic body this is the direction it
    /// faces, which need not be the direction of `velocity`.
    pub heading: Real,
    /// Velocity (world frame, m/s).
    pub velocity: Vec2,
    /// Turn rate (rad/s).
    pub yaw_rate: Real,
    /// Body radius (metres).
    pub radius: Real,
}

/// What the planner asks the base to do until the next plan.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Command {
    /// Holonomic: drive with this world-frame velocity (m/s).
    Velocity(Vec2),
    /// Unicycle: forward speed (m/s) and turn rate (rad/s).
    Unicycle {
        /// Forward speed along the heading.
        speed: Real,
        /// Turn rate, positive counter-clockwise.
        yaw_rate: Real,
    },
}

impl Command {
    /// The command that stops the robot.
    pub const STOP: Command = Command::Velocity(Vec2::new(0.0, 0.0));
}

/// What a robot intends: the point it steers to and the trajectory it expects to drive.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Intent {
    /// The goal handed to the short-term planner (PGP's subgoal, or the goal itself).
    pub subgoal: Vec2,
    /// Planned trajectory, starting after now, with its uncertainty.
    pub trajectory: Vec<TrajectorySample>,
}
