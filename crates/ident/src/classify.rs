//! Whose fault each library error is, and what it says more (its file
//! failure, its cause, the request setting it is about): the one
//! [`Classify`] of every error of the crates behind the door, from which
//! [`Error`](crate::Error) takes its exit code, [`ErrorCause`] and
//! [`Setting`](crate::Setting).

use tricept_check::CheckError;
use tricept_data::DataError;
use tricept_diagnose::{DeployError, DiagnoseError};
use tricept_engine::{IdentError, record::RecordError};
use tricept_export::ExportError;
use tricept_fleet::FleetError;
use tricept_kinematics::{KinematicsError, error::DescriptionError};
use tricept_model::ModelError;
use tricept_plant::PlantError;
use tricept_study::StudyError;

use crate::error::{Classify, ErrorCause, ErrorKind, FileFailure};

impl Classify for DataError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Input
    }

    fn cause(&self) -> Option<ErrorCause> {
        let at = |line: u64, column: Option<u64>| ErrorCause::Parse {
            line: Some(line),
            column,
        };
        match self {
            DataError::Json { line, column, .. } => Some(at(*line, Some(*column))),
            DataError::MissingColumn { line, .. }
            | DataError::DuplicateColumn { line, .. }
            | DataError::FieldCount { line, .. }
            | DataError::BadValue { line, .. } => Some(at(*line, None)),
            _ => None,
        }
    }

    fn file_failure(&self) -> Option<FileFailure> {
        match self {
            DataError::Io { file, source } => Some(FileFailure::new(file.clone(), source)),
            _ => None,
        }
    }
}

impl Classify for DescriptionError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Input
    }

    fn cause(&self) -> Option<ErrorCause> {
        match self {
            DescriptionError::Json { source } => Some(ErrorCause::Parse {
                line: Some(source.line() as u64),
                column: Some(source.column() as u64),
            }),
            DescriptionError::NewerFormat(n) => Some(ErrorCause::NewerFormat {
                found: n.found,
                supported: n.supported,
            }),
            _ => None,
        }
    }

    fn file_failure(&self) -> Option<FileFailure> {
        match self {
            DescriptionError::Io { path, source } => Some(FileFailure::new(path.clone(), source)),
            _ => None,
        }
    }
}

impl Classify for RecordError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Input
    }

    fn cause(&self) -> Option<ErrorCause> {
        match self {
            RecordError::Edited { fields, .. } => Some(ErrorCause::SealBroken {
                fields: fields.clone(),
            }),
            _ => None,
        }
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

    fn setting(&self) -> Option<(&'static str, String)> {
        match self {
            ExportError::Setting { setting, why } => Some((setting, why.clone())),
            ExportError::AxisName {
                name,
                controller,
                rule,
            } => Some((
                "axis_names",
                format!("`{name}` is not a {controller} axis name ({rule})"),
            )),
            _ => None,
        }
    }
}
