//! internal: use tricept-ident. Pooled calibration: every campaign a
//! machine ran, every machine of a batch (`docs/fleet.md`).
//!
//! - `reml.rs`: the batch's spread by REML and a machine's distance from
//!   the rest;
//! - `campaigns.rs`: the campaigns of one machine pooled, each campaign's
//!   share and whether it agrees with the rest ([`agreements`](crate::campaigns::agreements));
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
pub mod campaigns;
pub mod joint;
pub mod own;

// Layer 2: the batch, and what it says of a new machine.
pub mod batch;
pub mod prior_file;
mod report;

pub use batch::{Batch, BatchOptions, calibrate_batch};
pub use error::FleetError;
pub use prior_file::PriorFile;
