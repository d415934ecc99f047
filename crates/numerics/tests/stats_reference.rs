//! The distributions against closed forms computed here, independently of
//! `stats.rs` (issue 32): the chi-square tails far out (where a p-value of
//! 1e-21 must not become 0), `chi2_ln_sf` on both sides of `k + 2`, and
//! the incomplete beta and gamma functions on and off their domain.
//!
//! References:
//! - even `k = 2m`: `P(X > x) = exp(-x/2) sum_{j<m} (x/2)^j / j!` (the
//!   Poisson sum, exact);
//! - `k = 1`: `P(X > x) = erfc(sqrt(x/2))`; `k = 3`:
//!   `erfc(sqrt(x/2)) + sqrt(2x/pi) exp(-x/2)`, with `erfc` from its Taylor
//!   series (small arguments) or its continued fraction (large ones),
//!   written below;
//! - `I_x(a, 1) = x^a`, `I_x(1, b) = 1 - (1 - x)^b`;
//! - `I_x(a, b)` for integers by the binomial sum `sum_{j>=a} C(a+b-1, j)
//!   x^j (1-x)^(a+b-1-j)` (small values between `beta_inc`'s switch and
//!   `(a + 1) / (a + 2b)`);
//! - `I_x(a, b)` for an integer `a` by the negative binomial tail
//!   `(1-x)^b sum_{j>=a} (b)_j / j! x^j` (small values just below the switch
//!   for `b < 1`);
//! - `Gamma(1/4) = 3.6256099082219083119` (OEIS A068466), `Gamma(1/3) =
//!   2.6789385347077476337` (A073005), `Gamma(1/10) = Gamma(1.1) / 0.1` with
//!   `Gamma(1.1) = 0.95135076986687318363` (Abramowitz and Stegun, table
//!   6.1): below 1/2, where `ln_gamma` reflects.

use std::f64::consts::PI;

use tricept_numerics::stats::{
    beta_inc, chi2_isf, chi2_ln_sf, chi2_sf, chi2_two_sided, f_sf, gamma_p, ln_gamma,
};

/// `ln P(X > x)` for an even `k`, by the Poisson sum.
fn ln_sf_even(x: f64, k: u32) -> f64 {
    let h = x / 2.0;
    let mut term = 1.0;
    let mut sum = 1.0;
    for j in 1..k / 2 {
        term *= h / j as f64;
        sum += term;
    }
    -h + sum.ln()
}

/// `ln erfc(z)` for `z >= 0`: the Taylor series of `erf` below 2, the
/// continued fraction `erfc(z) = exp(-z^2) / sqrt(pi) / (z + 1/2 / (z + 1 /
/// (z + 3/2 / (z + ...))))` evaluated backwards from depth 400 above.
fn ln_erfc(z: f64) -> f64 {
    if z < 2.0 {
        let mut sum = 0.0;
        let mut power = z; // z^(2n+1) / n!
        for n in 0..80 {
            let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
            sum += sign * power / (2 * n + 1) as f64;
            power *= z * z / (n + 1) as f64;
        }
        (1.0 - 2.0 / PI.sqrt() * sum).ln()
    } else {
        let mut t = z;
        for n in (1..=400).rev() {
            t = z + (n as f64 / 2.0) / t;
        }
        -z * z - 0.5 * PI.ln() - t.ln()
    }
}

/// `ln P(X > x)` for `k = 1` or `k = 3`.
fn ln_sf_odd(x: f64, k: u32) -> f64 {
    let z = (x / 2.0).sqrt();
    let tail = ln_erfc(z);
    match k {
        1 => tail,
        3 => {
            // ln(erfc + sqrt(2x/pi) e^{-x/2}), the second term in logs.
            let second = 0.5 * (2.0 * x / PI).ln() - x / 2.0;
            let top = tail.max(second);
            top + ((tail - top).exp() + (second - top).exp()).ln()
        }
        _ => unreachable!(),
    }
}

fn reference_ln_sf(x: f64, k: u32) -> f64 {
    if k.is_multiple_of(2) {
        ln_sf_even(x, k)
    } else {
        ln_sf_odd(x, k)
    }
}

fn assert_relative(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got - want).abs() <= tol * want.abs(),
        "{what}: {got:e} vs {want:e}"
    );
}

#[test]
fn the_closed_forms_agree_with_tables() {
    // A check of the references themselves: chi2_1(0.95) = 3.841459,
    // chi2_3(0.999) = 16.26624, chi2_4(0.95) = 9.487729 (tables).
    assert_relative(
        reference_ln_sf(3.841_458_820_694_124, 1).exp(),
        0.05,
        1e-10,
        "k 1",
    );
    assert_relative(
        reference_ln_sf(16.266_236_196_238_13, 3).exp(),
        0.001,
        1e-9,
        "k 3",
    );
    assert_relative(
        reference_ln_sf(9.487_729_036_781_154, 4).exp(),
        0.05,
        1e-10,
        "k 4",
    );
}

#[test]
fn chi_square_tails_far_out_are_not_zero() {
    // chi2_sf(100, 3) = 1.55e-21 (issue 32's reference value).
    let p = chi2_sf(100.0, 3.0);
    assert!((p - 1.55e-21).abs() < 0.01e-21, "{p:e}");
    assert_relative(p, reference_ln_sf(100.0, 3).exp(), 1e-10, "sf(100, 3)");
    for (x, k) in [
        (100.0, 1),
        (100.0, 3),
        (100.0, 4),
        (250.0, 2),
        (400.0, 10),
        (1000.0, 3),
        (1000.0, 14),
        (30.0, 1),
        (30.0, 20),
    ] {
        let want = reference_ln_sf(x, k).exp();
        assert!(want > 0.0);
        assert_relative(chi2_sf(x, k as f64), want, 1e-9, &format!("sf({x}, {k})"));
    }
}

#[test]
fn chi_square_tails_near_the_mean_use_the_series() {
    // x below k/2 + 1 in units of x/2: the series branch of both functions.
    for (x, k) in [
        (0.01, 1),
        (0.5, 2),
        (1.0, 3),
        (3.0, 4),
        (4.0, 3),
        (5.9, 4),
        (9.0, 10),
        (11.0, 10),
        (15.0, 20),
        (21.9, 20),
    ] {
        let want = reference_ln_sf(x, k);
        let what = format!("({x}, {k})");
        assert_relative(chi2_sf(x, k as f64), want.exp(), 1e-11, &what);
        assert!(x < k as f64 + 2.0);
        assert_relative(chi2_ln_sf(x, k as f64), want, 1e-10, &what);
    }
}

#[test]
fn chi_square_tails_on_each_side_of_the_switch() {
    // x = k - 2 (x/2 = k/2 - 1), where the continued fraction divides by
    // zero: the series must answer. And tails of 1e-9 to 1e-20 between
    // k + 2 and 2k + 3, where `1 - P` by the series would keep only 7 to
    // no digits: the continued fraction must answer.
    for (x, k) in [
        (8.0, 10),
        (18.0, 20),
        (98.0, 100),
        (200.0, 100),
        (250.0, 124),
        (120.0, 50),
    ] {
        let want = reference_ln_sf(x, k);
        let what = format!("({x}, {k})");
        assert!(want.is_finite(), "{what}");
        assert_relative(chi2_sf(x, k as f64), want.exp(), 1e-11, &what);
        assert_relative(chi2_ln_sf(x, k as f64), want, 1e-11, &what);
    }
}

#[test]
fn chi_square_log_tails_beyond_underflow() {
    for (x, k) in [
        (100.0, 3),
        (2000.0, 2),
        (5000.0, 4),
        (5000.0, 3),
        (3000.0, 14),
    ] {
        let want = reference_ln_sf(x, k);
        assert_relative(
            chi2_ln_sf(x, k as f64),
            want,
            1e-12,
            &format!("ln sf({x}, {k})"),
        );
    }
    // At k + 2 the two branches meet.
    for k in [1, 2, 3, 4, 10] {
        let x = k as f64 + 2.0;
        let want = reference_ln_sf(x, k);
        assert_relative(chi2_ln_sf(x, k as f64), want, 1e-11, &format!("k {k}"));
        assert_relative(
            chi2_ln_sf(x - 1e-9, k as f64),
            want,
            1e-8,
            &format!("k {k}-"),
        );
    }
    // Nothing is surprising about a statistic of zero or less.
    assert_eq!(chi2_ln_sf(0.0, 3.0), 0.0);
    assert_eq!(chi2_ln_sf(-1.0, 3.0), 0.0);
    assert_eq!(chi2_sf(0.0, 3.0), 1.0);
    assert_eq!(chi2_sf(-1.0, 3.0), 1.0);
}

#[test]
fn quantiles_and_two_sided_tails() {
    // chi2_isf inverts the closed form.
    for (tail, k) in [(0.05, 1), (0.001, 3), (1e-12, 4), (0.5, 10)] {
        let x = chi2_isf(tail, k as f64);
        assert_relative(
            reference_ln_sf(x, k).exp(),
            tail,
            1e-6,
            &format!("{tail} {k}"),
        );
    }
    // k = 2: P(X > x) = exp(-x/2); twice the smaller tail, 1 at the median.
    let x = 2.0 * 10f64.ln();
    assert_relative(chi2_two_sided(x, 2.0), 2.0 * 0.1, 1e-12, "upper");
    let x = -2.0 * 0.99f64.ln();
    assert_relative(chi2_two_sided(x, 2.0), 2.0 * 0.01, 1e-9, "lower");
    assert!((chi2_two_sided(2.0 * 2f64.ln(), 2.0) - 1.0).abs() < 1e-15);
}

#[test]
fn incomplete_gamma_against_closed_forms() {
    // P(2, x) = 1 - exp(-x) (1 + x), both sides of x = a + 1.
    for x in [0.1f64, 1.0, 2.9, 3.1, 8.0, 30.0] {
        let want = 1.0 - (-x).exp() * (1.0 + x);
        assert!((gamma_p(2.0, x) - want).abs() < 1e-14, "P(2, {x})");
    }
    assert_eq!(gamma_p(2.0, 0.0), 0.0);
    assert_eq!(gamma_p(2.0, -1.0), 0.0);
}

#[test]
fn incomplete_beta_against_closed_forms_and_off_its_domain() {
    for x in [0.01, 0.2, 0.5, 0.8, 0.99] {
        for a in [0.5, 1.0, 2.5, 7.0] {
            let xa: f64 = x;
            assert_relative(beta_inc(a, 1.0, x), xa.powf(a), 1e-12, "I_x(a, 1)");
            let want = 1.0 - (1.0 - xa).powf(a);
            assert_relative(beta_inc(1.0, a, x), want, 1e-12, "I_x(1, b)");
        }
    }
    // Small values keep their digits: `I_x(1, b) = -expm1(b ln1p(-x))`
    // near 1e-7 (the form `1 - I_{1-x}(b, 1)` would keep 9 digits).
    for (x, b) in [(1e-8f64, 10.0f64), (1e-10, 3.0), (1e-9, 40.0)] {
        let want = -(b * (-x).ln_1p()).exp_m1();
        assert_relative(beta_inc(1.0, b, x), want, 1e-12, "small I_x(1, b)");
    }
    assert_eq!(beta_inc(2.0, 3.0, 0.0), 0.0);
    assert_eq!(beta_inc(2.0, 3.0, 1.0), 1.0);
    // Each argument out of its domain alone gives NaN.
    for (a, b, x) in [
        (0.0, 1.0, 0.5),
        (-1.0, 1.0, 0.5),
        (1.0, 0.0, 0.5),
        (1.0, -2.0, 0.5),
        (1.0, 1.0, -0.1),
        (1.0, 1.0, 1.1),
        (f64::NAN, 1.0, 0.5),
        (1.0, f64::NAN, 0.5),
        (1.0, 1.0, f64::NAN),
    ] {
        assert!(beta_inc(a, b, x).is_nan(), "I_{x}({a}, {b})");
    }
    // F(2, d2): P(F > x) = (1 + 2x/d2)^(-d2/2).
    for (x, d2) in [(0.5f64, 4.0f64), (3.0, 10.0), (20.0, 6.0)] {
        let want = (1.0 + 2.0 * x / d2).powf(-d2 / 2.0);
        assert_relative(f_sf(x, 2.0, d2), want, 1e-12, "F(2, d2)");
    }
    assert_eq!(f_sf(f64::INFINITY, 2.0, 3.0), 0.0);
    assert_eq!(f_sf(-1.0, 2.0, 3.0), 1.0);
}

/// `I_x(a, b)` for integers `a, b >= 1` by the binomial sum
/// `sum_{j=a}^{n} C(n, j) x^j (1 - x)^(n - j)`, `n = a + b - 1` (the
/// probability of at least `a` successes in `n` trials): every term is
/// positive, the first from logarithms of the factors of `C(n, a)`, the
/// next ones by the ratio `(n - j) / (j + 1) * x / (1 - x)`.
fn beta_inc_binomial(a: u32, b: u32, x: f64) -> f64 {
    let n = a + b - 1;
    let ln_choose: f64 = (1..=a)
        .map(|i| (f64::from(n - a + i) / f64::from(i)).ln())
        .sum();
    let mut term = (ln_choose + f64::from(a) * x.ln() + f64::from(n - a) * (-x).ln_1p()).exp();
    let mut sum = 0.0;
    for j in a..=n {
        sum += term;
        term *= f64::from(n - j) / f64::from(j + 1) * x / (1.0 - x);
    }
    sum
}

#[test]
fn small_incomplete_beta_below_the_switch_keeps_its_digits() {
    // Between (a + 1) / (a + 2b) and the switch (a + 1) / (a + b + 2) (for
    // b > 2), I_x(a, b) far below its mean is small: computed as
    // 1 - I_{1-x}(b, a) it would keep only the digits above 1e-16.
    for (a, b, x) in [(200, 200, 0.34), (100, 300, 0.15), (60, 60, 0.36)] {
        let (fa, fb) = (f64::from(a), f64::from(b));
        assert!(x > (fa + 1.0) / (fa + 2.0 * fb) && x < (fa + 1.0) / (fa + fb + 2.0));
        let want = beta_inc_binomial(a, b, x);
        assert!(want < 1e-3, "I_{x}({a}, {b}) = {want:e} is not small");
        assert_relative(
            beta_inc(fa, fb, x),
            want,
            1e-11,
            &format!("I_{x}({a}, {b})"),
        );
    }
    // The reference itself: I_x(1, b) = 1 - (1 - x)^b, I_x(a, 1) = x^a.
    assert_relative(
        beta_inc_binomial(1, 5, 0.2),
        1.0 - 0.8f64.powi(5),
        1e-14,
        "sum (1, 5)",
    );
    assert_relative(
        beta_inc_binomial(4, 1, 0.3),
        0.3f64.powi(4),
        1e-14,
        "sum (4, 1)",
    );
}

/// `I_x(a, b)` for an integer `a >= 1` and any `b > 0` by the negative
/// binomial tail `(1 - x)^b sum_{j>=a} (b)_j / j! x^j` (`(b)_j` the rising
/// factorial; the whole sum over `j >= 0` is `(1 - x)^(-b)`, and `I_x(1, b)
/// = 1 - (1 - x)^b`): positive terms, the first from logarithms, the next
/// ones by the ratio `(b + j) / (j + 1) * x`, summed until the rest
/// (below `term / (1 - x)` for `b < 1`) is under 1e-18 of the sum.
fn beta_inc_negative_binomial(a: u32, b: f64, x: f64) -> f64 {
    let ln_first: f64 = (0..a)
        .map(|i| ((b + f64::from(i)) / f64::from(i + 1)).ln())
        .sum();
    let mut term = (ln_first + b * (-x).ln_1p() + f64::from(a) * x.ln()).exp();
    let mut sum = 0.0;
    let mut j = f64::from(a);
    while term > 1e-18 * (1.0 - x) * sum {
        sum += term;
        term *= (b + j) / (j + 1.0) * x;
        j += 1.0;
    }
    sum
}

#[test]
fn incomplete_beta_just_below_the_switch_for_a_small_b() {
    // For b < 1 and a large, I_x(a, b) is small up to the switch (a + 1) /
    // (a + b + 2); the symmetric form 1 - I_{1-x}(b, a) keeps only its
    // digits above the rounding of the front factor (about 1e-12 of 1).
    // Points of the last 1 / (a + b + 2) below the switch.
    for (a, b) in [(1000, 0.01), (1000, 0.001), (100, 0.001)] {
        let fa = f64::from(a);
        let (low, switch) = (fa / (fa + b + 2.0), (fa + 1.0) / (fa + b + 2.0));
        for t in [0.0, 0.5, 0.9] {
            let x = low + t * (switch - low);
            let want = beta_inc_negative_binomial(a, b, x);
            assert!(want < 1e-2, "I_{x}({a}, {b}) = {want:e} is not small");
            assert_relative(beta_inc(fa, b, x), want, 1e-11, &format!("I_{x}({a}, {b})"));
        }
    }
    // The reference itself: I_x(1, b) = 1 - (1 - x)^b; for an integer b it
    // is the binomial sum.
    for (x, b) in [(0.3f64, 0.5f64), (0.9, 0.01)] {
        let want = -(b * (-x).ln_1p()).exp_m1();
        assert_relative(
            beta_inc_negative_binomial(1, b, x),
            want,
            1e-13,
            "tail (1, b)",
        );
    }
    assert_relative(
        beta_inc_negative_binomial(7, 3.0, 0.4),
        beta_inc_binomial(7, 3, 0.4),
        1e-13,
        "tail (7, 3)",
    );
}

#[test]
fn ln_gamma_below_one_half_reflects() {
    for (x, gamma) in [
        (0.25, 3.625_609_908_221_908),
        (1.0 / 3.0, 2.678_938_534_707_747_6),
        (0.1, 9.513_507_698_668_732),
    ] {
        assert_relative(ln_gamma(x), f64::ln(gamma), 1e-13, &format!("{x}"));
    }
    // The incomplete beta function needs it for a small shape: I_x(a, 1) = x^a.
    for x in [0.01f64, 0.3, 0.9] {
        assert_relative(beta_inc(0.2, 1.0, x), x.powf(0.2), 1e-12, "I_x(0.2, 1)");
        assert_relative(
            beta_inc(1.0, 0.3, x),
            1.0 - (1.0 - x).powf(0.3),
            1e-12,
            "I_x(1, 0.3)",
        );
    }
}
