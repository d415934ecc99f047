//! Why a diagnosis, or the deployment of its model, could not be made.

use tricept_engine::IdentError;

/// Why a diagnosis could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DiagnoseError {
    /// The geometric identification itself failed.
    #[error(transparent)]
    Ident(#[from] IdentError),
    /// Too few poses for cross-validation.
    #[error("too few poses ({0}) for a diagnosis: at least 20 are needed")]
    TooFewPoses(usize),
    /// The geometric model cannot be fitted to the data: the fit does not
    /// converge or needs geometric errors beyond any machine's.
    #[error(
        "the geometric model cannot be fitted to these data (after {iterations} iterations the largest geometric error is {largest_error_mm:.3e} mm): rows that do not belong together (swapped columns, another machine) or readings in the wrong units"
    )]
    NotConverged {
        /// Largest geometric error of the failed fit, mm.
        largest_error_mm: f64,
        /// Gauss-Newton iterations performed.
        iterations: u32,
    },
    /// The data cannot support a diagnosis.
    #[error("{0}")]
    Degenerate(String),
    /// A cross-validation fold (counted from 0) cannot be fitted.
    #[error("cross-validation fold {0} cannot be fitted: too few or too similar poses in it")]
    FoldNotFitted(usize),
    /// A report number is not finite (a defect: reported rather than printed).
    #[error("internal error: the report's `{field}` is not a finite number")]
    NonFinite {
        /// Path of the number in the report.
        field: String,
    },
    /// `noise_from_data` without enough repeated poses.
    #[error(
        "the noise can be estimated from the data only with repeated poses: {dof} degrees of freedom of pure error, at least {needed} needed (log some poses again on separate visits)"
    )]
    NoiseFromDataNeedsRepeats {
        /// Degrees of freedom available per channel.
        dof: usize,
        /// Degrees of freedom needed.
        needed: usize,
    },
}

/// Why the model of a diagnosis cannot be deployed into a machine file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DeployError {
    /// The final model cannot be refitted on the diagnosis' clean poses.
    #[error("the diagnosis' final model: {0}")]
    Refit(#[from] IdentError),
    /// A parameter that no part of a machine file holds.
    #[error("the diagnosis named a parameter `{0}` that a machine file cannot hold")]
    NotDeployable(String),
}
