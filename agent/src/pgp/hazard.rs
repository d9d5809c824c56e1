//! The cooperative collision hazard of one candidate sample (the PGP paper's Eqs. 1–3) over a
//! row of neighbours, `LANES` at a time and branch-free, with the bits of the scalar loop it
//! replaced; and the cheap bound on ln that culls neighbours too far away to matter.

use crate::fastmath::LANES;
use crate::math::{Real, Vec2};
use crate::risk::exp_neg;

/// An upper bound on ln(x) for normal x > 0, within 1 − ln 2 ≈ 0.31 of it: with x = m·2^e,
/// m ∈ [1, 2), ln x = e·ln 2 + ln m ≤ e·ln 2 + (m − 1). Far cheaper than `ln`.
#[inline(always)]
pub(super) fn ln_upper_bound(x: Real) -> Real {
    let bits = x.to_bits();
    // The unbiased exponent as a double, exactly and without an integer conversion (AVX2 has
    // none for 64-bit integers): 2^52 + biased exponent, from bits, minus 2^52 + 1023.
    const TWO_52: u64 = 0x4330_0000_0000_0000;
    let e = (Real::from_bits(TWO_52 | ((bits >> 52) & 0x7ff)) - Real::from_bits(TWO_52)) - 1023.0;
    let m = Real::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    e * std::f64::consts::LN_2 + (m - 1.0)
}

/// The ego's side of Eqs. 1–3 at one sample.
pub(super) struct EgoTerms {
    pub(super) pos: Vec2,
    /// σ_j,ego².
    pub(super) var: Real,
    /// σ_0,ego².
    pub(super) var0: Real,
    /// σ_0,ego / σ_j,ego.
    pub(super) ratio: Real,
    /// Upper bound of ln(ratio / risk_floor).
    pub(super) cull: Real,
}

/// Σ_k p^coll,coop_{j,k} (Eq. 3) at one ego sample, over a row of whole `LANES` blocks.
/// Terms provably below `risk_floor` (see [`PairTables`]) count as 0.
///
/// Every term is computed branch-free, `LANES` neighbours at a time, culled ones as +0; then
/// all are added one by one in neighbour order. The terms are never negative, so the zeros
/// change no bit: the result has exactly the bits of the scalar loop that skips culled terms
/// (tested against [`dynamic_hazard_scalar`]). Padding neighbours are always culled.
#[inline(always)]
pub(super) fn dynamic_hazard(
    ego: &EgoTerms,
    xs: &[Real],
    ys: &[Real],
    nb_var: &[Real],
    nb_ratio: &[Real],
    nb_cull: &[Real],
    nb_var0: &[Real],
) -> Real {
    debug_assert!(xs.len().is_multiple_of(LANES));
    let mut sum = 0.0;
    for b in 0..xs.len() / LANES {
        let r = b * LANES..(b + 1) * LANES;
        let block = [
            lanes(&xs[r.clone()]),
            lanes(&ys[r.clone()]),
            lanes(&nb_var[r.clone()]),
            lanes(&nb_ratio[r.clone()]),
            lanes(&nb_cull[r.clone()]),
            lanes(&nb_var0[r]),
        ];
        // In neighbour order, the culled terms as zeros: adding +0 to a sum of non-negative
        // terms (never −0) changes no bit, and there is no branch to mispredict.
        for term in hazard_terms(ego, block) {
            sum += term;
        }
    }
    sum
}

#[inline(always)]
fn lanes(values: &[Real]) -> &[Real; LANES] {
    values.try_into().expect("a block is LANES long")
}

/// Eq. 3's terms for `LANES` neighbours (columns x, y, σ², σ_0/σ_j, cull, σ_0²), culled ones
/// as +0.
#[inline(always)]
fn hazard_terms(ego: &EgoTerms, block: [&[Real; LANES]; 6]) -> [Real; LANES] {
    let [xs, ys, nb_var, nb_ratio, nb_cull, nb_var0] = block;
    let mut out = [0.0; LANES];
    for l in 0..LANES {
        let (dx, dy) = (ego.pos.x - xs[l], ego.pos.y - ys[l]);
        let d2 = dx * dx + dy * dy;
        let var = ego.var + nb_var[l];
        let inv = 1.0 / var;
        // Eq. 1: exp(−‖Δμ‖² / (2σ̃_i)) · σ̃_0 / σ̃_i, times Eq. 2's τ.
        let p = exp_neg(0.5 * d2 * inv) * (ego.var0 + nb_var0[l]) * inv * (ego.ratio * nb_ratio[l]);
        // As the scalar loop's `if d2 >= bound { continue }`: a NaN is kept.
        let bound = 2.0 * var * (ego.cull + nb_cull[l]);
        let kept = d2 < bound || d2.is_nan() || bound.is_nan();
        out[l] = if kept { p } else { 0.0 };
    }
    out
}

/// The one-neighbour-at-a-time form of [`dynamic_hazard`], which must give the same bits.
#[cfg(test)]
fn dynamic_hazard_scalar(
    ego: &EgoTerms,
    xs: &[Real],
    ys: &[Real],
    nb_var: &[Real],
    nb_ratio: &[Real],
    nb_cull: &[Real],
    nb_var0: &[Real],
) -> Real {
    let mut sum = 0.0;
    let neighbours = xs
        .iter()
        .zip(ys)
        .zip(nb_var)
        .zip(nb_ratio)
        .zip(nb_cull)
        .zip(nb_var0);
    for (((((&x, &y), &nv), &nr), &nc), &nv0) in neighbours {
        let (dx, dy) = (ego.pos.x - x, ego.pos.y - y);
        let d2 = dx * dx + dy * dy;
        let var = ego.var + nv;
        if d2 >= 2.0 * var * (ego.cull + nc) {
            continue;
        }
        let inv = 1.0 / var;
        // Eq. 1: exp(−‖Δμ‖² / (2σ̃_i)) · σ̃_0 / σ̃_i, times Eq. 2's τ.
        sum += exp_neg(0.5 * d2 * inv) * (ego.var0 + nv0) * inv * (ego.ratio * nr);
    }
    sum
}

#[cfg(test)]
mod ln_bound_tests {
    #[test]
    fn ln_upper_bound_bounds_ln_from_above_and_closely() {
        let mut x: f64 = 1e-3;
        while x < 1e12 {
            let (b, l) = (super::ln_upper_bound(x), x.ln());
            assert!(
                b >= l - 1e-12 && b - l <= 0.31,
                "x = {x}: bound {b}, ln {l}"
            );
            x *= 1.37;
        }
    }
}

#[cfg(test)]
mod hazard_tests {
    use super::*;
    use crate::math::vec2;

    proptest::proptest! {
        /// The branch-free hazard row has exactly the bits of the scalar loop that skips
        /// culled terms, whatever the mix of culled and kept neighbours.
        #[test]
        fn vectorised_row_has_the_bits_of_the_scalar_loop(
            ego in (-5.0..5.0f64, -5.0..5.0f64, 0.01..1.0f64, 0.01..1.0f64, 0.05..1.0f64),
            row in proptest::collection::vec(
                (-8.0..8.0f64, -8.0..8.0f64, 0.01..1.0f64, 0.05..1.0f64, 0.01..1.0f64),
                0..70,
            ),
            floor in proptest::sample::select(vec![1e-9, 1e-3, 0.0]),
        ) {
            let (x, y, var, var0, ratio) = ego;
            let cull = |r: Real| if floor > 0.0 { ln_upper_bound(r / floor) } else { Real::INFINITY };
            let ego = EgoTerms { pos: vec2(x, y), var, var0, ratio, cull: cull(ratio) };
            let xs: Vec<Real> = row.iter().map(|r| r.0).collect();
            let ys: Vec<Real> = row.iter().map(|r| r.1).collect();
            let nb_var: Vec<Real> = row.iter().map(|r| r.2).collect();
            let nb_ratio: Vec<Real> = row.iter().map(|r| r.3).collect();
            let nb_cull: Vec<Real> = row.iter().map(|r| cull(r.3)).collect();
            let nb_var0: Vec<Real> = row.iter().map(|r| r.4).collect();
            let scalar = dynamic_hazard_scalar(&ego, &xs, &ys, &nb_var, &nb_ratio, &nb_cull, &nb_var0);
            // Padded to whole blocks as `build_tables` pads its rows.
            let padded = xs.len().next_multiple_of(LANES);
            let pad = |mut v: Vec<Real>, with: Real| {
                v.resize(padded, with);
                v
            };
            let lanes = dynamic_hazard(
                &ego,
                &pad(xs, Real::INFINITY),
                &pad(ys, Real::INFINITY),
                &pad(nb_var, 1.0),
                &pad(nb_ratio, 0.0),
                &pad(nb_cull, 0.0),
                &pad(nb_var0, 0.0),
            );
            proptest::prop_assert_eq!(lanes.to_bits(), scalar.to_bits());
        }
    }
}
