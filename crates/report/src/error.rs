//! The report's errors: a history or an export that belongs to another
//! calibration (bad input: the door gives them exit code 2).

/// Why a page cannot be made from its inputs.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// A check history's line names another calibration.
    #[error(
        "{file}: check {check} is a check of another calibration (calibration_digest {found}; the machine file's calibration is {expected}): give the history of this calibration's checks"
    )]
    HistoryOfAnotherCalibration {
        /// The history file.
        file: String,
        /// The check (1-based, in file order).
        check: usize,
        /// The digest the check names.
        found: String,
        /// The machine file's calibration digest.
        expected: String,
    },
    /// An export summary names another calibration.
    #[error(
        "{file}: an export of another calibration (calibration_digest {found}; the machine file's calibration is {expected}): export this machine file"
    )]
    ExportOfAnotherCalibration {
        /// The export's summary file.
        file: String,
        /// The digest the summary names.
        found: String,
        /// The machine file's calibration digest.
        expected: String,
    },
    /// An input is not what its flag asks for.
    #[error("{file}: {why}")]
    NotReadable {
        /// The file.
        file: String,
        /// What is wrong with it.
        why: String,
    },
}
