//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! Measured data against the model: does the paper's geometric model
//! explain the data; if not, which effects of the vocabulary explain it,
//! what lies outside the vocabulary (described by a generic dictionary),
//! what the campaign cannot tell apart, what is implausible, what remains
//! unexplained; by how much the causes biased the geometric parameters,
//! and what the extended model gains.
//!
//! The crate is layered; a file imports only from its own layer or those
//! below (checked by `xtask/tests/tidy.rs`), bottom to top:
//!
//! 1. **Options and errors**: [`DiagnoseOptions`] and [`DictionaryOptions`](crate::options::DictionaryOptions)
//!    (`options.rs`), [`DiagnoseError`] and [`DeployError`] (`error.rs`),
//!    the plausibility table ([`Plausibility`](crate::plausibility::Plausibility), `plausibility.rs`), the
//!    report's types, JSON and text ([`Diagnosis`], `report.rs`; `finite.rs`:
//!    no non-finite number leaves it), the tests' reference distributions
//!    (`evidence.rs`).
//! 2. **The model**: the terms ([`Term`](crate::terms::Term): an effect of the vocabulary,
//!    whose spec is in [`tricept_model::effects`], or a [`GenericTerm`](crate::terms::GenericTerm)) and
//!    the campaign [`Frame`](crate::terms::Frame) (`terms.rs`); [`ExtendedModel`] (`model.rs`),
//!    the geometric model plus any terms.
//! 3. **The fit core** (`fit.rs`): a fitted model, the settings every fit
//!    shares, cross-validation, residuals, the outlier screen.
//! 4. **The analyses**: the linearised score of further terms (`linear/`),
//!    the generic dictionary and its period scan (`dictionary.rs`), pure
//!    error (`noise.rs`), selection from one pool with admission on the
//!    final model (`select.rs`), aliases (`alias.rs`), the platform's
//!    displacement between calibrations (`gain.rs`), residual structure and
//!    plots (`residuals.rs`).
//! 5. **Description and report assembly**: a named cause in words
//!    (`describe.rs`), the report from what the pipeline found
//!    (`assemble.rs`).
//! 6. **Orchestration**: [`diagnose`] (`run.rs`: checks, noise, outlier
//!    screen, selection, report), [`deploy`](fn@deploy) (`deploy.rs`: the final model
//!    into a machine file), [`detect`] (what a campaign can detect, before it
//!    is run).
//!
//! # Example
//! ```no_run
//! use tricept_diagnose::{DiagnoseOptions, diagnose};
//! use tricept_kinematics::Machine;
//! let m = Machine::paper();
//! let data = tricept_data::read_path("fixtures/data/diagnose-pitch.csv".as_ref()).unwrap();
//! let d = diagnose(&m, &data, &DiagnoseOptions::for_machine(&m)).unwrap();
//! println!("{:?}: {:?}", d.verdict, d.causes.iter().map(|c| &c.description).collect::<Vec<_>>());
//! ```
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

// Layers, bottom to top: a file imports only from its own layer or those
// below (`xtask/tests/tidy.rs` checks it).
// Layer 1: options and errors
mod error;
mod evidence;
pub mod finite;
pub mod options;
pub mod plausibility;
pub mod report;
#[cfg(test)]
mod testing;
// Layer 2: the model
mod model;
pub mod terms;
// Layer 3: the fit core
mod fit;
// Layer 4: dictionary, noise, selection, aliases, gain and residual plots
mod alias;
mod dictionary;
mod gain;
mod holdout;
mod linear;
pub mod noise;
mod residuals;
mod select;
// Layer 5: description and report assembly
mod assemble;
mod describe;
// Layer 6: orchestration: the diagnosis, its deployment, detectability
pub mod deploy;
pub mod detect;
mod run;

pub use deploy::{Deployed, deploy};
pub use error::{DeployError, DiagnoseError};
pub use model::ExtendedModel;
pub use options::DiagnoseOptions;
pub use report::Diagnosis;
pub use run::diagnose;
