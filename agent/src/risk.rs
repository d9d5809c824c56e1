//! The PGP paper's cooperative collision risk and survival analysis (Sec. III-A), equation by
//! equation. The hot loop in `pgp` inlines the same arithmetic; these functions are the
//! reference it is tested against.

use crate::math::Real;

/// Arguments of [`exp_neg`] are clamped to this; e^−60 ≈ 9·10⁻²⁷.
pub const EXP_NEG_MAX: Real = 60.0;

/// e^(−x) for x in [0, [`EXP_NEG_MAX`]], within 2 ulp of `f64::exp`, branch-free so that
/// loops over it vectorise (see [`crate::fastmath`]).
#[inline(always)]
pub fn exp_neg(x: Real) -> Real {
    crate::fastmath::exp_reduced(-x.clamp(0.0, EXP_NEG_MAX))
}

/// Eq. 1: probability that ego and agent k collide at step i,
/// p = exp(−‖μ_ego − μ_k‖² / (2σ̃_i)) · σ̃_0 / σ̃_i with σ̃ = σ_ego² + σ_k².
#[inline]
pub fn collision_probability(
    dist_sq: Real,
    sigma_ego_i: Real,
    sigma_k_i: Real,
    sigma_ego_0: Real,
    sigma_k_0: Real,
) -> Real {
    let var_i = sigma_ego_i * sigma_ego_i + sigma_k_i * sigma_k_i;
    let var_0 = sigma_ego_0 * sigma_ego_0 + sigma_k_0 * sigma_k_0;
    (-dist_sq / (2.0 * var_i)).exp() * var_0 / var_i
}

/// Eq. 2: cooperation factor τ = (σ_0,ego / σ_i,ego) · (σ_0,k / σ_i,k) ≤ 1.
#[inline]
pub fn cooperation_factor(
    sigma_ego_i: Real,
    sigma_k_i: Real,
    sigma_ego_0: Real,
    sigma_k_0: Real,
) -> Real {
    (sigma_ego_0 / sigma_ego_i) * (sigma_k_0 / sigma_k_i)
}

/// Eq. 3: cooperative collision risk p_coll · τ.
#[inline]
pub fn cooperative_collision_probability(
    dist_sq: Real,
    sigma_ego_i: Real,
    sigma_k_i: Real,
    sigma_ego_0: Real,
    sigma_k_0: Real,
) -> Real {
    collision_probability(dist_sq, sigma_ego_i, sigma_k_i, sigma_ego_0, sigma_k_0)
        * cooperation_factor(sigma_ego_i, sigma_k_i, sigma_ego_0, sigma_k_0)
}

/// Eq. 4: probability of hitting a static object at lateral distance `d` with ego standard
/// deviation `sigma`: 1 − erf(d / (σ√2)), computed as erfc for accuracy.
#[inline]
pub fn static_collision_probability(d: Real, sigma: Real) -> Real {
    libm::erfc(d / (sigma * std::f64::consts::SQRT_2))
}

/// Eq. 5: survival probabilities from per-step hazards. `hazards[j]` is
/// Σ_k p^coll,coop_{j,k} + p^coll,static_j + p^escape; writes
/// `survival[i] = Π_{j<i} exp(−hazards[j])` for i = 0..=hazards.len().
///
/// The cumulative hazards are summed first, in order; their exponentials are then taken in a
/// straight-line loop that vectorises, and the rare sums beyond `exp_neg`'s range redone
/// with `exp`.
#[inline(always)]
pub fn survival(hazards: &[Real], survival: &mut [Real]) {
    debug_assert_eq!(survival.len(), hazards.len() + 1);
    let mut acc = 0.0;
    survival[0] = 1.0;
    for (s, h) in survival[1..].iter_mut().zip(hazards) {
        acc += h;
        *s = acc;
    }
    let mut beyond = false;
    for s in &mut survival[1..] {
        beyond |= *s > EXP_NEG_MAX;
        *s = exp_neg(*s);
    }
    if beyond {
        let mut acc = 0.0;
        for (s, h) in survival[1..].iter_mut().zip(hazards) {
            acc += h;
            if acc > EXP_NEG_MAX {
                *s = (-acc).exp();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp_neg_agrees_with_std_within_two_ulp() {
        let mut worst: Real = 0.0;
        let mut x: Real = 0.0;
        while x <= EXP_NEG_MAX {
            let (ours, std) = (exp_neg(x), (-x).exp());
            let ulp = (std.to_bits() as i64 - ours.to_bits() as i64).abs();
            worst = worst.max(ulp as Real);
            x += 0.000_731;
        }
        assert!(worst <= 2.0, "worst error {worst} ulp");
        assert_eq!(exp_neg(0.0), 1.0);
        assert_eq!(exp_neg(-1.0), 1.0, "negative arguments clamp to 0");
        assert_eq!(exp_neg(1e9), exp_neg(EXP_NEG_MAX), "large arguments clamp");
    }

    const S0: Real = 0.1666;

    #[test]
    fn eq1_is_one_for_equal_means_at_step_zero() {
        assert_eq!(collision_probability(0.0, S0, S0, S0, S0), 1.0);
    }

    #[test]
    fn eq1_hand_checked_values() {
        // 1 m apart at σ0 each: σ̃ = 2·0.1666² = 0.05551112, exp(−1/0.11102224).
        let p = collision_probability(1.0, S0, S0, S0, S0);
        assert!((p - (-1.0f64 / 0.111_022_24).exp()).abs() < 1e-15);
        // Same means, σ grown to 3σ0 for both: normalisation gives 1/9.
        let p = collision_probability(0.0, 3.0 * S0, 3.0 * S0, S0, S0);
        assert!((p - 1.0 / 9.0).abs() < 1e-15);
        // 0.5 m apart, σ_ego = 0.3, σ_k = 0.4: σ̃ = 0.25, exp(−0.5)·(2·0.1666²)/0.25.
        let p = collision_probability(0.25, 0.3, 0.4, S0, S0);
        let expected = (-0.5f64).exp() * 0.055_511_12 / 0.25;
        assert!((p - expected).abs() < 1e-15);
    }

    #[test]
    fn eq2_tau_is_one_for_constant_sigma_and_shrinks_as_sigma_grows() {
        assert_eq!(cooperation_factor(S0, S0, S0, S0), 1.0);
        assert_eq!(cooperation_factor(0.4, 0.4, 0.4, 0.4), 1.0);
        assert!((cooperation_factor(2.0 * S0, S0, S0, S0) - 0.5).abs() < 1e-15);
        assert!((cooperation_factor(2.0 * S0, 3.0 * S0, S0, S0) - 1.0 / 6.0).abs() < 1e-15);
    }

    #[test]
    fn eq3_is_product_of_eq1_and_eq2() {
        let p = cooperative_collision_probability(0.3, 0.2, 0.25, S0, S0);
        let q =
            collision_probability(0.3, 0.2, 0.25, S0, S0) * cooperation_factor(0.2, 0.25, S0, S0);
        assert_eq!(p, q);
        assert_eq!(cooperative_collision_probability(0.0, S0, S0, S0, S0), 1.0);
    }

    #[test]
    fn eq4_static_risk_is_one_at_contact_and_falls_with_distance() {
        assert_eq!(static_collision_probability(0.0, S0), 1.0);
        // d = σ: 1 − erf(1/√2) = 0.31731050786291415.
        assert!((static_collision_probability(S0, S0) - 0.317_310_507_862_914_15).abs() < 1e-15);
        // d = 2σ: 0.04550026389635842.
        assert!((static_collision_probability(0.4, 0.2) - 0.045_500_263_896_358_42).abs() < 1e-15);
        assert!(static_collision_probability(3.0, S0) < 1e-15);
    }

    #[test]
    fn eq5_survival_starts_at_one_and_never_increases() {
        let hazards = [0.01, 0.5, 0.0, 0.2, 0.01];
        let mut s = [0.0; 6];
        survival(&hazards, &mut s);
        assert_eq!(s[0], 1.0);
        assert!((s[1] - (-0.01f64).exp()).abs() < 1e-15);
        assert!((s[5] - (-0.72f64).exp()).abs() < 1e-15);
        assert!(s.windows(2).all(|w| w[1] <= w[0]));
        // Only escape: exponential decay.
        let mut s = [0.0; 33];
        survival(&[0.01; 32], &mut s);
        assert!((s[32] - (-0.32f64).exp()).abs() < 1e-14);
    }
}
