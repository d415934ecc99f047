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
//! One request style: every workflow takes its request **by value**
//! (`calibrate(CalibrateRequest::new("data.csv"))`), and measured data are
//! always a [`DataInput`] (a file, a file already read, or a data set in
//! memory). A request describes one run and is spent by it: by value, the
//! workflow keeps the data it was given (a calibration holds its data
//! without copying them), and a caller can move a request to another thread
//! (the Python binding runs every workflow with the GIL released). The
//! constructor takes the few values a request cannot do without; the rest
//! are public fields with the CLI's defaults.
//!
//! The root is a curated set: the workflows (one function per verb), their
//! requests and results, the error with its exit codes, and the domain
//! types every user needs. The typed values requests are made of, the parts
//! of results and the few low-level items code beside the door needs are in
//! [`advanced`].
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
mod limits;
mod machine_file;

// Layer 1: the workflows.
mod calibrate;
mod check;
mod compensate;
mod data_input;
mod detectability;
mod diagnosis;
mod effects;
mod identifiability;
mod kinematics;
mod plan;
mod simulate;

// Layer 2: what a downstream crate may need besides the curated root.
pub mod advanced;

// The curated root: xtask/tests/tidy.rs holds this list and fails when the
// root grows past it. A new item goes into `advanced` unless it is a
// workflow, its request or result, the error, or a domain type every user
// needs.

// The workflows: one function per verb.
pub use calibrate::calibrate;
pub use check::check;
pub use compensate::compensate;
pub use detectability::detectability;
pub use diagnosis::diagnose;
pub use effects::effects;
pub use export::export;
pub use identifiability::assess_identifiability;
pub use kinematics::solve_point;
pub use plan::plan;
pub use simulate::simulate;

// Their requests, and what a request's constructor needs.
pub use calibrate::CalibrateRequest;
pub use check::CheckRequest;
pub use compensate::{Calibrated, CompensateRequest};
pub use detectability::DetectabilityRequest;
pub use diagnosis::DiagnoseRequest;
pub use export::ExportRequest;
pub use identifiability::{Campaign, IdentifiabilityRequest};
pub use kinematics::Verb as KinematicsVerb;
pub use plan::{Instrument, PlanRequest};
pub use simulate::SimulateRequest;

// Their results, each with its verdict (`exit_code()`).
pub use calibrate::Calibration;
pub use check::CheckResult;
pub use compensate::Compensation;
pub use detectability::DetectabilityReport;
pub use diagnosis::DiagnoseResult;
pub use effects::EffectList;
pub use export::Export;
pub use identifiability::Identifiability;
pub use kinematics::PointSolution;
pub use plan::Plan;
pub use simulate::Simulation;

// The error and the exit codes.
pub use error::{
    EXIT_INADEQUATE, EXIT_INPUT, EXIT_NOT_CONVERGED, EXIT_OK, EXIT_OTHER, Error, ErrorKind,
};

// The domain: the machine, the parameters, the data, the poses.
pub use data_input::DataInput;
pub use inputs::{LoadedMachine, Poses, SensorNoise, load_machine};
pub use nalgebra;
pub use tricept_kinematics::Machine;
pub use tricept_model::{ExtendedMachine, ParameterSet};

// Crate-internal shorthands (the workflows' files use `crate::NAME`).
pub(crate) use error::Classify;
pub(crate) use inputs::parse_effects;
