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
//!   [`LoadedMachine`] (its description, its warnings), which converts into
//!   the [`crate::MachineInput`] every request takes.
//! - **Output format**: the `format_version` of the JSON outputs
//!   ([`OUTPUT_FORMAT_VERSION`]) and the one way it is put into one
//!   ([`versioned_json`]: what `--json` prints).
//! - **Result parts** several workflows share: the [`Accuracy`] a written
//!   file promises, the [`MachineFile`] a result may write (kept apart
//!   from it, to write later by the same rule).
//! - **Low level**: the error mapping of the internal crates' errors
//!   ([`Classify`], and the file-system failure under one, [`FileFailure`]), the data set in memory ([`Dataset`]) and its reader,
//!   and the foreign crates whose types results hold (`nalgebra`,
//!   `serde_json`).
//! - **Beside the door**: files written as every verb writes them
//!   ([`files`]), the figures ([`plot`]), and the defaults the binary's
//!   flags show ([`DEFAULT_TOLERANCE_MM`], [`DEFAULT_POWER`],
//!   [`fusable_effects`]).
//!
//! # Example
//! ```
//! use tricept_ident::advanced::{LoadedMachine, SensorNoise, load_machine};
//! let noise = SensorNoise { length_noise_um: Some(2.0), ..SensorNoise::default() };
//! let loaded: LoadedMachine = load_machine(None, &noise)?;
//! assert!(loaded.warnings().is_empty());
//! # Ok::<(), tricept_ident::Error>(())
//! ```

pub use crate::accuracy::Accuracy;
pub use crate::calibrate::values::{
    EffectNames, EvalGrid, HeadModel, LengthSigma, TrackerTargetSpec,
};
pub use crate::data_input::read_data_from;
pub use crate::error::{Classify, FileFailure};
pub use crate::inputs::{
    FrameMmRad, HeadAngles, LoadedMachine, Poses, SensorNoise, Triple, TrueErrors, load_machine,
    parse_effects, parse_numbers,
};
pub use crate::json_version::{OUTPUT_FORMAT_VERSION, versioned_json};
pub use crate::machine_file::MachineFile;
pub use nalgebra;
pub use serde_json;
pub use tricept_check::DEFAULT_POWER;
// The internal crates' errors the door's [`Error`](crate::Error) is made
// from ([`Classify`]).
pub use tricept_check::CheckError;
pub use tricept_data::DataError;
pub use tricept_data::{Dataset, MeasuredPose, Readings};
pub use tricept_diagnose::{DeployError, DiagnoseError};

/// The door: the manufacturing tolerance a calibration is judged against by default, mm.
///
/// # Example
/// ```
/// use tricept_ident::advanced::DEFAULT_TOLERANCE_MM;
/// use tricept_ident::calibrate::CalibrateRequest;
/// assert_eq!(CalibrateRequest::new("campaign.csv").tolerance_mm, DEFAULT_TOLERANCE_MM);
/// ```
#[doc(inline)]
pub use tricept_engine::DEFAULT_TOLERANCE_MM;
pub use tricept_engine::fusion::{TrackerTarget, fusable_effects};
pub use tricept_engine::{IdentError, RecordError};
pub use tricept_fleet::FleetError;
pub use tricept_model::ModelError;
pub use tricept_model::{GeometricErrors, ParameterSet};
pub use tricept_numerics::sparse::BlockError;
pub use tricept_plant::PlantError;
/// The figures of the verbs that draw (SVG, atomic): `tricept_plot`.
pub use tricept_plot as plot;
pub use tricept_study::StudyError;

/// Files written as every verb writes them (atomic: temporary file and
/// rename; `-` for stdout) and messages made one bounded line, from
/// `tricept_data`.
///
/// # Example
/// ```
/// use tricept_ident::advanced::files::one_line;
/// let message = one_line("a message\nover two lines");
/// assert!(!message.contains('\n'));
/// ```
pub mod files {
    pub use tricept_data::{
        check_output_file, one_line, shown_path, write_atomic, write_external_path, write_path,
        write_to,
    };
}
