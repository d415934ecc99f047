//! internal: use tricept-ident (the door; this crate's items change with it).
//!
//! Feature unification, so that every target of the workspace compiles each
//! third-party crate once.
//!
//! Cargo compiles a crate once per feature set, and a crate's hash covers
//! its dependencies' hashes: when one target (say the tests, through a
//! dev-dependency) turns on one more feature of a small crate such as
//! `serde` or `typenum`, every crate above it (nalgebra, faer, gemm, ...)
//! is compiled a second time. `cargo xtask encoder-study`, `cargo test
//! --workspace`, `cargo run -p tricept-cli` and `cargo run -p
//! tricept-example-downstream` then each rebuild most of the dependencies.
//!
//! This crate has no code. Its `Cargo.toml` depends on those crates with the
//! union of the features the workspace's targets turn on, and
//! `tricept-engine` (which every binary and the downstream example build on)
//! depends on it, so every build resolves the same features. This is the
//! pattern of `cargo hakari`'s workspace-hack crates, kept by hand: `cargo
//! xtask one-build`, run by `.ci/run` after the tests, builds each README
//! target and fails naming any third-party crate it had to compile again.
