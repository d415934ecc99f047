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
//! (`calibrate::calibrate(CalibrateRequest::new("data.csv"))`); a machine is
//! always a [`MachineInput`] (a description file with sensor-noise
//! overrides, or a machine loaded already) and measured data are always a
//! [`DataInput`] (a file, a file already read, or a data set in memory). A
//! request describes one run and is spent by it: by value, the workflow
//! keeps the data it was given (a calibration holds its data without
//! copying them), and a caller can move a request to another thread (the
//! Python binding runs every workflow with the GIL released).
//!
//! Requests: `new` takes exactly what the workflow cannot do without, in
//! this order: what it works on (the measured data of calibrate, diagnose,
//! check and fleet; the calibrated machine that check, compensate, export
//! and report read; the campaign that identifiability and detectability
//! assess; the instrument plan plans for), then what the output is for and
//! where it goes (export's control, export's and report's folder or page).
//! Everything else has a default (the machine is the embedded Table 1
//! machine unless the workflow reads a calibration from it) and is a
//! public field with a chainable setter of the same name, so
//! `CalibrateRequest::new("d.csv").tolerance_mm(0.01)` and
//! `DiagnoseRequest::new("d.csv").machine("calibrated.json")` read alike
//! (requests are `#[non_exhaustive]`: a field added later gets its setter,
//! and no caller breaks). Paths convert from `&str`, `String`, `&String`,
//! `&Path`, `PathBuf` and `&PathBuf` wherever a request takes a
//! [`MachineInput`], a [`DataInput`] or a path.
//!
//! Results: every workflow's result has one shape, the [`Outcome`] trait
//! (also each result's own methods): `exit_code()`, `reason()` (why the
//! exit code is not 0; `None` when it is), `report()` (the text the verb
//! prints) and `to_json()` (what `--json` prints, `format_version`
//! first). A result that writes a machine file also has the shape of
//! [`WritesMachine`]: `accuracy()` (what the file promises) and
//! `write_machine(&self, path, WriteOptions)`, which returns the
//! [`Written`] file or the refusal as an [`Error`].
//!
//! ```
//! use tricept_ident::calibrate::{CalibrateRequest, calibrate};
//! use tricept_ident::{Outcome, WriteOptions};
//! let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/data/table2-grid-seed1.csv");
//! let calibration = calibrate(CalibrateRequest::new(data).tolerance_mm(0.05))?;
//! assert_eq!(calibration.reason(), None);
//! assert_eq!(calibration.to_json()["format_version"], 1);
//! let out = std::env::temp_dir().join(format!("tricept-lib-doc-{}.json", std::process::id()));
//! let written = calibration.write_machine(&out, WriteOptions::default())?;
//! assert!(written.forced().is_none());
//! # std::fs::remove_file(&out).ok();
//! # Ok::<(), tricept_ident::Error>(())
//! ```
//!
//! The root is a curated handful: one module per workflow ([`calibrate`],
//! [`check`], [`compensate`], [`detectability`], [`diagnosis`],
//! [`effects`], [`export`], [`fleet`], [`identifiability`], [`kinematics`],
//! [`plan`], [`report`], [`simulate`]), each with its function, its request, its result and the
//! parts they are made of; the error with its exit codes; the two inputs
//! and the machine loaded from one ([`LoadedMachine`]); the result's shape
//! and how a result writes its file. The typed values several requests
//! share and the few low-level items code beside the door needs are in
//! [`advanced`].
//!
//! Errors: every failure is an [`Error`] whose [`ErrorKind`] decides the
//! process exit code, one mapping for every verb ([`Error::exit_code`]),
//! and whose [`ErrorCause`] ([`Error::cause`]) says what failed for a
//! program to match on (a file not found, a parse error at a line and
//! column, a sealed file edited, a refused write, ...).
//!
//! Commanding a machine: [`kinematics::Machine`] applies everything a
//! machine file carries (the geometry and the leg effects a diagnosis
//! deploys), as `tricept ik --machine` does; the geometric machine alone
//! is only [`kinematics::Machine::geometry`].
//!
#![doc = include_str!("first_example.md")]
#![deny(missing_docs)]
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

// Layer 0: errors, limits and inputs.
mod accuracy;
mod classify;
mod commanding;
mod data_input;
mod error;
mod inputs;
mod json_version;
mod limits;
mod linalg;
mod machine_file;
mod machine_input;
mod outcome;
mod request;
mod setting;

// Layer 1: the workflows, one public module each (its function, its
// request, its result and the parts they are made of).
pub mod calibrate;
pub mod check;
pub mod compensate;
pub mod detectability;
pub mod diagnosis;
pub mod effects;
pub mod export;
pub mod fleet;
pub mod identifiability;
pub mod kinematics;
pub mod plan;
pub mod report;
pub mod simulate;

// Layer 2: what a downstream crate may need besides the workflows.
pub mod advanced;

// The curated root: xtask/tests/tidy.rs holds this list and fails when the
// root grows past it. A new item goes into its workflow's module, or into
// `advanced`, unless every user needs it.

// The error and the exit codes.
pub use error::FileFailure;
pub use error::{
    EXIT_INADEQUATE, EXIT_INPUT, EXIT_NOT_CONVERGED, EXIT_OK, EXIT_OTHER, Error, ErrorCause,
    ErrorKind,
};
pub use setting::Setting;

// The two inputs every workflow is fed: the machine and the measured data,
// and the machine as `MachineInput::load` returns it.
pub use data_input::DataInput;
pub use inputs::LoadedMachine;
pub use machine_input::MachineInput;
/// Measured data in memory (what a [`DataInput`] loads).
///
/// # Example
/// ```
/// use tricept_ident::Dataset;
/// use tricept_ident::advanced::read_data_from;
/// use tricept_ident::kinematics::GeometricMachine;
/// let csv = "q1,q2,q3,phi,theta,s\n700,700,700,0,0,5\n701,699,700,0.001,0,5\n";
/// let data: Dataset = read_data_from(csv.as_bytes(), "memory", &GeometricMachine::paper())?;
/// assert_eq!(data.poses.len(), 2);
/// # Ok::<(), tricept_ident::Error>(())
/// ```
#[doc(inline)]
pub use tricept_data::Dataset;

// The one shape of every workflow's result, and how one writes its file.
pub use outcome::{Outcome, WriteOptions, WritesMachine, Written};

// Crate-internal shorthands (the workflows' files use `crate::NAME`).
pub(crate) use error::Classify;
pub(crate) use inputs::parse_effects;
