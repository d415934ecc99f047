//! The gross-error screen of a fused identification: a wild tracker point,
//! a misread ballbar or a touch on the wrong feature must not wreck the fit,
//! and must be named by its file and line. It is the screen of the UP
//! limb's data (`tricept_engine::robust::screen_gross_errors`, `robust.rs`) applied to
//! every source's records, each record a block of rows (3 coordinates of a
//! point, 1 length, 1 touch, 3 readings of a pose):
//!
//! 1. **Robust start.** At the starting point (nominal machine, each
//!    source's nuisance from its closed-form fit) every record's
//!    standardised residuals are centred on their median and scaled by
//!    1.4826 times their median absolute deviation (never below the noise),
//!    per row of the record; the first fit uses the records within
//!    `START_Z` (10, as `identify`) units (at least half of each source's).
//! 2. **Deleted residuals, one record at a time.** At the current fit every
//!    record gets `T_j = e_j^T (I -+ H_jj)^-1 e_j / s^2`, `H_jj` its block
//!    of the union's hat matrix: in the fit its deleted residual, outside
//!    its prediction residual; `s^2` its source's reduced chi-square
//!    without it (never below 1). Records outside whose `T_j` is below the
//!    Bonferroni criterion `chi2_m(1 - alpha / n)` of their source are
//!    taken back; otherwise the single worst record above it is set aside;
//!    until nothing changes.
//!
//! At most 10 % of a source's records (never fewer than two) may end up
//! rejected; a source with more keeps them all and says so (a model or
//! setup problem, not gross errors). Rejected records are reported by file
//! and line, and the fit is redone without them.

use tricept_numerics::stats::chi2_isf;

use crate::error::IdentError;
use crate::fusion::estimate::{
    Evaluation, check_counts, fit_masked, fit_started, nuisance_layout, start,
};
use crate::fusion::model::FusedModel;
use crate::fusion::options::{FusionOptions, ScreenOptions};
use crate::fusion::result::{Fusion, RecordCheck, RejectedRecord, SourceFit};
use crate::fusion::source::Source;
use crate::robust::start_set;

/// `T_j` of one record (see the module docs) in a source whose fit is `fit`.
fn statistic(check: &RecordCheck, fit: &SourceFit) -> f64 {
    let m = check.rows as f64;
    let s2 = if check.active {
        // Without the record: its quadratic form and its redundant part gone.
        let dof = fit.redundancy - (m - check.leverage);
        if dof > 1.0 {
            (fit.chi_square - check.quadratic) / dof
        } else {
            1.0
        }
    } else if fit.redundancy > 1.0 {
        fit.chi_square / fit.redundancy
    } else {
        1.0
    };
    check.quadratic / s2.max(1.0)
}

/// The robust start (stage 1 of the module docs) from the evaluation of
/// every record at the starting point.
fn robust_start(sources: &[Source], eval: &Evaluation) -> Vec<Vec<bool>> {
    sources
        .iter()
        .zip(&eval.standardised)
        .map(|(source, z)| {
            let n = source.records();
            let m = source.rows().rows_per_record().max(1);
            let median = |mut v: Vec<f64>| -> f64 { tricept_numerics::stats::median(&mut v) };
            let channel = |c: usize| -> Vec<(usize, f64)> {
                z.iter()
                    .enumerate()
                    .filter(|(i, _)| i % m == c)
                    .map(|(_, (r, v, _))| (*r, *v))
                    .collect()
            };
            let mut score = vec![0.0f64; n];
            for c in 0..m {
                let values = channel(c);
                let centre = median(values.iter().map(|(_, v)| *v).collect());
                let mad = median(values.iter().map(|(_, v)| (v - centre).abs()).collect());
                let scale = (1.4826 * mad).max(1.0);
                for (r, v) in values {
                    if r < n {
                        score[r] = score[r].max((v - centre).abs() / scale);
                    }
                }
            }
            start_set(&score)
        })
        .collect()
}

/// The screened fit (see the module docs): the records kept and the fit on
/// them, with the rejected ones and any source over its cap recorded.
pub(crate) fn screened_fit(
    model: &FusedModel,
    sources: &[Source],
    options: &FusionOptions,
    screen: &ScreenOptions,
) -> Result<(Vec<Vec<bool>>, Fusion), IdentError> {
    let all: Vec<Vec<bool>> = sources.iter().map(|s| vec![true; s.records()]).collect();
    let total: usize = sources.iter().map(|s| s.records()).sum();
    let crit: Vec<f64> = sources
        .iter()
        .map(|s| {
            chi2_isf(
                screen.alpha / s.records().max(1) as f64,
                s.rows().rows_per_record() as f64,
            )
        })
        .collect();
    check_counts(model, sources, &all)?;
    let (offsets, n_nuisance) = nuisance_layout(sources);
    let started = start(model, sources, offsets, n_nuisance, &all)?;
    let mut active = robust_start(sources, &started.2);
    // Every record in the first fit (the usual case): it starts from the
    // evaluation the robust start already made.
    let mut started = (active == all).then_some(started);
    let mut seen: Vec<Vec<Vec<bool>>> = Vec::new();
    let mut last: Option<(Vec<Vec<bool>>, Fusion)> = None;
    for _ in 0..(2 * total + 4) {
        if seen.contains(&active) {
            break;
        }
        seen.push(active.clone());
        let attempt = match started.take() {
            Some(s) => fit_started(s, options),
            None => fit_masked(model, sources, &active, options),
        };
        let fit = match attempt {
            Ok(f) => f,
            // Too few records left, or a station that cannot be located
            // without them: fall back to the previous set.
            Err(_) if last.is_some() => break,
            Err(_) if active != all => {
                active = all.clone();
                continue;
            }
            Err(e) => return Err(e),
        };
        let t: Vec<Vec<f64>> = fit
            .checks
            .iter()
            .zip(&fit.sources)
            .map(|(c, s)| c.iter().map(|r| statistic(r, s)).collect())
            .collect();
        let mut next = active.clone();
        let mut changed = false;
        for (s, ts) in t.iter().enumerate() {
            for (j, &tj) in ts.iter().enumerate() {
                if !active[s][j] && tj <= crit[s] {
                    next[s][j] = true;
                    changed = true;
                }
            }
        }
        if !changed {
            let worst = t
                .iter()
                .enumerate()
                .flat_map(|(s, ts)| ts.iter().enumerate().map(move |(j, tj)| (s, j, *tj)))
                .filter(|&(s, j, tj)| active[s][j] && tj > crit[s])
                .max_by(|a, b| (a.2 / crit[a.0]).total_cmp(&(b.2 / crit[b.0])));
            if let Some((s, j, _)) = worst {
                next[s][j] = false;
                changed = true;
            }
        }
        last = Some((active.clone(), fit));
        if !changed {
            break;
        }
        active = next;
    }
    let Some((mut active, mut fit)) = last else {
        return Err(IdentError::Numerical("the gross-error screen found no fit"));
    };
    // A record left out by a cycle or a failed refit whose statistic is
    // below the criterion is not a gross error: back in.
    let mut back = false;
    for (s, checks) in fit.checks.iter().enumerate() {
        for (j, c) in checks.iter().enumerate() {
            if !c.active && statistic(c, &fit.sources[s]) <= crit[s] {
                active[s][j] = true;
                back = true;
            }
        }
    }
    // The cap, on the final set.
    let mut overflow = Vec::new();
    for (s, source) in sources.iter().enumerate() {
        let n = source.records();
        let cap = ((screen.max_share * n as f64).floor() as usize).max(2);
        let rejected = active[s].iter().filter(|a| !**a).count();
        if rejected > cap {
            active[s] = vec![true; n];
            overflow.push(format!("{} ({})", source.label(), source.file()));
        }
    }
    if back || !overflow.is_empty() {
        fit = fit_masked(model, sources, &active, options)?;
    }
    let rejected = fit
        .checks
        .iter()
        .zip(&fit.sources)
        .enumerate()
        .flat_map(|(s, (checks, sf))| {
            checks
                .iter()
                .enumerate()
                .filter(|(_, c)| !c.active)
                .map(move |(j, c)| RejectedRecord {
                    label: sources[s].label().to_string(),
                    file: sources[s].file().to_string(),
                    line: c.line,
                    record: j,
                    residual_sigma: statistic(c, sf).sqrt(),
                })
        })
        .collect();
    fit.set_screen(rejected, overflow);
    Ok((active, fit))
}
