//! The study's integration tests, one binary: planning, the check's plan,
//! differencing, invisible errors, predictions against independent
//! machines, and the study itself (one module per subject; an independent
//! simulator in the `tricept-truth` crate).

mod check_plan;
mod differencing;
mod invisible;
mod plan;
mod predictions;
mod study;
