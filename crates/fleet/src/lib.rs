//! internal: use tricept-ident. Pooled calibration: every campaign a
//! machine ran, every machine of a batch (`docs/fleet.md`).
//!
//! - `reml.rs`: the batch's spread by REML and a machine's distance from
//!   the rest;
//! - `campaigns.rs`: the campaigns of one machine pooled, each campaign's
//!   share and whether it agrees with the rest ([`agreements`]);
//! - `own.rs`: each machine alone (its own calibration and exit code) and
//!   the batch's rank decision;
//! - `joint.rs`: the joint fit of every member's readings on the sparse
//!   core ([`tricept_numerics::sparse`]);
//! - `batch.rs`: the hierarchical model end to end ([`calibrate_batch`]);
//! - `prior_file.rs`: the batch's prior for a new machine, sealed, with its
//!   provenance ([`PriorFile`]);
//! - `report.rs`: a batch as JSON and text.
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

// Layer 0: errors and the batch's statistics.
mod error;
pub mod reml;

// Layer 1: campaigns pooled, machines alone, and all of them at once.
mod campaigns;
mod joint;
mod own;

// Layer 2: the batch, and what it says of a new machine.
mod batch;
mod prior_file;
mod report;

pub use batch::{Batch, BatchOptions, MIN_MACHINES, MachineOutcome, calibrate_batch};
pub use campaigns::{Agreement, Agreements, agreements, campaign_chi_squares, pool};
pub use error::FleetError;
pub use joint::{JointFit, JointInput, first_step_problem, fit as joint_fit};
pub use own::{EXIT_INADEQUATE, EXIT_INPUT, EXIT_NOT_CONVERGED, EXIT_OK, OwnFit, batch_design};
pub use prior_file::{
    DataFileRecord, NamedCovariance, PRIOR_FORMAT, PRIOR_FORMAT_VERSION, PriorFile, PriorProvenance,
};
pub use tricept_numerics::sparse::{SolveStats, SolverKind};
