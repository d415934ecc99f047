//! internal: use tricept-ident. Pooled calibration: every campaign a
//! machine ran, every machine of a batch (`docs/fleet.md`).
//!
//! - `reml.rs`: the batch's spread by REML and a machine's distance from
//!   the rest.
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

mod error;
pub mod reml;

pub use error::FleetError;
