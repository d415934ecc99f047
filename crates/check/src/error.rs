//! `CheckError`: why a check could not be made.

/// Why a check could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CheckError {
    /// The machine file cannot serve as a reference.
    #[error("{0}")]
    Record(String),
    /// The check campaign cannot see any change.
    #[error("the check's poses cannot see a change: {0}")]
    Blind(String),
    /// A setting out of range.
    #[error("{0}")]
    Invalid(String),
    /// A pose the calibrated machine cannot solve.
    #[error("pose {pose}{}: {source}", if *line > 0 { format!(" (line {line})") } else { String::new() })]
    Kinematics {
        /// 1-based pose number.
        pose: usize,
        /// Line in the data file (0 when there is none).
        line: u64,
        /// The kinematic failure.
        source: tricept_kinematics::KinematicsError,
    },
    /// The history file cannot be read as a history (a line that is not a
    /// check, a file that cannot be read or is beyond the JSON inputs'
    /// size bound): the input's fault.
    #[error("{0}")]
    HistoryLine(String),
    /// The history file cannot be written.
    #[error("{0}")]
    History(String),
}
