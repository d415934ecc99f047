//! What a study produces: each trial's result, the summary of a sample, the
//! statistics of one estimator at one grade and the results at a grade.

use serde::Serialize;
use tricept_numerics::stats::quantile;

use crate::scenario::Scenario;

/// What one trial produced.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TrialResult {
    /// The paper's `mu`, mm.
    pub mu_mm: f64,
    /// Mean `|dr|` over the plane after compensation, mm.
    pub plane_mean_mm: f64,
    /// Largest `|dr|` over the plane after compensation, mm.
    pub plane_max_mm: f64,
    /// Mean `|dr - t|` over the plane after compensation, with `t` the
    /// best-fit rigid translation removed (touch-off), mm.
    pub plane_touched_mean_mm: f64,
}

/// Mean, median and the 5-95 % band of a sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Summary {
    /// Sample mean.
    pub mean: f64,
    /// Sample standard deviation.
    pub std_dev: f64,
    /// Median.
    pub median: f64,
    /// 5 % quantile.
    pub p05: f64,
    /// 95 % quantile.
    pub p95: f64,
    /// Distribution-free 95 % confidence interval of the median: the order
    /// statistics `n/2 -+ 1.96 sqrt(n)/2` (normal approximation to the
    /// binomial count below the true median).
    pub median_ci95: [f64; 2],
}

impl Summary {
    /// Summary of `values` (empty: all NaN).
    pub fn of(values: &[f64]) -> Summary {
        let n = values.len();
        if n == 0 {
            return Summary {
                mean: f64::NAN,
                std_dev: f64::NAN,
                median: f64::NAN,
                p05: f64::NAN,
                p95: f64::NAN,
                median_ci95: [f64::NAN; 2],
            };
        }
        let mean = values.iter().sum::<f64>() / n as f64;
        let var =
            values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n.max(2) - 1) as f64;
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let q = |p: f64| quantile(&sorted, p);
        Summary {
            mean,
            std_dev: var.sqrt(),
            median: q(0.5),
            p05: q(0.05),
            p95: q(0.95),
            median_ci95: {
                let half = 1.96 * (n as f64).sqrt() / 2.0;
                let mid = n as f64 / 2.0;
                let lo = ((mid - half).floor().max(0.0) as usize).min(n - 1);
                let hi = ((mid + half).ceil() as usize).min(n - 1);
                [sorted[lo], sorted[hi]]
            },
        }
    }
}

/// Statistics of one estimator at one grade.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PathResult {
    /// Number of trials.
    pub trials: usize,
    /// The paper's `mu`, mm.
    pub mu_mm: Summary,
    /// Share of trials with `mu > mu_0` (calibration made things worse).
    pub mu_worse_share: f64,
    /// Mean `|dr|` over the plane after compensation, mm.
    pub plane_mean_mm: Summary,
    /// Largest `|dr|` over the plane after compensation, mm.
    pub plane_max_mm: Summary,
    /// Mean `|dr|` after compensation and touch-off, mm.
    pub plane_touched_mean_mm: Summary,
    /// Share of trials whose mean plane error after compensation exceeds
    /// the mean before.
    pub plane_worse_share: f64,
}

impl PathResult {
    /// Statistics of `trials` against the scenario's uncalibrated values.
    pub fn of(trials: &[TrialResult], s: &Scenario) -> PathResult {
        let n = trials.len().max(1) as f64;
        let mu: Vec<f64> = trials.iter().map(|t| t.mu_mm).collect();
        let mean: Vec<f64> = trials.iter().map(|t| t.plane_mean_mm).collect();
        let max: Vec<f64> = trials.iter().map(|t| t.plane_max_mm).collect();
        let touched: Vec<f64> = trials.iter().map(|t| t.plane_touched_mean_mm).collect();
        PathResult {
            trials: trials.len(),
            mu_worse_share: mu.iter().filter(|m| **m > s.mu0_mm).count() as f64 / n,
            plane_worse_share: mean.iter().filter(|m| **m > s.before_plane_mean_mm).count() as f64
                / n,
            mu_mm: Summary::of(&mu),
            plane_mean_mm: Summary::of(&mean),
            plane_max_mm: Summary::of(&max),
            plane_touched_mean_mm: Summary::of(&touched),
        }
    }
}

/// Results at one encoder grade.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GradeResult {
    /// Angle noise of one encoder reading, arcsec.
    pub grade_arcsec: f64,
    /// Our identification, fast path.
    pub fast: PathResult,
    /// Our identification, exact path (when run).
    pub exact: Option<PathResult>,
    /// The paper's solve (absent when `H^T H` is singular).
    pub paper: Option<PathResult>,
    /// Condition number of the paper's `H^T H`.
    pub paper_condition: f64,
    /// Numerical rank of our identification at this grade.
    pub rank: usize,
}

#[cfg(test)]
mod tests {
    use super::Summary;
    use rand::{RngExt, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    #[test]
    fn the_median_interval_covers_the_true_median_95_percent_of_the_time() {
        // Exponential samples (skewed like mu), true median ln 2.
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        let (runs, mut covered) = (400, 0);
        for _ in 0..runs {
            let sample: Vec<f64> = (0..2001)
                .map(|_| -(1.0 - rng.random::<f64>()).ln())
                .collect();
            let [lo, hi] = Summary::of(&sample).median_ci95;
            if lo <= std::f64::consts::LN_2 && std::f64::consts::LN_2 <= hi {
                covered += 1;
            }
        }
        // Binomial(400, 0.95): 380 +- 4.4; allow about 3 standard deviations.
        assert!((367..=393).contains(&covered), "{covered} of {runs}");
    }

    #[test]
    fn summaries_of_tiny_samples_are_defined() {
        let one = Summary::of(&[2.0]);
        assert_eq!((one.median, one.median_ci95), (2.0, [2.0, 2.0]));
        assert!(Summary::of(&[]).median_ci95[0].is_nan());
    }
}
