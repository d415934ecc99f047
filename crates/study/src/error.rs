//! Why a study could not run.

use thiserror::Error;

/// Why a study could not run.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum StudyError {
    /// Identification failed.
    #[error(transparent)]
    Ident(#[from] tricept_engine::IdentError),
    /// The plant simulator failed.
    #[error(transparent)]
    Plant(#[from] tricept_plant::PlantError),
    /// The error model failed (a pose out of reach...).
    #[error(transparent)]
    Model(#[from] tricept_model::ModelError),
    /// Kinematics failed.
    #[error(transparent)]
    Kinematics(#[from] tricept_kinematics::KinematicsError),
    /// A check could not be planned.
    #[error(transparent)]
    Check(#[from] tricept_check::CheckError),
    /// An exact trial's Gauss-Newton did not converge.
    #[error("exact trial {trial}: identification did not converge")]
    NotConverged {
        /// The trial.
        trial: u64,
    },
    /// Inconsistent configuration.
    #[error("{0}")]
    Invalid(String),
}
