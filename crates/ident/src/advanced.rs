//! Beyond the workflows' modules: the typed values several requests are
//! made of, the machine loaded ahead of a workflow, and the few low-level
//! items of the internal crates that code beside the door (the `tricept`
//! binary, the Python binding, the benchmarks) needs. Most users need only
//! the root and a workflow's module; everything here may change with the
//! workflows that use it.
//!
//! - **Request values**: each parses from the text of the CLI flag that
//!   sets it ([`std::str::FromStr`], so the binary's clap value parsers
//!   are these types): [`Triple`] (`X,Y,Z`), [`HeadAngles`],
//!   [`TrueErrors`] (`--truth`), [`FrameMmRad`] (`--tracker-frame-mm-rad`),
//!   [`Poses`], [`TrackerTargetSpec`], [`LengthSigma`], [`HeadModel`],
//!   [`EffectNames`], [`EvalGrid`]; the sensor-noise overrides
//!   ([`SensorNoise`]) and the parameter set ([`ParameterSet`]).
//! - **The machine loaded ahead**: [`load_machine`] gives a
//!   [`crate::LoadedMachine`] (its description, its warnings), which
//!   converts into the [`crate::MachineInput`] every request takes (as
//!   [`crate::MachineInput::load`] does).
//! - **Output format**: the `format_version` of the JSON outputs
//!   ([`OUTPUT_FORMAT_VERSION`]) and the one way it is put into one
//!   ([`versioned_json`]: what `--json` prints).
//! - **Result parts**: the machine file a result may write
//!   ([`crate::calibrate::MachineFile`], kept apart from it, to write later
//!   by the same rule). The result's shape
//!   ([`crate::Outcome`], [`crate::WritesMachine`]), how it writes
//!   ([`crate::WriteOptions`], [`crate::Written`]) and the accuracy a
//!   written file promises ([`crate::calibrate::Accuracy`]) are at the root
//!   and in the workflows' modules.
//! - **Low level**: the error mapping of the internal crates' errors
//!   ([`Classify`]; the file-system failure under one is the root's
//!   [`crate::FileFailure`]), the reader of data in memory
//!   ([`read_data_from`], giving the root's [`crate::Dataset`]),
//!   and the foreign crates whose types results hold (`nalgebra`,
//!   `serde_json`).
//! - **Beside the door**: files written as every verb writes them
//!   ([`files`]), the figures ([`plot`]), and the defaults the binary's
//!   flags show ([`DEFAULT_TOLERANCE_MM`], [`DEFAULT_POWER`],
//!   [`fusable_effects`]).
//!
//! # Example
//! ```
//! use tricept_ident::LoadedMachine;
//! use tricept_ident::advanced::{SensorNoise, load_machine};
//! let noise = SensorNoise { length_noise_um: Some(2.0), ..SensorNoise::default() };
//! let loaded: LoadedMachine = load_machine(None, &noise)?;
//! assert!(loaded.warnings().is_empty());
//! # Ok::<(), tricept_ident::Error>(())
//! ```

pub use crate::calibrate::values::{
    EffectNames, EvalGrid, HeadModel, LengthSigma, TrackerTargetSpec,
};
pub use crate::data_input::read_data_from;
pub use crate::error::Classify;
pub use crate::inputs::{
    FrameMmRad, HeadAngles, Poses, SensorNoise, Triple, TrueErrors, load_machine, parse_effects,
    parse_numbers,
};
pub use crate::json_version::{OUTPUT_FORMAT_VERSION, versioned_json};
pub use nalgebra;
pub use serde_json;

/// The power a planned check detects its stated change with by default.
///
/// # Example
/// ```
/// use tricept_ident::advanced::DEFAULT_POWER;
/// use tricept_ident::plan::{Instrument, PlanRequest};
/// assert_eq!(PlanRequest::new(Instrument::Check).power, DEFAULT_POWER);
/// ```
#[doc(inline)]
pub use tricept_check::check::DEFAULT_POWER;
// The internal crates' errors the door's [`Error`](crate::Error) is made
// from ([`Classify`]).
pub use tricept_check::CheckError;
pub use tricept_data::DataError;
/// One pose of measured data (a [`crate::Dataset`]'s `poses`).
///
/// # Example
/// ```
/// use tricept_ident::advanced::{MeasuredPose, read_data_from};
/// use tricept_ident::kinematics::GeometricMachine;
/// let csv = "q1,q2,q3,phi,theta,s\n700,701,702,0,0,5\n";
/// let data = read_data_from(csv.as_bytes(), "memory", &GeometricMachine::paper())?;
/// let pose: &MeasuredPose = &data.poses[0];
/// assert_eq!(pose.commands_mm, [700.0, 701.0, 702.0]);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_data::MeasuredPose;
pub use tricept_data::Readings;
pub use tricept_diagnose::{DeployError, DiagnoseError};

/// The manufacturing tolerance a calibration is judged against by default, mm.
///
/// # Example
/// ```
/// use tricept_ident::advanced::DEFAULT_TOLERANCE_MM;
/// use tricept_ident::calibrate::CalibrateRequest;
/// assert_eq!(CalibrateRequest::new("campaign.csv").tolerance_mm, DEFAULT_TOLERANCE_MM);
/// ```
#[doc(inline)]
pub use tricept_engine::accuracy::DEFAULT_TOLERANCE_MM;
pub use tricept_engine::fusion::{TrackerTarget, fusable_effects};
pub use tricept_engine::{IdentError, record::RecordError};
pub use tricept_fleet::FleetError;
pub use tricept_model::GeometricErrors;
pub use tricept_model::ModelError;
/// Which geometric errors a calibration identifies.
///
/// # Example
/// ```
/// use tricept_ident::advanced::ParameterSet;
/// use tricept_ident::calibrate::CalibrateRequest;
/// let set = CalibrateRequest::new("campaign.csv").parameter_set;
/// assert_eq!(set.len(), set.names().len());
/// assert_eq!(ParameterSet::paper15().len(), 15);
/// ```
#[doc(inline)]
pub use tricept_model::ParameterSet;
pub use tricept_numerics::sparse::BlockError;
pub use tricept_plant::PlantError;
/// The figures of the verbs that draw (SVG, written atomically).
#[doc(inline)]
pub use tricept_plot as plot;
pub use tricept_study::StudyError;

/// Files written as every verb writes them (atomic: temporary file and
/// rename; `-` for stdout) and messages made one bounded line.
///
/// # Example
/// ```
/// use tricept_ident::advanced::files::one_line;
/// let message = one_line("a message\nover two lines");
/// assert!(!message.contains('\n'));
/// ```
pub mod files {
    /// A message made one bounded line, as every error of the door is.
    ///
    /// # Example
    /// ```
    /// use tricept_ident::advanced::files::one_line;
    /// assert_eq!(one_line("two\nlines"), one_line(&one_line("two\nlines")));
    /// assert!(!one_line("two\nlines").contains('\n'));
    /// ```
    #[doc(inline)]
    pub use tricept_data::message::one_line;
    /// A path as a message shows it (control characters escaped).
    ///
    /// # Example
    /// ```
    /// use tricept_ident::advanced::files::shown_path;
    /// assert_eq!(shown_path(std::path::Path::new("a\nb.csv")), "a\\nb.csv");
    /// ```
    #[doc(inline)]
    pub use tricept_data::message::shown_path;
    pub use tricept_data::{
        atomic::check_output_file, external::write_external_path, write_atomic, write_path,
        write_to,
    };
}
