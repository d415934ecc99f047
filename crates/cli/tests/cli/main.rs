//! The `tricept` binary end to end, one test binary: bad inputs, the check,
//! a closed stdout, the embedded docs, the exit-code table, the fused
//! identification, what writing survives, the report page, and a
//! calibration a user can trust (one module per subject; what they share
//! in `support`).

mod bad_inputs;
mod check;
mod closed_stdout;
mod docs;
mod exit_codes;
mod export;
mod fusion;
mod one_exit_code;
mod outputs;
mod relied_on;
mod report;
mod support;
mod trust;
