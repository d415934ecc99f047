//! The library half of the `tricept` command: what is worth benchmarking
//! and testing without spawning the binary. [`batch`] streams many points
//! from CSV through `ik`, `fk` or `tool-ik`.
//!
//! The binary (`src/main.rs`) holds the verbs; see `tricept --help`.
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod batch;
