//! The fit core every later stage shares: a model fitted to data
//! ([`Fit`]), the settings fixed for one diagnosis that every fit uses
//! ([`Fitter`]: the options, the noise, the test reference, the campaign
//! frame and the geometric model), what a failed fit is ([`FitError`]),
//! cross-validation, residuals, estimates and the outlier screen.

use std::sync::Arc;

use nalgebra::DMatrix;
use rayon::prelude::*;
use tricept_data::{Dataset, MeasuredPose};
use tricept_engine::{
    IdentError, Identification, IdentifyOptions, identify, model::GeometricModel,
    model::ReadingModel, robust::residuals_at, robust::screen_gross_errors,
    robust::screen_gross_errors_with_fit,
};

use tricept_model::effects::Needs;

use crate::error::DiagnoseError;
use crate::evidence::Reference;
use crate::model::ExtendedModel;
use crate::options::DiagnoseOptions;
use crate::report::Estimate;
use crate::terms::{Frame, Term};

/// A model fitted to data.
#[derive(Clone)]
pub(crate) struct Fit {
    pub(crate) model: ExtendedModel,
    pub(crate) id: Identification,
}

/// What every fit of one diagnosis uses.
pub(crate) struct Fitter<'a> {
    pub(crate) options: &'a DiagnoseOptions,
    /// Noise of one logged reading used by every fit (stated or estimated).
    pub(crate) sigma: [f64; 3],
    pub(crate) reference: Reference,
    pub(crate) frame: Arc<Frame>,
    pub(crate) geometric: GeometricModel,
}

impl Fitter<'_> {
    /// The geometric model with the frame and no terms.
    pub(crate) fn base_model(&self) -> ExtendedModel {
        ExtendedModel::with_terms(self.geometric.clone(), &[], self.frame.clone())
    }

    pub(crate) fn model(&self, terms: &[Term]) -> ExtendedModel {
        ExtendedModel::with_terms(self.geometric.clone(), terms, self.frame.clone())
    }

    pub(crate) fn identify_options(&self) -> IdentifyOptions {
        IdentifyOptions::with_sigma(self.sigma)
    }

    /// Fits `model` to `data`: a fit that does not converge, or whose
    /// geometric errors exceed `max_error_mm`, is not a fit.
    pub(crate) fn fit(&self, model: ExtendedModel, data: &Dataset) -> Result<Fit, FitError> {
        let id = identify(&model, data, &self.identify_options()).map_err(FitError::Ident)?;
        self.checked(model, id)
    }

    /// `id`, an identification of `model`, as a fit: one that did not
    /// converge, or whose geometric errors exceed `max_error_mm`, is not a
    /// fit.
    fn checked(&self, model: ExtendedModel, id: Identification) -> Result<Fit, FitError> {
        let g = model.n_geometric();
        let largest = id.estimate[..g].iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if !id.converged
            || !largest.is_finite()
            || largest > self.options.max_error_mm
            || !id.stats.chi_square.is_finite()
        {
            return Err(FitError::NotConverged {
                largest_error_mm: largest,
                iterations: id.iterations,
            });
        }
        Ok(Fit { model, id })
    }

    /// K-fold cross-validated RMS of the weighted held-out residuals of
    /// `model` on `data`, evaluated on the poses `evaluate` accepts;
    /// `Err(fold)` when a fold cannot be fitted.
    pub(crate) fn holdout_rms(
        &self,
        model: &ExtendedModel,
        data: &Dataset,
        evaluate: &(dyn Fn(usize) -> bool + Sync),
    ) -> Result<f64, usize> {
        let k = self.options.folds.max(2);
        let parts: Vec<Result<(f64, usize), usize>> = (0..k)
            .into_par_iter()
            .map(|fold| {
                let train = data.subset(|j| j % k != fold);
                let f = self.fit(model.clone(), &train).map_err(|_| fold + 1)?;
                let poses: Vec<MeasuredPose> = data
                    .poses
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| j % k == fold && evaluate(*j))
                    .map(|(_, p)| *p)
                    .collect();
                let mut sum = 0.0;
                let mut n = 0;
                for r in residuals_of(&f, &poses, &self.sigma) {
                    let r = r.ok_or(fold + 1)?;
                    sum += r.iter().map(|v| v * v).sum::<f64>();
                    n += 3;
                }
                Ok((sum, n))
            })
            .collect();
        let (mut sum, mut n) = (0.0, 0);
        for part in parts {
            let (s, c) = part?;
            sum += s;
            n += c;
        }
        if n == 0 {
            return Err(0);
        }
        Ok((sum / n as f64).sqrt())
    }

    /// Chi-square of `fit` on `clean` with the temperature logger's noise in
    /// the variance of readings that depend on temperature (errors in
    /// variables): the final adequacy of a model with terms that need the
    /// temperature.
    pub(crate) fn final_chi_square(&self, fit: &Fit, clean: &Dataset) -> f64 {
        let temperature_terms = fit
            .model
            .terms()
            .iter()
            .any(|t| t.needs() == Needs::Temperature);
        let sigma = self.sigma;
        if !temperature_terms || self.options.temperature_sigma_k <= 0.0 {
            return fit.id.stats.chi_square;
        }
        let predictor = fit.model.at(&fit.id.estimate);
        let k = fit.model.names().len();
        let mut jac = vec![0.0; 3 * k];
        let st = self.options.temperature_sigma_k;
        let mut chi2 = 0.0;
        for (pose, r) in clean.poses.iter().zip(&fit.id.residuals) {
            let mut at = |dt: f64| -> Option<[f64; 3]> {
                let mut p: MeasuredPose = *pose;
                p.temp_c = p.temp_c.map(|t| t + dt);
                let mut seed = None;
                predictor.predict(&p, &mut seed, &mut jac).ok()
            };
            let slope = match (at(0.5), at(-0.5)) {
                (Some(a), Some(b)) => std::array::from_fn(|c| a[c] - b[c]),
                _ => [0.0; 3],
            };
            for c in 0..3 {
                let var = sigma[c] * sigma[c] + (slope[c] * st).powi(2);
                chi2 += r[c] * r[c] / var;
            }
        }
        chi2
    }

    /// The outlier screen of `tricept_engine::robust` with the diagnosis'
    /// options; the indices of the flagged poses.
    pub(crate) fn screen_outliers(
        &self,
        model: &ExtendedModel,
        data: &Dataset,
    ) -> Result<Vec<usize>, IdentError> {
        Ok(screen_gross_errors(
            model,
            data,
            &self.identify_options(),
            self.options.alpha,
            self.options.max_outlier_share,
        )?
        .into_iter()
        .map(|r| r.pose)
        .collect())
    }

    /// [`Fitter::screen_outliers`] with the screen's fit of `model` to the
    /// poses it keeps, when it made one: the same as [`Fitter::fit`] on
    /// them (or its error), which the selection need not repeat.
    pub(crate) fn screen_outliers_with_fit(
        &self,
        model: &ExtendedModel,
        data: &Dataset,
    ) -> Result<(Vec<usize>, Option<FitResult>), IdentError> {
        let (rejected, id) = screen_gross_errors_with_fit(
            model,
            data,
            &self.identify_options(),
            self.options.alpha,
            self.options.max_outlier_share,
        )?;
        let flagged = rejected.into_iter().map(|r| r.pose).collect();
        Ok((flagged, id.map(|id| self.checked(model.clone(), id))))
    }
}

/// A fit, or why the model could not be fitted.
pub(crate) type FitResult = Result<Fit, FitError>;

/// Why a model could not be fitted.
#[derive(Debug)]
pub(crate) enum FitError {
    Ident(IdentError),
    NotConverged {
        largest_error_mm: f64,
        iterations: u32,
    },
}

impl From<FitError> for DiagnoseError {
    fn from(e: FitError) -> DiagnoseError {
        match e {
            FitError::Ident(e) => DiagnoseError::Ident(e),
            FitError::NotConverged {
                largest_error_mm,
                iterations,
            } => DiagnoseError::NotConverged {
                largest_error_mm,
                iterations,
            },
        }
    }
}

/// `data` without the poses `flagged` (`data` itself when none is).
pub(crate) fn clean_poses<'d>(
    data: &'d Dataset,
    flagged: &[usize],
) -> std::borrow::Cow<'d, Dataset> {
    if flagged.is_empty() {
        std::borrow::Cow::Borrowed(data)
    } else {
        std::borrow::Cow::Owned(data.subset(without(data.poses.len(), flagged)))
    }
}

/// Whether pose `j` of `n` is not among `flagged`.
pub(crate) fn without(n: usize, flagged: &[usize]) -> impl Fn(usize) -> bool + use<> {
    let mut keep = vec![true; n];
    for &j in flagged {
        if let Some(k) = keep.get_mut(j) {
            *k = false;
        }
    }
    move |j| keep.get(j).copied().unwrap_or(false)
}

/// Values and covariance of `term`'s parameters in `fit`.
pub(crate) fn term_estimates(fit: &Fit, term: &Term) -> (Vec<f64>, DMatrix<f64>) {
    let terms = fit.model.terms();
    let offsets = fit.model.offsets();
    let Some(i) = terms.iter().position(|t| t == term) else {
        return (Vec::new(), DMatrix::zeros(0, 0));
    };
    let at = offsets[i];
    let k = term.param_count();
    let values = fit.id.estimate[at..at + k].to_vec();
    let cov = fit.id.covariance.view((at, at), (k, k)).into_owned();
    (values, cov)
}

/// Weighted residuals of `poses` under a fitted model (offsets applied).
pub(crate) fn residuals_of(
    f: &Fit,
    poses: &[MeasuredPose],
    sigma: &[f64; 3],
) -> Vec<Option<[f64; 3]>> {
    // A fit's estimate always has its model's length.
    residuals_at(&f.model, &f.id.estimate, &f.id.offsets, poses, sigma)
        .unwrap_or_else(|_| vec![None; poses.len()])
}

/// Every parameter of a fitted model with its estimate.
pub(crate) fn estimates(f: &Fit) -> Vec<Estimate> {
    f.model
        .names()
        .iter()
        .zip(&f.id.estimate)
        .zip(&f.id.std_dev)
        .map(|((n, v), s)| Estimate {
            name: n.clone(),
            value: *v,
            std_dev: *s,
        })
        .collect()
}
