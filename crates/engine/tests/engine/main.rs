//! The identification engine's integration tests, one binary: the internal
//! identification, the fused identification and its trust, and the fuzz
//! regressions, campaigns pooled and a prior (one module per subject;
//! shared helpers in `common`).

mod common;
mod fusion;
mod fusion_trust;
mod fuzz_regressions;
mod identification;
mod pooled;
