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
//! Python binding runs every workflow with the GIL released). The
//! constructor takes the few values a request cannot do without; the rest
//! are public fields with the CLI's defaults.
//!
//! The root is a curated handful: one module per workflow ([`calibrate`],
//! [`check`], [`compensate`], [`detectability`], [`diagnosis`],
//! [`effects`], [`export`], [`fleet`], [`identifiability`], [`kinematics`],
//! [`plan`], [`report`], [`simulate`]), each with its function, its request, its result and the
//! parts they are made of; the error with its exit codes; and the two
//! inputs. The typed values several requests share, the machine loaded
//! ahead of a workflow and the few low-level items code beside the door
//! needs are in [`advanced`].
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
mod commanding;
mod data_input;
mod error;
mod inputs;
mod json_version;
mod limits;
mod linalg;
mod machine_file;
mod machine_input;

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
pub use error::{
    EXIT_INADEQUATE, EXIT_INPUT, EXIT_NOT_CONVERGED, EXIT_OK, EXIT_OTHER, Error, ErrorCause,
    ErrorKind,
};

// The two inputs every workflow is fed: the machine and the measured data.
pub use data_input::DataInput;
pub use machine_input::MachineInput;

// Crate-internal shorthands (the workflows' files use `crate::NAME`).
pub(crate) use error::Classify;
pub(crate) use inputs::parse_effects;
