//! Fuzz-target properties for `cargo fuzz` (see `checks.rs`).
mod checks;
pub use checks::*;
