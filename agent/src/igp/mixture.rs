//! foIGP's agent models as GP mixtures (Eq. 3.1, Defs. 2–3): a person has one intent per
//! destination of the scene, each a GP (the mean is where they would go, the covariance how
//! far they would compromise), with a preference w_k updated from the track.
//!
//! The rule for the preferences, ours (the paper leaves it open): a uniform prior over the
//! destinations, times the likelihood of every velocity seen in the kept history (the steps
//! between stored positions, and the present velocity) if the person were walking at that
//! speed straight at the destination, with independent Gaussian errors of variance
//! `velocity_sigma² + 2 noise_m² / Δt²` per axis: the GP's own velocity flexibility plus the
//! error of a velocity measured from two noisy positions Δt apart. Nothing is tuned.

use super::gp::{GpParams, TrajectoryGp};
use crate::math::{Real, Vec2};

/// Intents whose preference is below this share of the person's most preferred one are
/// dropped (an implementation cut-off: at 1 % they cannot win a combination against the
/// most preferred intent unless that one collides almost surely).
pub const MIN_RELATIVE_WEIGHT: Real = 0.01;

/// One intent of a person: the GP component and its preference w_k.
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    /// w_k (the kept components of a person sum to 1).
    pub weight: Real,
    /// 𝒩(μ_k, Σ_k).
    pub gp: TrajectoryGp,
}

/// The preferences w_k of a person seen at `seen` (time relative to now, oldest first, the
/// present last) moving with `velocity` now, for each of `destinations`; they sum to 1.
pub fn intent_weights(
    params: &GpParams,
    seen: &[(Real, Vec2)],
    velocity: Vec2,
    destinations: &[Vec2],
) -> Vec<Real> {
    let mut log_w = vec![0.0; destinations.len()];
    let mut observe = |from: Vec2, v: Vec2, dt: Real| {
        let variance = params.velocity_sigma.powi(2) + 2.0 * params.noise_m.powi(2) / (dt * dt);
        let speed = v.norm();
        for (lw, d) in log_w.iter_mut().zip(destinations) {
            let to = d - from;
            let expected = if to.norm() > 1e-9 {
                to * (speed / to.norm())
            } else {
                Vec2::zeros()
            };
            *lw -= (v - expected).norm_squared() / (2.0 * variance);
        }
    };
    for w in seen.windows(2) {
        let dt = w[1].0 - w[0].0;
        if dt > 1e-9 {
            observe(w[0].1, (w[1].1 - w[0].1) / dt, dt);
        }
    }
    if let Some(&(_, now)) = seen.last() {
        observe(now, velocity, params.dt);
    }
    let top = log_w.iter().copied().fold(Real::NEG_INFINITY, Real::max);
    let w: Vec<Real> = log_w.iter().map(|l| (l - top).exp()).collect();
    let total: Real = w.iter().sum();
    w.into_iter().map(|v| v / total).collect()
}

/// A person's mixture: one component per destination, preferences from the track, the ones
/// below [`MIN_RELATIVE_WEIGHT`] of the best dropped and the rest renormalised; every
/// component has the covariance of `flexibility`, the person's single GP regressed on the
/// track ([`TrajectoryGp::towards`]). `None` if there are no destinations (the caller falls
/// back on the single GP).
pub fn person_mixture(
    params: &GpParams,
    flexibility: &TrajectoryGp,
    seen: &[(Real, Vec2)],
    velocity: Vec2,
    destinations: &[Vec2],
) -> Option<Vec<Component>> {
    let &(_, position) = seen.last()?;
    if destinations.is_empty() {
        return None;
    }
    let weights = intent_weights(params, seen, velocity, destinations);
    let top = weights.iter().copied().fold(0.0, Real::max);
    let kept: Vec<(Real, Vec2)> = weights
        .into_iter()
        .zip(destinations.iter().copied())
        .filter(|&(w, _)| w >= MIN_RELATIVE_WEIGHT * top)
        .collect();
    let total: Real = kept.iter().map(|(w, _)| w).sum();
    Some(
        kept.into_iter()
            .map(|(w, d)| Component {
                weight: w / total,
                gp: TrajectoryGp::towards(params, flexibility, position, velocity, d),
            })
            .collect(),
    )
}
