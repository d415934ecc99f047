//! The door's one error type and the one mapping from a library error's
//! kind to the process exit code, for every verb.
//!
//! Every error of the crates behind the door is [`Classify`]: its kind
//! says whether the user's input is at fault ([`ErrorKind::Input`], exit
//! code 2) or not ([`ErrorKind::Other`], exit code 1). The mapping lives
//! here alone, so the same library error exits with the same code from
//! every verb that can meet it.

use std::fmt;

use tricept_check::CheckError;
use tricept_data::DataError;
use tricept_diagnose::{DeployError, DiagnoseError};
use tricept_engine::{IdentError, RecordError};
use tricept_export::ExportError;
use tricept_fleet::FleetError;
use tricept_kinematics::{DescriptionError, KinematicsError};
use tricept_model::ModelError;
use tricept_plant::PlantError;
use tricept_study::StudyError;

/// Exit code of a result that can be trusted.
pub const EXIT_OK: u8 = 0;
/// Exit code of anything that is not the input's fault.
pub const EXIT_OTHER: u8 = 1;
/// Exit code of bad input: a file, a flag, a request.
pub const EXIT_INPUT: u8 = 2;
/// Exit code of a fit that converged but whose model does not explain the
/// data, or of a campaign too small to calibrate.
pub const EXIT_INADEQUATE: u8 = 3;
/// Exit code of a fit that did not converge.
pub const EXIT_NOT_CONVERGED: u8 = 4;

/// Whose fault a failure is, which decides the exit code.
///
/// # Example
/// ```
/// use tricept_ident::{ErrorKind, EXIT_INPUT};
/// assert_eq!(ErrorKind::Input.exit_code(), EXIT_INPUT);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The input is at fault: a file, a flag, data that cannot be used
    /// (exit code 2).
    Input,
    /// Anything else: a numerical failure, an I/O failure of an output
    /// (exit code 1).
    Other,
    /// A result that is not to be trusted because its model does not
    /// explain the data (exit code 3): a refused write, say.
    Inadequate,
    /// A result that is not to be trusted because its fit did not converge
    /// (exit code 4).
    NotConverged,
}

impl ErrorKind {
    /// The process exit code of a failure of this kind.
    pub fn exit_code(self) -> u8 {
        match self {
            ErrorKind::Input => EXIT_INPUT,
            ErrorKind::Other => EXIT_OTHER,
            ErrorKind::Inadequate => EXIT_INADEQUATE,
            ErrorKind::NotConverged => EXIT_NOT_CONVERGED,
        }
    }

    /// The kind whose exit code is `code` (a verdict's code: 3 inadequate,
    /// 4 not converged, 2 input; anything else is [`ErrorKind::Other`]).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::{ErrorKind, EXIT_INADEQUATE};
    /// assert_eq!(ErrorKind::of_exit_code(EXIT_INADEQUATE), ErrorKind::Inadequate);
    /// assert_eq!(ErrorKind::of_exit_code(EXIT_INADEQUATE).exit_code(), EXIT_INADEQUATE);
    /// ```
    pub fn of_exit_code(code: u8) -> ErrorKind {
        match code {
            EXIT_INPUT => ErrorKind::Input,
            EXIT_INADEQUATE => ErrorKind::Inadequate,
            EXIT_NOT_CONVERGED => ErrorKind::NotConverged,
            _ => ErrorKind::Other,
        }
    }
}

/// A library error that knows whose fault it is.
///
/// # Example
/// ```
/// use tricept_ident::ErrorKind;
/// use tricept_ident::advanced::Classify;
/// use tricept_ident::export::ExportError;
/// let e = ExportError::Options("--max-points: must be at least 2".into());
/// assert_eq!(e.kind(), ErrorKind::Input);
/// ```
pub trait Classify {
    /// Whose fault this error is.
    fn kind(&self) -> ErrorKind;
}

/// A failure of a workflow: a one-line message (naming the file, line and
/// column where there is one) and its [`ErrorKind`].
///
/// # Example
/// ```
/// use tricept_ident::{Error, EXIT_INPUT};
/// let e = Error::input("--alpha: must lie between 0 and 0.5, got 2").in_file("check");
/// assert_eq!(e.exit_code(), EXIT_INPUT);
/// assert_eq!(e.to_string(), "check: --alpha: must lie between 0 and 0.5, got 2");
/// ```
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Error {
    kind: ErrorKind,
    message: String,
}

impl Error {
    /// An error of the given kind.
    pub fn new(kind: ErrorKind, message: impl Into<String>) -> Error {
        Error {
            kind,
            message: message.into(),
        }
    }

    /// An error of the user's input (exit code 2).
    pub fn input(message: impl Into<String>) -> Error {
        Error {
            kind: ErrorKind::Input,
            message: message.into(),
        }
    }

    /// Any other error (exit code 1).
    pub fn other(message: impl Into<String>) -> Error {
        Error {
            kind: ErrorKind::Other,
            message: message.into(),
        }
    }

    /// A library error with its kind and its message.
    pub fn from_library(e: &(impl Classify + fmt::Display)) -> Error {
        Error {
            kind: e.kind(),
            message: e.to_string(),
        }
    }

    /// A library error with `context: ` before its message, keeping its
    /// kind.
    pub fn with_context(context: impl fmt::Display, e: &(impl Classify + fmt::Display)) -> Error {
        Error {
            kind: e.kind(),
            message: format!("{context}: {e}"),
        }
    }

    /// The same error with `context: ` before its message (a file, a flag).
    #[must_use]
    pub fn in_file(self, context: impl fmt::Display) -> Error {
        Error {
            kind: self.kind,
            message: format!("{context}: {}", self.message),
        }
    }

    /// Whose fault it is.
    pub fn kind(&self) -> ErrorKind {
        self.kind
    }

    /// The process exit code: 2 for input, 3 and 4 for an untrusted
    /// result, 1 for anything else.
    pub fn exit_code(&self) -> u8 {
        self.kind.exit_code()
    }

    /// The one-line message.
    pub fn message(&self) -> &str {
        &self.message
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

impl<E: Classify + fmt::Display> From<E> for Error {
    fn from(e: E) -> Error {
        Error::from_library(&e)
    }
}

impl Classify for DataError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Input
    }
}

impl Classify for DescriptionError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Input
    }
}

impl Classify for RecordError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Input
    }
}

impl Classify for KinematicsError {
    /// Unreachable or non-finite inputs are the user's; solver failures
    /// are not.
    fn kind(&self) -> ErrorKind {
        match self {
            KinematicsError::NotFinite { .. }
            | KinematicsError::OutOfReach { .. }
            | KinematicsError::OutOfStroke { .. }
            | KinematicsError::NoAssembly { .. }
            | KinematicsError::Singular { .. } => ErrorKind::Input,
            _ => ErrorKind::Other,
        }
    }
}

impl Classify for IdentError {
    /// Data too small to calibrate, unreachable poses, inconsistent
    /// options and unusable external sources are the input's fault; a
    /// numerical failure is not.
    fn kind(&self) -> ErrorKind {
        match self {
            IdentError::TooFewPoses { .. }
            | IdentError::TooFewDistinctPoses { .. }
            | IdentError::Kinematics { .. }
            | IdentError::Invalid(_)
            | IdentError::Source { .. }
            | IdentError::NuisanceUnidentifiable { .. } => ErrorKind::Input,
            _ => ErrorKind::Other,
        }
    }
}

impl Classify for DiagnoseError {
    /// What the data cause is the input's fault; an identification error
    /// keeps its own kind.
    fn kind(&self) -> ErrorKind {
        match self {
            DiagnoseError::Ident(e) => e.kind(),
            _ => ErrorKind::Input,
        }
    }
}

impl Classify for DeployError {
    fn kind(&self) -> ErrorKind {
        match self {
            DeployError::Refit(e) => e.kind(),
            _ => ErrorKind::Input,
        }
    }
}

impl Classify for FleetError {
    /// What cannot be pooled is the input's fault; an identification
    /// error keeps its own kind; a solver's failure is not the input's.
    fn kind(&self) -> ErrorKind {
        match self {
            FleetError::Input(_) => ErrorKind::Input,
            FleetError::Identification { error, .. } => error.kind(),
            _ => ErrorKind::Other,
        }
    }
}

impl Classify for CheckError {
    fn kind(&self) -> ErrorKind {
        match self {
            CheckError::Record(_)
            | CheckError::Blind(_)
            | CheckError::Invalid(_)
            | CheckError::HistoryLine(_)
            | CheckError::Kinematics { .. } => ErrorKind::Input,
            _ => ErrorKind::Other,
        }
    }
}

impl Classify for ModelError {
    fn kind(&self) -> ErrorKind {
        match self {
            ModelError::Kinematics(e) => e.kind(),
            _ => ErrorKind::Input,
        }
    }
}

impl Classify for PlantError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Input
    }
}

impl Classify for StudyError {
    fn kind(&self) -> ErrorKind {
        match self {
            StudyError::Ident(e) => e.kind(),
            StudyError::Kinematics(e) => e.kind(),
            StudyError::Model(e) => e.kind(),
            StudyError::Check(e) => e.kind(),
            StudyError::Invalid(_) => ErrorKind::Input,
            _ => ErrorKind::Other,
        }
    }
}

impl Classify for ExportError {
    /// A failed write is not the input's fault; everything else is.
    fn kind(&self) -> ErrorKind {
        match self {
            ExportError::Io { .. } => ErrorKind::Other,
            ExportError::Kinematics(e) => e.kind(),
            _ => ErrorKind::Input,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_same_library_error_has_one_exit_code_wherever_it_is_wrapped() {
        let direct = IdentError::Invalid("x".into());
        let via_diagnose = DiagnoseError::Ident(IdentError::Invalid("x".into()));
        let via_study = StudyError::Ident(IdentError::Invalid("x".into()));
        assert_eq!(Error::from(direct).exit_code(), EXIT_INPUT);
        assert_eq!(Error::from(via_diagnose).exit_code(), EXIT_INPUT);
        assert_eq!(Error::from(via_study).exit_code(), EXIT_INPUT);
        let numerical = IdentError::Numerical("rank");
        assert_eq!(Error::from(numerical).exit_code(), EXIT_OTHER);
        let wrapped = StudyError::Ident(IdentError::Numerical("rank"));
        assert_eq!(Error::from(wrapped).exit_code(), EXIT_OTHER);
    }
}
