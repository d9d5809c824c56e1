//! One tracked body: the Kalman filter of Sec. III-C (Eqs. 7–10) on its noisy observed
//! position, and the Bayesian estimate of its avoidance strength A_o of Sec. III-D1
//! (Eqs. 12–14) over a discrete set of samples A_o^i.

use super::AsfmParams;
use super::model::{attraction, desired_toward, step, unit_repulsion};
use crate::math::{Real, Vec2};
use crate::model::Neighbour;

/// What a body walks toward: a known goal (the paper assumes one, estimated by \[12\], \[13\]),
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
    /// Time since it was first perceived (s).
    pub age: Real,
}

impl Tracked {
    /// `body` at first sight, with the prior N(0, σ²) over `samples`.
    pub fn new(body: &Neighbour, heading: Heading, samples: &[Real], p: &AsfmParams) -> Self {
        let var = p.prior_sigma * p.prior_sigma;
        let mut log_posterior: Vec<Real> = samples.iter().map(|a| -a * a / (2.0 * var)).collect();
        normalise(&mut log_posterior);
        let mut t = Self {
            id: body.id,
            radius: body.radius,
            raw: body.position,
            filtered: body.position,
            velocity: body.velocity,
            p: p.kalman_p0,
            heading,
            log_posterior,
            estimate: 0.0,
            unseen: 0.0,
            age: 0.0,
        };
        t.estimate = t.mean(samples);
        t
    }

    /// v⁰_o at `position` (Eq. 5, or the intended velocity).
    pub fn desired(&self, position: Vec2, p: &AsfmParams) -> Vec2 {
        match self.heading {
            Heading::Goal(g) => desired_toward(g, position, p.people_speed),
            Heading::Intended(v) => v,
        }
    }

    /// Eq. 1 over `dt` from (`r`, `v`) under Eq. 2 with strength `a`, the robot's push `u`
    /// (Eq. 3 per unit A) and v⁰ held at their values at the interval's start, in steps of at
    /// most the model's Δt (observations may come less often, e.g. every 0.4 s in ETH; the
    /// relaxation time τ = 0.1 s needs steps no longer than it). One step is Eq. 1 itself.
    fn predict(
        &self,
        (r, v): (Vec2, Vec2),
        a: Real,
        u: Vec2,
        desired: Vec2,
        dt: Real,
        p: &AsfmParams,
    ) -> (Vec2, Vec2) {
        let n = ((dt / p.dt - 1e-9).ceil() as usize).max(1);
        let h = dt / n as Real;
        let (mut r, mut v) = (r, v);
        for _ in 0..n {
            (r, v) = step(r, v, u * a + attraction(desired, v, p.tau), h);
        }
        (r, v)
    }

    /// One observation `z` taken `dt` after the last; the robot stood at `robot` (position,
    /// radius) at the last one. The filter's model uses `fixed` as A_o when given (the
    /// paper's fixed-Â_o methods), else the estimate.
    pub fn observe(
        &mut self,
        z: Vec2,
        dt: Real,
        robot: (Vec2, Real),
        samples: &[Real],
        fixed: Option<Real>,
        p: &AsfmParams,
    ) {
        let push = |at: Vec2| unit_repulsion(at - robot.0, self.radius + robot.1, p.range);
        // Eq. 7's prediction r̂′(t): the model (Eqs. 1–2) from r̂(t−Δt), v̂(t−Δt) with the
        // Â_o of then.
        let a_model = fixed.unwrap_or(self.estimate);
        let (predicted, predicted_v) = self.predict(
            (self.filtered, self.velocity),
            a_model,
            push(self.filtered),
            self.desired(self.filtered, p),
            dt,
            p,
        );
        // Eqs. 12–14 on the raw observations: sample i predicts
        // r̃(t−Δt) + v̂(t−Δt)·Δt + ½·â_i(t−Δt)·Δt², â_i = A_i·u + attraction (Eq. 2). Eq. 3 is
        // linear in A, so the prediction is m0 + A_i·w: the residual is e0 − A_i·w.
        let start = (self.raw, self.velocity);
        let (u, desired) = (push(self.raw), self.desired(self.raw, p));
        let m0 = self.predict(start, 0.0, u, desired, dt, p).0;
        let w = self.predict(start, 1.0, u, desired, dt, p).0 - m0;
        let e0 = z - m0;
        let two_var = 2.0 * p.likelihood_variance;
        for (lp, a) in self.log_posterior.iter_mut().zip(samples) {
            *lp -= (e0 - w * *a).norm_squared() / two_var;
        }
        normalise(&mut self.log_posterior);
        self.estimate = self.mean(samples);

        // Eqs. 7–9: correct the prediction with z.
        let gain = self.p / (self.p + p.kalman_r);
        let filtered = predicted + (z - predicted) * gain;
        self.p = (1.0 - gain) * self.p + p.process_noise;
        // Eq. 10, v̂(t) = (r̂(t) − r̂(t−Δt) + ½·â·Δt²)/Δt: the model's velocity plus the
        // correction's (the same for one step, and defined for several).
        let velocity = predicted_v + (filtered - predicted) / dt;
        self.filtered = filtered;
        self.velocity = velocity;
        if let Heading::Intended(v) = &mut self.heading {
            *v += (velocity - *v) * (dt / p.intent_time).min(1.0);
        }
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
