//! `tricept-ident`: the one door to tricept. Everything a `tricept` verb
//! does is a function here that takes a typed request and returns a typed
//! result with its verdict and its exit code: calibrate (the UP limb's
//! sensors alone or fused with external measurements), diagnose and deploy,
//! compensate, plan, check and simulate. The binary only translates flags
//! into requests and results into text or JSON.
//!
//! Behind the door are internal crates (`publish = false`) whose items may
//! change with the door: `tricept-engine` (identification), `tricept-diagnose`,
//! `tricept-check`, `tricept-study`, `tricept-plant`, `tricept-model`,
//! `tricept-kinematics` and `tricept-data`. ARCHITECTURE.md draws the split.
//!
//! Errors: every failure is an [`Error`] whose [`ErrorKind`] decides the
//! process exit code, one mapping for every verb ([`Error::exit_code`]).
//!
#![doc = include_str!("first_example.md")]
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

// Layer 0: errors, limits and inputs.
mod accuracy;
mod error;
mod export;
mod inputs;
pub mod limits;
pub mod machine_file;
pub use export::{
    AxisSummary, Controller, Export, ExportError, ExportOptions, ExportRequest, ExportSummary,
    NotExported, export,
};

// Layer 1: the workflows.
mod calibrate;
mod compensate;
mod identifiability;
mod plan;

// Workflows of the diagnosis, the check, the simulator and the kinematics
// (issue 27, helper B).
mod check;
mod data_input;
mod detectability;
mod diagnosis;
mod effects;
pub mod kinematics;
mod simulate;

pub use error::{
    Classify, EXIT_INADEQUATE, EXIT_INPUT, EXIT_NOT_CONVERGED, EXIT_OK, EXIT_OTHER, Error,
    ErrorKind,
};
pub use inputs::{
    HeadAngles, LoadedMachine, Poses, SensorNoise, Triple, TrueErrors, check_commands,
    description_error, load_machine, parse_effects, parse_head_angles, parse_numbers, positive,
    read_data, read_data_from,
};

pub use calibrate::values::{
    EffectNames, EvalGrid, HeadModel, LengthSigma, TrackerTargetSpec, eval_options, fused_model,
};
pub use calibrate::{
    CalibrateRequest, Calibration, Data, FusedSources, Written, calibrate, exit_line,
};

pub use accuracy::Accuracy;
pub use check::{CheckRequest, CheckResult, check};
pub use compensate::{
    Calibrated, CompensateRequest, Compensation, CorrectedTarget, MAP_FILES, TABLE_ERROR_LIMIT_UM,
    TABLE_FILES, compensate,
};
pub use data_input::DataInput;
pub use detectability::{DetectabilityReport, DetectabilityRequest, detectability};
pub use diagnosis::{Deployed, DiagnoseRequest, DiagnoseResult, diagnose, vocabulary_help};
pub use effects::{EffectList, effects};
pub use identifiability::{
    Campaign, Identifiability, IdentifiabilityRequest, assess_identifiability,
};
pub use plan::{Instrument, Plan, PlanRequest, plan};
pub use simulate::{
    BallbarSimulation, HeadErrors, SimulateRequest, Simulation, TouchSimulation, TrackerSimulation,
    TruthEffects, simulate,
};
pub use tricept_check::history::Trend;
pub use tricept_check::{CheckReport, DEFAULT_ALPHA as DEFAULT_CHECK_ALPHA};
pub use tricept_diagnose::detect::Detectability;
pub use tricept_diagnose::{Diagnosis, ResidualPlot};
pub use tricept_plant::Effect;

// Transitional: the engine's API as it was when it was `tricept-ident`,
// curated by issue 27 ("One door") into the workflows above. Not `Start`
// nor `identify_from` (the study's and xtask's, through the engine), nor
// the engine's `Compensation` (the door's is the workflow's result).
pub use tricept_engine::fusion;
pub use tricept_engine::{
    ADEQUACY_ALPHA, AccuracyModel, BARELY_SEEN_STD_DEV_MM, Combination, CompensationTable,
    CorrelatedPair, DEFAULT_TOLERANCE_MM, Design, GeometricModel, GeometricPredictor,
    INCONSISTENT_CHI2_PER_DOF, IdentError, IdentifiabilityReport, Identification, IdentifyOptions,
    LARGE_ESTIMATE_MM, LikelyCause, MAX_TABLE_NODES, NamedValues, Observability, PosePredictor,
    PredictedAccuracy, RECORD_METHODS, ReadingModel, RecordError, Rejection, ResidualStats,
    SPACING_LADDER_MM, Verdict, WORTHWHILE_RATIO, accuracy_points, check_calibration_record,
    compensation, corrected_commands, design, identifiability, identify, identify_robust,
    likely_causes, residuals_at, screen_gross_errors, screen_gross_errors_with_fit, solve_pose,
};
// What a downstream crate needs besides the door's own types: every crate
// whose types the public API takes or returns, and those types at the root.
pub use tricept_engine::{
    BallbarData, DataError, Dataset, EffectName, Effector, ErrorMap, ExtendedMachine, ExternalPose,
    Features, HeadBranch, HeadParameterSet, KinematicsError, LegGeometry, Machine,
    MachineDescription, MapStats, MeasuredPose, ModelError, ParameterSet, Readings, TouchData,
    TrackerData, UpJoints, Workspace, read_from, read_path,
};
pub use tricept_engine::{nalgebra, serde_json, tricept_data, tricept_kinematics, tricept_model};
