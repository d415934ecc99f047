//! Decisions from study results: the grade where calibration stops paying
//! ([`crossing_grade`]), the grade at which a pose set reaches a given
//! median `mu` ([`grade_for_mu`], [`equivalent_grade`]), and the grade to
//! buy for an accuracy target ([`recommend`]).
//!
//! Grades are searched with [`tricept_numerics::roots::threshold`] in log
//! space; every evaluation of a grade draws the same trials (common random
//! numbers), so the median `mu` is a smooth, increasing function of the
//! grade and the search is well posed.

use tricept_numerics::roots::{Spacing, Threshold, threshold};

use crate::fast::{GradeModel, LinearEstimator};
use crate::scenario::Scenario;
use crate::{StudyError, results::GradeResult, results::Summary};

/// A condition of the grade search that cannot be evaluated (the paper's
/// estimator is singular at this grade).
enum Stop {
    Unavailable,
    Failed(StudyError),
}

impl From<StudyError> for Stop {
    fn from(e: StudyError) -> Stop {
        Stop::Failed(e)
    }
}

/// The grade (arcsec) at which the median `mu` of `estimator(grade)`
/// reaches `mu_0`, by doubling from `start_arcsec` then bisection in log
/// space (12 steps), with `trials` fast trials per evaluation. `None` if it
/// does not cross below `limit_arcsec`, or if the estimator cannot be
/// formed (`Ok(None)` from `estimator`).
pub fn crossing_grade(
    s: &Scenario,
    start_arcsec: f64,
    limit_arcsec: f64,
    trials: usize,
    seed: u64,
    estimator: &dyn Fn(f64) -> Result<Option<LinearEstimator>, StudyError>,
) -> Result<Option<f64>, StudyError> {
    let reaches_mu0 = |g: f64| -> Result<bool, Stop> {
        let e = estimator(g)?.ok_or(Stop::Unavailable)?;
        let r = e.run(s, trials, seed, 1000 + g.to_bits() % 1000, &|_| {});
        Ok(Summary::of(&r.iter().map(|t| t.mu_mm).collect::<Vec<_>>()).median >= s.mu0_mm)
    };
    match threshold(
        start_arcsec,
        2.0 * start_arcsec,
        limit_arcsec,
        Spacing::Logarithmic,
        12,
        reaches_mu0,
    ) {
        Ok(t) => Ok(t.value()),
        Err(Stop::Unavailable) => Ok(None),
        Err(Stop::Failed(e)) => Err(e),
    }
}

/// Summary of `mu` over `trials` fast-path trials of `s` at `grade_arcsec`
/// (the same trials' noise for every grade: common random numbers).
pub fn mu_at_grade(
    s: &Scenario,
    grade_arcsec: f64,
    trials: usize,
    seed: u64,
) -> Result<Summary, StudyError> {
    let estimator = GradeModel::new(s, grade_arcsec)?.estimator;
    let r = estimator.run(s, trials, seed, 7777, &|_| {});
    Ok(Summary::of(&r.iter().map(|t| t.mu_mm).collect::<Vec<_>>()))
}

/// Standard error of a median, from its 95 % interval.
fn median_standard_error(s: &Summary) -> f64 {
    (s.median_ci95[1] - s.median_ci95[0]) / (2.0 * 1.96)
}

/// The grade (arcsec, between 0.01 and `limit_arcsec`) at which the median
/// `mu` of `s` equals `target_mm` ([`mu_at_grade`], 14 bisection steps in
/// log space). `None` when even `limit_arcsec` stays below the target; the
/// lower end when even 0.01 arcsec is above it.
pub fn grade_for_mu(
    s: &Scenario,
    target_mm: f64,
    limit_arcsec: f64,
    trials: usize,
    seed: u64,
) -> Result<Option<f64>, StudyError> {
    let t = threshold(
        0.01,
        limit_arcsec,
        limit_arcsec,
        Spacing::Logarithmic,
        14,
        |g| -> Result<bool, StudyError> {
            Ok(mu_at_grade(s, g, trials, seed)?.median >= target_mm)
        },
    )?;
    Ok(match t {
        Threshold::AtLower(g) | Threshold::At(g) => Some(g),
        Threshold::NotReached => None,
    })
}

/// The grade at which a pose set matches a reference median `mu`, with
/// its 95 % interval (a bound is `None` where no grade below the search
/// limit reaches it).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct EquivalentGrade {
    /// The grade, arcsec.
    pub grade_arcsec: f64,
    /// Its 95 % interval, arcsec.
    pub interval95_arcsec: [Option<f64>; 2],
}

/// The grade at which `s`'s median `mu` equals the `reference` median,
/// with a 95 % interval: the Monte Carlo standard errors of both medians
/// (from their order-statistic intervals) combined, and the search
/// repeated at the target moved by 1.96 of them either way.
pub fn equivalent_grade(
    s: &Scenario,
    reference: &Summary,
    trials: usize,
    seed: u64,
) -> Result<Option<EquivalentGrade>, StudyError> {
    let limit = 1e4;
    let Some(g) = grade_for_mu(s, reference.median, limit, trials, seed)? else {
        return Ok(None);
    };
    let at_g = mu_at_grade(s, g, trials, seed)?;
    let se = median_standard_error(reference).hypot(median_standard_error(&at_g));
    let lo = grade_for_mu(s, reference.median - 1.96 * se, limit, trials, seed)?;
    let hi = grade_for_mu(s, reference.median + 1.96 * se, limit, trials, seed)?;
    Ok(Some(EquivalentGrade {
        grade_arcsec: g,
        interval95_arcsec: [lo, hi],
    }))
}

/// The coarsest studied grade (arcsec) at which 95 % of the simulated
/// machines have a mean error after compensation and touch-off on the
/// middle plane of at most `target_um`; `None` when no studied grade does.
pub fn recommend(results: &[GradeResult], target_um: f64) -> Option<f64> {
    results
        .iter()
        .filter(|r| r.fast.plane_touched_mean_mm.p95 <= target_um * 1e-3)
        .map(|r| r.grade_arcsec)
        .fold(None, |acc: Option<f64>, g| {
            Some(acc.map_or(g, |x: f64| x.max(g)))
        })
}
