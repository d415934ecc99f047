//! Typed errors of the kinematics crate.
//!
//! Every solver in this crate returns one of these instead of a wrong number:
//! a configuration that cannot be reached, a Newton iteration that did not
//! converge, or a configuration whose Jacobian is too ill-conditioned for the
//! answer to mean anything.

use thiserror::Error;

/// Largest condition number (of the unit-free `J1`, see
/// [`crate::fk::FkSolution::condition`]) accepted before a configuration is
/// declared singular. In the Table 1 workspace it stays below 20.
pub const SINGULARITY_CONDITION_LIMIT: f64 = 1e6;

/// Why a kinematic computation could not produce a trustworthy answer.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum KinematicsError {
    /// An input was NaN or infinite.
    #[error("{what} is not a finite number ({value})")]
    NotFinite {
        /// Which input.
        what: &'static str,
        /// The offending value.
        value: f64,
    },
    /// The requested platform point or tool pose lies outside what the joints
    /// of the machine can reach (stroke or tilt limits, or no assembly exists).
    #[error("out of reach: {reason}")]
    OutOfReach {
        /// Human-readable reason naming the limit that was hit.
        reason: String,
    },
    /// A commanded leg length lies outside the leg's stroke.
    #[error("leg {leg} command {length_mm:.6} mm is outside the stroke [{min_mm}, {max_mm}] mm")]
    OutOfStroke {
        /// Leg number, 1-based as in the paper.
        leg: usize,
        /// The commanded length, mm.
        length_mm: f64,
        /// Lower stroke limit, mm.
        min_mm: f64,
        /// Upper stroke limit, mm.
        max_mm: f64,
    },
    /// No configuration satisfies the commanded leg lengths: the safeguarded
    /// Newton iteration stalled at a local minimum of the closure residual.
    #[error(
        "no assembly reaches these leg lengths (closure residual stalled at {residual_mm:.3e} mm)"
    )]
    NoAssembly {
        /// Euclidean norm of the leg-length residual where the search stalled, mm.
        residual_mm: f64,
    },
    /// The iteration limit was hit before the convergence tolerance.
    #[error("{solver} did not converge in {iterations} iterations (residual {residual:.3e})")]
    NotConverged {
        /// Which solver.
        solver: &'static str,
        /// Iterations performed.
        iterations: u32,
        /// Residual norm at the last iterate (mm, or mixed for the tool pose).
        residual: f64,
    },
    /// The configuration is (numerically) singular: the Jacobian's condition
    /// number exceeds the limit, so the answer would not be trustworthy.
    #[error("singular configuration: condition number {condition:.3e} exceeds {limit:.1e}")]
    Singular {
        /// Estimated condition number (dimensionless, see [`crate::fk::FkSolution::condition`]).
        condition: f64,
        /// The limit it exceeded.
        limit: f64,
    },
}

/// Errors found while loading or validating a machine description.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum DescriptionError {
    /// The JSON could not be parsed (syntax, wrong type, unknown key...).
    #[error("{source}")]
    Json {
        /// The parser's error, with line and column.
        #[from]
        source: serde_json::Error,
    },
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file declares a `format_version` newer than this tricept reads
    /// (refused before its other keys are read).
    #[error("{0}")]
    NewerFormat(#[from] crate::description::NewerFormat),
    /// The description parsed but describes an impossible machine.
    #[error("invalid machine description: {key}: {reason}")]
    Invalid {
        /// The JSON key (dotted path) at fault.
        key: String,
        /// What is wrong with it.
        reason: String,
    },
}
