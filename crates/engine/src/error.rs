//! Typed errors of the identification crate.

use thiserror::Error;
use tricept_kinematics::KinematicsError;

/// Why an identification could not produce a trustworthy answer.
///
#[cfg_attr(
    any(doc, doctest),
    doc = r#"
# Example
```
use tricept_engine::{model::GeometricModel, IdentifyOptions};
use tricept_kinematics::Machine;
use tricept_model::ParameterSet;
let m = Machine::paper();
let model = GeometricModel::new(m.clone(), ParameterSet::paper15());
let e = tricept_engine::identify(&model, &tricept_data::Dataset::default(), &IdentifyOptions::for_machine(&m))
    .unwrap_err();
assert!(matches!(e, tricept_engine::IdentError::TooFewPoses { poses: 0, .. }));
```
"#
)]
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum IdentError {
    /// Fewer readings than unknowns (plus one for a residual).
    #[error(
        "too few poses: {poses} poses give {readings} readings for {unknowns} unknowns (parameters + 3 sensor offsets); at least {needed} poses are needed"
    )]
    TooFewPoses {
        /// Poses given.
        poses: usize,
        /// Readings (3 per pose).
        readings: usize,
        /// Unknowns.
        unknowns: usize,
        /// Minimum number of poses.
        needed: usize,
    },
    /// Enough rows, but too few distinct poses: rows repeating the same
    /// commands average the noise and add no geometry.
    #[error(
        "too few distinct poses: the {poses} rows hold {distinct} distinct leg commands, and {unknowns} unknowns (parameters + 3 sensor offsets) need at least {needed} distinct poses"
    )]
    TooFewDistinctPoses {
        /// Rows given.
        poses: usize,
        /// Distinct command triples among them (counted up to `needed`).
        distinct: usize,
        /// Unknowns.
        unknowns: usize,
        /// Minimum number of distinct poses.
        needed: usize,
    },
    /// A pose the model cannot solve (commands out of reach, no assembly...).
    #[error("pose {} (line {line}): {source}", pose + 1)]
    Kinematics {
        /// Index of the pose (0-based; shown 1-based).
        pose: usize,
        /// Line of the pose in its file (0 if none).
        line: u64,
        /// The kinematic failure.
        source: KinematicsError,
    },
    /// A numerical failure of the linear algebra.
    #[error("numerical failure: {0}")]
    Numerical(&'static str),
    /// Inconsistent arguments.
    #[error("{0}")]
    Invalid(String),
    /// External data that cannot be used as given (too few records, a
    /// degenerate geometry), naming the source and, where one record is at
    /// fault, its line.
    #[error("{file}{}: {message}", line.map(|l| format!(": line {l}")).unwrap_or_default())]
    Source {
        /// The source's file or label.
        file: String,
        /// The line at fault, if one is.
        line: Option<u64>,
        /// What is wrong and what to do.
        message: String,
    },
    /// A source's own nuisance parameters (an instrument's frame, a pivot,
    /// a target offset) cannot be told apart from its data: the estimate
    /// would divide by rounding noise.
    #[error("{file}: {combination} cannot be determined from its data: {hint}")]
    NuisanceUnidentifiable {
        /// The source's file or label.
        file: String,
        /// The invisible combination of its nuisance parameters.
        combination: String,
        /// What to measure differently.
        hint: String,
    },
}
