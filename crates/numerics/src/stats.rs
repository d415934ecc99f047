//! The few distributions the project needs: chi-square tail probabilities
//! and quantiles (through the regularised incomplete gamma function), the
//! F distribution (through the regularised incomplete beta function), the
//! power of a chi-square test against a non-central alternative, and the
//! one definition of a sample quantile that every figure uses.

use crate::roots::{Spacing, threshold};

/// `ln Gamma(x)` for `x > 0` (Lanczos, g = 7; about 15 digits).
///
/// # Example
/// ```
/// assert!((tricept_numerics::stats::ln_gamma(4.0) - 6f64.ln()).abs() < 1e-14);
/// ```
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection.
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularised lower incomplete gamma `P(a, x)`.
///
/// # Example
/// ```
/// // P(1, x) = 1 - exp(-x).
/// assert!((tricept_numerics::stats::gamma_p(1.0, 2.0) - (1.0 - (-2.0f64).exp())).abs() < 1e-14);
/// ```
pub fn gamma_p(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x < a + 1.0 {
        // Series.
        let mut sum = 1.0 / a;
        let mut term = sum;
        let mut n = a;
        for _ in 0..1000 {
            n += 1.0;
            term *= x / n;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (sum.ln() - x + a * x.ln() - ln_gamma(a)).exp()
    } else {
        1.0 - gamma_q_continued_fraction(a, x)
    }
}

/// `Q(a, x) = 1 - P(a, x)` by Lentz's continued fraction (for `x >= a + 1`).
fn gamma_q_continued_fraction(a: f64, x: f64) -> f64 {
    ln_gamma_q_continued_fraction(a, x).exp()
}

/// `ln Q(a, x)` by Lentz's continued fraction (for `x >= a + 1`): finite
/// where `Q` itself underflows.
fn ln_gamma_q_continued_fraction(a: f64, x: f64) -> f64 {
    let tiny = 1e-300;
    let mut b = x + 1.0 - a;
    let mut c = 1.0 / tiny;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..1000 {
        let an = -(i as f64) * (i as f64 - a);
        b += 2.0;
        d = an * d + b;
        if d.abs() < tiny {
            d = tiny;
        }
        c = b + an / c;
        if c.abs() < tiny {
            c = tiny;
        }
        d = 1.0 / d;
        let delta = d * c;
        h *= delta;
        if (delta - 1.0).abs() < 1e-16 {
            break;
        }
    }
    -x + a * x.ln() - ln_gamma(a) + h.ln()
}

/// `P(X > x)` for `X ~ chi-square(k)`.
///
/// # Example
/// ```
/// assert!((tricept_numerics::stats::chi2_sf(3.841458820694124, 1.0) - 0.05).abs() < 1e-10);
/// ```
pub fn chi2_sf(x: f64, k: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    // The continued fraction converges for `x/2 >= k/2 + 1` (and divides by
    // zero at `x/2 = k/2 - 1`); the series covers the rest.
    if 0.5 * x >= 0.5 * k + 1.0 {
        gamma_q_continued_fraction(k / 2.0, x / 2.0)
    } else {
        1.0 - gamma_p(k / 2.0, x / 2.0)
    }
}

/// `ln P(X > x)` for `X ~ chi-square(k)`: finite for any finite `x`, where
/// [`chi2_sf`] underflows to zero (beyond `x` of about 1400), so that tests
/// of very strong signals can still be ranked by their p-value.
///
/// # Example
/// ```
/// use tricept_numerics::stats::{chi2_ln_sf, chi2_sf};
/// assert!((chi2_ln_sf(10.0, 3.0) - chi2_sf(10.0, 3.0).ln()).abs() < 1e-12);
/// assert_eq!(chi2_sf(5000.0, 3.0), 0.0);
/// let l = chi2_ln_sf(5000.0, 3.0);
/// assert!(l.is_finite() && l < -2400.0);
/// // With more degrees of freedom the same statistic is less surprising.
/// assert!(chi2_ln_sf(5000.0, 4.0) > l);
/// ```
pub fn chi2_ln_sf(x: f64, k: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if 0.5 * x >= 0.5 * k + 1.0 {
        ln_gamma_q_continued_fraction(k / 2.0, x / 2.0)
    } else {
        (1.0 - gamma_p(k / 2.0, x / 2.0)).ln()
    }
}

/// The `x` with `P(X > x) = tail` for `X ~ chi-square(k)` (bracketing and
/// bisection, [`crate::roots::threshold`]); `0` for `tail >= 1`.
///
/// # Example
/// ```
/// assert!((tricept_numerics::stats::chi2_isf(0.05, 1.0) - 3.841458820694124).abs() < 1e-8);
/// ```
pub fn chi2_isf(tail: f64, k: f64) -> f64 {
    let found = threshold(0.0, k.max(1.0), f64::MAX, Spacing::Linear, 200, |x| {
        Ok::<_, std::convert::Infallible>(chi2_sf(x, k) <= tail)
    });
    match found {
        Ok(t) => t.value().unwrap_or(f64::INFINITY),
        Err(never) => match never {},
    }
}

/// Regularised incomplete beta function `I_x(a, b)` for `a, b > 0` and
/// `0 <= x <= 1` (Lentz's continued fraction, about 14 digits); NaN
/// outside that domain.
///
/// # Example
/// ```
/// use tricept_numerics::stats::beta_inc;
/// // I_x(1, 1) = x; I_x(a, b) = 1 - I_{1-x}(b, a).
/// assert!((beta_inc(1.0, 1.0, 0.3) - 0.3).abs() < 1e-14);
/// assert!((beta_inc(2.5, 4.0, 0.2) + beta_inc(4.0, 2.5, 0.8) - 1.0).abs() < 1e-13);
/// ```
pub fn beta_inc(a: f64, b: f64, x: f64) -> f64 {
    if !(a > 0.0 && b > 0.0 && (0.0..=1.0).contains(&x)) {
        return f64::NAN;
    }
    if x == 0.0 || x == 1.0 {
        return x;
    }
    let ln_front = ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln();
    // The continued fraction converges fast for x < (a + 1) / (a + b + 2);
    // the symmetry I_x(a, b) = 1 - I_{1-x}(b, a) covers the rest.
    if x < (a + 1.0) / (a + b + 2.0) {
        ln_front.exp() * beta_continued_fraction(a, b, x) / a
    } else {
        1.0 - ln_front.exp() * beta_continued_fraction(b, a, 1.0 - x) / b
    }
}

/// The continued fraction of `I_x(a, b)` (modified Lentz).
fn beta_continued_fraction(a: f64, b: f64, x: f64) -> f64 {
    let tiny = 1e-300;
    let guard = |v: f64| if v.abs() < tiny { tiny } else { v };
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 / guard(1.0 - qab * x / qap);
    let mut h = d;
    // One Lentz step with partial numerator `aa`; returns the factor.
    let step = |aa: f64, c: &mut f64, d: &mut f64| {
        *d = 1.0 / guard(1.0 + aa * *d);
        *c = guard(1.0 + aa / *c);
        *d * *c
    };
    for m in 1..1000 {
        let m = m as f64;
        let m2 = 2.0 * m;
        h *= step(m * (b - m) * x / ((qam + m2) * (a + m2)), &mut c, &mut d);
        let delta = step(
            -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2)),
            &mut c,
            &mut d,
        );
        h *= delta;
        if (delta - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// `P(F > x)` for `F ~ F(d1, d2)`, Fisher's F distribution with `d1` and
/// `d2` degrees of freedom (the ratio of two independent chi-squares, each
/// divided by its degrees of freedom); 1 for `x <= 0`.
///
/// # Example
/// ```
/// use tricept_numerics::stats::f_sf;
/// // Tables: F(5, 10) exceeds 3.326 with probability 0.05.
/// assert!((f_sf(3.325_834_530_413_011, 5.0, 10.0) - 0.05).abs() < 1e-9);
/// ```
pub fn f_sf(x: f64, d1: f64, d2: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    if x.is_infinite() {
        return 0.0;
    }
    beta_inc(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * x))
}

/// Two-sided p-value of a chi-square statistic `x` with `k` degrees of
/// freedom against its null distribution (twice the smaller tail, at most
/// 1): small when `x` is too large *or* too small.
///
/// # Example
/// ```
/// use tricept_numerics::stats::chi2_two_sided;
/// assert!((chi2_two_sided(20.0, 20.0) - 1.0).abs() < 0.1);
/// assert!(chi2_two_sided(60.0, 20.0) < 1e-4);
/// assert!(chi2_two_sided(4.0, 20.0) < 1e-4);
/// ```
pub fn chi2_two_sided(x: f64, k: f64) -> f64 {
    let upper = chi2_sf(x, k);
    (2.0 * upper.min(1.0 - upper)).min(1.0)
}

/// `P(X > x)` for a non-central chi-square with `k` degrees of freedom and
/// non-centrality `lambda`: the Poisson mixture of central ones.
///
/// # Example
/// ```
/// use tricept_numerics::stats::{chi2_sf, noncentral_chi2_sf};
/// // No non-centrality: the central distribution.
/// assert!((noncentral_chi2_sf(5.0, 3.0, 0.0) - chi2_sf(5.0, 3.0)).abs() < 1e-14);
/// assert!(noncentral_chi2_sf(5.0, 3.0, 4.0) > chi2_sf(5.0, 3.0));
/// ```
pub fn noncentral_chi2_sf(x: f64, k: f64, lambda: f64) -> f64 {
    // The Poisson(mu) mixture of central chi-squares with k + 2j degrees
    // of freedom, summed over the terms that matter: below the mean by more
    // than 12 standard deviations (and 30) the weights are under e^-72.
    // Upwards the central tail probability grows with j; once it is 1 in
    // double precision every later term is its weight, and the weights left
    // sum to one minus those taken. The cost is O(sqrt(lambda)) terms at
    // most, O(1) when the non-centrality dwarfs `x`: a 1 nm noise level
    // must not make a search over lambda take minutes.
    let mu = 0.5 * lambda;
    let spread = 12.0 * mu.sqrt() + 30.0;
    let lo = (mu - spread).max(0.0).floor() as usize;
    let hi = (mu + spread).ceil() as usize;
    let ln_mu = mu.max(1e-300).ln();
    let mut sum = 0.0;
    let mut mass: f64 = 0.0;
    for j in lo..=hi {
        let jf = j as f64;
        let weight = (-mu + jf * ln_mu - ln_gamma(jf + 1.0)).exp();
        let sf = chi2_sf(x, k + 2.0 * jf);
        if sf >= 1.0 {
            sum += (1.0 - mass).max(0.0);
            break;
        }
        sum += weight * sf;
        mass += weight;
    }
    sum.min(1.0)
}

/// Power of the level-`alpha` chi-square test with `k` degrees of freedom
/// against non-centrality `lambda`.
///
/// # Example
/// ```
/// let p = tricept_numerics::stats::chi2_power(17.8, 1.0, 0.01);
/// assert!((p - 0.95).abs() < 0.005);
/// ```
pub fn chi2_power(lambda: f64, k: f64, alpha: f64) -> f64 {
    noncentral_chi2_sf(chi2_isf(alpha, k), k, lambda)
}

/// The non-centrality at which the level-`alpha` test with `k` degrees of
/// freedom has power `power`; `None` when no finite non-centrality reaches
/// it (a power of 1 or more).
///
/// # Example
/// ```
/// use tricept_numerics::stats::required_noncentrality;
/// let l = required_noncentrality(1.0, 0.05, 0.8).unwrap();
/// assert!((l - 7.85).abs() < 0.05); // (1.96 + 0.84)^2
/// assert_eq!(required_noncentrality(1.0, 0.05, 1.0), None);
/// ```
pub fn required_noncentrality(k: f64, alpha: f64, power: f64) -> Option<f64> {
    if power.is_nan() || power >= 1.0 {
        return None;
    }
    let found = threshold(0.0, 1.0, 1e12, Spacing::Linear, 100, |lambda| {
        Ok::<_, std::convert::Infallible>(chi2_power(lambda, k, alpha) >= power)
    });
    match found {
        Ok(t) => t.value(),
        Err(never) => match never {},
    }
}

/// The `p`-quantile (`0 <= p <= 1`) of an ascending sample, interpolated
/// linearly between order statistics (Hyndman and Fan's type 7, the
/// default of R and NumPy); NaN for an empty sample. Every percentile the
/// project reports uses it.
///
/// # Example
/// ```
/// use tricept_numerics::stats::quantile;
/// let sorted = [1.0, 2.0, 3.0, 4.0];
/// assert_eq!(quantile(&sorted, 0.5), 2.5);
/// assert_eq!(quantile(&sorted, 0.0), 1.0);
/// assert_eq!(quantile(&sorted, 1.0), 4.0);
/// assert!(quantile(&[], 0.5).is_nan());
/// ```
pub fn quantile(sorted: &[f64], p: f64) -> f64 {
    let n = sorted.len();
    if n == 0 {
        return f64::NAN;
    }
    let x = p.clamp(0.0, 1.0) * (n - 1) as f64;
    let (i, f) = (x.floor() as usize, x.fract());
    if i + 1 < n {
        sorted[i] * (1.0 - f) + sorted[i + 1] * f
    } else {
        sorted[n - 1]
    }
}

/// The median of an unsorted sample, exactly [`quantile`]`(sorted, 0.5)`
/// of the sample sorted by [`f64::total_cmp`], found by selection in
/// expected linear time instead of sorting (a robust start takes medians
/// of a million residuals); `values` is reordered. NaN for an empty
/// sample.
///
/// # Example
/// ```
/// use tricept_numerics::stats::median;
/// assert_eq!(median(&mut [4.0, 1.0, 3.0, 2.0]), 2.5);
/// assert_eq!(median(&mut [3.0, 1.0, 2.0]), 2.0);
/// assert!(median(&mut []).is_nan());
/// ```
pub fn median(values: &mut [f64]) -> f64 {
    let n = values.len();
    if n == 0 {
        return f64::NAN;
    }
    let x = 0.5 * (n - 1) as f64;
    let (i, f) = (x.floor() as usize, x.fract());
    let (_, &mut low, above) = values.select_nth_unstable_by(i, f64::total_cmp);
    match above.iter().copied().min_by(f64::total_cmp) {
        // The same arithmetic as `quantile` on the sorted sample.
        Some(high) => low * (1.0 - f) + high * f,
        None => low,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_by_selection_is_the_sorted_quantile() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for n in 1..60 {
            let sample: Vec<f64> = (0..n)
                .map(|_| {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    // Repeated values too: a few distinct levels.
                    ((state % 17) as f64 - 8.0) * 0.37
                })
                .collect();
            let mut sorted = sample.clone();
            sorted.sort_by(f64::total_cmp);
            let mut scratch = sample.clone();
            assert_eq!(
                median(&mut scratch).to_bits(),
                quantile(&sorted, 0.5).to_bits(),
                "n = {n}"
            );
        }
    }

    #[test]
    fn known_values() {
        // ln Gamma(5) = ln 24, Gamma(0.5) = sqrt(pi).
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-13);
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-13);
        // chi-square(1): P(X > 3.841459) = 0.05; chi-square(10): P(X > 18.307) = 0.05.
        assert!((chi2_sf(3.841_458_820_694_124, 1.0) - 0.05).abs() < 1e-10);
        assert!((chi2_sf(18.307_038_053_275_146, 10.0) - 0.05).abs() < 1e-9);
        assert!((chi2_isf(0.001, 3.0) - 16.266_236_196_238_13).abs() < 1e-7);
        // chi-square(2) is exponential: P(X > x) = exp(-x / 2).
        for x in [0.1, 1.0, 7.0, 40.0] {
            assert!(
                (chi2_sf(x, 2.0) - (-x / 2.0f64).exp()).abs()
                    < 1e-14 * 1f64.max((-x / 2.0f64).exp()) + 1e-15
            );
        }
    }

    #[test]
    fn tail_is_finite_and_monotone_everywhere() {
        // Regression: the branch test once mixed `x` with `a = k/2`, so the
        // continued fraction ran at `x/2 = k/2 - 1` (chi2_sf(5, 7) was NaN).
        for k in 1..=80 {
            let k = k as f64;
            let mut previous = 1.0;
            for step in 0..=400 {
                let x = 0.25 * step as f64;
                let tail = chi2_sf(x, k);
                assert!(
                    tail.is_finite() && (0.0..=1.0).contains(&tail),
                    "k={k} x={x}: {tail}"
                );
                assert!(tail <= previous + 1e-15, "k={k} x={x}: not monotone");
                previous = tail;
            }
        }
        // chi-square(7) at 5: 1 - P(3.5, 2.5) = 0.659963 (tables).
        assert!((chi2_sf(5.0, 7.0) - 0.659_963_3).abs() < 1e-6);
    }

    #[test]
    fn power_grows_with_noncentrality() {
        assert!((chi2_power(0.0, 2.0, 0.01) - 0.01).abs() < 2e-3);
        // One degree of freedom: the classic (z_{a/2} + z_b)^2 = (2.576 + 1.645)^2 = 17.8.
        let l = required_noncentrality(1.0, 0.01, 0.95).unwrap();
        assert!((l - 17.81).abs() < 0.05, "{l}");
        assert!(required_noncentrality(3.0, 0.01, 0.95).unwrap() > l);
        // A power of one is out of reach (the search used to double forever).
        assert_eq!(required_noncentrality(1.0, 0.01, 1.0), None);
    }
    #[test]
    fn the_windowed_noncentral_tail_equals_the_full_poisson_sum() {
        // The whole series from j = 0, as the definition reads.
        let full = |x: f64, k: f64, lambda: f64| {
            let mu = 0.5 * lambda;
            let top = (mu + 12.0 * mu.sqrt() + 30.0).ceil() as usize;
            (0..=top)
                .map(|j| {
                    let jf = j as f64;
                    (-mu + jf * mu.max(1e-300).ln() - ln_gamma(jf + 1.0)).exp()
                        * chi2_sf(x, k + 2.0 * jf)
                })
                .sum::<f64>()
                .min(1.0)
        };
        for (x, k) in [(5.0, 3.0), (30.0, 1.0), (400.0, 14.0)] {
            for lambda in [0.0, 0.5, 10.0, 200.0, 5000.0, 40_000.0] {
                let (a, b) = (noncentral_chi2_sf(x, k, lambda), full(x, k, lambda));
                // The full series accumulates rounding of order 1e-11 over
                // tens of thousands of terms.
                assert!(
                    (a - b).abs() < 1e-10,
                    "x {x} k {k} lambda {lambda}: {a} vs {b}"
                );
            }
        }
        // A non-centrality that dwarfs the critical value: power one, at
        // once (the full series would take 10^10 terms).
        assert_eq!(noncentral_chi2_sf(20.0, 3.0, 2e10), 1.0);
        assert!(required_noncentrality(3.0, 1e-4, 0.95).is_some());
    }

    #[test]
    fn f_distribution_matches_tables() {
        // Upper points (mpmath's regularised incomplete beta at 30 digits).
        for (x, d1, d2, p) in [
            (4.964_602_743, 1.0, 10.0, 0.05),
            (3.325_834_530, 5.0, 10.0, 0.05),
            (2.710_889_837, 5.0, 20.0, 0.05),
            (4.102_684_631, 5.0, 20.0, 0.01),
            (1.992_591_997, 10.0, 60.0, 0.05),
            (1.534_314_180, 60.0, 60.0, 0.05),
            (6.594_539_978, 3.0, 40.0, 0.001),
        ] {
            let got = f_sf(x, d1, d2);
            assert!(
                (got - p).abs() < 1e-6 * p.max(1e-3) + 1e-9,
                "F({d1},{d2}) at {x}: {got}"
            );
        }
        // F(1, d2) = t^2: P(F > t^2) = two-sided t tail; F(k, inf) -> chi2_k / k.
        assert!((f_sf(6.0, 3.0, 1e7) - chi2_sf(18.0, 3.0)).abs() < 1e-5);
        assert_eq!(f_sf(0.0, 2.0, 3.0), 1.0);
        assert!(beta_inc(-1.0, 1.0, 0.5).is_nan());
        // Monotone and finite over a wide range.
        let mut previous = 1.0;
        for step in 1..400 {
            let x = 0.05 * step as f64;
            let v = f_sf(x, 7.0, 23.0);
            assert!(v.is_finite() && v <= previous + 1e-15);
            previous = v;
        }
    }
}
