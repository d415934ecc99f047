//! Beyond the curated root: the typed values requests are made of, the
//! parts of results, and the few low-level items of the internal crates
//! that code beside the door (the `tricept` binary, the Python binding, the
//! benchmarks) needs. Most users need only the root; everything here may
//! change with the workflows that use it.
//!
//! - **Request values**: each parses from the text of the CLI flag that
//!   sets it ([`std::str::FromStr`], so the binary's clap value parsers
//!   are these types): [`Triple`] (`X,Y,Z`), [`HeadAngles`],
//!   [`TrueErrors`] (`--truth`), [`TruthEffects`] (`--truth-effect`),
//!   [`FrameMmRad`] (`--tracker-frame-mm-rad`),
//!   [`HeadErrors`], [`TrackerTargetSpec`], [`LengthSigma`], [`HeadModel`],
//!   [`EffectNames`], [`EvalGrid`]; and the parts of a request:
//!   [`FusedSources`], the simulated instruments, the export's
//!   [`ExportOptions`].
//! - **Result parts**: the reports inside results ([`CheckReport`],
//!   [`Diagnosis`], [`Detectability`], ...), the [`Accuracy`] a written
//!   file promises, the file names a workflow
//!   writes, the batch kinematics ([`solve_batch`], [`run`]).
//! - **Low level**: the error mapping of the internal crates' errors
//!   ([`Classify`]), the kinematics' errors and branches, the data set in
//!   memory ([`Dataset`]), and `serde_json`, whose `Value` results return.

pub use crate::accuracy::Accuracy;
pub use crate::calibrate::Written;
pub use crate::calibrate::values::{
    EffectNames, EvalGrid, FusedSources, HeadModel, LengthSigma, TrackerTargetSpec,
};
pub use crate::compensate::{CorrectedTarget, MAP_FILES, TABLE_ERROR_LIMIT_UM, TABLE_FILES};
pub use crate::diagnosis::{Deployed, vocabulary_help};
pub use crate::error::Classify;
pub use crate::export::{
    AxisSummary, Controller, ExportError, ExportOptions, ExportSummary, NotExported,
};
pub use crate::inputs::{
    FrameMmRad, HeadAngles, Triple, TrueErrors, parse_effects, parse_numbers, read_data_from,
};
pub use crate::kinematics::{BLOCK_ROWS, BatchError, Cell, machine_summary, run, solve_batch};
pub use crate::simulate::{
    BallbarSimulation, HeadErrors, TouchSimulation, TrackerSimulation, TruthEffects,
};
pub use serde_json;
pub use tricept_check::history::Trend;
pub use tricept_check::{CheckReport, DEFAULT_ALPHA as DEFAULT_CHECK_ALPHA};
pub use tricept_data::Dataset;
pub use tricept_diagnose::detect::Detectability;
pub use tricept_diagnose::{Diagnosis, ResidualPlot};
pub use tricept_engine::{IdentError, IdentifiabilityReport};
pub use tricept_kinematics::{HeadBranch, KinematicsError, MachineDescription};
pub use tricept_model::ErrorMap;
pub use tricept_model::effects::EffectName;
pub use tricept_plant::Effect;
