//! The errors of pooled calibrations.

use tricept_engine::IdentError;
use tricept_numerics::sparse::BlockError;

/// Why a pooled calibration has no result.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FleetError {
    /// The input cannot be pooled (too few machines, mismatched files).
    #[error("{0}")]
    Input(String),
    /// A data set could not be identified (its source named).
    #[error("{source_name}: {error}")]
    Identification {
        /// The data set's source.
        source_name: String,
        /// The engine's error.
        error: IdentError,
    },
    /// The pooled least-squares problem has no solution to report.
    #[error("the pooled fit: {0}")]
    Solver(#[from] BlockError),
    /// A numerical step failed.
    #[error("{0}")]
    Numerical(&'static str),
}
