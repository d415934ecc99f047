//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! The encoder-grade study (the paper's Fig. 4, and beyond): how accurate is
//! a self-calibrated Tricept as a function of the U-joint encoders' grade?
//!
//! For each grade (angle noise of one reading, arcsec), Monte Carlo trials
//! of simulated self-calibration give the paper's residual error
//! `mu = ||deps - deps_e||_1 / n_eps` and the compensated volumetric error on
//! the middle plane. Three estimators run on the same scenario:
//!
//! - **fast** ([`fast`]): our identification, linear in the noise around the
//!   exact noise-free estimate; one factorisation per grade, all trials in
//!   one matrix product per block (millions of trials per second);
//! - **exact** ([`exact`]): every trial's readings from the exact model and a
//!   full nonlinear identification (the check on the fast path);
//! - **paper** ([`paper`]): the paper's differenced, unweighted
//!   `(H^T H)^{-1} H^T l`.
//!
//! [`optimise`] chooses pose sets that maximise an observability index;
//! [`plan`] chooses a few external measurements (tracker points, ballbar
//! readings) that minimise the predicted tool-tip error, with the same
//! exchange;
//! [`grades`] turns results into decisions (where calibration stops paying,
//! which grade a pose set needs, which grade to buy); [`invisible`] states
//! from the geometry which platform-joint error the sensors cannot see.
//! Everything is seeded and bit-reproducible at any thread count.
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod campaign;
pub mod check_plan;
mod error;
pub mod exact;
pub mod fast;
pub mod grades;
pub mod invisible;
mod kernel;
pub mod optimise;
pub mod paper;
pub mod plan;
pub mod plan_sources;
pub mod results;
mod rng;
pub mod scenario;

pub use error::StudyError;
pub use scenario::Scenario;

use fast::GradeModel;
use results::{GradeResult, PathResult};

/// Runs the fast path at every grade; `exact_trials` exact trials and the
/// paper's solve alongside when asked.
#[allow(clippy::too_many_arguments)]
pub fn run_grades(
    s: &Scenario,
    grades_arcsec: &[f64],
    trials: usize,
    exact_trials: usize,
    with_paper: bool,
    seed: u64,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<GradeResult>, StudyError> {
    grades_arcsec
        .iter()
        .enumerate()
        .map(|(i, &g)| {
            let model = GradeModel::new(s, g)?;
            let fast = PathResult::of(&model.estimator.run(s, trials, seed, i as u64, progress), s);
            let exact = if exact_trials > 0 {
                Some(PathResult::of(
                    &exact::run_exact(s, &model, exact_trials, seed, i as u64, progress)?,
                    s,
                ))
            } else {
                None
            };
            let (paper, paper_condition) = if with_paper {
                match paper::paper_solve(s, g)? {
                    paper::PaperSolve::Formed {
                        estimator,
                        condition,
                    } => (
                        Some(PathResult::of(
                            &estimator.run(s, trials, seed ^ 0x5a5a, i as u64, progress),
                            s,
                        )),
                        condition,
                    ),
                    paper::PaperSolve::Singular { condition } => (None, condition),
                }
            } else {
                (None, f64::NAN)
            };
            Ok(GradeResult {
                grade_arcsec: g,
                fast,
                exact,
                paper,
                paper_condition,
                rank: model.design.rank(),
            })
        })
        .collect()
}
