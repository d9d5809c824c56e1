//! One tracked body: the Kalman filter of Sec. III-C (Eqs. 7–10) on its noisy observed
//! position, and the Bayesian estimate of its avoidance strength A_o of Sec. III-D1
//! (Eqs. 12–14) over a discrete set of samples A_o^i.

use super::AsfmParams;
use super::model::{attraction, desired_toward, unit_repulsion};
use crate::math::{Real, Vec2};
use crate::model::Neighbour;

/// What a body walks toward: a known goal (the paper assumes one, estimated by [12], [13]),
/// or, when none is known, the velocity it intends, estimated as a slow average of its
/// filtered velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Heading {
    /// Eq. 5 toward this goal at the params' `people_speed`.
    Goal(Vec2),
    /// v⁰_o itself.
    Intended(Vec2),
}

/// One body the robot tracks.
#[derive(Debug, Clone)]
pub struct Tracked {
    /// The perception's identifier.
    pub id: u64,
    /// Body radius (m).
    pub radius: Real,
    /// r̃_o(t): the last raw observation.
    pub raw: Vec2,
    /// r̂_o(t): the filtered position (Eq. 7).
    pub filtered: Vec2,
    /// v̂_o(t): the velocity estimate (Eq. 10).
    pub velocity: Vec2,
    /// â_o(t): the model's acceleration at r̂_o(t), v̂_o(t) with Â_o (Eq. 2), used by the next
    /// prediction and Eq. 10.
    pub accel: Vec2,
    /// P (isotropic, m²).
    pub p: Real,
    /// What the body walks toward.
    pub heading: Heading,
    /// Log posterior over the samples A_o^i, up to a constant (its largest entry is 0).
    log_posterior: Vec<Real>,
    /// Â_o: the posterior mean.
    pub estimate: Real,
    /// Time since it was last perceived (s).
    pub unseen: Real,
}

impl Tracked {
    /// `body` at first sight, with the prior N(0, σ²) over `samples`; `robot` is the robot's
    /// position and radius now; the filter's model uses `fixed` as A_o when given.
    pub fn new(
        body: &Neighbour,
        heading: Heading,
        robot: (Vec2, Real),
        samples: &[Real],
        fixed: Option<Real>,
        p: &AsfmParams,
    ) -> Self {
        let var = p.prior_sigma * p.prior_sigma;
        let mut log_posterior: Vec<Real> = samples.iter().map(|a| -a * a / (2.0 * var)).collect();
        normalise(&mut log_posterior);
        let mut t = Self {
            id: body.id,
            radius: body.radius,
            raw: body.position,
            filtered: body.position,
            velocity: body.velocity,
            accel: Vec2::zeros(),
            p: p.kalman_p0,
            heading,
            log_posterior,
            estimate: 0.0,
            unseen: 0.0,
        };
        t.estimate = t.mean(samples);
        let a = fixed.unwrap_or(t.estimate);
        t.accel = t.model_accel(t.filtered, t.velocity, a, robot, p);
        t
    }

    /// v⁰_o at `position` (Eq. 5, or the intended velocity).
    pub fn desired(&self, position: Vec2, p: &AsfmParams) -> Vec2 {
        match self.heading {
            Heading::Goal(g) => desired_toward(g, position, p.people_speed),
            Heading::Intended(v) => v,
        }
    }

    /// Eq. 2 on this body at `position`, `velocity` with strength `a` against the robot at
    /// `robot` (position, radius): Eq. 3 from the robot plus Eq. 4.
    fn model_accel(
        &self,
        position: Vec2,
        velocity: Vec2,
        a: Real,
        robot: (Vec2, Real),
        p: &AsfmParams,
    ) -> Vec2 {
        unit_repulsion(position - robot.0, self.radius + robot.1, p.range) * a
            + attraction(self.desired(position, p), velocity, p.tau)
    }

    /// One observation `z` taken `dt` after the last; the robot stood at `robot_before` then
    /// and stands at `robot_now` now (position, radius). The filter's model uses `fixed` as
    /// A_o when given (the paper's fixed-Â_o methods), else the estimate.
    #[allow(clippy::too_many_arguments)]
    pub fn observe(
        &mut self,
        z: Vec2,
        dt: Real,
        robot_before: (Vec2, Real),
        robot_now: (Vec2, Real),
        samples: &[Real],
        fixed: Option<Real>,
        p: &AsfmParams,
    ) {
        // Eqs. 12–14 on the raw observations: sample i predicts
        // r̃(t−Δt) + v̂(t−Δt)·Δt + ½·â_i(t−Δt)·Δt², with â_i = A_i·u + attraction (Eq. 2; Eq. 3
        // is linear in A). The residual is e0 − A_i·w.
        let half = 0.5 * dt * dt;
        let u = unit_repulsion(
            self.raw - robot_before.0,
            self.radius + robot_before.1,
            p.range,
        );
        let att = attraction(self.desired(self.raw, p), self.velocity, p.tau);
        let e0 = z - self.raw - self.velocity * dt - att * half;
        let w = u * half;
        let two_var = 2.0 * p.likelihood_variance;
        for (lp, a) in self.log_posterior.iter_mut().zip(samples) {
            *lp -= (e0 - w * *a).norm_squared() / two_var;
        }
        normalise(&mut self.log_posterior);
        self.estimate = self.mean(samples);

        // Eqs. 7–9: predict with the model (Eq. 1 under â(t−Δt)), correct with z.
        let predicted = self.filtered + self.velocity * dt + self.accel * half;
        let gain = self.p / (self.p + p.kalman_r);
        let filtered = predicted + (z - predicted) * gain;
        self.p = (1.0 - gain) * self.p + p.process_noise;
        // Eq. 10.
        let velocity = (filtered - self.filtered + self.accel * half) / dt;
        self.filtered = filtered;
        self.velocity = velocity;
        if let Heading::Intended(v) = &mut self.heading {
            *v += (velocity - *v) * (dt / p.intent_time).min(1.0);
        }
        let a = fixed.unwrap_or(self.estimate);
        self.accel = self.model_accel(filtered, velocity, a, robot_now, p);
        self.raw = z;
        self.unseen = 0.0;
    }

    /// The posterior mean over `samples`.
    fn mean(&self, samples: &[Real]) -> Real {
        let (mut num, mut den) = (0.0, 0.0);
        for (lp, a) in self.log_posterior.iter().zip(samples) {
            let w = lp.exp();
            num += w * a;
            den += w;
        }
        num / den
    }

    /// The posterior's probabilities over the samples (they sum to 1).
    pub fn posterior(&self) -> Vec<Real> {
        let w: Vec<Real> = self.log_posterior.iter().map(|lp| lp.exp()).collect();
        let sum: Real = w.iter().sum();
        w.into_iter().map(|x| x / sum).collect()
    }
}

/// Shifts log weights so that the largest is 0 (keeps exp() in range; the posterior is the
/// same).
fn normalise(log_weights: &mut [Real]) {
    let top = log_weights
        .iter()
        .copied()
        .fold(Real::NEG_INFINITY, Real::max);
    if top.is_finite() {
        for lp in log_weights.iter_mut() {
            *lp -= top;
        }
    }
}
