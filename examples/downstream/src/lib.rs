//! No code: this library exists for its doc test, which is `tricept-ident`'s
//! first documented example compiled in a crate whose only dependency is
//! `tricept-ident` (the program is `src/main.rs`).
//!
#![doc = include_str!("../../../crates/ident/src/first_example.md")]
