//! The `tricept` binary end to end, one test binary: bad inputs, the check,
//! a closed stdout, the embedded docs, the edges (special files, `-`,
//! refusals before work, the history lock, bounded messages), the
//! exit-code table, the fused identification, pooled campaigns and
//! batches, the seal, seeded fuzzing of every input kind, what writing
//! survives, the report page, and a calibration a user can trust (one
//! module per subject; what they share in `support`).

mod bad_inputs;
mod check;
mod closed_stdout;
mod compat;
mod docs;
mod door;
mod edges;
mod exit_codes;
mod export;
mod fleet;
mod fusion;
mod fuzz;
mod golden;
mod one_exit_code;
mod outputs;
mod relied_on;
mod report;
mod schema;
mod seal;
mod support;
mod trust;
