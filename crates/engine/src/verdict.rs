//! Whether an identification can be trusted, in three answers a program
//! can act on and warnings a person can read.
//!
//! - **Converged**: the Gauss-Newton iteration met its tolerance. A fit
//!   that did not is not a calibration, whatever its numbers.
//! - **Adequate**: the model explains the data to the stated sensor noise:
//!   the weighted chi-square passes its test at [`ADEQUACY_ALPHA`], the
//!   level the diagnosis uses. A converged fit that is not adequate has put
//!   something the model lacks (an unmodelled effect, more noise than
//!   stated) into its parameters; `tricept diagnose` finds out what.
//! - **Inconsistent**: the data cannot come from the described machine at
//!   all: chi-square per degree of freedom above
//!   [`INCONSISTENT_CHI2_PER_DOF`] (residuals of about 30 noise standard
//!   deviations on average). That is a wrong machine file, swapped
//!   columns or readings in the wrong units, not a calibration problem;
//!   [`crate::suspects::likely_causes`] tests which.

use serde::Serialize;
use tricept_numerics::stats::chi2_sf;

use crate::identify::Identification;

/// Significance level of the adequacy test (the diagnosis' level).
pub const ADEQUACY_ALPHA: f64 = 1e-3;

/// Chi-square per degree of freedom above which data cannot come from the
/// described machine: unmodelled effects of realistic size give tens to a
/// few hundred (the compliance example of `docs/diagnosis.md`: 19).
pub const INCONSISTENT_CHI2_PER_DOF: f64 = 1000.0;

/// A geometric estimate above this (mm) is worth a warning even when the
/// data fit: machines are built to drawings to better than this.
pub const LARGE_ESTIMATE_MM: f64 = 10.0;

/// An estimated parameter whose standard deviation exceeds this (mm) is
/// barely seen by the data: its value means little.
pub const BARELY_SEEN_STD_DEV_MM: f64 = 1.0;

/// The verdict on an identification.
///
/// # Example
/// ```
/// use tricept_engine::{model::GeometricModel, IdentifyOptions, identify};
/// use tricept_kinematics::Machine;
/// use tricept_model::ParameterSet;
/// use tricept_plant::{Campaign, Plant};
/// let m = Machine::paper();
/// let set = ParameterSet::paper15();
/// let data = Plant::geometric(m.clone(), set.to_errors(&set.table2()))
///     .simulate(&Campaign::grid(&m, 1))
///     .unwrap();
/// let id = identify(&GeometricModel::new(m.clone(), set), &data, &IdentifyOptions::for_machine(&m)).unwrap();
/// let v = id.verdict();
/// assert!(v.converged && v.adequate && !v.inconsistent);
/// assert!(v.warnings.is_empty());
/// ```
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    /// The iteration met its tolerance.
    pub converged: bool,
    /// The model explains the data to the stated noise.
    pub adequate: bool,
    /// `P(chi2_dof > chi_square)`.
    pub chi_square_p_value: f64,
    /// The data cannot come from the described machine.
    pub inconsistent: bool,
    /// What a person should know, one sentence each.
    pub warnings: Vec<String>,
}

impl Identification {
    /// The verdict on this fit (see the module docs of `verdict.rs`).
    pub fn verdict(&self) -> Verdict {
        let s = &self.stats;
        let chi2_per_dof = s.reduced_chi_square;
        let p = if s.dof > 0 {
            chi2_sf(s.chi_square, s.dof as f64)
        } else {
            f64::NAN
        };
        let adequate = p > ADEQUACY_ALPHA;
        // NaN (no degrees of freedom) counts as inconsistent.
        let inconsistent = chi2_per_dof.is_nan() || chi2_per_dof > INCONSISTENT_CHI2_PER_DOF;
        let largest = self
            .names
            .iter()
            .zip(&self.estimate)
            .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
        let mut warnings = Vec::new();
        if !self.converged {
            warnings.push(format!(
                "the fit did NOT converge in {} Gauss-Newton iterations: its estimates are not a calibration",
                self.iterations
            ));
        }
        let a = tricept_kinematics::units::RAD_PER_ARCSEC;
        if inconsistent {
            warnings.push(format!(
                "the data cannot come from the described machine: chi2/dof {chi2_per_dof:.3e} (residual rms phi {:.1} arcsec, theta {:.1} arcsec, s {:.1} um){}; likely causes: a wrong machine file (the machine, its U-joint axis order), swapped columns (phi/theta, q1/q2/q3) or readings in the wrong units (s in m instead of mm, angles not in rad)",
                s.rms[0] / a,
                s.rms[1] / a,
                s.rms[2] * 1e3,
                match largest {
                    Some((n, v)) => format!(", estimates up to {v:.1} mm ({n})"),
                    None => String::new(),
                }
            ));
        } else if !adequate {
            warnings.push(format!(
                "the geometric model does not explain the data: chi2/dof {chi2_per_dof:.2} for {} dof (p = {p:.1e}); an unmodelled effect (leg lead, backlash, thermal growth, compliance, sensor errors) or more sensor noise than stated has gone into the estimates, and such a calibration can make the machine worse than none: run `tricept diagnose` on the same data",
                s.dof
            ));
        }
        if let Some((n, v)) = largest
            && !inconsistent
            && v.abs() > LARGE_ESTIMATE_MM
        {
            warnings.push(format!(
                "{n} = {v:.2} mm: an error this large means the machine description is far from this machine; check that it is the right file"
            ));
        }
        let barely: Vec<String> = self
            .names
            .iter()
            .zip(&self.estimate)
            .zip(&self.std_dev)
            .filter_map(|((n, v), sd)| {
                sd.filter(|s| *s > BARELY_SEEN_STD_DEV_MM)
                    .map(|s| format!("{n} = {v:.3} +- {s:.3} mm"))
            })
            .collect();
        if !barely.is_empty() {
            warnings.push(format!(
                "the data barely see {}: these estimates mean little (more or better spread poses help; a machine file that is itself a calibration should keep its `calibration` record, whose nominal machine decides what is held)",
                barely.join(", ")
            ));
        }
        Verdict {
            converged: self.converged,
            adequate,
            chi_square_p_value: p,
            inconsistent,
            warnings,
        }
    }
}
