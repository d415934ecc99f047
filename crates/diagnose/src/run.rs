//! The diagnosis: is the geometric model adequate; if not, what explains
//! the data, what does not, and what cannot be told apart.
//!
//! 1. **Checks.** Every value finite, at least 20 poses; data without
//!    distinct line numbers are numbered from 1 in pose order.
//! 2. **Noise.** Repeated poses give the pure error ([`crate::noise`]); with
//!    `noise_from_data` the tests use the data's noise and F distributions.
//! 3. **Outliers.** The outlier screen of `tricept_engine::robust`; flagged
//!    poses make the cause `outliers`, and the rest of the analysis uses
//!    the clean poses. The screen is repeated with the selected causes, so
//!    that a misfit they explain is not taken for gross errors.
//! 4. **Selection** from one pool, the vocabulary and the generic
//!    dictionary, with plausibility and admission on the final model
//!    ([`crate::select`]).
//! 5. **Aliases** ([`crate::alias`]).
//! 6. **Final adequacy**: the final model's chi-square (with the
//!    temperature logger's noise propagated into readings that depend on
//!    temperature: errors in variables) and the dictionary screened once
//!    more at the final model; when either fails, the data are *partially
//!    explained* and the remainder is reported.
//! 7. **Report**, with a last check that every number in it is finite.

use std::borrow::Cow;

use tricept_data::Dataset;
use tricept_kinematics::Machine;

use crate::assemble::{Outcome, report};
use crate::error::DiagnoseError;
use crate::evidence::Reference;
use crate::finite::first_non_finite;
use crate::fit::{clean_poses, residuals_of};
use crate::noise::{pure_error, repeats};
use crate::options::{DiagnoseOptions, MIN_PURE_ERROR_DOF};
use crate::report::Diagnosis;
use crate::select::{Setup, select};

/// Diagnoses `data` taken on a machine whose nominal model is `nominal`.
///
/// # Example
/// ```no_run
/// use tricept_diagnose::{diagnose, DiagnoseOptions};
/// use tricept_kinematics::Machine;
/// let m = Machine::paper();
/// let data = tricept_data::read_path("fixtures/data/diagnose-hidden-effect.csv".as_ref()).unwrap();
/// let d = diagnose(&m, &data, &DiagnoseOptions::for_machine(&m)).unwrap();
/// println!("{:?}: {:?}", d.verdict, d.causes.iter().map(|c| c.effect).collect::<Vec<_>>());
/// ```
pub fn diagnose(
    nominal: &Machine,
    data: &Dataset,
    options: &DiagnoseOptions,
) -> Result<Diagnosis, DiagnoseError> {
    let n = data.poses.len();
    if n < 20 {
        return Err(DiagnoseError::TooFewPoses(n));
    }
    check_values(data)?;
    let mut limitations = Vec::new();
    let data = numbered(data, &mut limitations);
    let repeated = repeats(&data, options.repeat_tolerance_mm);
    let distinct = n - repeated.dof();
    if distinct < 20 {
        return Err(DiagnoseError::Degenerate(format!(
            "only {distinct} distinct leg commands among {n} rows (repeated commands do not count): at least 20 distinct poses are needed to fit and test the model",
        )));
    }
    let mut setup = Setup::new(nominal, &data, options);
    if !options.dictionary.enabled {
        limitations.push(
            "the generic dictionary was not searched: effects outside the vocabulary can only be reported as unexplained".into(),
        );
    }
    if setup.fitter.frame.temperature.is_none() {
        limitations.push(
            "the logged temperature is missing or varies by less than 0.25 K: thermal effects cannot be seen".into(),
        );
    }
    if options.noise_from_data {
        let dof = repeated.dof();
        if dof < MIN_PURE_ERROR_DOF {
            return Err(DiagnoseError::NoiseFromDataNeedsRepeats {
                dof,
                needed: MIN_PURE_ERROR_DOF,
            });
        }
        // Within a repeat group a model without context terms predicts the
        // same readings: the raw readings' spread is the first estimate.
        let raw: Vec<Option<[f64; 3]>> = data
            .poses
            .iter()
            .map(|p| {
                let y = p.readings.to_array();
                Some(std::array::from_fn(|c| y[c] / options.sigma[c]))
            })
            .collect();
        if let Some((ss, dof)) = pure_error(&repeated, &raw) {
            setup.fitter.sigma = rescaled(options.sigma, ss, dof);
            setup.fitter.reference = Reference {
                pure_error_dof: Some(3.0 * dof as f64),
            };
        }
    }
    let mut outcome = run(&setup, &data)?;
    if options.noise_from_data {
        // The spread about the final model: refit once if it moved.
        let res = residuals_of(&outcome.selection.current, &data.poses, &setup.fitter.sigma);
        if let Some((ss, dof)) = pure_error(&repeated, &res) {
            let ratio = ss.map(|s| (s / dof as f64).sqrt());
            if ratio.iter().any(|r| (r - 1.0).abs() > 0.1) {
                setup.fitter.sigma = rescaled(setup.fitter.sigma, ss, dof);
                outcome = run(&setup, &data)?;
            }
        }
    }
    let d = report(nominal, &data, &setup, outcome, &repeated, limitations)?;
    match first_non_finite(&d) {
        Some(field) => Err(DiagnoseError::NonFinite { field }),
        None => Ok(d),
    }
}

/// `sigma` scaled by the pure error's ratio per channel.
fn rescaled(sigma: [f64; 3], ss: [f64; 3], dof: usize) -> [f64; 3] {
    std::array::from_fn(|c| {
        let ratio = (ss[c] / dof as f64).sqrt();
        if ratio > 0.0 && ratio.is_finite() {
            sigma[c] * ratio
        } else {
            sigma[c]
        }
    })
}

/// Every logged value must be finite.
fn check_values(data: &Dataset) -> Result<(), DiagnoseError> {
    for p in &data.poses {
        let mut values: Vec<f64> = p.commands_mm.to_vec();
        values.extend(p.readings.to_array());
        values.extend(p.temp_c);
        values.extend(p.time_s);
        if values.iter().any(|v| !v.is_finite()) {
            return Err(DiagnoseError::Degenerate(format!(
                "line {}: a value is not a finite number",
                p.line
            )));
        }
    }
    Ok(())
}

/// The data with distinct line numbers (numbered from 1 in pose order
/// when they are not).
fn numbered<'d>(data: &'d Dataset, limitations: &mut Vec<String>) -> Cow<'d, Dataset> {
    let mut lines: Vec<u64> = data.poses.iter().map(|p| p.line).collect();
    lines.sort_unstable();
    lines.dedup();
    if lines.len() == data.poses.len() {
        return Cow::Borrowed(data);
    }
    limitations.push(
        "the poses carry no distinct line numbers: rows are numbered from 1 in pose order".into(),
    );
    let mut d = data.clone();
    for (j, p) in d.poses.iter_mut().enumerate() {
        p.line = j as u64 + 1;
    }
    Cow::Owned(d)
}

fn run(setup: &Setup<'_>, data: &Dataset) -> Result<Outcome, DiagnoseError> {
    let fitter = &setup.fitter;
    let base = fitter.base_model();
    // The screen's fit of the geometric model to the poses it keeps is the
    // selection's geometric fit on the first round.
    let (geometric_flagged, mut geo) = fitter.screen_outliers_with_fit(&base, data)?;
    let mut flagged = geometric_flagged.clone();
    let mut rounds = 0;
    loop {
        rounds += 1;
        let clean = clean_poses(data, &flagged);
        let selection = select(setup, &clean, geo.take())?;
        // A selection that named nothing ends on the geometric model, whose
        // screen of these data is the first one.
        let again = if selection.current.model.terms().is_empty() {
            geometric_flagged.clone()
        } else {
            fitter.screen_outliers(&selection.current.model, data)?
        };
        if again == flagged || rounds == 3 {
            return Ok(Outcome { flagged, selection });
        }
        flagged = again;
    }
}
