//! The check's integration tests, one binary (one module per subject):
//! every branch of the verdict and its statistics (`branches`), tallies of
//! hidden changes on plant campaigns (`changes`), and the set of changes
//! and warm machines (`sets`); `common` builds calibrated machines and
//! their check campaigns. `cargo test -p tricept-check --test check
//! changes:: -- --nocapture` prints the TALLY lines docs/check.md quotes.

mod branches;
mod changes;
mod common;
mod sets;
