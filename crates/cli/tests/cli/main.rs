//! The `tricept` binary end to end, one test binary: bad inputs, the check,
//! a closed stdout, the embedded docs, the exit-code table, the fused
//! identification, pooled campaigns and batches, what writing survives, and a calibration a user can
//! trust (one module per subject; what they share in `support`).

mod bad_inputs;
mod check;
mod closed_stdout;
mod docs;
mod exit_codes;
mod export;
mod fleet;
mod fusion;
mod one_exit_code;
mod outputs;
mod relied_on;
mod support;
mod trust;
