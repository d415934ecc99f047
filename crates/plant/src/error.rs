//! Why a simulation failed.

use thiserror::Error;
use tricept_kinematics::KinematicsError;

/// Why a simulation failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum PlantError {
    /// A target pose the nominal machine cannot reach, or an actual machine
    /// that cannot assemble at the commands.
    #[error("pose {} ({target_mm:?} mm): {source}", index + 1)]
    Kinematics {
        /// Index of the target in the campaign (0-based; shown 1-based).
        index: usize,
        /// The target, mm.
        target_mm: [f64; 3],
        /// The kinematic failure.
        source: KinematicsError,
    },
    /// An inconsistent configuration.
    #[error("invalid plant configuration: {0}")]
    Invalid(String),
}
