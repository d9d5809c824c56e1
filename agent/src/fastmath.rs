//! `exp` and `atan2` in plain IEEE arithmetic, for the hot loops of the crowd model.
//!
//! libm's versions are calls with branches, so loops over them stay scalar; these inline into
//! straight-line code (selects instead of branches) that the compiler vectorises. They use
//! only +, −, ×, ÷ and bit moves, never fused multiply–add, so they give the same bits on
//! every machine and at every vector width. Both are within 2 ulp of `f64::exp` / `f64::atan2`
//! over the ranges documented below (tested on millions of arguments).

use crate::math::{Real, Vec2, vec2};

/// e^x for x in [−708, 709] by Cody–Waite reduction x·log2(e) = n + r, |r·ln 2| ≤ ln2/2, a
/// degree-13 Taylor polynomial (truncation error < 5·10⁻¹⁸ relative) and 2^n assembled from
/// bits. Outside that range the result is meaningless; callers clamp.
#[inline(always)]
pub(crate) fn exp_reduced(x: Real) -> Real {
    const LOG2E: Real = std::f64::consts::LOG2_E;
    // ln 2 split so that n·LN2_HI is exact for |n| < 2^11.
    const LN2_HI: Real = Real::from_bits(0x3fe6_2e42_fee0_0000); // fdlibm's ln2_hi
    const LN2_LO: Real = Real::from_bits(0x3dea_39ef_3579_3c76); // fdlibm's ln2_lo
    // 1.5·2^52: adding it rounds to the nearest integer, which lands in the low mantissa bits.
    const MAGIC: Real = 6_755_399_441_055_744.0;
    let shifted = x * LOG2E + MAGIC;
    let n = shifted - MAGIC;
    let r = (x - n * LN2_HI) - n * LN2_LO;
    // Σ r^i / i!, i = 0..=13: 1 + r(1 + r(1/2 + r·q(r))) with q, the terms from 1/3!, by
    // Estrin's scheme, whose short dependency chains keep a vector unit busy.
    const A: [Real; 11] = [
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5_040.0,
        1.0 / 40_320.0,
        1.0 / 362_880.0,
        1.0 / 3_628_800.0,
        1.0 / 39_916_800.0,
        1.0 / 479_001_600.0,
        1.0 / 6_227_020_800.0,
    ];
    let r2 = r * r;
    let r4 = r2 * r2;
    let r8 = r4 * r4;
    let low = (A[0] + A[1] * r) + (A[2] + A[3] * r) * r2;
    let mid = (A[4] + A[5] * r) + (A[6] + A[7] * r) * r2;
    let high = (A[8] + A[9] * r) + A[10] * r2;
    let q = (low + mid * r4) + high * r8;
    let p = 1.0 + r * (1.0 + r * (0.5 + r * q));
    // n is in [−1022, 1023]: 2^n is a normal number with biased exponent n + 1023.
    let n_bits = shifted.to_bits().wrapping_sub(MAGIC.to_bits());
    let scale = Real::from_bits(n_bits.wrapping_add(1023) << 52);
    p * scale
}

/// e^x. Exact to 2 ulp for x in [−708, 709]; 0 below −708 (where libm returns numbers
/// smaller than 3·10⁻³⁰⁸), +∞ above 709, NaN for NaN.
#[inline(always)]
pub fn exp(x: Real) -> Real {
    let e = exp_reduced(x.clamp(-708.0, 709.0));
    if x < -708.0 {
        0.0
    } else if x > 709.0 {
        Real::INFINITY
    } else {
        e
    }
}

/// atan(u) for |u| ≤ 0.66: Cephes' rational approximation u + u·z·P(z)/Q(z), z = u².
#[inline(always)]
fn atan_small(u: Real) -> Real {
    const P: [Real; 5] = [
        -8.750_608_600_031_904e-1,
        -1.615_753_718_733_365e1,
        -7.500_855_792_314_705e1,
        -1.228_866_684_490_136_2e2,
        -6.485_021_904_942_025e1,
    ];
    const Q: [Real; 5] = [
        2.485_846_490_142_306_3e1,
        1.650_270_098_316_988_5e2,
        4.328_810_604_912_903e2,
        4.853_903_996_359_137e2,
        1.945_506_571_482_614e2,
    ];
    let z = u * u;
    let p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
    let q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
    u * (z * p / q) + u
}

/// atan2(y, x) for finite arguments, with libm's quadrants and signed zeros:
/// atan2(±0, +0) = ±0, atan2(±0, −0) = ±π, atan2(y ≠ 0, ±0) = ±π/2.
///
/// The smaller of |x|, |y| over the larger gives t in [0, 1]; t > 0.66 is reduced through
/// atan t = π/4 + atan((t − 1)/(t + 1)), as Cephes does (two divisions in all); the octant and quadrant are then
/// restored with π/4, π/2 and π carried as two doubles each.
#[inline(always)]
pub fn atan2(y: Real, x: Real) -> Real {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    // The parts of π/4, π/2 and π that their doubles lack.
    const PIO4_LO: Real = 3.061_616_997_868_383e-17;
    const PIO2_LO: Real = 6.123_233_995_736_766e-17;
    const PI_LO: Real = 1.224_646_799_147_353_2e-16;
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let (num, den) = if swap { (ax, ay) } else { (ay, ax) };
    // t = num/den; u = t, or (t − 1)/(t + 1) when t > 0.66, in one division.
    let big = num > 0.66 * den;
    let u = if big { num - den } else { num } / if big { num + den } else { den };
    let u = if den == 0.0 { 0.0 } else { u };
    // The angle as hi + lo, so that the reflections below keep the constants' low parts.
    let v = atan_small(u);
    let (hi, lo) = if big {
        (FRAC_PI_4 + v, PIO4_LO)
    } else {
        (v, 0.0)
    };
    let (hi, lo) = if swap {
        (FRAC_PI_2 - hi, PIO2_LO - lo)
    } else {
        (hi, lo)
    };
    let (hi, lo) = if x.is_sign_negative() {
        (PI - hi, PI_LO - lo)
    } else {
        (hi, lo)
    };
    (hi + lo).copysign(y)
}

/// Partial sums per vectorised sum, and the block size of the loops that feed them.
pub const LANES: usize = 8;

/// `LANES` partial sums (item i of a sum kept in partial sum i mod `LANES`) added in a fixed
/// order: sums that vectorise and have the same bits at every vector width.
#[inline(always)]
pub fn lanes_total(acc: &[Real; LANES]) -> Real {
    ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]))
}

/// Items per pass of the vectorised loops that feed [`LaneSums`] (a multiple of `LANES`).
pub const CHUNK: usize = 64;

/// `LANES` partial sums of 2-D vectors: item i of a sum adds to partial sum i mod `LANES`, and
/// [`total`](Self::total) adds them in a fixed order. The loops then vectorise, give the same
/// bits at every vector width, and give the same bits for any superset of the items that act
/// (the others add exact zeros).
#[derive(Debug, Clone, Copy)]
pub struct LaneSums {
    /// Partial sums of the x components.
    pub x: [Real; LANES],
    /// Partial sums of the y components.
    pub y: [Real; LANES],
}

impl LaneSums {
    /// All partial sums zero.
    pub const ZERO: Self = Self {
        x: [0.0; LANES],
        y: [0.0; LANES],
    };

    /// The sum, in the fixed order of [`lanes_total`].
    #[inline(always)]
    pub fn total(&self) -> Vec2 {
        vec2(lanes_total(&self.x), lanes_total(&self.y))
    }

    /// Adds `fx[k]`, `fy[k]` to partial sum k mod `LANES` (lengths are multiples of `LANES`).
    #[inline(always)]
    pub fn accumulate(&mut self, fx: &[Real], fy: &[Real]) {
        for (x, y) in fx.chunks_exact(LANES).zip(fy.chunks_exact(LANES)) {
            for l in 0..LANES {
                self.x[l] += x[l];
                self.y[l] += y[l];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Distance in units in the last place between two finite doubles of the same sign.
    fn ulps(a: Real, b: Real) -> u64 {
        if a == b {
            return 0;
        }
        assert_eq!(a.is_sign_negative(), b.is_sign_negative(), "{a} vs {b}");
        a.to_bits().abs_diff(b.to_bits())
    }

    #[test]
    fn exp_is_within_two_ulp_of_libm() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut worst = 0;
        for i in 0..2_000_000 {
            // Half over the whole range, half over the crowd model's [−40, 2].
            let x = if i % 2 == 0 {
                rng.random_range(-708.0..709.0)
            } else {
                rng.random_range(-40.0..2.0)
            };
            worst = worst.max(ulps(exp(x), x.exp()));
        }
        for x in [
            0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300, -708.0, 709.0, 0.5, -0.5,
        ] {
            worst = worst.max(ulps(exp(x), x.exp()));
        }
        assert!(worst <= 2, "worst {worst} ulp");
        assert_eq!(exp(0.0), 1.0);
        assert_eq!(exp(-800.0), 0.0);
        assert_eq!(exp(710.0), Real::INFINITY);
        assert!(exp(Real::NAN).is_nan());
    }

    #[test]
    fn atan2_is_within_two_ulp_of_libm() {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let mut worst = 0;
        for i in 0..2_000_000 {
            let scale = if i % 3 == 0 { 1e-3 } else { 10.0 };
            let y: Real = rng.random_range(-1.0..1.0) * scale;
            let x: Real = rng.random_range(-1.0..1.0) * scale;
            worst = worst.max(ulps(atan2(y, x), y.atan2(x)));
        }
        // Near the octant borders and the reduction threshold, and very unequal magnitudes.
        for &(y, x) in &[
            (1.0, 1.0),
            (-1.0, 1.0),
            (1.0, -1.0),
            (0.66, 1.0),
            (0.660_000_000_000_1, 1.0),
            (1.0, 0.66),
            (1e-300, 1.0),
            (1.0, 1e-300),
            (-3.0, -1e-20),
            (2.5, -7.0),
        ] {
            worst = worst.max(ulps(atan2(y, x), y.atan2(x)));
        }
        assert!(worst <= 2, "worst {worst} ulp");
    }

    #[test]
    fn atan2_has_libms_signed_zeros_and_axes() {
        for y in [0.0, -0.0, 1.0, -1.0] {
            for x in [0.0, -0.0, 1.0, -1.0] {
                let (ours, libm) = (atan2(y, x), y.atan2(x));
                assert_eq!(ours.to_bits(), libm.to_bits(), "atan2({y}, {x})");
            }
        }
    }
}
