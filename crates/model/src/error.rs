//! Typed errors of the error-model crate.

use thiserror::Error;
use tricept_kinematics::KinematicsError;

/// What can go wrong when building or evaluating the error model.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ModelError {
    /// A parameter name that the set does not contain.
    #[error("unknown parameter `{name}` for set {set} (known: {known})")]
    UnknownParameter {
        /// The name given.
        name: String,
        /// The set's label.
        set: String,
        /// The set's names, space separated.
        known: String,
    },
    /// A parameter-set label that does not exist.
    #[error("unknown parameter set `{0}` (known: paper15, full21)")]
    UnknownParameterSet(String),
    /// A full error vector with a component the set cannot represent.
    #[error(
        "the {set} set cannot represent {component} = {value} mm (its frame conventions fix it)"
    )]
    NotRepresentable {
        /// The set's label.
        set: String,
        /// The offending 21-vector component.
        component: String,
        /// Its value, mm.
        value: f64,
    },
    /// Parameter values that are not JSON.
    #[error("parameter values: {0}")]
    Json(#[from] serde_json::Error),
    /// Parameter values that are JSON but not `{name: value_mm}`.
    #[error("parameter values: {0}")]
    Values(String),
    /// The kinematics failed at some pose.
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
}
