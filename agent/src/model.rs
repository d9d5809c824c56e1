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

/// The drive a command goes to. A simulated robot and an omnidirectional base execute velocity
/// commands as they are; a differential drive cannot move sideways, so a velocity command is
/// first turned into the forward speed and turn rate that follow it ([`Base::executable`]), and
/// the safety layer checks that.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Base {
    /// Executes velocity and unicycle commands (the simulator's robots, omnidirectional bases).
    #[default]
    Holonomic,
    /// Executes unicycle commands only.
    Differential {
        /// Turn rate limit (rad/s).
        max_yaw_rate: Real,
    },
}

/// A differential base turns toward a velocity command's direction at this rate per radian of
/// heading error (1/s): a quarter turn takes about 0.8 s at 2 rad/s.
pub const HEADING_GAIN: Real = 2.0;

impl Base {
    /// What this base can execute of `command` from `ego`: for a differential drive, a velocity
    /// command becomes a turn toward it at [`HEADING_GAIN`] and the speed along the heading that
    /// does not drive off its line (none while it points more than 90° away).
    pub fn executable(self, command: Command, ego: &EgoState) -> Command {
        match (self, command) {
            (Base::Differential { max_yaw_rate }, Command::Velocity(v)) => {
                let speed = v.norm();
                if speed < 1e-9 {
                    return Command::Unicycle {
                        speed: 0.0,
                        yaw_rate: 0.0,
                    };
                }
                let error = crate::math::wrap_angle(crate::math::angle_of(&v) - ego.heading);
                Command::Unicycle {
                    speed: speed * error.cos().max(0.0),
                    yaw_rate: (HEADING_GAIN * error).clamp(-max_yaw_rate, max_yaw_rate),
                }
            }
            _ => command,
        }
    }
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
