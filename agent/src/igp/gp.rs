//! The agent models of foIGP (Defs. 2–3): each person's and the robot's future positions as a
//! Gaussian process, a prior mean line with a kernel on the deviation from it, conditioned on
//! the positions seen so far.

use crate::math::{Real, Vec2};
use nalgebra::DMatrix;

/// The agent models: how a person's or the robot's future positions are distributed.
///
/// Every trajectory has a prior mean (the constant-velocity line for a person, a straight line
/// to the goal for the robot) and the kernel
/// `k(t, τ) = velocity_sigma² · t · τ + deviation_m² · exp(−(t − τ)² / (2 · lengthscale_s²))`
/// on the deviation from it, conditioned on the positions seen so far (noise `noise_m`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpParams {
    /// Time between trajectory samples (s): the recordings' 2.5 fps.
    pub dt: Real,
    /// Number of future samples T.
    pub steps: usize,
    /// Standard deviation of the smooth deviation from the prior line (m).
    pub deviation_m: Real,
    /// Time scale of that deviation (s).
    pub lengthscale_s: Real,
    /// Standard deviation of a constant velocity offset from the prior line (m/s).
    pub velocity_sigma: Real,
    /// Standard deviation of a measured position (m).
    pub noise_m: Real,
    /// Past positions (spaced at least `dt` apart) a person's GP is conditioned on.
    pub history: usize,
}

impl Default for GpParams {
    fn default() -> Self {
        Self {
            dt: 0.4,
            steps: 12,
            deviation_m: 0.3,
            lengthscale_s: 2.0,
            velocity_sigma: 0.15,
            noise_m: 0.05,
            history: 8,
        }
    }
}

impl GpParams {
    pub(super) fn kernel(&self, t: Real, tau: Real) -> Real {
        let d = t - tau;
        self.velocity_sigma.powi(2) * t * tau
            + self.deviation_m.powi(2) * (-d * d / (2.0 * self.lengthscale_s.powi(2))).exp()
    }

    /// The sample times t_k = k · dt, k = 1..=T.
    pub fn times(&self) -> impl Iterator<Item = Real> + '_ {
        (1..=self.steps).map(|k| k as Real * self.dt)
    }
}

/// One body's GP over its positions at the sample times: intent μ and flexibility Σ (the same
/// Σ for x and y).
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryGp {
    /// μ: mean positions at t_1..t_T.
    pub mean: Vec<Vec2>,
    /// Σ: covariance of a coordinate between sample times (T × T), measurement noise included.
    pub cov: DMatrix<Real>,
    /// Σ⁻¹.
    pub(super) precision: DMatrix<Real>,
    /// Lower Cholesky factor of Σ, for sampling.
    pub(super) chol: DMatrix<Real>,
}

impl TrajectoryGp {
    /// The GP of a body whose prior mean is `prior(t)`, conditioned on positions `seen`
    /// (time relative to now, ≤ 0).
    pub(super) fn conditioned(
        params: &GpParams,
        prior: impl Fn(Real) -> Vec2,
        seen: &[(Real, Vec2)],
    ) -> Self {
        let times: Vec<Real> = params.times().collect();
        let n = seen.len();
        let noise = params.noise_m.powi(2);
        let k_oo = DMatrix::from_fn(n, n, |a, b| {
            params.kernel(seen[a].0, seen[b].0) + if a == b { noise } else { 0.0 }
        });
        let k_so = DMatrix::from_fn(times.len(), n, |a, b| params.kernel(times[a], seen[b].0));
        let k_ss = DMatrix::from_fn(times.len(), times.len(), |a, b| {
            params.kernel(times[a], times[b])
        });
        let residual = DMatrix::from_fn(n, 2, |a, c| (seen[a].1 - prior(seen[a].0))[c]);
        // K_oo has the noise on its diagonal, so it is positive definite.
        let (alpha, reduced) = match k_oo.cholesky() {
            Some(chol) => (
                chol.solve(&residual),
                k_so.clone() * chol.solve(&k_so.transpose()),
            ),
            None => (
                DMatrix::zeros(n, 2),
                DMatrix::zeros(times.len(), times.len()),
            ),
        };
        let shift = &k_so * alpha;
        let mean = times
            .iter()
            .enumerate()
            .map(|(k, &t)| prior(t) + Vec2::new(shift[(k, 0)], shift[(k, 1)]))
            .collect();
        let mut cov = k_ss - reduced;
        cov = (&cov + cov.transpose()) * 0.5;
        for k in 0..times.len() {
            cov[(k, k)] += noise;
        }
        Self::from_mean_cov(mean, cov)
    }

    /// A GP with the given mean and covariance (symmetric positive definite; a little jitter is
    /// added if the factorisation needs it).
    pub fn from_mean_cov(mean: Vec<Vec2>, mut cov: DMatrix<Real>) -> Self {
        let n = cov.nrows();
        let mut jitter = 1e-9;
        let chol = loop {
            if let Some(c) = cov.clone().cholesky() {
                break c;
            }
            for k in 0..n {
                cov[(k, k)] += jitter;
            }
            jitter *= 10.0;
        };
        let precision = chol.inverse();
        Self {
            mean,
            cov,
            precision,
            chol: chol.l(),
        }
    }

    /// A person who is at `position` with `velocity` now and was at `past` before (times
    /// relative to now, negative): GP regression on the history around the constant-velocity
    /// line (foIGP, IGP_Diag).
    pub fn person(
        params: &GpParams,
        position: Vec2,
        velocity: Vec2,
        past: &[(Real, Vec2)],
    ) -> Self {
        let mut seen = Vec::with_capacity(past.len() + 1);
        seen.extend_from_slice(past);
        seen.push((0.0, position));
        Self::conditioned(params, |t| position + velocity * t, &seen)
    }

    /// A person's constant-velocity line with the kernel conditioned on the present position
    /// only (IGP_Lin's linear prediction model).
    pub fn linear(params: &GpParams, position: Vec2, velocity: Vec2) -> Self {
        Self::conditioned(params, |t| position + velocity * t, &[(0.0, position)])
    }

    /// A person at `position` walking with `velocity` who intends to go to `destination`: a
    /// mean that starts at their velocity and turns towards the destination at their speed,
    /// relaxing over the kernel's time scale (`lengthscale_s`) and stopping there, with the
    /// covariance of `flexibility`, the person's GP regressed on their history
    /// ([`TrajectoryGp::person`]; a GP's posterior covariance depends on when it was observed,
    /// not on its mean). The intent's prior mean is taken to pass through the observed track,
    /// so conditioning on it leaves the mean as it is: the track tells *which* intent through
    /// the preferences (`mixture::intent_weights`), and how flexible the person is through
    /// the covariance. (Regressing an intent line on the track instead would let the kernel's
    /// velocity term fit the observed heading and undo the intent.)
    pub fn towards(
        params: &GpParams,
        flexibility: &TrajectoryGp,
        position: Vec2,
        velocity: Vec2,
        destination: Vec2,
    ) -> Self {
        let speed = velocity.norm();
        // The mean integrated at 1/10 of a sample step: v̇ = (speed · û(d − p) − v) / τ.
        let substeps = 10;
        let h = params.dt / substeps as Real;
        let tau = params.lengthscale_s;
        let mut p = position;
        let mut v = velocity;
        let mut mean = Vec::with_capacity(params.steps);
        for _ in 0..params.steps {
            for _ in 0..substeps {
                let to = destination - p;
                let distance = to.norm();
                if distance <= speed * h || distance < 1e-9 {
                    p = destination;
                    v = Vec2::zeros();
                    continue;
                }
                let wanted = to * (speed / distance);
                v += (wanted - v) * (h / tau).min(1.0);
                p += v * h;
            }
            mean.push(p);
        }
        Self {
            mean,
            ..flexibility.clone()
        }
    }

    /// The robot: a straight line from `position` to `goal` at `speed`, stopping there.
    pub fn robot(params: &GpParams, position: Vec2, goal: Vec2, speed: Real) -> Self {
        let to_goal = goal - position;
        let distance = to_goal.norm();
        let direction = if distance > 1e-9 {
            to_goal / distance
        } else {
            Vec2::zeros()
        };
        Self::conditioned(
            params,
            |t| position + direction * (speed * t).min(distance),
            &[(0.0, position)],
        )
    }

    /// σ: the standard deviation of each sample's coordinates.
    pub fn sigma(&self) -> Vec<Real> {
        self.cov.diagonal().iter().map(|v| v.sqrt()).collect()
    }

    pub(super) fn steps(&self) -> usize {
        self.mean.len()
    }

    /// −½ (x − μ)ᵀ Σ⁻¹ (x − μ), both coordinates.
    pub(super) fn log_prior(&self, x: &[Vec2]) -> Real {
        let mut sum = 0.0;
        for (a, (xa, ma)) in x.iter().zip(&self.mean).enumerate() {
            let da = xa - ma;
            for (b, (xb, mb)) in x.iter().zip(&self.mean).enumerate() {
                sum += self.precision[(a, b)] * da.dot(&(xb - mb));
            }
        }
        -0.5 * sum
    }
}
