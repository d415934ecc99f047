//! The exact Monte Carlo path: every trial's readings are the exact model's
//! noise-free readings plus fresh noise (each logged value the mean of
//! `readings_per_pose` Gaussian draws, as on the machine), identified by the
//! full nonlinear Gauss-Newton of `tricept-engine`, and compensated on the
//! exact model.
//!
//! Gauss-Newton starts at the noise-free estimate `p*` and the FK at the
//! true joints: the minimiser does not depend on the start (tested), only
//! the number of iterations does. Each trial has its own generator seeded
//! from (seed, grade, trial).

use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use tricept_data::Dataset;
use tricept_engine::{Identification, identify::Start, identify::identify_from};
use tricept_model::{params::residual_mu, volumetric::volumetric_errors};

use crate::fast::{GradeModel, model_of, options_for, start_for};
use crate::rng::trial_rng;
use crate::scenario::Scenario;
use crate::{StudyError, results::TrialResult};

/// The data of exact trial `trial`: noise-free readings plus the mean of
/// `readings_per_pose` draws per reading.
pub fn trial_data(
    s: &Scenario,
    g: &GradeModel,
    seed: u64,
    grade_index: u64,
    trial: u64,
) -> Dataset {
    let mut rng = trial_rng(seed, grade_index, trial);
    let k = s.readings_per_pose.max(1);
    let single = [0, 1, 2].map(|c| g.sigma[c] * f64::from(k).sqrt());
    let noise: Vec<f64> = (0..s.rows())
        .map(|row| {
            let sum: f64 = (0..k)
                .map(|_| {
                    let z: f64 = StandardNormal.sample(&mut rng);
                    z
                })
                .sum();
            single[row % 3] * sum / f64::from(k)
        })
        .collect();
    Dataset {
        poses: s.noisy_poses(&noise),
        source: format!("exact trial {trial}"),
    }
}

/// Identifies `data` as an exact trial does, from `start` (default `p*`).
pub fn identify_trial(
    s: &Scenario,
    g: &GradeModel,
    data: &Dataset,
    start: Option<Vec<f64>>,
) -> Result<Identification, StudyError> {
    let model = model_of(s);
    let options = options_for(s, g.grade_arcsec);
    let start = Start {
        parameters: Some(start.unwrap_or_else(|| g.estimator.p_star.clone())),
        ..start_for(s, Some(&g.design))
    };
    Ok(identify_from(&model, data, &options, &start)?)
}

/// One exact trial.
pub fn exact_trial(
    s: &Scenario,
    g: &GradeModel,
    seed: u64,
    grade_index: u64,
    trial: u64,
) -> Result<TrialResult, StudyError> {
    let data = trial_data(s, g, seed, grade_index, trial);
    let id = identify_trial(s, g, &data, None)?;
    if !id.converged {
        return Err(StudyError::NotConverged { trial });
    }
    let model = model_of(s);
    let map = volumetric_errors(&model.machine_at(&id.estimate), &s.actual, &s.plane_mm)?;
    let stats = map.stats();
    Ok(TrialResult {
        mu_mm: residual_mu(&s.truth, &id.estimate),
        plane_mean_mm: stats.mean_mm,
        plane_max_mm: stats.max_mm,
        plane_touched_mean_mm: map.without_mean_translation().stats().mean_mm,
    })
}

/// Runs `trials` exact trials in parallel (results in trial order).
pub fn run_exact(
    s: &Scenario,
    g: &GradeModel,
    trials: usize,
    seed: u64,
    grade_index: u64,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<TrialResult>, StudyError> {
    (0..trials as u64)
        .into_par_iter()
        .map(|t| {
            let r = exact_trial(s, g, seed, grade_index, t);
            progress(1);
            r
        })
        .collect()
}
