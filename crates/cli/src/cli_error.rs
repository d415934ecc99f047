//! The CLI's error type: a one-line message and an exit code.

use tricept_kinematics::{DescriptionError, KinematicsError};

/// Exit code for usage and input errors.
pub const EXIT_INPUT: u8 = 2;
/// Exit code for every other failure.
pub const EXIT_OTHER: u8 = 1;
/// Exit code of a fit that converged but whose model does not explain the
/// data (`identify`, `compensate`).
pub const EXIT_INADEQUATE: u8 = 3;
/// Exit code of a fit that did not converge.
pub const EXIT_NOT_CONVERGED: u8 = 4;

/// A failure to report: printed as `error: <message>` on stderr.
#[derive(Debug)]
pub struct CliError {
    /// Process exit code (2 input, 1 other).
    pub code: u8,
    /// One line naming the file, row and column where there is one.
    pub message: String,
}

impl CliError {
    /// An input error (exit code 2).
    pub fn input(message: impl Into<String>) -> CliError {
        CliError {
            code: EXIT_INPUT,
            message: message.into(),
        }
    }

    /// Any other error (exit code 1).
    pub fn other(message: impl Into<String>) -> CliError {
        CliError {
            code: EXIT_OTHER,
            message: message.into(),
        }
    }

    /// A kinematics failure: unreachable or non-finite inputs are the
    /// user's input (2); solver failures are not (1).
    pub fn kinematics(context: &str, e: &KinematicsError) -> CliError {
        let message = format!("{context}: {e}");
        match e {
            KinematicsError::NotFinite { .. }
            | KinematicsError::OutOfReach { .. }
            | KinematicsError::OutOfStroke { .. }
            | KinematicsError::NoAssembly { .. }
            | KinematicsError::Singular { .. } => CliError::input(message),
            _ => CliError::other(message),
        }
    }

    /// A machine description that cannot be loaded (always an input error).
    pub fn description(path: &str, e: &DescriptionError) -> CliError {
        let message = match e {
            DescriptionError::Json { source } => format!(
                "{path}: line {}, column {}: {}",
                source.line(),
                source.column(),
                strip_position(&source.to_string())
            ),
            DescriptionError::Io { .. } => e.to_string(),
            DescriptionError::Invalid { .. } => format!("{path}: {e}"),
            _ => format!("{path}: {e}"),
        };
        CliError::input(message)
    }
}

/// serde_json appends " at line L column C"; the CLI states it up front.
fn strip_position(s: &str) -> String {
    match s.rfind(" at line ") {
        Some(i) => s[..i].to_string(),
        None => s.to_string(),
    }
}
