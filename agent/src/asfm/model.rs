//! The Social Force Model of the paper's Sec. II: the circular repulsion of Eq. 3, the
//! attraction of Eqs. 4–5 and the update of Eq. 1, for bodies with or without radii. The
//! exponential is [`crate::fastmath::exp`] (within 2 ulp of libm's, inlined).

use crate::fastmath::exp;
use crate::math::{Real, Vec2, vec2};

/// Eq. 3: A·e^{−‖d‖/B}·d/‖d‖ on a body at relative position `d` = r_i − r_j. With bodies
/// (`radii` > 0) the distance in the exponent is between surfaces, ‖d‖ − radii; the paper's
/// bodies are points (radii 0).
#[inline]
pub fn repulsion(d: Vec2, radii: Real, strength: Real, range: Real) -> Vec2 {
    let norm = d.norm();
    if norm == 0.0 || strength == 0.0 {
        return vec2(0.0, 0.0);
    }
    d * (strength * exp(-(norm - radii) / range) / norm)
}

/// Eq. 3's direction and decay without the strength: e^{−(‖d‖ − radii)/B}·d/‖d‖. Eq. 3 is
/// linear in A, so one unit push serves every A of the estimate.
#[inline]
pub fn unit_repulsion(d: Vec2, radii: Real, range: Real) -> Vec2 {
    repulsion(d, radii, 1.0, range)
}

/// Eq. 4: (v⁰ − v)/τ.
#[inline]
pub fn attraction(desired: Vec2, velocity: Vec2, tau: Real) -> Vec2 {
    (desired - velocity) / tau
}

/// Eq. 5: v^max toward the goal; zero at the goal.
#[inline]
pub fn desired_toward(goal: Vec2, position: Vec2, v_max: Real) -> Vec2 {
    let to = goal - position;
    let norm = to.norm();
    if norm == 0.0 {
        vec2(0.0, 0.0)
    } else {
        to * (v_max / norm)
    }
}

/// Eq. 1 for the position and Eq. 11 for the velocity: one step of Δt under acceleration `a`.
#[inline]
pub fn step(position: Vec2, velocity: Vec2, a: Vec2, dt: Real) -> (Vec2, Vec2) {
    (
        position + velocity * dt + a * (0.5 * dt * dt),
        velocity + a * dt,
    )
}
