//! Measured data against the model: does the paper's geometric model
//! explain the data; if not, which effects of the vocabulary explain it,
//! what lies outside the vocabulary (described by a generic dictionary),
//! what the campaign cannot tell apart, what is implausible, what remains
//! unexplained; by how much the causes biased the geometric parameters,
//! and what the extended model gains.
//!
//! - [`diagnose`] (`run.rs`): the pipeline: checks, noise, outlier screen,
//!   selection, aliases, final adequacy and remainder, report.
//! - `terms.rs`: the terms of an extended model ([`Term`]: a [`Candidate`]
//!   of the vocabulary or a [`GenericTerm`]) and the campaign [`Frame`].
//! - `dictionary.rs`, `linear.rs`: the generic dictionary, its period scan
//!   and linear screen.
//! - `select.rs`: one pool of candidates, the evidence rules, swaps,
//!   admission on the final model, cross-validation.
//! - `plausibility.rs` ([`Plausibility`]), `alias.rs`, `noise.rs`,
//!   `evidence.rs`: physical ranges, aliases, pure error, test references.
//! - `residuals.rs`: residual structure and residual plots.
//! - [`Diagnosis`] (`report.rs`): the report, as data, JSON and text;
//!   `finite.rs`: no non-finite number leaves it.
//! - [`ExtendedModel`] (`model.rs`): the geometric model plus any terms
//!   ([`tricept_model::effects`]).
//! - [`detect`]: what a campaign can detect, before it is run.
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

mod alias;
pub mod detect;
mod dictionary;
mod evidence;
mod finite;
mod linear;
mod model;
mod noise;
mod plausibility;
mod report;
mod residuals;
mod run;
mod select;
mod terms;

pub use dictionary::DictionaryOptions;
pub use finite::first_non_finite;
pub use model::{Candidate, ExtendedModel, MIN_TEMPERATURE_RANGE_K, REFERENCE_TEMPERATURE_C};
pub use noise::NOISE_CHECK_LEVEL;
pub use plausibility::{Plausibility, PlausibilityError, Range};
pub use report::{
    Alias, Cause, CauseKind, ChannelRms, Diagnosis, Estimate, Evidence, FinalFit, Gain, NoiseCheck,
    NoiseSource, PureError, RejectStage, Rejected, Remainder, ResidualPlot, Structure, TermScore,
    Tested, Verdict,
};
pub use run::{DiagnoseError, DiagnoseOptions, MIN_PURE_ERROR_DOF, diagnose};
pub use terms::{Frame, GenericTerm, OrderAxis, Scope, Term};
pub use tricept_model::effects::{CauseName, GenericFamily};
