//! Statistics for paired comparisons: the Wilcoxon signed-rank test, as the PGP paper uses it.

/// Two-sided p-value of the Wilcoxon signed-rank test on paired differences, with SciPy's
/// defaults for large samples (`zero_method="wilcox"`: zero differences are dropped;
/// `method="approx"`: normal approximation with the tie correction, no continuity correction).
/// `None` when no non-zero difference remains.
pub fn wilcoxon_signed_rank(differences: &[f64]) -> Option<f64> {
    let mut d: Vec<f64> = differences
        .iter()
        .copied()
        .filter(|x| *x != 0.0 && x.is_finite())
        .collect();
    let n = d.len();
    if n == 0 {
        return None;
    }
    d.sort_by(|a, b| a.abs().total_cmp(&b.abs()));
    // Average ranks over ties of |d|.
    let mut ranks = vec![0.0; n];
    let mut tie_term = 0.0;
    let mut i = 0;
    while i < n {
        let mut j = i;
        while j + 1 < n && d[j + 1].abs() == d[i].abs() {
            j += 1;
        }
        let rank = (i + j) as f64 / 2.0 + 1.0;
        ranks[i..=j].iter_mut().for_each(|r| *r = rank);
        let t = (j - i + 1) as f64;
        tie_term += t * t * t - t;
        i = j + 1;
    }
    let w_plus: f64 = d
        .iter()
        .zip(&ranks)
        .filter(|(x, _)| **x > 0.0)
        .map(|(_, r)| r)
        .sum();
    let nf = n as f64;
    let mean = nf * (nf + 1.0) / 4.0;
    let var = nf * (nf + 1.0) * (2.0 * nf + 1.0) / 24.0 - tie_term / 48.0;
    if var <= 0.0 {
        return Some(1.0);
    }
    let z = (w_plus - mean) / var.sqrt();
    Some(libm::erfc(z.abs() / std::f64::consts::SQRT_2))
}

/// Mean of the finite values, `None` if there are none.
pub fn mean(values: impl IntoIterator<Item = f64>) -> Option<f64> {
    let (mut sum, mut n) = (0.0, 0usize);
    for v in values.into_iter().filter(|v| v.is_finite()) {
        sum += v;
        n += 1;
    }
    (n > 0).then(|| sum / n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Values from SciPy 1.17.1: `scipy.stats.wilcoxon(d, method="approx").pvalue`
    /// (see coordinator/studies/tests/reference/wilcoxon_reference.py).
    #[test]
    fn matches_scipy_normal_approximation() {
        let d = [
            1.5, -0.3, 2.2, 0.7, -1.1, 3.4, 0.9, 1.8, -0.2, 2.5, 0.4, 1.1,
        ];
        let p = wilcoxon_signed_rank(&d).expect("non-empty");
        assert!((p - SCIPY_P1).abs() < 1e-12, "{p}");
        let d = [1.0, 1.0, -1.0, 2.0, 2.0, 0.0, 3.0, -2.0, 1.0, 0.0];
        let p = wilcoxon_signed_rank(&d).expect("non-empty");
        assert!((p - SCIPY_P2).abs() < 1e-12, "{p}");
    }

    const SCIPY_P1: f64 = 0.020_609_595_400_318_82;
    const SCIPY_P2: f64 = 0.175_834_039_182_613_42;

    #[test]
    fn symmetric_differences_give_p_one_and_none_for_all_zero() {
        assert_eq!(wilcoxon_signed_rank(&[0.0, 0.0]), None);
        let p = wilcoxon_signed_rank(&[1.0, -1.0, 2.0, -2.0]).expect("non-empty");
        assert!((p - 1.0).abs() < 1e-12);
    }

    #[test]
    fn mean_skips_nan() {
        assert_eq!(mean([1.0, f64::NAN, 3.0]), Some(2.0));
        assert_eq!(mean([f64::NAN]), None);
    }
}
