//! Measured data against the model: does the paper's geometric model
//! explain the data; if not, which unmodelled effect does, by how much it
//! biased the geometric parameters, and what the extended model gains.
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod detect;
pub mod diagnose;
pub mod model;

pub use model::{Candidate, ExtendedModel};
