//! Robot bodies: holonomic or unicycle motion under speed and acceleration limits. A body
//! moves the way its command asks (a velocity command drives it holonomically, a (v, ω)
//! command as a unicycle), never faster or harder than its limits allow.

use crate::scenario::RobotSpec;
use agent::math::{Real, Vec2, angle_of, clamp_norm, unit};
use agent::model::{Command, EgoState};

/// A simulated robot.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RobotBody {
    /// Position, heading, velocity, yaw rate, radius.
    pub state: EgoState,
    /// Where it is going.
    pub goal: Vec2,
    /// Limits.
    pub spec: RobotSpec,
    /// A real robot the world does not move: it stands where it was last placed
    /// ([`RobotBody::place`]), as its own odometry reported it, whatever its command.
    #[serde(default)]
    pub external: bool,
}

impl RobotBody {
    /// A robot at rest at `start`, facing `goal`.
    pub fn new(start: Vec2, goal: Vec2, spec: RobotSpec) -> Self {
        let heading = angle_of(&(goal - start));
        let state = EgoState {
            position: start,
            heading,
            velocity: Vec2::zeros(),
            yaw_rate: 0.0,
            radius: spec.radius_m,
        };
        Self {
            state,
            goal,
            spec,
            external: false,
        }
    }

    /// Puts the body where its robot reported itself: position, heading, velocity and turn
    /// rate (the radius is the body's own).
    pub fn place(&mut self, position: Vec2, heading: Real, velocity: Vec2, yaw_rate: Real) {
        let s = &mut self.state;
        s.position = position;
        s.heading = heading;
        s.velocity = velocity;
        s.yaw_rate = yaw_rate;
    }

    /// Executes `command` for `dt` seconds within the limits; an external body stays where it
    /// was placed.
    pub fn apply(&mut self, command: Command, dt: Real) {
        if self.external {
            return;
        }
        let s = &mut self.state;
        let lim = &self.spec;
        match command {
            Command::Velocity(v) => {
                let target = clamp_norm(v, lim.max_speed);
                s.velocity += clamp_norm(target - s.velocity, lim.max_accel * dt);
                if s.velocity.norm() > 1e-3 {
                    s.heading = angle_of(&s.velocity);
                }
                s.yaw_rate = 0.0;
            }
            Command::Unicycle { speed, yaw_rate } => {
                let current = s.velocity.dot(&unit(s.heading));
                let target = speed.clamp(-lim.max_speed, lim.max_speed);
                let v = current + (target - current).clamp(-lim.max_accel * dt, lim.max_accel * dt);
                let w_target = yaw_rate.clamp(-lim.max_yaw_rate, lim.max_yaw_rate);
                let dw =
                    (w_target - s.yaw_rate).clamp(-lim.max_yaw_accel * dt, lim.max_yaw_accel * dt);
                s.yaw_rate += dw;
                s.heading += s.yaw_rate * dt;
                s.velocity = unit(s.heading) * v;
            }
        }
        s.position += s.velocity * dt;
    }

    /// Whether the goal is within the tolerance.
    pub fn arrived(&self) -> bool {
        (self.goal - self.state.position).norm() < self.spec.goal_tolerance_m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;
    use agent::math::vec2;

    fn body() -> RobotBody {
        let spec = Scenario::builtin("open-space").expect("valid").robot;
        RobotBody::new(vec2(0.0, 0.0), vec2(10.0, 0.0), spec)
    }

    /// A real robot's body goes where it is placed and nowhere else, whatever its command.
    #[test]
    fn an_external_body_stays_where_it_was_placed() {
        let mut b = body();
        b.external = true;
        b.place(vec2(2.0, 1.0), 0.5, vec2(0.3, 0.0), 0.1);
        for _ in 0..10 {
            b.apply(Command::Velocity(vec2(1.0, 1.0)), 0.1);
        }
        assert_eq!(b.state.position, vec2(2.0, 1.0));
        assert_eq!(b.state.velocity, vec2(0.3, 0.0));
        assert_eq!((b.state.heading, b.state.yaw_rate), (0.5, 0.1));
        b.external = false;
        b.apply(Command::Velocity(vec2(1.0, 0.0)), 0.1);
        assert_ne!(
            b.state.position,
            vec2(2.0, 1.0),
            "simulated again, it moves"
        );
    }

    #[test]
    fn velocity_commands_respect_acceleration_and_speed() {
        let mut b = body();
        b.apply(Command::Velocity(vec2(5.0, 0.0)), 0.1);
        assert!(
            (b.state.velocity.x - 0.15).abs() < 1e-12,
            "1.5 m/s² for 0.1 s"
        );
        for _ in 0..20 {
            b.apply(Command::Velocity(vec2(5.0, 0.0)), 0.1);
        }
        assert!(
            (b.state.velocity.norm() - 1.0).abs() < 1e-12,
            "capped at max_speed"
        );
    }

    #[test]
    fn unicycle_commands_respect_turn_limits() {
        let mut b = body();
        b.apply(
            Command::Unicycle {
                speed: 1.0,
                yaw_rate: 5.0,
            },
            0.1,
        );
        assert!(
            (b.state.yaw_rate - 0.15).abs() < 1e-12,
            "1.5 rad/s² for 0.1 s"
        );
        for _ in 0..20 {
            b.apply(
                Command::Unicycle {
                    speed: 1.0,
                    yaw_rate: 5.0,
                },
                0.1,
            );
        }
        assert!(
            (b.state.yaw_rate - 1.0).abs() < 1e-12,
            "capped at max_yaw_rate"
        );
        assert!((b.state.velocity.norm() - 1.0).abs() < 1e-12);
    }
}
