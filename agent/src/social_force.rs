//! The Social Force Model as PySocialForce 1.1.2 implements it (Helbing & Molnár 1995 with
//! Moussaïd et al.'s 2009 interaction force and 2010 group forces): the desired, social and
//! obstacle forces, the velocity cap, and every parameter (the group forces and the crowd's
//! update, which only simulated people need, are `world_sim::crowd`'s).
//!
//! This module holds the force law and the Social Force planner ([`SocialForceAgent`]); the
//! simulated crowd that steps many people by the same law lives in `world_sim::crowd`. The
//! arithmetic follows PySocialForce's, quirks included, because trajectories are
//! cross-checked against it:
//! - the interaction angle θ is the plain difference of two `atan2` angles, not wrapped;
//! - walls act through points sampled along them (`resolution` per metre, end points
//!   included), each point within range pushing on its own;
//! - the desired force pulls towards `max_speed` (1.3 × the initial speed by default);
//! - an agent closer than 0.5 m to its goal stops.

use crate::fastmath::{self, LaneSums};
use crate::map::StaticMap;
use crate::math::{Real, Vec2, left_normal, vec2};
use crate::model::{EgoState, Neighbour};
use crate::obstacle_points::ObstaclePoints;

/// `[desired_force]`
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct DesiredForceParams {
    /// Weight.
    pub factor: Real,
    /// Relaxation time (s).
    pub relaxation_time: Real,
    /// Closer than this to the goal (m), the force only brakes.
    pub goal_threshold: Real,
}

/// `[social_force]`: Moussaïd et al. 2009.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SocialForceParams {
    /// A: weight.
    pub factor: Real,
    /// λ: weight of the relative velocity in the interaction direction.
    pub lambda_importance: Real,
    /// γ: B = γ·‖D‖.
    pub gamma: Real,
    /// n: angular decay of the sideways force.
    pub n: Real,
    /// n′: angular decay of the deceleration force.
    pub n_prime: Real,
}

/// `[obstacle_force]`
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ObstacleForceParams {
    /// Weight.
    pub factor: Real,
    /// Decay length (m).
    pub sigma: Real,
    /// Range beyond the body radius (m).
    pub threshold: Real,
}

/// `[group_repulsive_force]`
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct GroupRepulsiveParams {
    /// Weight.
    pub factor: Real,
    /// Members closer than this push apart (m).
    pub threshold: Real,
}

/// All of PySocialForce's parameters; `Default` is what PySocialForce 1.1.2 uses with its
/// `default.toml`, except `step_width`. (Its `PedState` reads `step_width`, `agent_radius` and
/// `max_speed_multiplier` from the top level of the config while `default.toml` puts them
/// under `[scene]`, so its effective step is the code default of 0.4 s; ours is the
/// simulation step, 0.1 s by default.)
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SfParams {
    /// Integration step (s).
    pub step_width: Real,
    /// Body radius used by the obstacle force (m).
    pub agent_radius: Real,
    /// Maximum speed = this × initial (preferred) speed.
    pub max_speed_multiplier: Real,
    /// Obstacle sampling points per metre.
    pub resolution: Real,
    /// Whether the three group forces act.
    pub enable_group: bool,
    /// Desired force.
    pub desired: DesiredForceParams,
    /// Pedestrian interaction force.
    pub social: SocialForceParams,
    /// Obstacle force.
    pub obstacle: ObstacleForceParams,
    /// Group coherence weight (alternative, pedsim_ros form).
    pub group_coherence_factor: Real,
    /// Group repulsion.
    pub group_repulsive: GroupRepulsiveParams,
    /// Group gaze weight (alternative form).
    pub group_gaze_factor: Real,
    /// An agent closer than this to its goal stops (m).
    pub arrival_distance: Real,
    /// `None`: every pair interacts, as in PySocialForce (O(N²)). `Some(r)`: only pairs
    /// closer than r (m), found through a grid (O(N)); for large crowds. Not a PySocialForce
    /// parameter.
    pub interaction_range: Option<Real>,
}

impl Default for SfParams {
    fn default() -> Self {
        Self {
            step_width: 0.1,
            agent_radius: 0.35,
            max_speed_multiplier: 1.3,
            resolution: 10.0,
            enable_group: true,
            desired: DesiredForceParams {
                factor: 1.0,
                relaxation_time: 0.5,
                goal_threshold: 0.2,
            },
            social: SocialForceParams {
                factor: 5.1,
                lambda_importance: 2.0,
                gamma: 0.35,
                n: 2.0,
                n_prime: 3.0,
            },
            obstacle: ObstacleForceParams {
                factor: 10.0,
                sigma: 0.2,
                threshold: 3.0,
            },
            // PySocialForce looks a force's section up by its class name: the Alt group forces
            // it uses read `[group_coherence_force_alt]` and `[group_gaze_force_alt]`, which
            // default.toml does not have, so they act with factor 1.0, not its 3.0 and 4.0.
            group_coherence_factor: 1.0,
            group_repulsive: GroupRepulsiveParams {
                factor: 1.0,
                threshold: 0.55,
            },
            group_gaze_factor: 1.0,
            arrival_distance: 0.5,
            interaction_range: None,
        }
    }
}

/// `stateutils.normalize` for one vector: the unit vector and the norm, zero for zero. It
/// multiplies by 1/‖v‖ where numpy divides (one division instead of two; 1 ulp apart).
#[inline(always)]
pub fn normalize(v: Vec2) -> (Vec2, Real) {
    let n = v.norm();
    if n == 0.0 {
        (vec2(0.0, 0.0), 0.0)
    } else {
        (v * (1.0 / n), n)
    }
}

/// `DesiredForce`: relax towards `max_speed` along the direction to `goal`.
#[inline(always)]
pub fn desired_force(
    pos: Vec2,
    vel: Vec2,
    goal: Vec2,
    max_speed: Real,
    p: &DesiredForceParams,
) -> Vec2 {
    let (direction, dist) = normalize(goal - pos);
    let f = if dist > p.goal_threshold {
        direction * max_speed - vel
    } else {
        -vel
    };
    f / p.relaxation_time * p.factor
}

/// `SocialForce` exerted on `a` by `b` (without the overall factor). Straight-line code
/// (`exp` and `atan2` from [`fastmath`], selects for PySocialForce's special cases) so that
/// the crowd's loops over it vectorise.
#[inline(always)]
pub fn social_force_pair(
    pos_a: Vec2,
    vel_a: Vec2,
    pos_b: Vec2,
    vel_b: Vec2,
    p: &SocialForceParams,
) -> Vec2 {
    // The reaction is dead code here and is not computed.
    mutual_social_forces(pos_a, vel_a, pos_b, vel_b, p).0
}

/// The social forces of a pair on each other: on `a` by `b`, and on `b` by `a`.
///
/// Exchanging a and b negates D (the normalised position difference plus λ times the velocity
/// difference) and e (the direction between them) exactly, and keeps ‖D‖, B, and the angle w
/// from e to D. Only θ can differ, by ±2π, where PySocialForce's unwrapped difference of two
/// `atan2` angles jumps (see [`pysf_theta`]). So the pair shares two square roots, three
/// divisions and the arctangent, and each side pays for its two exponentials. Where θ is the
/// same both ways, the reaction is exactly minus the action.
///
/// The reaction is exactly [`social_force_pair`]`(pos_b, vel_b, pos_a, vel_a, p)` whenever
/// the two positions differ. For coincident positions (e = 0), θ is measured from the x axis
/// instead, which w does not give; callers recompute that case with [`social_force_pair`].
#[inline(always)]
pub fn mutual_social_forces(
    pos_a: Vec2,
    vel_a: Vec2,
    pos_b: Vec2,
    vel_b: Vec2,
    p: &SocialForceParams,
) -> (Vec2, Vec2) {
    let (diff_direction, diff_length) = normalize(pos_a - pos_b);
    let vel_diff = vel_b - vel_a;
    let (interaction_direction, interaction_length) =
        normalize(vel_diff * p.lambda_importance + diff_direction);
    let b = p.gamma * interaction_length;
    let w = pysf_angle(diff_direction, interaction_direction);
    let decay = -diff_length / b;
    let normal = left_normal(&interaction_direction);
    let theta_a = pysf_wrap(w, diff_direction, interaction_direction);
    let (velocity_on_a, angle_on_a) = force_amounts(decay, b, theta_a, p);
    let theta_b = pysf_wrap(w, -diff_direction, -interaction_direction);
    let (velocity_on_b, angle_on_b) = force_amounts(decay, b, theta_b, p);
    let on_a = interaction_direction * velocity_on_a + normal * angle_on_a;
    let on_b = -(interaction_direction * velocity_on_b + normal * angle_on_b);
    // PySocialForce divides by B = 0 when ‖D‖ = 0; numpy's exp(−inf) makes the force zero.
    if b == 0.0 {
        (vec2(0.0, 0.0), vec2(0.0, 0.0))
    } else {
        (on_a, on_b)
    }
}

/// The deceleration and sideways amounts of the social force for e^(−d/B) = e^`decay`, B and
/// θ (a plain function, not a closure, so that it is compiled into the vectorised loops).
#[inline(always)]
fn force_amounts(decay: Real, b: Real, theta: Real, p: &SocialForceParams) -> (Real, Real) {
    let velocity_amount = fastmath::exp(decay - (p.n_prime * b * theta).powi(2));
    let sign = if theta > 0.0 {
        1.0
    } else if theta < 0.0 {
        -1.0
    } else {
        0.0
    };
    let angle_amount = -sign * fastmath::exp(decay - (p.n * b * theta).powi(2));
    (velocity_amount, angle_amount)
}

/// θ = atan2(i) − atan2(e), not wrapped into (−π, π], as PySocialForce computes the
/// interaction angle (`vec_diff_angle`), with one `atan2` instead of two: the angle w from e to
/// i in [−π, π], moved by 2π when the turn from e to i crosses the negative x axis, where the
/// two angles jump (e in the upper half-plane and i in the lower one with w > 0, or the
/// reverse with w < 0; the half-planes are told apart by sign bits, as `atan2` does). For
/// e = 0, `atan2(e)` = 0 and θ = atan2(i); for i = 0, θ = −atan2(e).
#[inline(always)]
pub fn pysf_theta(e: Vec2, i: Vec2) -> Real {
    pysf_wrap(pysf_angle(e, i), e, i)
}

/// The `atan2` of [`pysf_theta`]: the angle w from e to i, or the special cases' angles.
#[inline(always)]
fn pysf_angle(e: Vec2, i: Vec2) -> Real {
    let e_zero = (e.x == 0.0) & (e.y == 0.0);
    let i_zero = (i.x == 0.0) & (i.y == 0.0);
    let (y, x) = if e_zero {
        (i.y, i.x)
    } else if i_zero {
        (-e.y, e.x)
    } else {
        (e.x * i.y - e.y * i.x, e.x * i.x + e.y * i.y)
    };
    fastmath::atan2(y, x)
}

/// The 2π move of [`pysf_theta`], for w = [`pysf_angle`]`(e, i)`.
#[inline(always)]
fn pysf_wrap(w: Real, e: Vec2, i: Vec2) -> Real {
    use std::f64::consts::TAU;
    let (e_lower, i_lower) = (e.y.is_sign_negative(), i.y.is_sign_negative());
    // Parallel vectors on the negative x axis with zeros of opposite sign: π vs −π.
    let on_the_cut = (w == 0.0) & (e.x < 0.0);
    if !e_lower & i_lower & ((w > 0.0) | on_the_cut) {
        w - TAU
    } else if e_lower & !i_lower & ((w < 0.0) | on_the_cut) {
        w + TAU
    } else {
        w
    }
}

/// `ObstacleForce` on a body at `pos`: the pushes of every point (the Social Force planner's
/// walls; the crowd visits only the points near each person, with the same bits, through
/// `world_sim::crowd::Walls`).
#[inline(always)]
pub fn obstacle_force(
    pos: Vec2,
    obstacles: &ObstaclePoints,
    radius: Real,
    p: &ObstacleForceParams,
) -> Vec2 {
    let mut acc = LaneSums::ZERO;
    obstacles.add_pushes(
        &mut acc,
        pos,
        radius,
        p.threshold + radius,
        p.sigma,
        (0, obstacles.blocks()),
    );
    acc.total() * p.factor
}

/// `PedState.capped_velocity` for one agent.
#[inline]
pub fn capped_velocity(desired: Vec2, max_speed: Real) -> Vec2 {
    let speed = desired.norm();
    if speed == 0.0 {
        return vec2(0.0, 0.0);
    }
    desired * (max_speed / speed).min(1.0)
}

/// The Social Force planner's parameters; `Default` is the PGP paper's Table I
/// (v^max = 1 m/s, A = 5.1, λ = 3.0, γ = 0.35, n = 1, n′ = 3.0) on PySocialForce's other
/// defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SfAgentParams {
    /// Force model parameters (groups are not used by the planner).
    pub model: SfParams,
    /// v^max (m/s): the desired force pulls towards it and the velocity is capped at it.
    pub max_speed: Real,
}

impl Default for SfAgentParams {
    fn default() -> Self {
        let model = SfParams {
            social: SocialForceParams {
                factor: 5.1,
                lambda_importance: 3.0,
                gamma: 0.35,
                n: 1.0,
                n_prime: 3.0,
            },
            enable_group: false,
            ..SfParams::default()
        };
        Self {
            model,
            max_speed: 1.0,
        }
    }
}

/// A robot that moves like a Social Force pedestrian: one force evaluation per plan.
#[derive(Debug, Clone)]
pub struct SocialForceAgent {
    params: SfAgentParams,
}

impl SocialForceAgent {
    /// A planner with the given parameters.
    pub fn new(params: SfAgentParams) -> Self {
        Self { params }
    }

    /// The parameters in use.
    pub fn params(&self) -> &SfAgentParams {
        &self.params
    }

    /// The total force on the ego driving towards `target`.
    pub fn force(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        target: Vec2,
    ) -> Vec2 {
        let m = &self.params.model;
        let mut social = vec2(0.0, 0.0);
        for nb in neighbours {
            social += social_force_pair(
                ego.position,
                ego.velocity,
                nb.position,
                nb.velocity,
                &m.social,
            );
        }
        let points = map.sampled_points(m.resolution);
        desired_force(
            ego.position,
            ego.velocity,
            target,
            self.params.max_speed,
            &m.desired,
        ) + social * m.social.factor
            + obstacle_force(ego.position, &points, ego.radius, &m.obstacle)
    }

    /// The velocity command: v + dt·F, capped at v^max, zero within the arrival distance.
    pub fn command(
        &mut self,
        ego: &EgoState,
        neighbours: &[Neighbour],
        map: &StaticMap,
        target: Vec2,
        dt: Real,
    ) -> Vec2 {
        if (target - ego.position).norm() < self.params.model.arrival_distance {
            return vec2(0.0, 0.0);
        }
        let f = self.force(ego, neighbours, map, target);
        capped_velocity(ego.velocity + f * dt, self.params.max_speed)
    }
}

#[cfg(test)]
mod tests;
